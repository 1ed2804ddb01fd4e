//! Intervals whose coverage is measured: an estimator's 68% and 95% intervals taken from the
//! residuals ln(E_true / E_est) of held-out presses rather than from its own fit.
//!
//! The residuals are grouped in bins of the estimated modulus (soft and hard fruit are read
//! with different errors: a soft one makes a wide contact, a hard one hardly dents). Each bin
//! keeps its median residual, the estimator's bias there, which recentres new estimates
//! (interpolated linearly in ln E between bin medians, so that the order of two close
//! estimates never flips), and the quantiles at 2.5, 16, 84 and 97.5% of what is left. A new
//! estimate gets its recentred value times exp(those quantiles): a split-conformal interval,
//! which holds the truth on new presses as often as on the held-out ones when both come from
//! the same kind of scene. The quantile levels are widened by (n + 1) / n, the finite-sample
//! correction.
//!
//! A press's error grows with what its own reading leaves open (a depth fit through three
//! frames pins the modulus far less than one through eight: on the held-out presses of two
//! real sensors' profiles |residual| and the fit's own standard error correlate at 0.85), so
//! the residuals are taken in units of sqrt(se^2 + floor^2), se the estimate's own standard
//! error in ln E and floor the held-out presses' median se (normalised conformal scores): a
//! press the estimator itself reads loosely gets a wide interval, a well-pinned one a narrow
//! one, and coverage still holds over the presses as a whole.
//!
//! Elongated contacts (a banana's first touch is a line across the pad, its imprint runs off
//! the frame) are read with another bias than round ones: when the held-out set has enough of
//! them they get bins of their own, chosen by the contact's aspect in the estimate's evidence.

use crate::hardness::estimate::{
    EstimateError, Evidence, HardnessEstimate, HardnessEstimator, ModulusInterval, PhysicsEvidence,
    PressSequence,
};
use crate::hardness::scale::Hardness;
use crate::stats::quantile;
use crate::tactile::sensor_profile::{ProfileId, SensorProfile};
use crate::tactile::spec::TactileSpec;
use serde::{Deserialize, Serialize};

pub const FORMAT: &str = "tactex-interval-calibration/2";
/// The format before residuals were scaled by each press's own error: read as unscaled.
const FORMAT_UNSCALED: &str = "tactex-interval-calibration/1";
/// The two-sided levels: 68% and 95%.
const LEVELS: [f64; 4] = [0.025, 0.16, 0.84, 0.975];
/// A first contact this many times longer than wide is elongated. On the held-out presses of
/// seed 101 every banana's was 3.3-8.1 and every other fruit's at most 1.8.
pub const ELONGATED_ASPECT: f64 = 2.5;
/// The fewest held-out presses a bin may rest on: below about 40 the 2.5% and 97.5%
/// quantiles are each one press.
pub const MIN_PER_BIN: usize = 40;

#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct IntervalCalibration {
    pub format: String,
    /// The estimator whose residuals these are (`HardnessEstimator::name`).
    pub estimator: String,
    /// The twin's contact physics the held-out presses were made at.
    pub fidelity: String,
    /// How the held-out presses were made (the command), so that anyone can make them again.
    pub protocol: String,
    /// The presses `bins` rest on: all of them, or the round contacts when `elongated_contact`
    /// holds the others.
    pub presses: usize,
    pub bins: Vec<ResidualBin>,
    /// The bins of presses whose first contact was elongated (`ELONGATED_ASPECT`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub elongated_contact: Option<ResidualGroup>,
    /// The sensor the held-out presses were rendered with and read through; absent: the
    /// built-in GelSight Mini. Residuals measured through one sensor say nothing of another's.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sensor: Option<ProfileId>,
    /// The floor (ln E) of the scale the residuals are in units of, sqrt(se^2 + floor^2);
    /// absent: residuals in ln E, whatever the press's own error.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub own_se_floor_ln: Option<f64>,
}

/// One group of held-out presses and its bins.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct ResidualGroup {
    pub presses: usize,
    pub bins: Vec<ResidualBin>,
}

