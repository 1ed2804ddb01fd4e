//! Sample quantiles as numpy computes them by default (method "linear", Hyndman and Fan's
//! type 7): the order statistic at position (n - 1) q, interpolated linearly.

use super::{StatsError, check};

/// The `q` quantile of `x`, q in [0, 1].
pub fn quantile(x: &[f64], q: f64) -> Result<f64, StatsError> {
    check("x", x, 1)?;
    if !(0.0..=1.0).contains(&q) {
        return Err(StatsError {
            what: "q",
            message: format!("{q} is outside [0, 1]"),
        });
    }
    let mut sorted = x.to_vec();
    sorted.sort_by(f64::total_cmp);
    let h = (sorted.len() - 1) as f64 * q;
    let (lo, frac) = (h.floor() as usize, h.fract());
    let hi = (lo + 1).min(sorted.len() - 1);
    Ok(sorted[lo] + frac * (sorted[hi] - sorted[lo]))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn matches_numpy_percentile() {
        // np.percentile([3, 1, 4, 1, 5, 9, 2, 6], [0, 25, 50, 75, 100])
        let x = [3.0, 1.0, 4.0, 1.0, 5.0, 9.0, 2.0, 6.0];
        for (q, want) in [
            (0.0, 1.0),
            (0.25, 1.75),
            (0.5, 3.5),
            (0.75, 5.25),
            (1.0, 9.0),
        ] {
            assert!((quantile(&x, q).unwrap() - want).abs() < 1e-12, "q {q}");
        }
        // np.quantile([2.5, 7.25, 1.0, 9.5, 4.0], [0.1, 0.25, 0.5, 0.9])
        let y = [2.5, 7.25, 1.0, 9.5, 4.0];
        for (q, want) in [(0.1, 1.6), (0.25, 2.5), (0.5, 4.0), (0.9, 8.6)] {
            assert!((quantile(&y, q).unwrap() - want).abs() < 1e-12, "q {q}");
        }
    }

    #[test]
    fn refuses_empty_samples_and_bad_levels() {
        assert!(quantile(&[], 0.5).is_err());
        assert!(quantile(&[1.0], 1.5).is_err());
        assert!(quantile(&[1.0, f64::NAN], 0.5).is_err());
    }
}
