//! Hardness from how much of the robot's travel the gel took, for objects of any shape.
//!
//! Two elastic bodies pressed together share the approach by compliance, whatever their
//! shapes (exact for half-spaces). The estimator recovers the gel's indentation map of every
//! frame (photometric slopes against the no-contact frame, integrated), takes its peak and
//! its contact size, and fits the split (core's `gel_share_fit`) with the bonded gel layer's
//! stiffening at each frame's contact size, so a wide flat contact on a thin gel is not read
//! as a softer object. The object's modulus follows from the compliance ratio and the gel's
//! modulus.

use crate::hardness::estimate::{
    EstimateError, Evidence, HardnessEstimate, HardnessEstimator, ModulusInterval,
    OWN_FIT_INTERVAL, PhysicsEvidence, PressSequence, Z95,
};
use crate::hardness::gel_share_fit::{fit_gel_share, gel_share};
use crate::hardness::layer_compliance::hertz_ellipse_centre_compliance_ratio;
use crate::hardness::scale::Hardness;
use crate::hertz::Elastic;
use crate::tactile::frame_reading::read_frame;
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
        for frame in &press.frames {
            let reading =
                read_frame(&frame.image, &press.reference.image, spec).ok_or_else(|| {
                    EstimateError::BadSequence("frame and reference sizes differ".into())
                })?;
            contact_axes.push(reading.contact_axes_mm);
            within_frame.push(reading.within_frame);
            peaks.push(reading.peak_mm);
        }
        if !peaks.last().is_some_and(|p| *p > 0.0) {
            return Err(EstimateError::NoImprint);
        }
        // An imprint that reaches the frame's edge has no undisturbed gel left to zero the
        // integration on, so its peak reads short: fit the frames whose imprint lies within
        // the frame, or the first three (the least cut) when fewer do.
        let mut used: Vec<usize> = (0..n).filter(|k| within_frame[*k]).collect();
        if used.len() < 3 {
            used = (0..n.min(3)).collect();
        }
        let pick = |v: &[f64]| used.iter().map(|k| v[*k]).collect::<Vec<f64>>();
        let h = spec.gel.thickness_mm;
        let layer: Vec<f64> = contact_axes
            .iter()
            .map(|[a, b]| hertz_ellipse_centre_compliance_ratio([a / h, b / h], spec.gel.poisson))
            .collect();
        let fit = fit_gel_share(&pick(&peaks), &pick(&press.travel_mm), &pick(&layer))
            .ok_or(EstimateError::NoImprint)?;
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
        let last = *used.last().expect("at least two frames used");
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
