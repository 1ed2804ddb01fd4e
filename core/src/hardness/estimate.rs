//! Hardness from a press sequence, behind one trait so that learned models (ONNX) and the
//! physics inversions are interchangeable.
//!
//! Two physics estimators read how much of the robot's travel the gel took. This one fits the
//! Hertz half-space slope field and so suits a gel that behaves as a half-space (the
//! Hertz-level twin); `indentation_estimator` fits the gel's integrated indentation with the
//! bonded layer's stiffening and holds for any shape on the real 4 mm gel. In Hertz contact
//! each body's surface moves by its compliance share of the approach, so the gel's slope field
//! is s * du/dr of the Hertz displacement with s = c_gel / (c_gel + c_object). From the frames
//! it recovers the gel's surface slopes (photometric inversion against the no-contact frame),
//! finds the contact centre, and fits the local object radius R, the approach at the first
//! contact frame and the share s to all frames at the known arm travel. The object's modulus
//! follows from s and the gel's modulus.

use crate::frames::TactileFrame;
use crate::hardness::scale::Hardness;
use crate::hertz::{Elastic, Hertz, object_modulus_from_share};
use crate::tactile::slopes::{ColourDrift, SlopeField, recover_slopes};
use crate::tactile::spec::TactileSpec;
use serde::Serialize;

/// What the press routine records for one object.
#[derive(Clone, Debug)]
pub struct PressSequence {
    /// The no-contact frame taken just above the object.
    pub reference: TactileFrame,
    /// Frames from the first contact frame on, one per press step.
    pub frames: Vec<TactileFrame>,
    /// Arm travel of each frame past the first contact frame (mm).
    pub travel_mm: Vec<f64>,
}

/// The evidence an estimate rests on, so that explanations can cite it.
#[derive(Clone, Debug, Serialize, PartialEq)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Evidence {
    /// A physics inversion: how the travel split between gel and object.
    Physics(PhysicsEvidence),
    /// A learned model: which model read which frames, and how far its answers spread.
    Learned(LearnedEvidence),
}

#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct LearnedEvidence {
    /// The model file and the runtime that ran it (tract or ONNX Runtime).
    pub model: String,
    pub backend: String,
    /// Press frames read (0-based from the first contact frame).
    pub frames_used: Vec<usize>,
    /// Standard deviation of ln(E) over the flipped copies of the input.
    pub flip_spread_ln: f64,
    /// The model's RMSE in ln(E) on held-out shapes, from its model card.
    pub heldout_rmse_ln: f64,
    /// The sensor its training data was drawn around, where its card says.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub trained_on_sensor: Option<String>,
    /// Set when the frames come from another sensor than that: what this means.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub other_sensor: Option<String>,
}

#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct PhysicsEvidence {
    /// Share of the approach taken by the gel, and its standard error.
    pub gel_share: f64,
    pub gel_share_se: f64,
    /// Local radius of the object at the contact (mm).
    pub local_radius_mm: f64,
    /// Total approach of gel and object at the first contact frame (mm).
    pub first_contact_approach_mm: f64,
    /// Contact radius at the last frame (mm).
    pub last_contact_radius_mm: f64,
    /// Gel indentation at the last frame (mm).
    pub last_gel_indentation_mm: f64,
    pub frames_used: usize,
    /// Centre compliance of the bonded gel layer relative to the half-space at the last
    /// frame's contact size (1: the half-space split).
    pub gel_layer_factor: f64,
    /// RMS residual of the fit, in `fit_residual_unit` (what the estimator fits).
    pub fit_residual_rms: f64,
    pub fit_residual_unit: &'static str,
    /// Poisson's ratio assumed for the object.
    pub object_poisson: f64,
    /// Wide over narrow semi-axis of the contact at the first frame the fit used (1: round; a
    /// banana's touches as a line across the pad), which the interval calibration reads
    /// apart; None where the estimator does not look.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub first_contact_aspect: Option<f64>,
}

#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct HardnessEstimate {
    pub hardness: Hardness,
    pub interval: ModulusInterval,
    pub evidence: Evidence,
}

