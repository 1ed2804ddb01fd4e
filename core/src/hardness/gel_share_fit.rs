//! The object's compliance from how much of the robot's travel the gel took, frame by frame.
//!
//! Two bodies pressed together split the approach by compliance: at the first-touch point the
//! gel's indentation is s times the approach, s = phi c_gel / (phi c_gel + c_object), where
//! c = (1 - nu^2) / E and phi is the bonded gel layer's centre compliance relative to the
//! half-space at that frame's contact size (core's `layer_compliance`). phi falls as the
//! contact grows against the gel's thickness, so each frame gets its own. The approach at the
//! first contact frame is unknown: the fit solves it together with the compliance ratio
//! rho = c_object / c_gel, so only the known travel between frames sets the scale.

/// The fitted split.
#[derive(Clone, Debug, PartialEq)]
pub struct ShareFit {
    /// c_object / c_gel (0: rigid object).
    pub compliance_ratio: f64,
    /// One-standard-error interval of the ratio, from the fit's curvature in ln rho.
    pub compliance_ratio_interval: [f64; 2],
    /// Total approach at the first contact frame (mm).
    pub first_contact_approach_mm: f64,
    /// RMS of the indentation residual (mm).
    pub residual_rms_mm: f64,
}

/// The gel's share of the approach at layer factor `layer` and compliance ratio `rho`.
pub fn gel_share(layer: f64, rho: f64) -> f64 {
    layer / (layer + rho)
}

/// Residual sum of squares of indentation = s_k (a0 + travel_k) at ratio `rho`, with the
/// first-contact approach a0 >= 0 solved in closed form.
fn residual(rho: f64, indentation: &[f64], travel: &[f64], layer: &[f64]) -> (f64, f64) {
    let share = |k: usize| gel_share(layer[k], rho);
    let (mut num, mut den) = (0.0, 0.0);
    for k in 0..indentation.len() {
        let s = share(k);
        num += s * (indentation[k] - s * travel[k]);
        den += s * s;
    }
    let a0 = if den > 0.0 { (num / den).max(0.0) } else { 0.0 };
    let rss = (0..indentation.len())
        .map(|k| (indentation[k] - share(k) * (a0 + travel[k])).powi(2))
        .sum();
    (rss, a0)
}

/// Fits rho and the first-contact approach to per-frame indentation (mm), travel past the
/// first contact frame (mm) and layer factors phi (see the module docs). None when the
/// inputs are too few, unequal in length or not finite.
pub fn fit_gel_share(indentation_mm: &[f64], travel_mm: &[f64], layer: &[f64]) -> Option<ShareFit> {
    let n = indentation_mm.len();
    if n < 2 || travel_mm.len() != n || layer.len() != n {
        return None;
    }
    let all_finite = |v: &[f64]| v.iter().all(|x| x.is_finite());
    if !(all_finite(indentation_mm) && all_finite(travel_mm) && all_finite(layer)) {
        return None;
    }
    if layer.iter().any(|p| *p <= 0.0) {
        return None;
    }
    let rss = |ln_rho: f64| residual(ln_rho.exp(), indentation_mm, travel_mm, layer).0;
    // From a thousand times stiffer than the gel to a thousand times softer, then golden
    // section on the best bracket.
    let (lo, hi, steps) = (-7.0f64, 7.0f64, 140);
    let grid: Vec<f64> = (0..=steps)
        .map(|i| lo + (hi - lo) * i as f64 / steps as f64)
        .collect();
    let best = (0..grid.len())
        .min_by(|a, b| rss(grid[*a]).total_cmp(&rss(grid[*b])))
        .expect("a non-empty grid");
    let (mut a, mut b) = (
        grid[best.saturating_sub(1)],
        grid[(best + 1).min(grid.len() - 1)],
    );
    let golden = (5f64.sqrt() - 1.0) / 2.0;
    for _ in 0..60 {
        let (c, d) = (b - golden * (b - a), a + golden * (b - a));
        if rss(c) < rss(d) {
            b = d;
        } else {
            a = c;
        }
    }
    let ln_rho = 0.5 * (a + b);
    let rho = ln_rho.exp();
    let (best_rss, a0) = residual(rho, indentation_mm, travel_mm, layer);
    // Standard error in ln rho from the curvature of the RSS: var = 2 sigma^2 / RSS''.
    let h = 0.05;
    let curvature = (rss(ln_rho + h) - 2.0 * best_rss + rss(ln_rho - h)) / (h * h);
    let sigma2 = best_rss / (n as f64 - 2.0).max(1.0);
    let se = if curvature > 0.0 {
        (2.0 * sigma2 / curvature).sqrt()
    } else {
        f64::INFINITY
    };
    Some(ShareFit {
        compliance_ratio: rho,
        compliance_ratio_interval: [(ln_rho - se).exp(), (ln_rho + se).exp()],
        first_contact_approach_mm: a0,
        residual_rms_mm: (best_rss / n as f64).sqrt(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn synthetic(rho: f64, a0: f64, layer: &[f64]) -> (Vec<f64>, Vec<f64>) {
        let travel: Vec<f64> = (0..layer.len()).map(|k| 0.25 * k as f64).collect();
        let indentation = travel
            .iter()
            .zip(layer)
            .map(|(t, p)| p / (p + rho) * (a0 + t))
            .collect();
        (indentation, travel)
    }

    #[test]
    fn recovers_the_split_of_a_half_space_pair() {
        let layer = [1.0; 8];
        for rho in [0.01, 0.3, 1.0, 4.0, 50.0] {
            let (ind, travel) = synthetic(rho, 0.12, &layer);
            let fit = fit_gel_share(&ind, &travel, &layer).expect("a fit");
            assert!(
                (fit.compliance_ratio / rho - 1.0).abs() < 1e-4,
                "rho {rho}: {}",
                fit.compliance_ratio
            );
            assert!((fit.first_contact_approach_mm - 0.12).abs() < 1e-4);
        }
    }

    #[test]
    fn a_stiffening_layer_is_not_mistaken_for_a_softer_object() {
        // The layer stiffens as the contact grows: the indentation grows slower than linear.
        let layer = [0.9, 0.8, 0.7, 0.62, 0.55, 0.5, 0.46, 0.43];
        let (ind, travel) = synthetic(1.5, 0.2, &layer);
        let fit = fit_gel_share(&ind, &travel, &layer).expect("a fit");
        assert!((fit.compliance_ratio / 1.5 - 1.0).abs() < 1e-4);
        let half_space = fit_gel_share(&ind, &travel, &[1.0; 8]).expect("a fit");
        assert!(
            half_space.compliance_ratio > 2.0,
            "ignoring the layer reads a softer object"
        );
    }

    #[test]
    fn bad_inputs_give_no_fit() {
        assert!(fit_gel_share(&[0.1], &[0.0], &[1.0]).is_none());
        assert!(fit_gel_share(&[0.1, 0.2], &[0.0], &[1.0, 1.0]).is_none());
        assert!(fit_gel_share(&[0.1, f64::NAN], &[0.0, 0.25], &[1.0, 1.0]).is_none());
        assert!(fit_gel_share(&[0.1, 0.2], &[0.0, 0.25], &[1.0, 0.0]).is_none());
    }
}
