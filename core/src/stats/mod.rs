//! Statistics of the paper's validation tables, each checked against scipy's or numpy's
//! values in its tests: rank tests (Mann-Whitney U), t-tests (Welch, one-sample),
//! Holm-Bonferroni, Spearman's rank correlation, sample quantiles, t and Wilson confidence
//! intervals, and the regression metrics RMSE and R^2. Distribution functions come from
//! statrs.

mod correlation;
mod intervals;
mod mann_whitney;
mod multiple;
mod quantile;
mod ranks;
mod t_tests;

pub use correlation::{r_squared, rmse, spearman};
pub use intervals::{mean_interval, proportion_interval};
pub use mann_whitney::{MannWhitneyMethod, mann_whitney_u};
pub use multiple::holm_bonferroni;
pub use quantile::quantile;
pub use ranks::average_ranks;
pub use t_tests::{one_sample_t, welch_t};

/// Which way the alternative hypothesis points (the first sample larger: `Greater`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Alternative {
    TwoSided,
    Greater,
    Less,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TestResult {
    pub statistic: f64,
    pub p_value: f64,
    /// Degrees of freedom, where the test has them.
    pub df: Option<f64>,
}

#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{what}: {message}")]
pub struct StatsError {
    pub what: &'static str,
    pub message: String,
}

pub(crate) fn check(what: &'static str, x: &[f64], min_len: usize) -> Result<(), StatsError> {
    if x.len() < min_len {
        return Err(StatsError {
            what,
            message: format!("needs at least {min_len} values, got {}", x.len()),
        });
    }
    if x.iter().any(|v| !v.is_finite()) {
        return Err(StatsError {
            what,
            message: "values must be finite".into(),
        });
    }
    Ok(())
}

/// The mean of `values`; None for none. The one definition the library's figures use.
pub fn mean(values: &[f64]) -> Option<f64> {
    (!values.is_empty()).then(|| values.iter().sum::<f64>() / values.len() as f64)
}

/// The median of `values` (the mean of the middle two for an even count), sorting them in
/// place; None for none. The one definition the library's figures use (a robust "middle
/// element" pick inside a reading, such as a marker spacing, is its own thing).
pub fn median(values: &mut [f64]) -> Option<f64> {
    if values.is_empty() {
        return None;
    }
    values.sort_by(f64::total_cmp);
    let n = values.len();
    Some(if n % 2 == 1 {
        values[n / 2]
    } else {
        0.5 * (values[n / 2 - 1] + values[n / 2])
    })
}

/// The mean of a sample the tests here have already checked is not empty.
pub(crate) fn sample_mean(x: &[f64]) -> f64 {
    x.iter().sum::<f64>() / x.len() as f64
}

/// Sample variance (n - 1 in the denominator).
pub(crate) fn variance(x: &[f64]) -> f64 {
    let m = sample_mean(x);
    x.iter().map(|v| (v - m).powi(2)).sum::<f64>() / (x.len() - 1) as f64
}