#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct ResidualBin {
    /// Estimates with ln(E_est / MPa) below this fall in the bin (the last bin: no edge).
    pub ln_modulus_below: Option<f64>,
    pub presses: usize,
    /// Median ln(E_est / MPa) of the bin's presses, and their median ln(E_true / E_est):
    /// the recentring at that estimate.
    pub ln_modulus_median: f64,
    pub median_residual: f64,
    /// Quantiles of ln(E_true / E_recentred) at 2.5, 16, 84 and 97.5%, in units of the
    /// press's scale when the calibration has `own_se_floor_ln`.
    pub residual_quantiles: [f64; 4],
}

/// One held-out press: the estimator's raw ln(E_est / MPa), the residual ln(E_true / E_est),
/// whether its first contact was elongated, and the estimator's own standard error in ln E
/// (`ModulusInterval::ln_half_width68` of its uncalibrated interval).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HeldOutPress {
    pub ln_estimate: f64,
    pub residual: f64,
    pub elongated: bool,
    pub own_ln_se: Option<f64>,
}

#[derive(Debug, thiserror::Error)]
pub enum CalibrationError {
    #[error("{source_name}: {message}")]
    Invalid {
        source_name: String,
        message: String,
    },
}

/// Whether a first contact of this aspect (wide over narrow) is elongated.
pub fn is_elongated(first_contact_aspect: f64) -> bool {
    first_contact_aspect >= ELONGATED_ASPECT
}

/// Whether an estimate's first contact was elongated, as its evidence says (None: its
/// evidence does not say).
fn elongated_contact(evidence: &Evidence) -> Option<bool> {
    match evidence {
        Evidence::Physics(PhysicsEvidence {
            first_contact_aspect: Some(aspect),
            ..
        }) => Some(is_elongated(*aspect)),
        _ => None,
    }
}

impl IntervalCalibration {
    /// Fits the bins from held-out presses: as many equal-count bins as hold `MIN_PER_BIN`
    /// presses each, up to `max_bins`; the elongated contacts apart when both groups have
    /// `MIN_PER_BIN`.
    pub fn fit(
        estimator: &str,
        fidelity: &str,
        protocol: &str,
        samples: &[HeldOutPress],
        max_bins: usize,
    ) -> Result<Self, CalibrationError> {
        let invalid = |message: String| CalibrationError::Invalid {
            source_name: format!("calibration of {estimator}"),
            message,
        };
        if samples.iter().any(|s| {
            !(s.ln_estimate.is_finite()
                && s.residual.is_finite()
                && s.own_ln_se.is_none_or(|se| se.is_finite() && se >= 0.0))
        }) {
            return Err(invalid(
                "a residual, estimate or standard error is not finite".into(),
            ));
        }
        if samples.len() < MIN_PER_BIN {
            return Err(invalid(format!(
                "{} held-out presses; at least {MIN_PER_BIN} are needed",
                samples.len()
            )));
        }
        // The median own error over the presses that state one; none: unscaled. A floor of
        // zero (every press pinned exactly) would divide by zero, so it is kept above 1e-3.
        let own: Vec<f64> = samples.iter().filter_map(|s| s.own_ln_se).collect();
        let floor = quantile(&own, 0.5).ok().map(|m| m.max(1e-3));
        let pairs = |elongated: Option<bool>| -> Vec<Scored> {
            samples
                .iter()
                .filter(|s| elongated.is_none_or(|e| s.elongated == e))
                .map(|s| Scored {
                    ln_estimate: s.ln_estimate,
                    residual: s.residual,
                    scale: scale(floor, s.own_ln_se),
                })
                .collect()
        };
        let (round, long) = (pairs(Some(false)), pairs(Some(true)));
        let (main, elongated_contact) = if round.len() >= MIN_PER_BIN && long.len() >= MIN_PER_BIN {
            let group = ResidualGroup {
                presses: long.len(),
                bins: fit_bins(long, max_bins),
            };
            (round, Some(group))
        } else {
            (pairs(None), None)
        };
        Ok(Self {
            format: FORMAT.into(),
            estimator: estimator.into(),
            fidelity: fidelity.into(),
            protocol: protocol.into(),
            presses: main.len(),
            bins: fit_bins(main, max_bins),
            sensor: None,
            elongated_contact,
            own_se_floor_ln: floor,
        })
    }