/// How far the true modulus may lie from an estimate: a 68% and a 95% interval (MPa; an upper
/// bound of None: not distinguishable from rigid), and what they rest on. An estimator gives
/// its own (its fit's or its model card's error); `interval_calibration` replaces them with
/// intervals whose coverage was measured on held-out presses.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct ModulusInterval {
    pub p68_mpa: [Option<f64>; 2],
    pub p95_mpa: [Option<f64>; 2],
    pub source: String,
    /// Whether the coverage was measured (on held-out presses through the sensor in use).
    /// An estimator's own interval is not, and answers do not word it as "likely".
    pub calibrated: bool,
}

/// Normal quantile of the two-sided 95% interval.
pub const Z95: f64 = 1.959_964;

impl ModulusInterval {
    /// A log-normal interval: `ln_modulus` +- one and +- 1.96 standard deviations.
    pub fn log_normal(ln_modulus: f64, ln_sigma: f64, source: impl Into<String>) -> Self {
        let at = |k: f64| Some((ln_modulus + k * ln_sigma).exp());
        Self {
            p68_mpa: [at(-1.0), at(1.0)],
            p95_mpa: [at(-Z95), at(Z95)],
            source: source.into(),
            calibrated: false,
        }
    }

    /// No interval at all (a test's or a hand-made report's).
    pub fn none(source: impl Into<String>) -> Self {
        Self {
            p68_mpa: [None, None],
            p95_mpa: [None, None],
            source: source.into(),
            calibrated: false,
        }
    }

    /// Whether the 68% (`wide` false) or 95% interval holds `modulus_mpa` (infinite: rigid).
    /// Half the 68% interval's width in ln E: the estimate's standard error in ln E as the
    /// interval states it (None when a bound is open or not positive).
    pub fn ln_half_width68(&self) -> Option<f64> {
        let [Some(lo), Some(hi)] = self.p68_mpa else {
            return None;
        };
        (lo > 0.0 && hi >= lo && hi.is_finite()).then(|| 0.5 * (hi / lo).ln())
    }

    pub fn holds(&self, modulus_mpa: f64, wide: bool) -> Option<bool> {
        let [lo, hi] = if wide { self.p95_mpa } else { self.p68_mpa };
        let lo = lo?;
        Some(modulus_mpa >= lo && hi.is_none_or(|hi| modulus_mpa <= hi))
    }
}

/// What an estimator's own interval rests on, for `ModulusInterval::source`.
pub const OWN_FIT_INTERVAL: &str = "the fit's own standard error (not calibrated)";

#[derive(Debug, Clone, thiserror::Error)]
pub enum EstimateError {
    #[error("press sequence: {0}")]
    BadSequence(String),
    #[error("press sequence: no contact imprint in the frames")]
    NoImprint,
    #[error("hardness model {0}")]
    Model(String),
    /// The press was read, but the reading lies where the estimator cannot resolve a
    /// modulus (a fit that failed, a share of the travel at the model's ends): the object is
    /// reported as not measured, with why, rather than as a number with a tight interval.
    #[error("not measurable: {0}")]
    OutsideCompetence(String),
}

/// Reads a modulus from a press. Shared across threads: the pipeline reads one object's
/// press while the arm presses the next.
pub trait HardnessEstimator: Send + Sync {
    fn name(&self) -> &str;
    fn estimate(
        &self,
        press: &PressSequence,
        spec: &TactileSpec,
    ) -> Result<HardnessEstimate, EstimateError>;

    /// Why this estimator cannot read the presses of `spec`'s sensor, `frames` long, if it
    /// cannot: a learned model reads one frame size and its picked frames. Asked when the
    /// estimator is chosen, so a mismatch fails before any press is made.
    fn cannot_read(&self, _spec: &TactileSpec, _frames: usize) -> Option<String> {
        None
    }
}

/// A boxed estimator estimates as the one inside (the binary picks one at run time).
impl<T: HardnessEstimator + ?Sized> HardnessEstimator for Box<T> {
    fn name(&self) -> &str {
        (**self).name()
    }

    fn estimate(
        &self,
        press: &PressSequence,
        spec: &TactileSpec,
    ) -> Result<HardnessEstimate, EstimateError> {
        (**self).estimate(press, spec)
    }

