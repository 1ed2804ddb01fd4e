//! Marker dots on a tactile image: detection (dark blobs against the local background),
//! tracking against a reference frame, and the displacement statistic of the contact test.

use image::{GrayImage, Luma, RgbImage};
use imageproc::distance_transform::Norm;
use imageproc::morphology::{Mask, close, grayscale_dilate, grayscale_erode};
use imageproc::region_labelling::{Connectivity, connected_components};

/// Radius (px) of the closing that erases the dots to estimate the gel behind them: larger
/// than any marker at tactile-frame resolutions (GelSight Mini dots are ~4-6 px across at
/// 320x240, FOTS's ~10 px).
const BACKGROUND_RADIUS_PX: u8 = 8;

/// Marker centroids in pixels (x, y): centroids of the dots' silhouettes (pixels much darker
/// than the gel behind them), sorted by row then column. The gel behind a dot is estimated by
/// a grey-level closing (the dots are small dark holes in a smooth bright field), so shading
/// gradients and coloured glows around a contact do not bias the centroids.
pub fn detect_markers(img: &RgbImage) -> Vec<(f64, f64)> {
    let (w, h) = img.dimensions();
    let lum = GrayImage::from_fn(w, h, |x, y| {
        let p = img.get_pixel(x, y);
        Luma([((p[0] as u32 * 54 + p[1] as u32 * 183 + p[2] as u32 * 19) >> 8) as u8])
    });
    let disk = Mask::disk(BACKGROUND_RADIUS_PX);
    let background = grayscale_erode(&grayscale_dilate(&lum, &disk), &disk);
    let darkness =
        |x: u32, y: u32| background.get_pixel(x, y)[0] as f64 - lum.get_pixel(x, y)[0] as f64;
    let dark = GrayImage::from_fn(w, h, |x, y| {
        let b = background.get_pixel(x, y)[0] as f64;
        Luma([if darkness(x, y) > 0.45 * b { 255 } else { 0 }])
    });
    // Closing fills specular specks and notches inside a dot so they do not pull its centroid.
    let dark = close(&dark, Norm::LInf, 2);
    let labels = connected_components(&dark, Connectivity::Eight, Luma([0u8]));
    let n = labels.pixels().map(|p| p[0]).max().unwrap_or(0) as usize;
    // Per blob: sums of x and y over its silhouette, and its pixel count. Uniform weights:
    // shading inside a dot (specks, the glow of a contact) says nothing about its centre.
    let mut acc = vec![(0.0f64, 0.0f64, 0usize); n + 1];
    for (x, y, l) in labels.enumerate_pixels() {
        let id = l[0] as usize;
        if id > 0 {
            let a = &mut acc[id];
            a.0 += x as f64;
            a.1 += y as f64;
            a.2 += 1;
        }
    }
    let mut out: Vec<(f64, f64)> = acc
        .iter()
        .skip(1)
        // Specks and smudges are not dots. A dot cut by the frame edge is kept: its centroid
        // is that of the visible part.
        .filter(|a| (6..=600).contains(&a.2))
        .map(|a| (a.0 / a.2 as f64, a.1 / a.2 as f64))
        .collect();
    out.sort_by(|p, q| {
        (p.1.round(), p.0)
            .partial_cmp(&(q.1.round(), q.0))
            .unwrap_or(std::cmp::Ordering::Equal)
    });
    out
}

/// The grid pitch: the median distance from each marker to its nearest neighbour. None with
/// fewer than two markers.
pub fn grid_pitch_px(markers: &[(f64, f64)]) -> Option<f64> {
    let mut nearest: Vec<f64> = markers
        .iter()
        .enumerate()
        .filter_map(|(i, p)| {
            markers
                .iter()
                .enumerate()
                .filter(|(j, _)| *j != i)
                .map(|(_, q)| (p.0 - q.0).hypot(p.1 - q.1))
                .min_by(f64::total_cmp)
        })
        .collect();
    nearest.sort_by(f64::total_cmp);
    nearest.get(nearest.len() / 2).copied()
}

/// For each reference marker, its displacement to the nearest current marker within
/// `max_px`, or None when it was lost.
pub fn track(
    reference: &[(f64, f64)],
    current: &[(f64, f64)],
    max_px: f64,
) -> Vec<Option<(f64, f64)>> {
    reference
        .iter()
        .map(|r| {
            current
                .iter()
                .map(|c| (c.0 - r.0, c.1 - r.1))
                .filter(|d| d.0.hypot(d.1) <= max_px)
                .min_by(|a, b| a.0.hypot(a.1).total_cmp(&b.0.hypot(b.1)))
        })
        .collect()
}

/// Tracking noise floor: displacements below this are taken as the marker not moving.
pub const MARKER_NOISE_FLOOR_PX: f64 = 0.5;

/// Mean displacement of the markers that moved beyond the noise floor (0 if none did): the
/// "mean marker displacement" of the contact test, taken over the markers the contact moves
/// rather than the whole grid, so that it does not shrink with the pad's size.
pub fn mean_moved_displacement(displacements: &[Option<(f64, f64)>]) -> f64 {
    let moved: Vec<f64> = displacements
        .iter()
        .flatten()
        .map(|d| d.0.hypot(d.1))
        .filter(|m| *m > MARKER_NOISE_FLOOR_PX)
        .collect();
    if moved.is_empty() {
        0.0
    } else {
        moved.iter().sum::<f64>() / moved.len() as f64
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use image::Rgb;

    fn dots(centres: &[(f64, f64)]) -> RgbImage {
        RgbImage::from_fn(120, 90, |x, y| {
            let inside = centres
                .iter()
                .any(|c| (x as f64 - c.0).hypot(y as f64 - c.1) <= 3.0);
            if inside {
                Rgb([30, 30, 30])
            } else {
                Rgb([170, 150, 140])
            }
        })
    }

    #[test]
    fn finds_and_tracks_dots() {
        let rest = [
            (20.0, 20.0),
            (60.0, 20.0),
            (100.0, 20.0),
            (20.0, 60.0),
            (60.0, 60.0),
        ];
        let found = detect_markers(&dots(&rest));
        assert_eq!(found.len(), rest.len());
        for (f, r) in found.iter().zip(&rest) {
            assert!((f.0 - r.0).hypot(f.1 - r.1) < 0.3, "{f:?} vs {r:?}");
        }
        let moved: Vec<_> = rest.iter().map(|r| (r.0 + 3.0, r.1 - 1.0)).collect();
        let d = track(&found, &detect_markers(&dots(&moved)), 8.0);
        assert!(
            d.iter()
                .all(|d| d.is_some_and(|d| (d.0 - 3.0).abs() < 0.3 && (d.1 + 1.0).abs() < 0.3))
        );
        assert!((mean_moved_displacement(&d) - 10f64.sqrt()).abs() < 0.3);
    }
}
