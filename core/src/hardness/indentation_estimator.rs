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
use crate::tactile::depth::integrate_slopes;
use crate::tactile::slopes::recover_slopes;
use crate::tactile::spec::TactileSpec;
use std::f64::consts::PI;

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

/// The peak of an indentation map: the mean of its 20 deepest pixels, which averages out the
/// integration's pixel noise while staying within the contact's centre.
fn peak(depth: &[f64]) -> f64 {
    let mut sorted: Vec<f64> = depth.to_vec();
    let n = sorted.len().min(20);
    let k = sorted.len() - n;
    sorted.select_nth_unstable_by(k, f64::total_cmp);
    sorted[k..].iter().sum::<f64>() / n as f64
}

/// The contact's semi-axes (mm, wide then narrow) from the imprint's half-depth region (where
/// `inside` holds), taken
/// as the half-depth ellipse of a Hertz dimple: its area fixes the scale (the half-depth
/// ellipse's axes are 0.866 of the contact's) and its second moments the aspect, so an
/// elongated imprint (a banana's) keeps its narrow side. Empty: [0, 0].
fn contact_ellipse(
    depth: &[f64],
    w: usize,
    inside: impl Fn(f64) -> bool,
    mm_per_px: f64,
) -> [f64; 2] {
    let (mut n, mut sx, mut sy, mut sxx, mut syy, mut sxy) = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    for (i, d) in depth.iter().enumerate() {
        if inside(*d) {
            let (x, y) = ((i % w) as f64, (i / w) as f64);
            n += 1.0;
            sx += x;
            sy += y;
            sxx += x * x;
            syy += y * y;
            sxy += x * y;
        }
    }
    if n == 0.0 {
        return [0.0, 0.0];
    }
    let (mx, my) = (sx / n, sy / n);
    let (cxx, cyy, cxy) = (sxx / n - mx * mx, syy / n - my * my, sxy / n - mx * my);
    let mean = 0.5 * (cxx + cyy);
    let spread = (0.25 * (cxx - cyy).powi(2) + cxy * cxy).sqrt();
    // Eigenvalues of the covariance; a pixel's own 1/12 keeps a one-pixel line finite.
    let (wide, narrow) = (
        mean + spread + 1.0 / 12.0,
        (mean - spread).max(0.0) + 1.0 / 12.0,
    );
    let aspect = (wide / narrow).sqrt();
    let equal_area_radius = (n / PI).sqrt() * mm_per_px / 0.866;
    [
        equal_area_radius * aspect.sqrt(),
        equal_area_radius / aspect.sqrt(),
    ]
}

/// The frame's outermost two pixels, row-major indices.
fn border(w: usize, h: usize) -> impl Iterator<Item = usize> {
    (0..h).flat_map(move |y| {
        (0..w)
            .filter(move |x| *x < 2 || y < 2 || x + 2 >= w || y + 2 >= h)
            .map(move |x| y * w + x)
    })
}