    /// Reads and checks a calibration file's text; `source_name` names it in errors.
    pub fn parse(text: &str, source_name: &str) -> Result<Self, CalibrationError> {
        let invalid = |message: String| CalibrationError::Invalid {
            source_name: source_name.into(),
            message,
        };
        let c: Self = serde_json::from_str(text).map_err(|e| invalid(e.to_string()))?;
        match (c.format.as_str(), c.own_se_floor_ln) {
            (FORMAT, Some(f)) if !(f.is_finite() && f > 0.0) => {
                return Err(invalid(
                    "own_se_floor_ln: must be finite and positive".into(),
                ));
            }
            (FORMAT, _) | (FORMAT_UNSCALED, None) => {}
            (FORMAT_UNSCALED, Some(_)) => {
                return Err(invalid(format!(
                    "own_se_floor_ln: not read by {FORMAT_UNSCALED:?}"
                )));
            }
            _ => return Err(invalid(format!("format: {:?} is not {FORMAT:?}", c.format))),
        }
        check_bins(&c.bins, "bins").map_err(invalid)?;
        if let Some(group) = &c.elongated_contact {
            check_bins(&group.bins, "elongated_contact.bins").map_err(invalid)?;
        }
        Ok(c)
    }

    /// The sensor these residuals were measured through.
    pub fn measured_through(&self) -> ProfileId {
        self.sensor
            .clone()
            .unwrap_or_else(|| SensorProfile::gelsight_mini().id())
    }

    /// The bins for a press, with the presses they rest on and what sets them apart.
    fn group(&self, elongated: bool) -> (&[ResidualBin], usize, &'static str) {
        match (&self.elongated_contact, elongated) {
            (Some(g), true) => (&g.bins, g.presses, " with an elongated contact"),
            _ => (&self.bins, self.presses, ""),
        }
    }

    /// The recentred estimate of a raw `modulus_mpa`.
    fn recentred(&self, modulus_mpa: f64, elongated: bool) -> f64 {
        let (bins, _, _) = self.group(elongated);
        modulus_mpa * shift_at(&centres(bins), modulus_mpa.ln()).exp()
    }

    /// The calibrated intervals for a raw estimate of `modulus_mpa` whose own standard error
    /// in ln E is `own_ln_se`, around its recentred value.
    pub fn interval(
        &self,
        modulus_mpa: f64,
        elongated: bool,
        own_ln_se: Option<f64>,
    ) -> ModulusInterval {
        let (bins, presses, group) = self.group(elongated);
        let ln = modulus_mpa.ln();
        let bin = bins
            .iter()
            .find(|b| b.ln_modulus_below.is_none_or(|edge| ln < edge))
            .expect("the last bin has no edge");
        let e = self.recentred(modulus_mpa, elongated);
        let k = scale(self.own_se_floor_ln, own_ln_se);
        let [a, b, c, d] = bin.residual_quantiles.map(|q| Some(e * (k * q).exp()));
        ModulusInterval {
            p68_mpa: [b, c],
            p95_mpa: [a, d],
            source: format!(
                "calibrated on {presses} held-out presses{group} at {} ({} in this bin; the estimator's {:.3} MPa recentred by {:+.0}%{})",
                self.fidelity,
                bin.presses,
                modulus_mpa,
                100.0 * (e / modulus_mpa - 1.0),
                match (self.own_se_floor_ln, own_ln_se) {
                    (Some(_), Some(se)) =>
                        format!("; widths scaled by its own error, {se:.3} in ln E"),
                    _ => String::new(),
                }
            ),
            calibrated: true,
        }
    }
}

/// A held-out press as the bins take it: its residual's scale is `scale`'s.
struct Scored {
    ln_estimate: f64,
    residual: f64,
    scale: f64,
}

/// The scale a press's residual is taken in: sqrt(se^2 + floor^2), an unstated se counted as
/// the floor; 1 for an unscaled calibration.
fn scale(floor: Option<f64>, own_ln_se: Option<f64>) -> f64 {
    match floor {
        Some(f) => {
            let se = own_ln_se.filter(|v| v.is_finite()).unwrap_or(f);
            se.hypot(f)
        }
        None => 1.0,
    }
}

