//! 95% confidence intervals: Student's t interval of a mean (scipy.stats.t.interval) and
//! Wilson's score interval of a proportion (statsmodels' proportion_confint, method wilson).

use super::{StatsError, check};
use statrs::distribution::{ContinuousCDF, Normal, StudentsT};

/// The t interval of the mean of `x` at `level` (e.g. 0.95).
pub fn mean_interval(x: &[f64], level: f64) -> Result<[f64; 2], StatsError> {
    check("x", x, 2)?;
    let n = x.len() as f64;
    let mean = x.iter().sum::<f64>() / n;
    let var = x.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0);
    let t = StudentsT::new(0.0, 1.0, n - 1.0)
        .map_err(|e| StatsError {
            what: "x",
            message: e.to_string(),
        })?
        .inverse_cdf(0.5 + level / 2.0);
    let half = t * (var / n).sqrt();
    Ok([mean - half, mean + half])
}

/// Wilson's score interval of `successes` out of `n` at `level`.
pub fn proportion_interval(successes: usize, n: usize, level: f64) -> Result<[f64; 2], StatsError> {
    if n == 0 || successes > n {
        return Err(StatsError {
            what: "proportion",
            message: format!("{successes} successes out of {n}"),
        });
    }
    let z = Normal::standard().inverse_cdf(0.5 + level / 2.0);
    let (k, n) = (successes as f64, n as f64);
    let p = k / n;
    let centre = (p + z * z / (2.0 * n)) / (1.0 + z * z / n);
    let half = z * (p * (1.0 - p) / n + z * z / (4.0 * n * n)).sqrt() / (1.0 + z * z / n);
    Ok([(centre - half).max(0.0), (centre + half).min(1.0)])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn t_interval_matches_scipy() {
        // scipy.stats.t.interval(0.95, 4, loc=22, scale=sem([19, 22, 16, 29, 24]))
        let [lo, hi] = mean_interval(&[19.0, 22.0, 16.0, 29.0, 24.0], 0.95).unwrap();
        assert!((lo - 15.854_076_768_404_42).abs() < 1e-9, "{lo}");
        assert!((hi - 28.145_923_231_595_58).abs() < 1e-9, "{hi}");
    }

    #[test]
    fn wilson_interval_matches_statsmodels() {
        let [lo, hi] = proportion_interval(8, 10, 0.95).unwrap();
        assert!((lo - 0.490_162_471_536_641_8).abs() < 1e-9, "{lo}");
        assert!((hi - 0.943_317_848_545_624_7).abs() < 1e-9, "{hi}");
        let [lo, hi] = proportion_interval(40, 40, 0.95).unwrap();
        assert!((lo - 0.912_378_398_802_713_5).abs() < 1e-9 && hi == 1.0);
        assert!(proportion_interval(3, 2, 0.95).is_err());
    }
}
