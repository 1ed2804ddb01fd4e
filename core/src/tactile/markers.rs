//! Marker dots on a tactile image: detection (dark blobs against the local background),
//! tracking against a reference frame, and the displacement statistic of the contact test.

use super::circle_fit::fit_circle;
use super::closing::{close_binary_with_square, close_with_disk};
use image::{GrayImage, Luma, RgbImage};
use imageproc::geometry::convex_hull;
use imageproc::point::Point;
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
    detect_dots(img).into_iter().map(|d| d.centre_px).collect()
}

/// One marker dot as seen: where, how large and how dark.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Dot {
    pub centre_px: (f64, f64),
    /// Pixels of its silhouette.
    pub area_px: usize,
    /// Whether the frame's edge cuts it (its area is then a part).
    pub cut_by_frame: bool,
    /// The share of the gel's light its darkest pixel blocks (0 none, 1 all).
    pub darkness: f64,
}

/// The dots of `detect_markers`, with their size and darkness, in the same order.
pub fn detect_dots(img: &RgbImage) -> Vec<Dot> {
    let (w, h) = img.dimensions();
    let lum = GrayImage::from_fn(w, h, |x, y| {
        let p = img.get_pixel(x, y);
        Luma([((p[0] as u32 * 54 + p[1] as u32 * 183 + p[2] as u32 * 19) >> 8) as u8])
    });
    let background = close_with_disk(&lum, BACKGROUND_RADIUS_PX);
    let darkness =
        |x: u32, y: u32| background.get_pixel(x, y)[0] as f64 - lum.get_pixel(x, y)[0] as f64;
    let dark = GrayImage::from_fn(w, h, |x, y| {
        let b = background.get_pixel(x, y)[0] as f64;
        Luma([if darkness(x, y) > 0.45 * b { 255 } else { 0 }])
    });
    // Closing fills specular specks and notches inside a dot so they do not pull its centroid.
    let dark = close_binary_with_square(&dark, 2);
    let labels = connected_components(&dark, Connectivity::Eight, Luma([0u8]));
    let n = labels.pixels().map(|p| p[0]).max().unwrap_or(0) as usize;
    let mut blobs: Vec<Vec<Point<i32>>> = vec![Vec::new(); n + 1];
    for (x, y, l) in labels.enumerate_pixels() {
        if l[0] > 0 {
            blobs[l[0] as usize].push(Point::new(x as i32, y as i32));
        }
    }
    let mut out: Vec<Dot> = blobs
        .into_iter()
        .skip(1)
        // Specks and smudges are not dots. A dot cut by the frame edge is kept: its centroid
        // is that of the visible part.
        .filter(|b| (6..=600).contains(&b.len()))
        .map(|b| {
            let cut_by_frame = b
                .iter()
                .any(|p| p.x == 0 || p.y == 0 || p.x + 1 == w as i32 || p.y + 1 == h as i32);
            let blocked = b
                .iter()
                .map(|p| {
                    let (x, y) = (p.x as u32, p.y as u32);
                    darkness(x, y) / (background.get_pixel(x, y)[0] as f64).max(1.0)
                })
                .fold(0.0, f64::max);
            Dot {
                centre_px: dot_centre(&b, cut_by_frame),
                area_px: b.len(),
                cut_by_frame,
                darkness: blocked.clamp(0.0, 1.0),
            }
        })
        .collect();
    out.sort_by(|p, q| {
        let (p, q) = (p.centre_px, q.centre_px);
        (p.1.round(), p.0)
            .partial_cmp(&(q.1.round(), q.0))
            .unwrap_or(std::cmp::Ordering::Equal)
    });
    out
}

/// Centre of a dot from its silhouette. A bright ridge or glint that cuts a bite or a chord
/// out of a dot (the highlights at a sharp indenter's edge) leaves the corners of the cut on
/// the dot's outline, so the circle through the silhouette's convex hull vertices is the
/// dot's; a plain pixel mean would be pulled away from the cut. Falls back to the hull's
/// area centroid when the vertices do not make a plausible circle, and for a dot cut by the
/// frame's edge (its centre is that of the visible part). Shading inside the dot plays no
/// part.
fn dot_centre(pixels: &[Point<i32>], cut_by_frame: bool) -> (f64, f64) {
    let mean = (
        pixels.iter().map(|p| p.x as f64).sum::<f64>() / pixels.len() as f64,
        pixels.iter().map(|p| p.y as f64).sum::<f64>() / pixels.len() as f64,
    );
    let hull = convex_hull(pixels.to_vec());
    // Shoelace area and centroid of the hull polygon.
    let (mut area2, mut cx, mut cy) = (0.0, 0.0, 0.0);
    for (i, a) in hull.iter().enumerate() {
        let b = hull[(i + 1) % hull.len()];
        let cross = (a.x * b.y - b.x * a.y) as f64;
        area2 += cross;
        cx += (a.x + b.x) as f64 * cross;
        cy += (a.y + b.y) as f64 * cross;
    }
    // A line or a point (a one-pixel-wide blob) has no area: its pixel mean is its centre.
    if area2.abs() < 1.0 {
        return mean;
    }
    let centroid = (cx / (3.0 * area2), cy / (3.0 * area2));
    if cut_by_frame {
        return centroid;
    }
    let equivalent_radius = (area2.abs() / 2.0 / std::f64::consts::PI).sqrt();
    let vertices: Vec<[f64; 2]> = hull.iter().map(|p| [p.x as f64, p.y as f64]).collect();
    // Six vertices at least: fewer do not pin a dot's outline.
    let circle = (vertices.len() >= 6)
        .then(|| fit_circle(&vertices))
        .flatten();
    match circle {
        // A cut removes at most about half a dot: its circle is at most ~1.5x the radius of
        // a disc of the hull's area, and its centre lies within that circle.
        Some(([x, y], r))
            if r < 1.8 * equivalent_radius + 1.0 && (x - centroid.0).hypot(y - centroid.1) < r =>
        {
            (x, y)
        }
        _ => centroid,
    }
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
    fn a_glint_cutting_into_a_dot_does_not_move_its_centre() {
        // A dot of radius 6 at (30, 30) with a bright notch 5 px tall and 4 deep cut into its
        // left side, as a ridge's highlight cuts into the real frames' dots.
        let dark = |x: u32, y: u32| {
            let (dx, dy) = (x as f64 - 30.0, y as f64 - 30.0);
            dx.hypot(dy) <= 6.0 && !(dx < -2.5 && dy.abs() <= 2.0)
        };
        let img = RgbImage::from_fn(60, 60, |x, y| {
            if dark(x, y) {
                Rgb([30, 30, 30])
            } else {
                Rgb([170, 150, 140])
            }
        });
        let pixels: Vec<(f64, f64)> = (0..60u32)
            .flat_map(|y| (0..60u32).map(move |x| (x, y)))
            .filter(|&(x, y)| dark(x, y))
            .map(|(x, y)| (x as f64, y as f64))
            .collect();
        let mean_x = pixels.iter().map(|p| p.0).sum::<f64>() / pixels.len() as f64;
        assert!(
            mean_x - 30.0 > 0.6,
            "the notch pulls a pixel mean: {mean_x}"
        );
        let found = detect_markers(&img);
        assert_eq!(found.len(), 1);
        let (x, y) = found[0];
        assert!((x - 30.0).hypot(y - 30.0) < 0.3, "{x}, {y}");
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