/// Equal-count bins of held-out presses (at least `MIN_PER_BIN` of them), by estimate.
fn fit_bins(mut sorted: Vec<Scored>, max_bins: usize) -> Vec<ResidualBin> {
    sorted.sort_by(|a, b| a.ln_estimate.total_cmp(&b.ln_estimate));
    let bins = (sorted.len() / MIN_PER_BIN).clamp(1, max_bins.max(1));
    let n = sorted.len();
    let mut out = Vec::with_capacity(bins);
    let range = |b: usize| (b * n / bins, (b + 1) * n / bins);
    let median = |v: Vec<f64>| quantile(&v, 0.5).expect("a bin is not empty");
    let centres: Vec<(f64, f64)> = (0..bins)
        .map(|b| {
            let (lo, hi) = range(b);
            let part = &sorted[lo..hi];
            (
                median(part.iter().map(|s| s.ln_estimate).collect()),
                median(part.iter().map(|s| s.residual).collect()),
            )
        })
        .collect();
    for (b, &(ln_modulus_median, median_residual)) in centres.iter().enumerate() {
        let (lo, hi) = range(b);
        let residuals: Vec<f64> = sorted[lo..hi]
            .iter()
            .map(|s| (s.residual - shift_at(&centres, s.ln_estimate)) / s.scale)
            .collect();
        let m = residuals.len() as f64;
        let widen = |q: f64| (0.5 + (q - 0.5) * (m + 1.0) / m).clamp(0.0, 1.0);
        let residual_quantiles = LEVELS
            .map(|q| quantile(&residuals, widen(q)).expect("non-empty, finite, level in [0, 1]"));
        let ln_modulus_below =
            (b + 1 < bins).then(|| (sorted[hi - 1].ln_estimate + sorted[hi].ln_estimate) / 2.0);
        out.push(ResidualBin {
            ln_modulus_below,
            presses: residuals.len(),
            ln_modulus_median,
            median_residual,
            residual_quantiles,
        });
    }
    out
}

/// Checks one set of bins as read from a file; `field` names it in the message.
fn check_bins(bins: &[ResidualBin], field: &str) -> Result<(), String> {
    if bins.is_empty() {
        return Err(format!("{field}: none"));
    }
    for (i, b) in bins.iter().enumerate() {
        let q = b.residual_quantiles;
        if q.iter().any(|v| !v.is_finite()) || q.windows(2).any(|w| w[0] > w[1]) {
            return Err(format!(
                "{field}[{i}].residual_quantiles: must be finite and rising"
            ));
        }
        let last = i + 1 == bins.len();
        match (b.ln_modulus_below, last) {
            (Some(_), true) => {
                return Err(format!(
                    "{field}[{i}].ln_modulus_below: the last bin has no edge"
                ));
            }
            (None, false) => return Err(format!("{field}[{i}].ln_modulus_below: missing")),
            (Some(e), false) if !e.is_finite() => {
                return Err(format!("{field}[{i}].ln_modulus_below: not finite"));
            }
            _ => {}
        }
    }
    let edges: Vec<f64> = bins.iter().filter_map(|b| b.ln_modulus_below).collect();
    if edges.windows(2).any(|w| w[0] >= w[1]) {
        return Err(format!("{field}: edges must rise"));
    }
    let centres = centres(bins);
    if centres
        .iter()
        .any(|(a, b)| !(a.is_finite() && b.is_finite()))
        || centres.windows(2).any(|w| w[0].0 >= w[1].0)
    {
        return Err(format!(
            "{field}: ln_modulus_median and median_residual must be finite, medians rising"
        ));
    }
    // Recentring must keep the order of estimates: ln E + shift(ln E) must rise.
    if centres
        .windows(2)
        .any(|w| (w[1].1 - w[0].1) / (w[1].0 - w[0].0) <= -1.0)
    {
        return Err(format!(
            "{field}: the recentring would reverse the order of estimates"
        ));
    }
    Ok(())
}

