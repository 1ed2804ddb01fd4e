//! Hardness from how much of the robot's travel the gel took, for objects of any shape.
//!
//! Two elastic bodies pressed together share the approach by compliance, whatever their
//! shapes (exact for half-spaces). The estimator recovers the gel's indentation map of every
//! frame (photometric slopes against the no-contact frame, integrated), takes its peak and
//! its contact size, and fits the split (core's `gel_share_fit`) with the bonded gel layer's
//! stiffening at each frame's contact size, so a wide flat contact on a thin gel is not read
//! as a softer object. The object's modulus follows from the compliance ratio and the gel's
//! modulus.

use crate::hardness::border_level::read_share_of_indentation;
use crate::hardness::estimate::{
    EstimateError, Evidence, HardnessEstimate, HardnessEstimator, ModulusInterval,
    OWN_FIT_INTERVAL, PhysicsEvidence, PressSequence, Z95, check_gel_share,
};
use crate::hardness::gel_share_fit::{ShareFit, fit_gel_share, gel_share};
use crate::hardness::layer_compliance::hertz_ellipse_centre_compliance_ratio;
use crate::hardness::scale::Hardness;
use crate::hertz::Elastic;
use crate::tactile::frame_reading::read_frame;
use crate::tactile::slopes::ColourDrift;
use crate::tactile::spec::TactileSpec;

#[derive(Clone, Debug)]
pub struct IndentationEstimator {
    /// Poisson's ratio assumed for the object (fruit flesh: 0.2-0.5; Mohsenin 1986).
    pub object_poisson: f64,
}

impl Default for IndentationEstimator {
    fn default() -> Self {
        Self {
            object_poisson: 0.35,
        }
    }
}

impl HardnessEstimator for IndentationEstimator {
    fn name(&self) -> &str {
        "indentation"
    }

    fn estimate(
        &self,
        press: &PressSequence,
        spec: &TactileSpec,
    ) -> Result<HardnessEstimate, EstimateError> {
        let n = press.frames.len();
        if n < 2 || n != press.travel_mm.len() {
            return Err(EstimateError::BadSequence(format!(
                "need at least 2 frames with one travel each, got {n} frames and {} travels",
                press.travel_mm.len()
            )));
        }
        if press.travel_mm.iter().any(|t| !t.is_finite()) {
            return Err(EstimateError::BadSequence("travel must be finite".into()));
        }
        let mut peaks = Vec::with_capacity(n);
        let mut contact_axes = Vec::with_capacity(n);
        let mut within_frame = Vec::with_capacity(n);
        let mut drift = ColourDrift::Measured;
        for frame in &press.frames {
            let reading = read_frame(&frame.image, &press.reference.image, spec, drift)
                .ok_or_else(|| {
                    EstimateError::BadSequence("frame and reference sizes differ".into())
                })?;
            drift = drift.for_next_frame(reading.drift);
            contact_axes.push(reading.contact_axes_mm);
            within_frame.push(reading.within_frame);
            // The peak read against the frame's border, as the gel's indentation.
            let share = read_share_of_indentation(&reading, &spec.gel);
            peaks.push(reading.peak_mm / share);
            // Once the imprint reaches the frame's edge, the deeper frames' imprints reach it
            // too, and they are not fitted: they are not read (a fruit's contact outgrows a
            // real sensor's frame after about three of the eight).
            if !reading.within_frame && peaks.len() >= MIN_FITTED_FRAMES {
                break;
            }
        }
        if !peaks.last().is_some_and(|p| *p > 0.0) {
            return Err(EstimateError::NoImprint);
        }
        // An imprint that reaches the frame's edge has no undisturbed gel left to zero the
        // integration on, so its peak reads short: fit the frames whose imprint lies within
        // the frame, or the first three (the least cut) when fewer do.
        let mut used: Vec<usize> = (0..peaks.len()).filter(|k| within_frame[*k]).collect();
        if used.len() < MIN_FITTED_FRAMES {
            used = (0..peaks.len().min(MIN_FITTED_FRAMES)).collect();
        }
        let pick = |v: &[f64]| used.iter().map(|k| v[*k]).collect::<Vec<f64>>();
        let h = spec.gel.thickness_mm;
        let layer: Vec<f64> = contact_axes
            .iter()
            .map(|[a, b]| hertz_ellipse_centre_compliance_ratio([a / h, b / h], spec.gel.poisson))
            .collect();
        let fit = fit_gel_share(&pick(&peaks), &pick(&press.travel_mm), &pick(&layer))
            .ok_or(EstimateError::NoImprint)?;
        let last = *used.last().expect("at least two frames used");
        check_competence(
            &fit,
            gel_share(layer[last], fit.compliance_ratio),
            peaks[last],
            &press.travel_mm,
        )?;
        let gel = Elastic {
            modulus_mpa: Some(spec.gel.modulus_mpa),
            poisson: spec.gel.poisson,
        };
        let object_one_minus_nu2 = 1.0 - self.object_poisson * self.object_poisson;
        // rho -> 0 is a rigid object; the modulus follows from c_object = rho c_gel.
        let to_modulus =
            |rho: f64| (rho > 1e-6).then(|| object_one_minus_nu2 / (rho * gel.compliance()));
        let hardness = match to_modulus(fit.compliance_ratio) {
            Some(e) => Hardness::ModulusMpa(e),
            None => Hardness::Rigid,
        };
        let [rho_lo, rho_hi] = fit.compliance_ratio_interval;
        // The fit's interval is one standard error in ln rho; the 95% one widens it in ln.
        let rho = fit.compliance_ratio;
        let widen = |r: f64| rho * (r / rho).powf(Z95);
        let share_at = |rho: f64| gel_share(layer[last], rho);
        let last_approach = fit.first_contact_approach_mm + press.travel_mm[last];
        // The circle of the contact's area.
        let contact_radius = (contact_axes[last][0] * contact_axes[last][1]).sqrt();
        Ok(HardnessEstimate {
            hardness,
            // A softer object has the larger compliance ratio.
            interval: ModulusInterval {
                p68_mpa: [to_modulus(rho_hi), to_modulus(rho_lo)],
                p95_mpa: [to_modulus(widen(rho_hi)), to_modulus(widen(rho_lo))],
                source: OWN_FIT_INTERVAL.into(),
                calibrated: false,
            },
            evidence: Evidence::Physics(PhysicsEvidence {
                gel_share: share_at(fit.compliance_ratio),
                // Carried over from the ratio's interval.
                gel_share_se: 0.5 * (share_at(rho_lo) - share_at(rho_hi)),
                local_radius_mm: contact_radius * contact_radius / last_approach.max(1e-9),
                first_contact_approach_mm: fit.first_contact_approach_mm,
                last_contact_radius_mm: contact_radius,
                last_gel_indentation_mm: peaks[last],
                frames_used: used.len(),
                gel_layer_factor: layer[last],
                fit_residual_rms: fit.residual_rms_mm,
                fit_residual_unit: "mm",
                object_poisson: self.object_poisson,
                first_contact_aspect: Some({
                    let [a, b] = contact_axes[used[0]];
                    a / b.max(1e-9)
                }),
            }),
        })
    }
}

