//! Student t-tests as scipy.stats computes them: Welch's two-sample test (unequal variances,
//! Welch-Satterthwaite degrees of freedom) and the one-sample test.

use super::{Alternative, StatsError, TestResult, check, sample_mean, variance};
use statrs::distribution::{ContinuousCDF, StudentsT};

fn p_value(t: f64, df: f64, alternative: Alternative) -> Result<f64, StatsError> {
    let dist = StudentsT::new(0.0, 1.0, df).map_err(|e| StatsError {
        what: "degrees of freedom",
        message: e.to_string(),
    })?;
    Ok(match alternative {
        Alternative::TwoSided => (2.0 * dist.sf(t.abs())).min(1.0),
        Alternative::Greater => dist.sf(t),
        Alternative::Less => dist.cdf(t),
    })
}

/// Welch's t-test of mean(x) against mean(y).
pub fn welch_t(x: &[f64], y: &[f64], alternative: Alternative) -> Result<TestResult, StatsError> {
    check("x", x, 2)?;
    check("y", y, 2)?;
    let (a, b) = (variance(x) / x.len() as f64, variance(y) / y.len() as f64);
    if a + b == 0.0 {
        return Err(StatsError {
            what: "x, y",
            message: "both samples are constant".into(),
        });
    }
    let t = (sample_mean(x) - sample_mean(y)) / (a + b).sqrt();
    let df = (a + b).powi(2) / (a * a / (x.len() - 1) as f64 + b * b / (y.len() - 1) as f64);
    Ok(TestResult {
        statistic: t,
        p_value: p_value(t, df, alternative)?,
        df: Some(df),
    })
}

/// One-sample t-test of mean(x) against `mu`.
pub fn one_sample_t(
    x: &[f64],
    mu: f64,
    alternative: Alternative,
) -> Result<TestResult, StatsError> {
    check("x", x, 2)?;
    let v = variance(x);
    if v == 0.0 {
        return Err(StatsError {
            what: "x",
            message: "the sample is constant".into(),
        });
    }
    let df = (x.len() - 1) as f64;
    let t = (sample_mean(x) - mu) / (v / x.len() as f64).sqrt();
    Ok(TestResult {
        statistic: t,
        p_value: p_value(t, df, alternative)?,
        df: Some(df),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    const X: [f64; 5] = [19.0, 22.0, 16.0, 29.0, 24.0];
    const Y: [f64; 4] = [20.0, 11.0, 17.0, 12.0];

    #[test]
    fn welch_matches_scipy() {
        // scipy.stats.ttest_ind(x, y, equal_var=False): t = 2.2831482556870477,
        // p = 0.05675092592187574, df = 6.928837482846501; 'greater': p = 0.02837546296093787.
        let r = welch_t(&X, &Y, Alternative::TwoSided).unwrap();
        assert!((r.statistic - 2.2831482556870477).abs() < 1e-12);
        assert!((r.df.unwrap() - 6.928837482846501).abs() < 1e-12);
        assert!((r.p_value - 0.05675092592187574).abs() < 1e-10);
        let g = welch_t(&X, &Y, Alternative::Greater).unwrap();
        assert!((g.p_value - 0.02837546296093787).abs() < 1e-10);
    }

    #[test]
    fn one_sample_matches_scipy() {
        // scipy.stats.ttest_1samp(x, 20): t = 0.9035079029052513, p = 0.41734905117810495.
        let r = one_sample_t(&X, 20.0, Alternative::TwoSided).unwrap();
        assert!((r.statistic - 0.9035079029052513).abs() < 1e-12);
        assert!((r.p_value - 0.41734905117810495).abs() < 1e-10);
        assert!(one_sample_t(&[3.0, 3.0], 1.0, Alternative::TwoSided).is_err());
    }
}
