//! Where two touching fruits of one colour meet seen from above: the two notches in their
//! joint outline.
//!
//! The height watershed (`height_split`) parts fruits whose tops stand clear of the crevice
//! between them. A small fruit tucked under a taller one's flank does not: from above, the
//! tall fruit's silhouette edge stands higher than the small one's top, and when their
//! colours match nothing else tells them apart. Their joint outline still shows where they
//! meet: two notches, one on each side, where the outline leaves the convex hull. This module
//! finds the two deepest notches and cuts the region along the line through them; the
//! detector keeps the cut only when the two parts look like catalog fruit and the whole does
//! not.

use image::{GrayImage, Luma};
use imageproc::geometry;
use imageproc::point::Point;
use imageproc::region_labelling::{Connectivity, connected_components};

/// Notches shallower than this (pixels) are the ragged edge of one fruit's depth mask (the
/// depth camera's edge noise makes notches of up to about 4 px on a single fruit).
pub const MIN_NOTCH_PX: f64 = 5.0;

/// The region's pixels parted along the line through its two deepest outline notches, or None
/// when it has fewer than two notches of `MIN_NOTCH_PX`.
pub fn cut_at_neck(pixels: &[(u32, u32)]) -> Option<[Vec<(u32, u32)>; 2]> {
    let &(first_u, first_v) = pixels.first()?;
    let (mut u0, mut v0, mut u1, mut v1) = (first_u, first_v, first_u, first_v);
    for &(u, v) in pixels {
        (u0, v0, u1, v1) = (u0.min(u), v0.min(v), u1.max(u), v1.max(v));
    }
    // A one-pixel border of background round the region, so that the outside is connected.
    let (w, h) = ((u1 - u0 + 3) as usize, (v1 - v0 + 3) as usize);
    let at = |u: u32, v: u32| (v - v0 + 1) as usize * w + (u - u0 + 1) as usize;
    let mut region = vec![false; w * h];
    for &(u, v) in pixels {
        region[at(u, v)] = true;
    }
    let filled = fill_holes(&region, w, h);
    let hull = convex_hull(&filled, w);
    if hull.len() < 3 {
        return None;
    }
    let mut notches = notch_depths(&filled, w, h, &hull);
    notches.sort_by(|a, b| b.0.total_cmp(&a.0));
    let [(d1, p1), (d2, p2)] = [*notches.first()?, *notches.get(1)?];
    if d2 < MIN_NOTCH_PX || d1 < MIN_NOTCH_PX {
        return None;
    }
    let (nx, ny) = (-(p2[1] - p1[1]), p2[0] - p1[0]);
    let (mut left, mut right) = (Vec::new(), Vec::new());
    for &(u, v) in pixels {
        let (x, y) = ((u - u0 + 1) as f64, (v - v0 + 1) as f64);
        if (x - p1[0]) * nx + (y - p1[1]) * ny > 0.0 {
            left.push((u, v));
        } else {
            right.push((u, v));
        }
    }
    (!left.is_empty() && !right.is_empty()).then_some([left, right])
}

/// The region with its holes (a specular highlight with no depth) filled: every pixel whose
/// background component does not reach the frame's border.
fn fill_holes(region: &[bool], w: usize, h: usize) -> Vec<bool> {
    let background = GrayImage::from_fn(w as u32, h as u32, |x, y| {
        Luma([if region[y as usize * w + x as usize] {
            0
        } else {
            255
        }])
    });
    let labels = connected_components(&background, Connectivity::Four, Luma([0u8]));
    // The border is background all round, so its one label is the outside.
    let outside = labels.get_pixel(0, 0)[0];
    labels.pixels().map(|l| l[0] != outside).collect()
}

/// Convex hull of the set pixels' centres (imageproc's Graham scan), counter-clockwise as
/// seen with y up.
fn convex_hull(set: &[bool], w: usize) -> Vec<[f64; 2]> {
    let points: Vec<Point<i32>> = set
        .iter()
        .enumerate()
        .filter(|(_, s)| **s)
        .map(|(i, _)| Point::new((i % w) as i32, (i / w) as i32))
        .collect();
    let mut hull: Vec<[f64; 2]> = geometry::convex_hull(points)
        .into_iter()
        .map(|p| [p.x as f64, p.y as f64])
        .collect();
    let twice_area: f64 = (0..hull.len())
        .map(|i| {
            let (a, b) = (hull[i], hull[(i + 1) % hull.len()]);
            a[0] * b[1] - b[0] * a[1]
        })
        .sum();
    if twice_area < 0.0 {
        hull.reverse();
    }
    hull
}

