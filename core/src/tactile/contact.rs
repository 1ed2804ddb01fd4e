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
//!
//! A quieter sensor sees a shallow imprint long before the fixed threshold does: given a second
//! no-contact frame, `ContactTest` measures the sensor's own noise floor and calls contact when
//! the worst tile's dissimilarity 1 - SSIM is `floor_ratio` (1.3) times the floor's. Measured on
//! the twin's frames over 12 seeds: noise of 0.5, 1 and 2 grey levels gives floors of
//! 0.9938, 0.9803 and 0.930, each within +-6% in dissimilarity, so 1.3 is over 4 spreads.
//!
//! The tiles and the 7x7 window are in pixels, so the thresholds hold at the pixel size they
//! were measured at (`ContactRule::pixel_mm`, FOTS's 0.051 mm). A sensor of finer pixels
//! (R1.5's 0.0295 mm) would see a shallow imprint's slopes over a smaller patch of gel in
//! each window, against the same camera noise per pixel, and fire late: its frames are read
//! binned, each grey level the mean of a b x b block, b the nearest whole ratio of the sizes.

use super::markers::{detect_markers, grid_pitch_px, mean_moved_displacement, track};
use super::ssim::{gray, ssim_map};
use image::RgbImage;
use serde::Serialize;

/// The paper's frame-wide SSIM threshold (with marker motion over 2 px), reported as
/// `ContactEvidence::paper_reading`.
pub const PAPER_FRAME_SSIM: f64 = 0.96;

#[derive(Clone, Copy, Debug)]
pub struct ContactRule {
    pub tile_px: usize,
    pub tile_ssim: f64,
    pub marker_px: f64,
    /// With a noise floor measured (two no-contact frames), contact is also called when the
    /// worst tile's dissimilarity (1 - SSIM) exceeds the floor's by this factor.
    pub floor_ratio: f64,
    /// The pixel size (mm) the tiles and thresholds hold at: finer frames are binned to it.
    pub pixel_mm: f64,
}

impl Default for ContactRule {
    fn default() -> Self {
        Self {
            tile_px: 32,
            tile_ssim: 0.88,
            marker_px: 2.0,
            floor_ratio: 1.3,
            pixel_mm: 0.05,
        }
    }
}

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ContactEvidence {
    /// Frame-wide mean SSIM against the no-contact frame.
    pub ssim: f64,
    /// The lowest tile mean of the SSIM map.
    pub min_tile_ssim: f64,
    /// The tile SSIM below which the test calls contact (at or below the fixed `tile_ssim`).
    pub tile_threshold: f64,
    /// Worst tile SSIM between the two no-contact frames (None: no second frame was taken).
    pub noise_floor: Option<f64>,
    /// Mean displacement of the markers that moved (None: the frame has no markers).
    pub marker_px: Option<f64>,
    pub contact: bool,
    /// Which parts of the criterion fired: `tile_ssim` (the worst tile at or below the fixed
    /// 0.88 measured on real frames), `noise_floor` (at or below the threshold the sensor's
    /// own noise raised it to) and `markers` (mean marker motion over `marker_px`).
    pub fired_by: Vec<&'static str>,
    /// The paper's own reading on this frame: frame-wide SSIM <= 0.96 and markers moved > 2
    /// px. Reported beside the criterion, which calls contact on shallower imprints.
    pub paper_reading: bool,
}

/// The contact test against one no-contact frame, with the reference's grey levels and
/// markers computed once for a whole descent.
#[derive(Clone, Debug)]
pub struct ContactTest {
    rule: ContactRule,
    /// The side of the blocks the grey levels are binned over.
    bin: usize,
    /// The frame's size in pixels, and the binned grey levels' size.
    frame_size: (u32, u32),
    width: usize,
    height: usize,
    reference_gray: Vec<f64>,
    reference_markers: Vec<(f64, f64)>,
    pitch_px: Option<f64>,
    /// Worst tile SSIM between two no-contact frames: how far camera noise alone moves it.
    pub noise_floor: Option<f64>,
    pub tile_threshold: f64,
}