fn centres(bins: &[ResidualBin]) -> Vec<(f64, f64)> {
    bins.iter()
        .map(|b| (b.ln_modulus_median, b.median_residual))
        .collect()
}

/// The recentring ln(E_true / E_est) at `ln_modulus`: linear between the bins' medians,
/// constant beyond the first and last.
fn shift_at(centres: &[(f64, f64)], ln_modulus: f64) -> f64 {
    let (first, last) = (centres[0], centres[centres.len() - 1]);
    if ln_modulus <= first.0 {
        return first.1;
    }
    if ln_modulus >= last.0 {
        return last.1;
    }
    let w = centres
        .windows(2)
        .find(|w| ln_modulus <= w[1].0)
        .expect("inside the range");
    let t = (ln_modulus - w[0].0) / (w[1].0 - w[0].0);
    w[0].1 + t * (w[1].1 - w[0].1)
}

/// An estimator whose intervals come from a calibration; its estimates are its inner one's.
pub struct Calibrated<E> {
    pub inner: E,
    pub calibration: IntervalCalibration,
}

impl<E: HardnessEstimator> HardnessEstimator for Calibrated<E> {
    fn name(&self) -> &str {
        self.inner.name()
    }

    fn estimate(
        &self,
        press: &PressSequence,
        spec: &TactileSpec,
    ) -> Result<HardnessEstimate, EstimateError> {
        let mut estimate = self.inner.estimate(press, spec)?;
        let elongated = elongated_contact(&estimate.evidence) == Some(true);
        // A rigid reading keeps the estimator's own bound: no held-out press was rigid.
        if let Some(e) = estimate.hardness.modulus_mpa().filter(|e| *e > 0.0) {
            let own = estimate.interval.ln_half_width68();
            estimate.interval = self.calibration.interval(e, elongated, own);
            let recentred = Hardness::from_modulus_mpa(self.calibration.recentred(e, elongated))
                .map_err(|err| EstimateError::Model(format!("recentred estimate: {err}")))?;
            estimate.hardness = recentred;
        }
        Ok(estimate)
    }

