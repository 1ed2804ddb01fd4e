//! A frame read through the profile (core's `read_frame`, as the indentation estimator reads
//! every frame) scored against a ball press: the contact radius against the marked one, and
//! the peak depth against the depth the rebuilt press has in the layer model at that radius
//! (a rigid ball: the gel takes the whole travel). For `tactex compare`, on real and rendered
//! frames.

use image::RgbImage;
use serde::Serialize;
use tactex_core::stats::median;
use tactex_core::tactile::ball_calibration::BallPress;
use tactex_core::tactile::frame_reading::read_frame;
use tactex_core::tactile::slopes::ColourDrift;
use tactex_core::tactile::spec::TactileSpec;

#[derive(Serialize, Debug, Clone, Copy)]
pub struct ReadingScore {
    pub peak_depth_mm: f64,
    pub contact_radius_mm: f64,
    /// Read over modelled peak depth, minus one.
    pub depth_error: f64,
    /// Read over marked contact radius, minus one.
    pub radius_error: f64,
    pub within_frame: bool,
}

/// `frame` read against `reference` through `spec`, scored against the press's marked radius
/// and the model's depth for it.
pub fn score_reading(
    frame: &RgbImage,
    reference: &RgbImage,
    spec: &TactileSpec,
    press: &BallPress,
    model_depth_mm: f64,
) -> Option<ReadingScore> {
    let r = read_frame(frame, reference, spec, ColourDrift::Measured)?;
    let radius = r.contact_radius_mm();
    Some(ReadingScore {
        peak_depth_mm: r.peak_mm,
        contact_radius_mm: radius,
        depth_error: r.peak_mm / model_depth_mm - 1.0,
        radius_error: radius / (press.contact_radius_px * spec.mm_per_px) - 1.0,
        within_frame: r.within_frame,
    })
}

#[derive(Serialize, Debug, Clone, Copy)]
pub struct ReadingSummary {
    pub presses: usize,
    /// Median of read over true, minus one.
    pub depth_error_median: f64,
    pub depth_error_median_abs: f64,
    pub radius_error_median: f64,
    pub radius_error_median_abs: f64,
}

pub fn summarise<'a>(scores: impl Iterator<Item = &'a ReadingScore>) -> ReadingSummary {
    let all: Vec<&ReadingScore> = scores.collect();
    let med = |f: &dyn Fn(&ReadingScore) -> f64| {
        let mut v: Vec<f64> = all.iter().map(|s| f(s)).collect();
        median(&mut v).unwrap_or(f64::NAN)
    };
    ReadingSummary {
        presses: all.len(),
        depth_error_median: med(&|s| s.depth_error),
        depth_error_median_abs: med(&|s| s.depth_error.abs()),
        radius_error_median: med(&|s| s.radius_error),
        radius_error_median_abs: med(&|s| s.radius_error.abs()),
    }
}
