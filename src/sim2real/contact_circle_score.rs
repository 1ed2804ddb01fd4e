//! The contact-circle estimate (core's `estimate_contact_circle`) scored against hand-marked
//! circles: per press and summarised, for `tactex compare` on real and rendered frames.

use image::RgbImage;
use serde::Serialize;
use tactex_core::stats::median;
use tactex_core::tactile::ball_calibration::BallPress;
use tactex_core::tactile::contact_circle::estimate_contact_circle;

#[derive(Serialize, Debug, Clone, Copy)]
pub struct CircleScore {
    pub centre_px: [f64; 2],
    pub radius_px: f64,
    /// Distance of the estimated centre from the marked one.
    pub centre_error_px: f64,
    /// Estimated minus marked radius.
    pub radius_error_px: f64,
}

/// The circle estimated on `frame` against its no-contact `reference`, scored against the
/// press's marked circle; None when no circle is found.
pub fn score_circle(
    frame: &RgbImage,
    reference: &RgbImage,
    press: &BallPress,
) -> Option<CircleScore> {
    let c = estimate_contact_circle(frame, reference)?;
    let [mx, my] = press.centre_px;
    Some(CircleScore {
        centre_px: c.centre_px,
        radius_px: c.radius_px,
        centre_error_px: (c.centre_px[0] - mx).hypot(c.centre_px[1] - my),
        radius_error_px: c.radius_px - press.contact_radius_px,
    })
}

#[derive(Serialize, Debug, Clone, Copy)]
pub struct CircleSummary {
    /// Presses with a circle found, of `presses`.
    pub found: usize,
    pub presses: usize,
    pub centre_error_median_px: f64,
    pub radius_error_median_px: f64,
    pub radius_error_mean_abs_px: f64,
}

pub fn summarise<'a>(scores: impl Iterator<Item = &'a Option<CircleScore>>) -> CircleSummary {
    let all: Vec<&Option<CircleScore>> = scores.collect();
    let found: Vec<&CircleScore> = all.iter().filter_map(|s| s.as_ref()).collect();
    let median = |mut v: Vec<f64>| median(&mut v).unwrap_or(f64::NAN);
    let n = found.len().max(1) as f64;
    CircleSummary {
        found: found.len(),
        presses: all.len(),
        centre_error_median_px: median(found.iter().map(|s| s.centre_error_px).collect()),
        radius_error_median_px: median(found.iter().map(|s| s.radius_error_px).collect()),
        radius_error_mean_abs_px: found.iter().map(|s| s.radius_error_px.abs()).sum::<f64>() / n,
    }
}