    fn cannot_read(&self, spec: &TactileSpec, frames: usize) -> Option<String> {
        self.inner.cannot_read(spec, frames)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A deterministic stand-in for a normal residual: the inverse normal CDF at evenly
    /// spaced levels (exact quantiles, no sampling noise), shifted by `bias`.
    fn normal_residuals(n: usize, sigma: f64, bias: f64) -> Vec<f64> {
        let normal = statrs::distribution::Normal::new(0.0, 1.0).unwrap();
        use statrs::distribution::ContinuousCDF;
        (0..n)
            .map(|i| bias + sigma * normal.inverse_cdf((i as f64 + 0.5) / n as f64))
            .collect()
    }

    fn held_out(pairs: impl IntoIterator<Item = (f64, f64)>, elongated: bool) -> Vec<HeldOutPress> {
        pairs
            .into_iter()
            .map(|(ln_estimate, residual)| HeldOutPress {
                ln_estimate,
                residual,
                elongated,
                own_ln_se: None,
            })
            .collect()
    }

    #[test]
    fn normal_residuals_give_the_normal_intervals_and_each_bin_its_own() {
        // Soft estimates scatter by 0.1 in ln E and read 5% low; hard ones scatter by 0.3.
        let mut samples: Vec<(f64, f64)> = normal_residuals(400, 0.1, 0.05)
            .into_iter()
            .enumerate()
            .map(|(i, r)| (-1.0 + 0.001 * i as f64, r))
            .collect();
        samples.extend(
            normal_residuals(400, 0.3, 0.0)
                .into_iter()
                .enumerate()
                .map(|(i, r)| (1.0 + 0.001 * i as f64, r)),
        );
        let c = IntervalCalibration::fit("test", "layer", "test", &held_out(samples, false), 2)
            .unwrap();
        assert_eq!(c.bins.len(), 2);
        assert!(c.elongated_contact.is_none());
        // Below the first bin's median the bias applies whole: the soft read is raised 5%.
        let soft_e = (-1.0f64).exp();
        assert!((c.recentred(soft_e, false) / soft_e - 0.05f64.exp()).abs() < 0.005);
        let soft = c.interval(soft_e, false, None);
        let [lo, hi] = soft.p68_mpa.map(|v| (v.unwrap() / soft_e).ln());
        assert!(
            (lo - (0.05 - 0.1)).abs() < 0.01 && (hi - (0.05 + 0.1)).abs() < 0.01,
            "{lo} {hi}"
        );
        let hard = c.interval(3.0, false, None);
        let [lo, hi] = hard.p95_mpa.map(|v| (v.unwrap() / 3.0).ln());
        assert!(
            (lo + 1.96 * 0.3).abs() < 0.02 && (hi - 1.96 * 0.3).abs() < 0.02,
            "{lo} {hi}"
        );
        let text = serde_json::to_string(&c).unwrap();
        let back = IntervalCalibration::parse(&text, "t.json").unwrap();
        for (a, b) in back.bins.iter().zip(&c.bins) {
            for (x, y) in a.residual_quantiles.iter().zip(b.residual_quantiles) {
                assert!((x - y).abs() < 1e-12);
            }
        }
    }

    #[test]
    fn presses_read_loosely_get_wide_intervals_and_each_kind_is_covered() {
        // Presses pinned to 0.05, 0.1 and 0.4 in ln E by their own fits, each erring by its own
        // error beside a model error of the median's size (0.1): unscaled intervals would be
        // too wide for the first and too narrow for the last; scaled ones hold 68% and 95% of
        // each kind.
        let groups = [(0.05, 150), (0.1, 100), (0.4, 150)];
        let err = |se: f64| f64::hypot(se, 0.1);
        let samples: Vec<HeldOutPress> = groups
            .iter()
            .flat_map(|&(se, n)| {
                normal_residuals(n, 1.0, 0.0)
                    .into_iter()
                    .enumerate()
                    .map(move |(i, z)| HeldOutPress {
                        ln_estimate: 0.001 * i as f64,
                        residual: err(se) * z,
                        elongated: false,
                        own_ln_se: Some(se),
                    })
            })
            .collect();
        let c = IntervalCalibration::fit("indentation", "layer", "", &samples, 1).unwrap();
        assert_eq!(c.own_se_floor_ln, Some(0.1));
        for (se, _) in groups {
            let z = normal_residuals(100, 1.0, 0.0);
            let cover = |wide: bool| {
                let inside = z
                    .iter()
                    .filter(|&&z| {
                        let truth = 2.0 * (err(se) * z).exp();
                        c.interval(2.0, false, Some(se)).holds(truth, wide) == Some(true)
                    })
                    .count();
                inside as f64 / z.len() as f64
            };
            assert!(
                (0.62..=0.74).contains(&cover(false)),
                "se {se}: {}",
                cover(false)
            );
            assert!(
                (0.92..=0.98).contains(&cover(true)),
                "se {se}: {}",
                cover(true)
            );
        }
        let floor = 0.1;
        let width = |se| {
            let [lo, hi] = c.interval(2.0, false, Some(se)).p68_mpa;
            (hi.unwrap() / lo.unwrap()).ln()
        };
        assert!(width(0.4) > 3.0 * width(0.05));
        // A press that states no error is taken at the floor; an unscaled file ignores it.
        assert_eq!(
            width(floor),
            c.interval(2.0, false, None).ln_half_width68().unwrap() * 2.0
        );
        let back =
            IntervalCalibration::parse(&serde_json::to_string(&c).unwrap(), "c.json").unwrap();
        assert_eq!(back.own_se_floor_ln, c.own_se_floor_ln);
    }

    #[test]
    fn a_file_of_the_unscaled_format_is_read_unscaled_and_a_bad_floor_refused() {
        let samples = held_out(
            (0..80).map(|i| (0.01 * i as f64, 0.1 * (i % 7) as f64)),
            false,
        );
        let mut unscaled = IntervalCalibration::fit("learned", "layer", "", &samples, 1).unwrap();
        assert_eq!(unscaled.own_se_floor_ln, None);
        unscaled.format = FORMAT_UNSCALED.into();
        let text = serde_json::to_string(&unscaled).unwrap();
        let back = IntervalCalibration::parse(&text, "old.json").unwrap();
        assert_eq!(
            back.interval(2.0, false, Some(3.0)),
            back.interval(2.0, false, None)
        );
        let mut bad = unscaled.clone();
        bad.own_se_floor_ln = Some(0.1);
        let e = IntervalCalibration::parse(&serde_json::to_string(&bad).unwrap(), "old.json")
            .unwrap_err();
        assert!(
            e.to_string().starts_with("old.json: own_se_floor_ln"),
            "{e}"
        );
        bad.format = FORMAT.into();
        bad.own_se_floor_ln = Some(-1.0);
        let e = IntervalCalibration::parse(&serde_json::to_string(&bad).unwrap(), "c.json")
            .unwrap_err();
        assert!(e.to_string().contains("finite and positive"), "{e}");
    }

    #[test]
    fn too_few_presses_and_broken_files_are_refused_with_the_field() {
        let few = held_out((0..10).map(|i| (i as f64, 0.0)), false);
        let e = IntervalCalibration::fit("learned", "layer", "", &few, 3).unwrap_err();
        assert!(e.to_string().contains("at least 40"), "{e}");
        let ok = IntervalCalibration::fit(
            "learned",
            "layer",
            "",
            &held_out((0..80).map(|i| (i as f64, 0.01 * i as f64)), false),
            2,
        )
        .unwrap();
        let mut flips = ok.clone();
        flips.bins[1].median_residual = flips.bins[0].median_residual
            - 2.0 * (flips.bins[1].ln_modulus_median - flips.bins[0].ln_modulus_median);
        let e = IntervalCalibration::parse(&serde_json::to_string(&flips).unwrap(), "c.json")
            .unwrap_err();
        assert!(e.to_string().contains("reverse the order"), "{e}");
        let mut bad = ok.clone();
        bad.bins[0].residual_quantiles = [0.1, 0.0, 0.2, 0.3];
        let e = IntervalCalibration::parse(&serde_json::to_string(&bad).unwrap(), "c.json")
            .unwrap_err();
        assert!(
            e.to_string()
                .starts_with("c.json: bins[0].residual_quantiles"),
            "{e}"
        );
        let e = IntervalCalibration::parse("{}", "c.json").unwrap_err();
        assert!(e.to_string().starts_with("c.json: "), "{e}");
    }

    #[test]
    fn elongated_contacts_get_their_own_recentring() {
        // Round contacts read 25% soft; elongated ones 5% hard.
        let mut samples = held_out(
            normal_residuals(200, 0.1, 0.25)
                .into_iter()
                .enumerate()
                .map(|(i, r)| (0.005 * i as f64, r)),
            false,
        );
        samples.extend(held_out(
            normal_residuals(60, 0.1, -0.05)
                .into_iter()
                .enumerate()
                .map(|(i, r)| (0.01 * i as f64, r)),
            true,
        ));
        let c = IntervalCalibration::fit("indentation", "layer", "", &samples, 1).unwrap();
        assert_eq!(
            (c.presses, c.elongated_contact.as_ref().unwrap().presses),
            (200, 60)
        );
        let shift = |elongated| (c.recentred(1.5, elongated) / 1.5).ln();
        assert!((shift(false) - 0.25).abs() < 0.01, "{}", shift(false));
        assert!((shift(true) + 0.05).abs() < 0.01, "{}", shift(true));
        assert!(
            c.interval(1.5, true, None)
                .source
                .contains("elongated contact")
        );
        let back =
            IntervalCalibration::parse(&serde_json::to_string(&c).unwrap(), "c.json").unwrap();
        let (a, b) = (
            back.elongated_contact.unwrap(),
            c.elongated_contact.clone().unwrap(),
        );
        assert_eq!(a.presses, b.presses);
        assert!((a.bins[0].median_residual - b.bins[0].median_residual).abs() < 1e-12);
        // Too few elongated contacts for bins of their own: one set for all.
        let c = IntervalCalibration::fit("indentation", "layer", "", &samples[..230], 1).unwrap();
        assert!(c.elongated_contact.is_none());
        assert_eq!(c.presses, 230);
    }
}