    fn cannot_read(&self, spec: &TactileSpec, frames: usize) -> Option<String> {
        (**self).cannot_read(spec, frames)
    }
}

/// The least share of the travel the gel may take for an estimator to resolve the object,
/// and the least the object must take. The modulus goes as (1 - s) / s, so d ln E / d s =
/// -1 / (s (1 - s)): where s (1 - s) < 0.02, a reading error of 1% of the travel moves the
/// modulus by more than half. Below it the object is far softer than the gel, above one
/// minus it far stiffer, and the press cannot say by how much (through a profile's reading a
/// 1.45 MPa banana read 398 MPa there, the depth fit's end of range, as a number).
pub(crate) const MIN_GEL_SHARE: f64 = 0.0205;

/// Refuses a press in which the gel took too small or too large a share of the travel to
/// resolve the object, saying so in the user's terms (every physics estimator's rule).
pub(crate) fn check_gel_share(share: f64) -> Result<(), EstimateError> {
    if share < MIN_GEL_SHARE {
        return Err(EstimateError::OutsideCompetence(format!(
            "the gel took {:.1}% of the travel: the object is too soft against the gel to \
             resolve (below {:.1}%)",
            100.0 * share,
            100.0 * MIN_GEL_SHARE
        )));
    }
    if share > 1.0 {
        // More than all of it: the reading, not the object, is out of bounds.
        return Err(EstimateError::OutsideCompetence(format!(
            "the frames read {:.0}% of the travel as the gel's indentation, more than the \
             whole travel: the reading overshoots here (a stiff object read deep), so the \
             press cannot tell the object from a rigid one",
            100.0 * share
        )));
    }
    if share > 1.0 - MIN_GEL_SHARE {
        return Err(EstimateError::OutsideCompetence(format!(
            "the gel took {:.1}% of the travel: the object is too stiff against the gel to \
             resolve (above {:.1}%): the press cannot tell it from a rigid one",
            100.0 * share,
            100.0 * (1.0 - MIN_GEL_SHARE),
        )));
    }
    Ok(())
}

/// Physics inversion of the Hertz compliance split from the slope field (see the module docs).
#[derive(Clone, Debug)]
pub struct HertzSlopeEstimator {
    /// Poisson's ratio assumed for the object (fruit flesh: 0.2-0.5; Mohsenin 1986).
    pub object_poisson: f64,
    /// Every n-th pixel in each direction enters the fit.
    pub stride: usize,
}

impl Default for HertzSlopeEstimator {
    fn default() -> Self {
        Self {
            object_poisson: 0.35,
            stride: 3,
        }
    }
}

struct Sample {
    frame: usize,
    r_mm: f64,
    slope: f64,
}

impl HardnessEstimator for HertzSlopeEstimator {
    fn name(&self) -> &str {
        "hertz_slopes"
    }

