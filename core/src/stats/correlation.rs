//! Spearman's rank correlation (Pearson on average ranks, ties included; p-value from the t
//! distribution with n - 2 degrees of freedom, as scipy.stats.spearmanr), and the regression
//! metrics RMSE and R^2 (1 - residual / total sum of squares, sklearn's r2_score).

use super::ranks::average_ranks;
use super::{StatsError, TestResult, check, sample_mean};
use statrs::distribution::{ContinuousCDF, StudentsT};

fn same_length(x: &[f64], y: &[f64]) -> Result<(), StatsError> {
    if x.len() != y.len() {
        return Err(StatsError {
            what: "x, y",
            message: format!("lengths differ: {} and {}", x.len(), y.len()),
        });
    }
    Ok(())
}

pub fn spearman(x: &[f64], y: &[f64]) -> Result<TestResult, StatsError> {
    check("x", x, 3)?;
    check("y", y, 3)?;
    same_length(x, y)?;
    let (rx, ry) = (average_ranks(x), average_ranks(y));
    let (mx, my) = (sample_mean(&rx), sample_mean(&ry));
    let cov: f64 = rx.iter().zip(&ry).map(|(a, b)| (a - mx) * (b - my)).sum();
    let vx: f64 = rx.iter().map(|a| (a - mx).powi(2)).sum();
    let vy: f64 = ry.iter().map(|b| (b - my).powi(2)).sum();
    if vx == 0.0 || vy == 0.0 {
        return Err(StatsError {
            what: "x, y",
            message: "a constant sample has no rank correlation".into(),
        });
    }
    let r = (cov / (vx * vy).sqrt()).clamp(-1.0, 1.0);
    let df = (x.len() - 2) as f64;
    let p = if r.abs() == 1.0 {
        0.0
    } else {
        let t = r * (df / (1.0 - r * r)).sqrt();
        let dist = StudentsT::new(0.0, 1.0, df).map_err(|e| StatsError {
            what: "x",
            message: e.to_string(),
        })?;
        (2.0 * dist.sf(t.abs())).min(1.0)
    };
    Ok(TestResult {
        statistic: r,
        p_value: p,
        df: Some(df),
    })
}

pub fn rmse(truth: &[f64], predicted: &[f64]) -> Result<f64, StatsError> {
    check("truth", truth, 1)?;
    check("predicted", predicted, 1)?;
    same_length(truth, predicted)?;
    let sq: f64 = truth
        .iter()
        .zip(predicted)
        .map(|(t, p)| (t - p).powi(2))
        .sum();
    Ok((sq / truth.len() as f64).sqrt())
}

pub fn r_squared(truth: &[f64], predicted: &[f64]) -> Result<f64, StatsError> {
    check("truth", truth, 2)?;
    check("predicted", predicted, 2)?;
    same_length(truth, predicted)?;
    let m = sample_mean(truth);
    let total: f64 = truth.iter().map(|t| (t - m).powi(2)).sum();
    if total == 0.0 {
        return Err(StatsError {
            what: "truth",
            message: "constant truth has no variance to explain".into(),
        });
    }
    let residual: f64 = truth
        .iter()
        .zip(predicted)
        .map(|(t, p)| (t - p).powi(2))
        .sum();
    Ok(1.0 - residual / total)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spearman_with_ties_matches_scipy() {
        // scipy.stats.spearmanr([1,2,3,4,5], [5,6,7,8,7]): 0.8207826816681233,
        // p = 0.08858700531354384.
        let r = spearman(&[1.0, 2.0, 3.0, 4.0, 5.0], &[5.0, 6.0, 7.0, 8.0, 7.0]).unwrap();
        assert!((r.statistic - 0.8207826816681233).abs() < 1e-15);
        assert!((r.p_value - 0.08858700531354384).abs() < 1e-10);
    }

    #[test]
    fn regression_metrics_match_sklearn() {
        // sklearn.metrics: y = [3, -0.5, 2, 7], p = [2.5, 0.0, 2, 8]:
        // mean_squared_error -> 0.375 (RMSE 0.6123724356957945), r2_score -> 0.9486081370449679
        let (t, p) = ([3.0, -0.5, 2.0, 7.0], [2.5, 0.0, 2.0, 8.0]);
        assert!((rmse(&t, &p).unwrap() - 0.6123724356957945).abs() < 1e-15);
        assert!((r_squared(&t, &p).unwrap() - 0.9486081370449679).abs() < 1e-15);
        assert!(rmse(&t, &p[..3]).is_err());
    }
}