/// Whether an imprint of this peak lies within the frame: its half-depth region stays off
/// the border, and the border is level (its deepest 5% lie less than half the peak below its
/// shallowest 5%). The map's zero is the border's median, so a border pressed in on one side
/// (a broad fruit whose contact outgrows the pad) lowers the zero and the peak reads short
/// while the half-depth region, measured from that same zero, never reaches the edge.
fn imprint_within_frame(depth: &[f64], valid: &[bool], w: usize, h: usize, peak: f64) -> bool {
    if border(w, h).any(|i| depth[i] > 0.5 * peak) {
        return false;
    }
    let mut edge: Vec<f64> = border(w, h)
        .filter(|i| valid[*i])
        .map(|i| depth[i])
        .collect();
    if edge.len() < 20 {
        return true;
    }
    edge.sort_by(f64::total_cmp);
    let at = |q: f64| edge[((edge.len() - 1) as f64 * q).round() as usize];
    at(0.95) - at(0.05) <= 0.5 * peak
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
            let slopes =
                recover_slopes(&frame.image, &press.reference.image, spec).ok_or_else(|| {
                    EstimateError::BadSequence("frame and reference sizes differ".into())
                })?;
            let depth = integrate_slopes(&slopes, spec.mm_per_px);
            let p = peak(&depth);
            let deep = |d: f64| d > 0.5 * p;
            contact_axes.push(contact_ellipse(&depth, slopes.width, deep, spec.mm_per_px));
            within_frame.push(imprint_within_frame(
                &depth,
                &slopes.valid,
                slopes.width,
                slopes.height,
                p,
            ));
            peaks.push(p);
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

#[cfg(test)]
mod tests {
    use super::*;

    /// A Gaussian dimple of depth 1 centred at (cx, cy) px with width `sigma` on a 160 x 120
    /// frame, over a gel lowered by `tilt` at the top edge and not at the bottom (a broad
    /// contact beyond the top edge), zeroed as `integrate_slopes` zeroes: the border's median.
    fn imprint(cx: f64, cy: f64, sigma: f64, tilt: f64) -> Vec<f64> {
        let (w, h) = (160usize, 120usize);
        let mut depth: Vec<f64> = (0..w * h)
            .map(|i| {
                let (x, y) = ((i % w) as f64 - cx, (i / w) as f64 - cy);
                let lowered = tilt * (1.0 - (i / w) as f64 / (h - 1) as f64);
                (-(x * x + y * y) / (2.0 * sigma * sigma)).exp() + lowered
            })
            .collect();
        let mut edge: Vec<f64> = border(w, h).map(|i| depth[i]).collect();
        edge.sort_by(f64::total_cmp);
        let zero = edge[edge.len() / 2];
        depth.iter_mut().for_each(|d| *d -= zero);
        depth
    }

    #[test]
    fn an_imprint_that_outgrows_the_pad_on_one_side_is_not_within_the_frame() {
        let valid = vec![true; 160 * 120];
        let within = |d: &[f64]| imprint_within_frame(d, &valid, 160, 120, peak(d));
        // A small imprint in the middle leaves the border level, and a slightly lowered
        // side is tolerated.
        assert!(within(&imprint(80.0, 60.0, 12.0, 0.0)));
        assert!(within(&imprint(80.0, 60.0, 12.0, 0.3)));
        // The gel pressed in along the top edge by 0.7 of the imprint's depth: its
        // half-depth region, measured from the border's lowered median, stays off the edge
        // (the case the half-depth test alone missed), yet the zero is wrong.
        let broad = imprint(80.0, 60.0, 12.0, 0.7);
        let p = peak(&broad);
        assert!(!border(160, 120).any(|i| broad[i] > 0.5 * p));
        assert!(!within(&broad));
        // An imprint whose half-depth region reaches the edge is cut as before.
        assert!(!within(&imprint(3.0, 60.0, 12.0, 0.0)));
    }

    #[test]
    fn an_elongated_turned_imprint_keeps_its_two_semi_axes() {
        // A paraboloid dimple 1 - (x'/A)^2 - (y'/B)^2 turned 30 degrees: its half-depth ellipse
        // has semi-axes A/sqrt 2 and B/sqrt 2, the contact's are those over 0.866.
        let (w, h, big, small) = (160usize, 120usize, 40.0f64, 12.0f64);
        let (c, s) = (30f64.to_radians().cos(), 30f64.to_radians().sin());
        let depth: Vec<f64> = (0..w * h)
            .map(|i| {
                let (x, y) = ((i % w) as f64 - 80.0, (i / w) as f64 - 60.0);
                let (xr, yr) = (c * x + s * y, -s * x + c * y);
                (1.0 - (xr / big).powi(2) - (yr / small).powi(2)).max(0.0)
            })
            .collect();
        let [a, b] = contact_ellipse(&depth, w, |d| d > 0.5, 0.1);
        let want = |axis: f64| axis / 2f64.sqrt() * 0.1 / 0.866;
        assert!((a / want(big) - 1.0).abs() < 0.02, "{a} vs {}", want(big));
        assert!(
            (b / want(small) - 1.0).abs() < 0.03,
            "{b} vs {}",
            want(small)
        );
        assert_eq!(contact_ellipse(&[0.0; 4], 2, |d| d > 0.5, 0.1), [0.0, 0.0]);
    }
}