/// Each notch (a 4-connected run of pixels inside the hull and outside the region) as its
/// depth, the largest distance of its pixels from the hull's boundary, and that pixel.
fn notch_depths(filled: &[bool], w: usize, h: usize, hull: &[[f64; 2]]) -> Vec<(f64, [f64; 2])> {
    let edges: Vec<([f64; 2], [f64; 2])> = (0..hull.len())
        .map(|i| (hull[i], hull[(i + 1) % hull.len()]))
        .collect();
    // Inside or on the hull, within half a pixel.
    let inside = |p: [f64; 2]| {
        edges.iter().all(|(a, b)| {
            let (ex, ey) = (b[0] - a[0], b[1] - a[1]);
            let len = ex.hypot(ey).max(1e-12);
            (ex * (p[1] - a[1]) - ey * (p[0] - a[0])) / len >= -0.5
        })
    };
    let depth = |p: [f64; 2]| {
        edges
            .iter()
            .map(|(a, b)| {
                let (ex, ey) = (b[0] - a[0], b[1] - a[1]);
                let t = (((p[0] - a[0]) * ex + (p[1] - a[1]) * ey)
                    / (ex * ex + ey * ey).max(1e-12))
                .clamp(0.0, 1.0);
                (p[0] - a[0] - t * ex).hypot(p[1] - a[1] - t * ey)
            })
            .fold(f64::INFINITY, f64::min)
    };
    let gap = GrayImage::from_fn(w as u32, h as u32, |x, y| {
        let i = y as usize * w + x as usize;
        Luma([u8::from(!filled[i] && inside([x as f64, y as f64])) * 255])
    });
    let labels = connected_components(&gap, Connectivity::Four, Luma([0u8]));
    let mut notches: Vec<(f64, [f64; 2])> = Vec::new();
    for (x, y, l) in labels.enumerate_pixels() {
        let label = l[0] as usize;
        if label == 0 {
            continue;
        }
        if notches.len() < label {
            notches.resize(label, (0.0, [0.0; 2]));
        }
        let p = [x as f64, y as f64];
        let d = depth(p);
        if d > notches[label - 1].0 {
            notches[label - 1] = (d, p);
        }
    }
    notches
}

#[cfg(test)]
mod tests {
    use super::*;

    fn discs(discs: &[(f64, f64, f64)]) -> Vec<(u32, u32)> {
        let mut out = Vec::new();
        for v in 0..200u32 {
            for u in 0..300u32 {
                if discs
                    .iter()
                    .any(|&(cu, cv, r)| (u as f64 - cu).hypot(v as f64 - cv) <= r)
                {
                    out.push((u, v));
                }
            }
        }
        out
    }

    #[test]
    fn a_large_and_a_small_disc_touching_part_where_they_meet() {
        let pixels = discs(&[(100.0, 100.0, 32.0), (140.0, 120.0, 15.0)]);
        let [a, b] = cut_at_neck(&pixels).expect("two notches");
        let (small, large) = if a.len() < b.len() { (a, b) } else { (b, a) };
        let centre = |g: &[(u32, u32)]| {
            g.iter()
                .fold([0.0, 0.0], |s, p| [s[0] + p.0 as f64, s[1] + p.1 as f64])
                .map(|c| c / g.len() as f64)
        };
        let (cs, cl) = (centre(&small), centre(&large));
        assert!(
            (cs[0] - 142.0).abs() < 4.0 && (cs[1] - 121.0).abs() < 4.0,
            "{cs:?}"
        );
        assert!(
            (cl[0] - 100.0).abs() < 2.0 && (cl[1] - 100.0).abs() < 2.0,
            "{cl:?}"
        );
    }

    #[test]
    fn one_ellipse_with_a_hole_and_a_ragged_edge_is_not_cut() {
        let mut pixels: Vec<(u32, u32)> = Vec::new();
        for v in 0..200u32 {
            for u in 0..300u32 {
                let (x, y) = ((u as f64 - 150.0) / 60.0, (v as f64 - 100.0) / 35.0);
                let ragged = (u * 31 + v * 17) % 7 == 0 && x * x + y * y > 0.9;
                let hole = (u as f64 - 140.0).hypot(v as f64 - 95.0) < 8.0;
                if x * x + y * y <= 1.0 && !ragged && !hole {
                    pixels.push((u, v));
                }
            }
        }
        assert!(cut_at_neck(&pixels).is_none());
    }

    #[test]
    fn a_crescent_has_one_notch_and_is_not_cut() {
        let pixels: Vec<(u32, u32)> = discs(&[(150.0, 100.0, 60.0)])
            .into_iter()
            .filter(|&(u, v)| (u as f64 - 150.0).hypot(v as f64 - 150.0) > 45.0)
            .collect();
        assert!(cut_at_neck(&pixels).is_none());
    }
}