impl ContactTest {
    /// The test for frames of `mm_per_px` (None: read at their own pixels, unbinned); None
    /// if the binned frame is smaller than one tile.
    pub fn new(reference: &RgbImage, rule: &ContactRule, mm_per_px: Option<f64>) -> Option<Self> {
        let bin = bin_for(rule.pixel_mm, mm_per_px);
        let (w, h) = (
            reference.width() as usize / bin,
            reference.height() as usize / bin,
        );
        let t = rule.tile_px.max(1);
        if w < t + 6 || h < t + 6 {
            return None;
        }
        let markers = detect_markers(reference);
        let pitch_px = (markers.len() >= 4)
            .then(|| grid_pitch_px(&markers))
            .flatten();
        Some(Self {
            rule: *rule,
            bin,
            frame_size: reference.dimensions(),
            width: w,
            height: h,
            reference_gray: binned_gray(reference, bin),
            reference_markers: markers,
            pitch_px,
            noise_floor: None,
            tile_threshold: rule.tile_ssim,
        })
    }

    /// As `new`, with the threshold raised to `floor_ratio` times the dissimilarity of the
    /// noise floor measured
    /// between `reference` and a second no-contact frame `second`: a quiet sensor (the twin's,
    /// or a good camera) then calls contact as soon as the imprint beats its own noise, where
    /// the fixed threshold, set for the noisier real frames, would wait for a deep imprint.
    pub fn with_noise_floor(
        reference: &RgbImage,
        second: &RgbImage,
        rule: &ContactRule,
        mm_per_px: Option<f64>,
    ) -> Option<Self> {
        let mut test = Self::new(reference, rule, mm_per_px)?;
        if second.dimensions() != reference.dimensions() {
            return None;
        }
        let map = ssim_map(
            &binned_gray(second, test.bin),
            &test.reference_gray,
            test.width,
            test.height,
            255.0,
        )?;
        let floor = test.worst_tile(&map);
        test.noise_floor = Some(floor);
        test.tile_threshold = rule.tile_ssim.max(1.0 - rule.floor_ratio * (1.0 - floor));
        Some(test)
    }

    /// The lowest mean of the SSIM map over the (half-overlapping) tiles.
    fn worst_tile(&self, map: &[f64]) -> f64 {
        let (mw, mh) = (self.width - 6, self.height - 6);
        let t = self.rule.tile_px.max(1);
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
        worst
    }

    /// Evidence of `frame`; None if its size differs from the reference's.
    pub fn evidence(&self, frame: &RgbImage) -> Option<ContactEvidence> {
        if frame.dimensions() != self.frame_size {
            return None;
        }
        let frame_gray = binned_gray(frame, self.bin);
        let map = ssim_map(
            &frame_gray,
            &self.reference_gray,
            self.width,
            self.height,
            255.0,
        )?;
        let ssim = map.iter().sum::<f64>() / map.len() as f64;
        let worst = self.worst_tile(&map);
        let marker_px = self.pitch_px.map(|pitch| {
            mean_moved_displacement(&track(
                &self.reference_markers,
                &detect_markers(frame),
                0.45 * pitch,
            ))
        });
        let mut fired_by = Vec::new();
        // Strictly below the floor's threshold: a noiseless sensor (floor 1) sees any change,
        // and a frame identical to the reference is never contact.
        if worst <= self.rule.tile_ssim {
            fired_by.push("tile_ssim");
        } else if worst < self.tile_threshold {
            fired_by.push("noise_floor");
        }
        if marker_px.is_some_and(|m| m > self.rule.marker_px) {
            fired_by.push("markers");
        }
        Some(ContactEvidence {
            ssim,
            min_tile_ssim: worst,
            tile_threshold: self.tile_threshold,
            noise_floor: self.noise_floor,
            marker_px,
            contact: !fired_by.is_empty(),
            fired_by,
            paper_reading: ssim <= PAPER_FRAME_SSIM
                && marker_px.is_some_and(|m| m > self.rule.marker_px),
        })
    }
}

/// Contact evidence of `frame` against the no-contact `reference` (fixed threshold), binned
/// as `ContactTest::new` bins; None if their sizes differ or the frame is smaller than one
/// tile.
pub fn contact_evidence(
    frame: &RgbImage,
    reference: &RgbImage,
    rule: &ContactRule,
    mm_per_px: Option<f64>,
) -> Option<ContactEvidence> {
    ContactTest::new(reference, rule, mm_per_px)?.evidence(frame)
}

