//! Has the gel touched something? The paper's contact criterion compares each frame with the
//! no-contact frame by SSIM and by marker motion. SSIM here is scikit-image's (grey levels,
//! 7x7 uniform window, data range 255); the frame-wide mean dilutes a small imprint with the
//! frame's size, so the test uses the local SSIM: the mean of the SSIM map over 32 px tiles
//! (half-overlapping), and calls contact when the worst tile falls to `tile_ssim` or below,
//! or when the markers moved more than `marker_px` on average (frames with markers only).
//!
//! Thresholds, measured on the FOTS real frames: worst-tile SSIM of the 31 ball presses
//! against the background 0.74-0.82; the background against itself with camera noise of 1, 2
//! and 3 grey levels (and a 15-level colour drift) 0.99, 0.96 and 0.91.

use super::markers::{detect_markers, grid_pitch_px, mean_moved_displacement, track};
use super::ssim::{gray, ssim_map};
use image::RgbImage;
use serde::Serialize;

#[derive(Clone, Copy, Debug)]
pub struct ContactRule {
    pub tile_px: usize,
    pub tile_ssim: f64,
    pub marker_px: f64,
}

impl Default for ContactRule {
    fn default() -> Self {
        Self {
            tile_px: 32,
            tile_ssim: 0.88,
            marker_px: 2.0,
        }
    }
}

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ContactEvidence {
    /// Frame-wide mean SSIM against the no-contact frame.
    pub ssim: f64,
    /// The lowest tile mean of the SSIM map.
    pub min_tile_ssim: f64,
    /// Mean displacement of the markers that moved (None: the frame has no markers).
    pub marker_px: Option<f64>,
    pub contact: bool,
}

/// Contact evidence of `frame` against the no-contact `reference`; None if their sizes differ
/// or the frame is smaller than one tile.
pub fn contact_evidence(
    frame: &RgbImage,
    reference: &RgbImage,
    rule: &ContactRule,
) -> Option<ContactEvidence> {
    if frame.dimensions() != reference.dimensions() {
        return None;
    }
    let (w, h) = (frame.width() as usize, frame.height() as usize);
    let map = ssim_map(&gray(frame), &gray(reference), w, h, 255.0)?;
    let (mw, mh) = (w - 6, h - 6);
    let t = rule.tile_px.max(1);
    if mw < t || mh < t {
        return None;
    }
    let step = (t / 2).max(1);
    let mut worst = f64::INFINITY;
    let starts = |n: usize| (0..=n - t).step_by(step).chain(std::iter::once(n - t));
    for y0 in starts(mh) {
        for x0 in starts(mw) {
            let mut sum = 0.0;
            for y in y0..y0 + t {
                sum += map[y * mw + x0..y * mw + x0 + t].iter().sum::<f64>();
            }
            worst = worst.min(sum / (t * t) as f64);
        }
    }
    let ssim = map.iter().sum::<f64>() / map.len() as f64;
    let rest = detect_markers(reference);
    let marker_px = (rest.len() >= 4)
        .then(|| grid_pitch_px(&rest))
        .flatten()
        .map(|pitch| mean_moved_displacement(&track(&rest, &detect_markers(frame), 0.45 * pitch)));
    let contact = worst <= rule.tile_ssim || marker_px.is_some_and(|m| m > rule.marker_px);
    Some(ContactEvidence {
        ssim,
        min_tile_ssim: worst,
        marker_px,
        contact,
    })
}