    fn estimate(
        &self,
        press: &PressSequence,
        spec: &TactileSpec,
    ) -> Result<HardnessEstimate, EstimateError> {
        if press.frames.len() < 2 || press.frames.len() != press.travel_mm.len() {
            return Err(EstimateError::BadSequence(format!(
                "need at least 2 frames with one travel each, got {} frames and {} travels",
                press.frames.len(),
                press.travel_mm.len()
            )));
        }
        if press.travel_mm.iter().any(|t| !t.is_finite()) {
            return Err(EstimateError::BadSequence("travel must be finite".into()));
        }
        let mut drift = ColourDrift::Measured;
        let fields: Vec<SlopeField> = press
            .frames
            .iter()
            .map(|f| {
                let field = recover_slopes(&f.image, &press.reference.image, spec, drift)?;
                drift = drift.for_next_frame(field.drift);
                Some(field)
            })
            .collect::<Option<_>>()
            .ok_or_else(|| EstimateError::BadSequence("frame and reference sizes differ".into()))?;
        let last = fields.last().expect("at least two frames");
        let centre = radial_centre(last).ok_or(EstimateError::NoImprint)?;
        let px = last.mm_per_px;

        let mut samples = Vec::new();
        for (i, f) in fields.iter().enumerate() {
            for y in (0..f.height).step_by(self.stride) {
                for x in (0..f.width).step_by(self.stride) {
                    let k = y * f.width + x;
                    if !f.valid[k] {
                        continue;
                    }
                    let (dx, dy) = (x as f64 - centre.0, y as f64 - centre.1);
                    let r = dx.hypot(dy);
                    if r < 3.0 {
                        continue;
                    }
                    let slope = (f.gx[k] as f64 * dx + f.gy[k] as f64 * dy) / r;
                    samples.push(Sample {
                        frame: i,
                        r_mm: r * px,
                        slope,
                    });
                }
            }
        }
        if samples.len() < 100 {
            return Err(EstimateError::NoImprint);
        }

        let travel = &press.travel_mm;
        let fit = |log_r: f64, approach0: f64| -> (f64, f64) {
            let radius = log_r.exp();
            let mut sxy = 0.0;
            let mut sxx = 0.0;
            let mut syy = 0.0;
            for s in &samples {
                let h = Hertz {
                    radius_mm: radius,
                    approach_mm: approach0 + travel[s.frame],
                    contact_modulus_mpa: 1.0,
                };
                let model = h.total_displacement_slope(s.r_mm);
                sxy += model * s.slope;
                sxx += model * model;
                syy += s.slope * s.slope;
            }
            if sxx <= 0.0 {
                return (0.0, syy);
            }
            let share = sxy / sxx;
            (share, syy - share * sxy)
        };

        // Coarse grid over ln R and the first-contact approach, then a shrinking pattern search.
        let (mut best_lr, mut best_a0, mut best_rss) = (0.0, 0.0, f64::INFINITY);
        for i in 0..=20 {
            let lr = (1.0f64).ln() + i as f64 * ((400.0f64).ln() - (1.0f64).ln()) / 20.0;
            for j in 0..=15 {
                let a0 = 0.02 + j as f64 * 0.2;
                let (_, rss) = fit(lr, a0);
                if rss < best_rss {
                    (best_lr, best_a0, best_rss) = (lr, a0, rss);
                }
            }
        }
        let (mut step_lr, mut step_a0) = (0.15, 0.1);
        while step_a0 > 1e-4 {
            let mut improved = false;
            for (dl, da) in [
                (step_lr, 0.0),
                (-step_lr, 0.0),
                (0.0, step_a0),
                (0.0, -step_a0),
            ] {
                let (lr, a0) = (best_lr + dl, (best_a0 + da).max(1e-4));
                let (_, rss) = fit(lr, a0);
                if rss < best_rss {
                    (best_lr, best_a0, best_rss) = (lr, a0, rss);
                    improved = true;
                }
            }
            if !improved {
                step_lr *= 0.5;
                step_a0 *= 0.5;
            }
        }
        let radius = best_lr.exp();
        let (share, rss) = fit(best_lr, best_a0);

        // Standard error from the spread of per-frame shares at the fitted geometry: pixels of
        // one frame are correlated, frames are the honest replicates.
        let per_frame: Vec<f64> = (0..fields.len())
            .filter_map(|i| {
                let (mut sxy, mut sxx) = (0.0, 0.0);
                for s in samples.iter().filter(|s| s.frame == i) {
                    let h = Hertz {
                        radius_mm: radius,
                        approach_mm: best_a0 + travel[i],
                        contact_modulus_mpa: 1.0,
                    };
                    let m = h.total_displacement_slope(s.r_mm);
                    sxy += m * s.slope;
                    sxx += m * m;
                }
                (sxx > 0.0).then(|| sxy / sxx)
            })
            .collect();
        let n = per_frame.len() as f64;
        let mean = per_frame.iter().sum::<f64>() / n;
        let share_se =
            (per_frame.iter().map(|s| (s - mean).powi(2)).sum::<f64>() / (n - 1.0).max(1.0) / n)
                .sqrt();
        if !(share.is_finite() && share > 0.0) {
            return Err(EstimateError::NoImprint);
        }
        // The slope fit's first contact is loosely held (it trades off against the local
        // radius), so unlike the depth fit's it is not a reason to refuse: through FOTS that
        // rule refused three soft presses read better than the rest.
        check_gel_share(share)?;

        let gel = Elastic {
            modulus_mpa: Some(spec.gel.modulus_mpa),
            poisson: spec.gel.poisson,
        };
        let to_modulus =
            |s: f64| object_modulus_from_share(gel, self.object_poisson, s.clamp(1e-6, 1.0));
        let hardness = match to_modulus(share) {
            Some(e) => Hardness::ModulusMpa(e),
            None => Hardness::Rigid,
        };
        let last_approach = best_a0 + travel.last().copied().unwrap_or(0.0);
        let last_hertz = Hertz {
            radius_mm: radius,
            approach_mm: last_approach,
            contact_modulus_mpa: 1.0,
        };
        Ok(HardnessEstimate {
            hardness,
            interval: ModulusInterval {
                p68_mpa: [to_modulus(share - share_se), to_modulus(share + share_se)],
                p95_mpa: [
                    to_modulus(share - Z95 * share_se),
                    to_modulus(share + Z95 * share_se),
                ],
                source: OWN_FIT_INTERVAL.into(),
                calibrated: false,
            },
            evidence: Evidence::Physics(PhysicsEvidence {
                gel_share: share,
                gel_share_se: share_se,
                local_radius_mm: radius,
                first_contact_approach_mm: best_a0,
                last_contact_radius_mm: last_hertz.contact_radius_mm(),
                last_gel_indentation_mm: share.min(1.0) * last_approach,
                frames_used: fields.len(),
                gel_layer_factor: 1.0,
                fit_residual_rms: (rss.max(0.0) / samples.len() as f64).sqrt(),
                fit_residual_unit: "slope",
                object_poisson: self.object_poisson,
                first_contact_aspect: None,
            }),
        })
    }
}