/// The side of the blocks that bring pixels of `mm_per_px` nearest to `pixel_mm`: 1 for
/// pixels as coarse or coarser, or an unknown size.
pub fn bin_for(pixel_mm: f64, mm_per_px: Option<f64>) -> usize {
    match mm_per_px.filter(|&s| s > 0.0).map(|s| pixel_mm / s) {
        // A pixel size so small that the ratio overflows bins as coarsely as any.
        Some(ratio) if ratio > 1.0 => ratio.round().min(64.0) as usize,
        _ => 1,
    }
}

/// The image's grey levels, each the mean over a `bin` x `bin` block (a last partial row or
/// column of blocks is left out).
fn binned_gray(img: &RgbImage, bin: usize) -> Vec<f64> {
    let g = gray(img);
    if bin <= 1 {
        return g;
    }
    let (w, h) = (img.width() as usize, img.height() as usize);
    let (bw, bh) = (w / bin, h / bin);
    let mut out = vec![0.0; bw * bh];
    for y in 0..bh * bin {
        let row = &g[y * w..][..bw * bin];
        for (o, block) in out[(y / bin) * bw..][..bw]
            .iter_mut()
            .zip(row.chunks_exact(bin))
        {
            *o += block.iter().sum::<f64>();
        }
    }
    let n = (bin * bin) as f64;
    out.iter_mut().for_each(|v| *v /= n);
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use image::Rgb;

    /// A textured gel (so that SSIM sees structure) with a shallow dark disc of `radius` px.
    fn frame(scale: u32, radius: f64) -> RgbImage {
        RgbImage::from_fn(96 * scale, 80 * scale, |x, y| {
            let (x, y) = (x / scale, y / scale);
            let r = ((x as f64 - 48.0).powi(2) + (y as f64 - 40.0).powi(2)).sqrt();
            let base = 120 + ((x * 7 + y * 13) % 17) as u8;
            let v = if r < radius { base - 6 } else { base };
            Rgb([v, v, v])
        })
    }

    #[test]
    fn pixels_finer_than_the_rules_are_binned_to_the_nearest_whole_ratio() {
        assert_eq!(bin_for(0.05, None), 1);
        assert_eq!(bin_for(0.05, Some(0.0634)), 1);
        assert_eq!(bin_for(0.05, Some(0.0511)), 1);
        assert_eq!(bin_for(0.05, Some(0.0295)), 2);
        assert_eq!(bin_for(0.05, Some(0.0125)), 4);
        assert_eq!(bin_for(0.05, Some(0.0)), 1);
        assert_eq!(bin_for(0.05, Some(f64::NAN)), 1);
        assert_eq!(bin_for(0.05, Some(1e-12)), 64);
        assert_eq!(bin_for(0.05, Some(5e-324)), 64);
    }

    #[test]
    fn a_frame_at_twice_the_resolution_reads_as_the_frame_at_the_rules_pixel_size() {
        let rule = ContactRule::default();
        for radius in [0.0, 6.0, 12.0] {
            let coarse = contact_evidence(&frame(1, radius), &frame(1, 0.0), &rule, Some(0.05));
            let fine = contact_evidence(&frame(2, radius), &frame(2, 0.0), &rule, Some(0.025));
            assert_eq!(coarse, fine, "radius {radius}");
            // Read at its own pixels, the fine frame's imprint is the same contrast over
            // smoother windows: a different reading.
            let unbinned = contact_evidence(&frame(2, radius), &frame(2, 0.0), &rule, None);
            if radius > 0.0 {
                assert_ne!(unbinned.unwrap().min_tile_ssim, fine.unwrap().min_tile_ssim);
            }
        }
    }

    #[test]
    fn frames_smaller_than_a_tile_once_binned_have_no_test() {
        let rule = ContactRule::default();
        let small = RgbImage::new(60, 60);
        assert!(ContactTest::new(&small, &rule, None).is_some());
        assert!(ContactTest::new(&small, &rule, Some(0.025)).is_none());
    }
}
