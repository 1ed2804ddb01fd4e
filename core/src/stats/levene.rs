//! Levene's test for equal variances, median-centred (Brown-Forsythe; scipy's default
//! `center='median'`): the one-way ANOVA F of the absolute deviations from each group's median.

use super::{StatsError, TestResult, check, mean};
use statrs::distribution::{ContinuousCDF, FisherSnedecor};

fn median(x: &[f64]) -> f64 {
    let mut s = x.to_vec();
    s.sort_by(f64::total_cmp);
    let n = s.len();
    if n % 2 == 1 {
        s[n / 2]
    } else {
        (s[n / 2 - 1] + s[n / 2]) / 2.0
    }
}

pub fn levene_median(groups: &[&[f64]]) -> Result<TestResult, StatsError> {
    if groups.len() < 2 {
        return Err(StatsError {
            what: "groups",
            message: "needs at least two groups".into(),
        });
    }
    for g in groups {
        check("group", g, 2)?;
    }
    let z: Vec<Vec<f64>> = groups
        .iter()
        .map(|g| {
            let m = median(g);
            g.iter().map(|v| (v - m).abs()).collect()
        })
        .collect();
    let k = groups.len() as f64;
    let n: f64 = z.iter().map(|g| g.len() as f64).sum();
    let group_means: Vec<f64> = z.iter().map(|g| mean(g)).collect();
    let grand = z.iter().flatten().sum::<f64>() / n;
    let between: f64 = z
        .iter()
        .zip(&group_means)
        .map(|(g, m)| g.len() as f64 * (m - grand).powi(2))
        .sum();
    let within: f64 = z
        .iter()
        .zip(&group_means)
        .map(|(g, m)| g.iter().map(|v| (v - m).powi(2)).sum::<f64>())
        .sum();
    if within == 0.0 {
        return Err(StatsError {
            what: "groups",
            message: "no spread within any group".into(),
        });
    }
    let w = (n - k) / (k - 1.0) * between / within;
    let f = FisherSnedecor::new(k - 1.0, n - k).map_err(|e| StatsError {
        what: "groups",
        message: e.to_string(),
    })?;
    Ok(TestResult {
        statistic: w,
        p_value: f.sf(w),
        df: Some(k - 1.0),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn matches_scipy() {
        // scipy.stats.levene(x, y, center='median'): W = 0.003968253968253976,
        // p = 0.9515322676471096; three groups: W = 3.579478054567022, p = 0.050425641380670065.
        let x = [19.0, 22.0, 16.0, 29.0, 24.0];
        let y = [20.0, 11.0, 17.0, 12.0];
        let r = levene_median(&[&x, &y]).unwrap();
        assert!((r.statistic - 0.003968253968253976).abs() < 1e-12);
        assert!((r.p_value - 0.9515322676471096).abs() < 1e-10);
        let a = [1.0, 2.0, 2.0, 3.0, 4.0, 4.0, 4.0, 5.0];
        let b = [3.0, 4.0, 5.0, 5.0, 6.0, 6.0, 7.0];
        let c = [2.0, 9.0, 4.0, 1.0, 7.0];
        let r = levene_median(&[&a, &b, &c]).unwrap();
        assert!((r.statistic - 3.579478054567022).abs() < 1e-12);
        assert!((r.p_value - 0.050425641380670065).abs() < 1e-10);
    }
}