/// The point the slope field converges on: least squares of g x (p - c) = 0 over valid
/// pixels (slopes of an axisymmetric imprint are radial). None without an imprint.
fn radial_centre(f: &SlopeField) -> Option<(f64, f64)> {
    let (mut a11, mut a12, mut a22, mut b1, mut b2) = (0.0, 0.0, 0.0, 0.0, 0.0);
    let mut weight_sum = 0.0;
    for y in 0..f.height {
        for x in 0..f.width {
            let k = y * f.width + x;
            if !f.valid[k] {
                continue;
            }
            let (gx, gy) = (f.gx[k] as f64, f.gy[k] as f64);
            let g2 = gx * gx + gy * gy;
            // Weak slopes are mostly noise; weight by slope magnitude.
            if g2 < 1e-4 {
                continue;
            }
            let w = g2.sqrt();
            // Row of the linear system: [gy, -gx] . c = gy x - gx y, normalised by |g|.
            let (r1, r2, rhs) = (gy / w, -gx / w, (gy * x as f64 - gx * y as f64) / w);
            a11 += w * r1 * r1;
            a12 += w * r1 * r2;
            a22 += w * r2 * r2;
            b1 += w * r1 * rhs;
            b2 += w * r2 * rhs;
            weight_sum += w;
        }
    }
    let det = a11 * a22 - a12 * a12;
    if weight_sum < 1.0 || det.abs() < 1e-9 * (a11 * a22).max(1e-30) {
        return None;
    }
    Some(((a22 * b1 - a12 * b2) / det, (a11 * b2 - a12 * b1) / det))
}

#[cfg(test)]
mod gel_share_tests {
    use super::*;

    /// The rule in its three outcomes; a reading past the whole travel is said to be the
    /// reading's fault (it printed "the gel took 125% of the travel").
    #[test]
    fn a_gel_share_outside_competence_says_why_in_the_users_terms() {
        assert!(check_gel_share(0.5).is_ok());
        let why = |s: f64| match check_gel_share(s) {
            Err(EstimateError::OutsideCompetence(m)) => m,
            other => panic!("{s}: {other:?}"),
        };
        assert!(why(0.01).contains("too soft against the gel"));
        assert!(why(0.99).contains("too stiff against the gel"));
        let over = why(1.25);
        assert!(
            over.contains("125% of the travel") && over.contains("more than the whole travel"),
            "{over}"
        );
    }
}
