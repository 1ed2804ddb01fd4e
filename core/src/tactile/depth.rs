//! The gel's indentation map from its slopes: least-squares integration (Frankot and
//! Chellappa 1988) on the mirror extension of the frame, which makes the slope field
//! continuous across the frame's edges and the solve a Poisson problem with Neumann
//! boundaries, so an imprint touching the edge is not wrapped onto the opposite side.

use super::slopes::SlopeField;
use crate::spectral::{Mirror, idct2_2d, mirror_transform};

/// Sides of the border whose medians differ by more than this share of the imprint's depth
/// are not level: the imprint presses one of them in.
const UNLEVEL_SHARE: f64 = 0.6;
/// The zero level moves from the border's median to its lowest side across this width of
/// unlevelness, centred on `UNLEVEL_SHARE`.
const UNLEVEL_BAND: f64 = 0.2;

/// Indentation (mm, into the gel) per pixel, row-major, zero where the gel is undisturbed
/// (the median of the frame's border, or of its lowest side where the border is far from
/// level). Slopes of invalid pixels (markers) count as zero.
pub fn integrate_slopes(field: &SlopeField) -> Vec<f64> {
    let mm_per_px = field.mm_per_px;
    let (w, h) = (field.width, field.height);
    // On the mirror extension gx is odd across vertical edges and even across horizontal
    // ones, gy the other way round, and the surface even both ways: each is the transform
    // of its own kind, frequency by frequency the extension's FFT up to one phase.
    let slope = |g: &[f32]| -> Vec<f64> {
        g.iter()
            .zip(&field.valid)
            .map(|(&v, &ok)| if ok { f64::from(v) * mm_per_px } else { 0.0 })
            .collect()
    };
    let px = mirror_transform(&slope(&field.gx), w, h, Mirror::Odd, Mirror::Even);
    let py = mirror_transform(&slope(&field.gy), w, h, Mirror::Even, Mirror::Odd);
    let mut z = vec![0.0; w * h];
    for u in 0..w {
        let wx = std::f64::consts::PI * u as f64 / w as f64;
        for v in 0..h {
            let wy = std::f64::consts::PI * v as f64 / h as f64;
            let d = wx * wx + wy * wy;
            if d > 0.0 {
                // Z = -j (wx Px + wy Py) / (wx^2 + wy^2), with the sine transform's -2j.
                let k = u * h + v;
                z[k] = -(wx * px[k] + wy * py[k]) / d;
            }
        }
    }
    let mut depth = idct2_2d(&z, w, h);
    let zero = zero_level(&depth, w, h);
    depth.iter_mut().for_each(|d| *d -= zero);
    depth
}

/// The level an indentation map of `w` x `h` is zeroed at: the median of the frame's
/// border, or its lowest side's where the border is far from level. The gel's surface has
/// no other reference in a frame; what the estimators model of a reading is read against
/// the same level.
pub fn zero_level(depth: &[f64], w: usize, h: usize) -> f64 {
    let sides = [
        (0..w).map(|x| depth[x]).collect(),
        (0..w).map(|x| depth[(h - 1) * w + x]).collect(),
        (0..h).map(|y| depth[y * w]).collect(),
        (0..h).map(|y| depth[y * w + w - 1]).collect(),
    ];
    let peak = depth.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    zero_level_of_border(&sides, peak)
}

