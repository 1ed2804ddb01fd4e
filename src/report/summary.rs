//! Summaries the benches and evaluations print: one definition of a median for all of them.

/// The median of `v` (the mean of the middle two for an even count); NaN for none, as the
/// reports print it.
pub fn median(mut v: Vec<f64>) -> f64 {
    tactex_core::stats::median(&mut v).unwrap_or(f64::NAN)
}