/// The fewest frames the depth fit takes: the first ones when fewer lie within the frame.
const MIN_FITTED_FRAMES: usize = 3;

/// A fit whose residual is more than this share of the last frame's depth does not describe
/// the press: the depths do not grow with the travel as two elastic bodies' do.
const MAX_FIT_RESIDUAL_SHARE: f64 = 0.25;

/// Refuses a reading the model cannot stand behind, saying why in the user's terms.
fn check_competence(
    fit: &ShareFit,
    share: f64,
    last_depth_mm: f64,
    travel_mm: &[f64],
) -> Result<(), EstimateError> {
    let outside = |why: String| Err(EstimateError::OutsideCompetence(why));
    let travelled = travel_mm.iter().cloned().fold(0.0f64, f64::max);
    if fit.first_contact_approach_mm > travelled.max(0.0) {
        return outside(format!(
            "the depth fit puts first contact {:.2} mm before the first frame, more than the \
             press travelled ({travelled:.2} mm): the gel's depths do not follow the travel",
            fit.first_contact_approach_mm
        ));
    }
    if fit.residual_rms_mm > MAX_FIT_RESIDUAL_SHARE * last_depth_mm {
        return outside(format!(
            "the depth fit misses the gel's depths by {:.3} mm rms against a last depth of \
             {last_depth_mm:.3} mm: the press does not read as two elastic bodies",
            fit.residual_rms_mm
        ));
    }
    check_gel_share(share)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fit(rho: f64, a0: f64, residual: f64) -> ShareFit {
        ShareFit {
            compliance_ratio: rho,
            compliance_ratio_interval: [rho * 0.9, rho * 1.1],
            first_contact_approach_mm: a0,
            residual_rms_mm: residual,
        }
    }

    #[test]
    fn a_press_read_as_two_elastic_bodies_is_measured() {
        // A tomato on the stock Mini: a fifth of the travel in the gel, first contact a
        // fifth of a millimetre in, the depths fitted to 2 microns.
        let travel = [0.0, 0.25, 0.5, 0.75];
        assert!(check_competence(&fit(1.0, 0.22, 0.002), 0.22, 0.16, &travel).is_ok());
    }

    #[test]
    fn a_fit_that_puts_first_contact_beyond_the_whole_press_is_not_measured() {
        let travel = [0.0, 0.25, 0.5, 0.75];
        let err = check_competence(&fit(1.0, 505.0, 0.002), 0.22, 0.26, &travel).unwrap_err();
        assert!(
            matches!(&err, EstimateError::OutsideCompetence(why) if why.contains("first contact"))
        );
    }

    #[test]
    fn depths_the_fit_misses_by_a_quarter_are_not_measured() {
        let travel = [0.0, 0.25, 0.5, 0.75];
        let err = check_competence(&fit(1.0, 0.2, 0.18), 0.22, 0.26, &travel).unwrap_err();
        assert!(matches!(&err, EstimateError::OutsideCompetence(why) if why.contains("misses")));
    }

    #[test]
    fn an_object_too_soft_against_the_gel_to_resolve_is_not_measured() {
        // At a share of 1% a reading error of 1% of the travel doubles the modulus.
        let travel = [0.0, 0.25, 0.5, 0.75];
        let err = check_competence(&fit(50.0, 0.2, 0.0001), 0.01, 0.01, &travel).unwrap_err();
        assert!(matches!(&err, EstimateError::OutsideCompetence(why) if why.contains("too soft")));
        assert!(check_competence(&fit(20.0, 0.2, 0.0001), 0.03, 0.02, &travel).is_ok());
    }

    #[test]
    fn an_object_too_stiff_against_the_gel_to_resolve_is_not_a_number_at_the_fits_end() {
        // The gel took 99.6% of the travel (the depth fit at the end of its range, a thousand
        // times stiffer than the gel): no modulus, a rigid-like bound in words.
        let travel = [0.0, 0.25, 0.5, 0.75];
        let err = check_competence(&fit(9e-4, 0.2, 0.0001), 0.996, 0.7, &travel).unwrap_err();
        assert!(matches!(&err, EstimateError::OutsideCompetence(why) if why.contains("too stiff")));
        assert!(check_competence(&fit(0.01, 0.2, 0.0001), 0.95, 0.7, &travel).is_ok());
    }
}