/// `zero_level` from the map's four sides (top, bottom, left, right, each with its corners)
/// and its highest value: all of the map the level depends on.
pub fn zero_level_of_border(sides: &[Vec<f64>; 4], peak: f64) -> f64 {
    let mut border: Vec<f64> = sides.iter().flatten().copied().collect();
    border.sort_by(f64::total_cmp);
    let mut zero = border[border.len() / 2];
    // An imprint that runs off the frame along one side (a banana lying along the rows,
    // pressed off its ridge) presses that side in, and the border's median with it: the
    // imprint read 0.38 mm for 0.51. A border that is far from level is zeroed on its
    // lowest side instead, the gel furthest from the contact.
    let side_median = |mut v: Vec<f64>| {
        let k = v.len() / 2;
        *v.select_nth_unstable_by(k, f64::total_cmp).1
    };
    let medians = sides.clone().map(side_median);
    let (lowest, highest) = medians
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), s| {
            (lo.min(*s), hi.max(*s))
        });
    // Blended across a band round the threshold rather than switched: the level of an
    // imprint running off the frame must not jump with a tenth of a grey level.
    let peak = peak - zero;
    if peak > 0.0 {
        let unlevel = (highest - lowest) / peak;
        let t = ((unlevel - UNLEVEL_SHARE) / UNLEVEL_BAND + 0.5).clamp(0.0, 1.0);
        zero += t * (lowest - zero);
    }
    zero
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Slopes of a known surface by central differences, integrated back.
    fn round_trip(surface: impl Fn(f64, f64) -> f64, w: usize, h: usize, mm_per_px: f64) -> f64 {
        let at = |x: f64, y: f64| surface(x * mm_per_px, y * mm_per_px);
        let mut field = SlopeField {
            width: w,
            height: h,
            mm_per_px,
            gx: vec![0.0; w * h],
            gy: vec![0.0; w * h],
            valid: vec![true; w * h],
            drift: None,
        };
        for y in 0..h {
            for x in 0..w {
                let (xf, yf) = (x as f64, y as f64);
                field.gx[y * w + x] = ((at(xf + 0.5, yf) - at(xf - 0.5, yf)) / mm_per_px) as f32;
                field.gy[y * w + x] = ((at(xf, yf + 0.5) - at(xf, yf - 0.5)) / mm_per_px) as f32;
            }
        }
        let depth = integrate_slopes(&field);
        let mut worst: f64 = 0.0;
        for y in 0..h {
            for x in 0..w {
                worst = worst.max((depth[y * w + x] - at(x as f64, y as f64)).abs());
            }
        }
        worst
    }

    #[test]
    fn a_hertzian_dimple_integrates_back_to_its_depth() {
        // A spherical cap of radius 10 mm pressed 0.5 mm, centred in a 160 x 120 frame.
        let (r, d, px) = (10.0, 0.5, 0.0634);
        let (cx, cy) = (80.0 * px, 60.0 * px);
        let a2 = 2.0 * r * d;
        let cap = |x: f64, y: f64| {
            let q = (x - cx).powi(2) + (y - cy).powi(2);
            if q < a2 { d - q / (2.0 * r) } else { 0.0 }
        };
        let err = round_trip(cap, 160, 120, px);
        assert!(err < 0.02 * d, "worst error {err} mm of a {d} mm dimple");
    }

    #[test]
    fn an_imprint_at_the_frame_edge_is_not_wrapped_around() {
        let (r, d, px) = (8.0, 0.4, 0.0634);
        let (cx, cy) = (150.0 * px, 20.0 * px);
        let cap = |x: f64, y: f64| {
            let q = (x - cx).powi(2) + (y - cy).powi(2);
            (d - q / (2.0 * r)).max(0.0)
        };
        let err = round_trip(cap, 160, 120, px);
        assert!(err < 0.05 * d, "worst error {err} mm of a {d} mm dimple");
    }

    /// The peak read from a cap of `d` mm centred at (cx, 60) px of a 160 x 120 frame.
    fn peak_read(cx: f64, d: f64) -> f64 {
        let (r, px, w, h) = (20.0, 0.0634, 160, 120);
        let mut field = SlopeField {
            width: w,
            height: h,
            mm_per_px: px,
            gx: vec![0.0; w * h],
            gy: vec![0.0; w * h],
            valid: vec![true; w * h],
            drift: None,
        };
        let cap = |x: f64, y: f64| {
            let q = (x - cx * px).powi(2) + (y - 60.0 * px).powi(2);
            (d - q / (2.0 * r)).max(0.0)
        };
        for y in 0..h {
            for x in 0..w {
                let (xf, yf) = (x as f64 * px, y as f64 * px);
                field.gx[y * w + x] =
                    ((cap(xf + 0.5 * px, yf) - cap(xf - 0.5 * px, yf)) / px) as f32;
                field.gy[y * w + x] =
                    ((cap(xf, yf + 0.5 * px) - cap(xf, yf - 0.5 * px)) / px) as f32;
            }
        }
        integrate_slopes(&field)
            .into_iter()
            .fold(f64::NEG_INFINITY, f64::max)
    }

    #[test]
    fn the_depth_read_moves_smoothly_as_an_imprint_runs_off_the_frame() {
        // Where the border turns from level to pressed in on one side, the zero level must
        // not jump: a press read through a real sensor sat on that switch, and a tenth of a
        // grey level moved its third frame's depth by 14%.
        let d = 0.6;
        let peaks: Vec<f64> = (0..=80).map(|i| peak_read(80.0 + i as f64, d)).collect();
        for (i, pair) in peaks.windows(2).enumerate() {
            assert!(
                (pair[1] - pair[0]).abs() < 0.02 * d,
                "at {} px: {:.4} -> {:.4} mm",
                80 + i,
                pair[0],
                pair[1]
            );
        }
    }
}
