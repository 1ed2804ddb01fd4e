//! Holm-Bonferroni step-down adjustment of p-values for multiple comparisons.

use super::{StatsError, check};

/// Adjusted p-values in the input's order: the i-th smallest is multiplied by (m - i), made
/// monotone from the smallest up, and capped at 1.
pub fn holm_bonferroni(p: &[f64]) -> Result<Vec<f64>, StatsError> {
    check("p", p, 1)?;
    if p.iter().any(|v| !(0.0..=1.0).contains(v)) {
        return Err(StatsError {
            what: "p",
            message: "p-values must lie in [0, 1]".into(),
        });
    }
    let m = p.len();
    let mut order: Vec<usize> = (0..m).collect();
    order.sort_by(|&a, &b| p[a].total_cmp(&p[b]));
    let mut out = vec![0.0; m];
    let mut running = 0.0f64;
    for (i, &k) in order.iter().enumerate() {
        running = running.max(((m - i) as f64 * p[k]).min(1.0));
        out[k] = running;
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn matches_the_reference_values() {
        // statsmodels multipletests([0.01, 0.04, 0.03, 0.2], method='holm')
        let got = holm_bonferroni(&[0.01, 0.04, 0.03, 0.2]).unwrap();
        for (g, w) in got.iter().zip([0.04, 0.09, 0.09, 0.2]) {
            assert!((g - w).abs() < 1e-15, "{got:?}");
        }
        assert!(holm_bonferroni(&[0.5, 1.5]).is_err());
    }
}
