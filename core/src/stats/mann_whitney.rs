//! Mann-Whitney U test as scipy.stats.mannwhitneyu computes it: U of the first sample; by
//! default the exact distribution when either sample has at most 8 values and there are no
//! ties, else the normal approximation with tie correction and continuity correction.

use super::ranks::{average_ranks, tie_groups};
use super::{Alternative, StatsError, TestResult, check};
use statrs::distribution::{ContinuousCDF, Normal};

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MannWhitneyMethod {
    /// scipy's default choice.
    Auto,
    Exact,
    Asymptotic,
}

/// Number of arrangements giving each U = 0..=n1*n2 (no ties), by the recurrence
/// f(m, n, u) = f(m - 1, n, u - n) + f(m, n - 1, u).
fn u_counts(n1: usize, n2: usize) -> Vec<f64> {
    // table[m][n] as a vector over u, built up in n for each m.
    let mut prev: Vec<Vec<f64>> = (0..=n2).map(|_| vec![1.0]).collect(); // m = 0: only u = 0
    for m in 1..=n1 {
        let mut cur: Vec<Vec<f64>> = Vec::with_capacity(n2 + 1);
        cur.push(vec![1.0]); // n = 0: only u = 0
        for n in 1..=n2 {
            let mut f = vec![0.0; m * n + 1];
            for (u, c) in prev[n].iter().enumerate() {
                f[u + n] += c;
            }
            for (u, c) in cur[n - 1].iter().enumerate() {
                f[u] += c;
            }
            cur.push(f);
        }
        prev = cur;
    }
    prev.pop().expect("n2 + 1 entries")
}

pub fn mann_whitney_u(
    x: &[f64],
    y: &[f64],
    alternative: Alternative,
    method: MannWhitneyMethod,
) -> Result<TestResult, StatsError> {
    check("x", x, 1)?;
    check("y", y, 1)?;
    let (n1, n2) = (x.len(), y.len());
    let all: Vec<f64> = x.iter().chain(y).copied().collect();
    let ranks = average_ranks(&all);
    let r1: f64 = ranks[..n1].iter().sum();
    let u1 = r1 - (n1 * (n1 + 1)) as f64 / 2.0;
    let u2 = (n1 * n2) as f64 - u1;
    let ties = tie_groups(&all);
    let has_ties = ties.iter().any(|&t| t > 1);
    let exact = match method {
        MannWhitneyMethod::Exact => true,
        MannWhitneyMethod::Asymptotic => false,
        MannWhitneyMethod::Auto => n1.min(n2) <= 8 && !has_ties,
    };
    let p = if exact {
        let counts = u_counts(n1, n2);
        let total: f64 = counts.iter().sum();
        // P(U >= u) for the U of the first sample.
        let sf = |u: f64| -> f64 {
            let k = u.ceil().max(0.0) as usize;
            counts.iter().skip(k).sum::<f64>() / total
        };
        match alternative {
            Alternative::Greater => sf(u1),
            Alternative::Less => sf(u2),
            Alternative::TwoSided => (2.0 * sf(u1.max(u2))).min(1.0),
        }
    } else {
        let n = (n1 + n2) as f64;
        let tie_term: f64 = ties.iter().map(|&t| (t * t * t - t) as f64).sum();
        let sigma = ((n1 * n2) as f64 / 12.0 * ((n + 1.0) - tie_term / (n * (n - 1.0)))).sqrt();
        let mu = (n1 * n2) as f64 / 2.0;
        let u = match alternative {
            Alternative::Greater => u1,
            Alternative::Less => u2,
            Alternative::TwoSided => u1.max(u2),
        };
        let z = (u - mu - 0.5) / sigma;
        let sf = Normal::standard().sf(z);
        match alternative {
            Alternative::TwoSided => (2.0 * sf).min(1.0),
            _ => sf,
        }
    };
    Ok(TestResult {
        statistic: u1,
        p_value: p,
        df: None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    const X: [f64; 5] = [19.0, 22.0, 16.0, 29.0, 24.0];
    const Y: [f64; 4] = [20.0, 11.0, 17.0, 12.0];

    #[test]
    fn matches_scipy_exact_and_asymptotic() {
        // scipy.stats.mannwhitneyu(x, y, method=...), SciPy 1.x.
        let exact = mann_whitney_u(&X, &Y, Alternative::TwoSided, MannWhitneyMethod::Auto).unwrap();
        assert_eq!(exact.statistic, 17.0);
        assert!((exact.p_value - 0.1111111111111111).abs() < 1e-15);
        let asym =
            mann_whitney_u(&X, &Y, Alternative::TwoSided, MannWhitneyMethod::Asymptotic).unwrap();
        // statrs's erfc agrees with scipy's to ~5e-12 here.
        assert!(
            (asym.p_value - 0.11134688653314041).abs() < 1e-10,
            "{}",
            asym.p_value
        );
        let greater =
            mann_whitney_u(&X, &Y, Alternative::Greater, MannWhitneyMethod::Exact).unwrap();
        assert!((greater.p_value - 0.05555555555555555).abs() < 1e-15);
        let less =
            mann_whitney_u(&X, &Y, Alternative::Less, MannWhitneyMethod::Asymptotic).unwrap();
        assert!((less.p_value - 0.9669037101389033).abs() < 1e-10);
    }

    #[test]
    fn ties_take_the_corrected_normal_approximation() {
        // a = [1,2,2,3,4,4,4,5], b = [3,4,5,5,6,6,7]: U = 8, p = 0.021920655864769517
        // (two-sided), 0.010960327932384759 (less).
        let a = [1.0, 2.0, 2.0, 3.0, 4.0, 4.0, 4.0, 5.0];
        let b = [3.0, 4.0, 5.0, 5.0, 6.0, 6.0, 7.0];
        let two = mann_whitney_u(&a, &b, Alternative::TwoSided, MannWhitneyMethod::Auto).unwrap();
        assert_eq!(two.statistic, 8.0);
        assert!((two.p_value - 0.021920655864769517).abs() < 1e-10);
        let less = mann_whitney_u(&a, &b, Alternative::Less, MannWhitneyMethod::Auto).unwrap();
        assert!((less.p_value - 0.010960327932384759).abs() < 1e-10);
    }

    #[test]
    fn empty_or_nan_input_is_an_error() {
        assert!(mann_whitney_u(&[], &Y, Alternative::TwoSided, MannWhitneyMethod::Auto).is_err());
        assert!(
            mann_whitney_u(
                &[f64::NAN],
                &Y,
                Alternative::TwoSided,
                MannWhitneyMethod::Auto
            )
            .is_err()
        );
    }
}
