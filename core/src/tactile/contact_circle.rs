//! Where the gel touches: the contact region and its circle, from a tactile frame and the
//! no-contact frame, on real frames as on the twin's.
//!
//! Why the slope peak: an indenter pressed into an elastic gel leaves a surface whose slope
//! grows towards the contact edge and falls off outside it (for a sphere on a half-space the
//! slope r/R inside, Hertz's decay outside, continuous and largest at r = a). A GelSight's
//! colour change is, to first order, linear in the slope, so along each ray from the imprint's
//! centre the colour change peaks at the contact edge, whatever the lights' directions.
//! The slope falls far more steeply outside the edge than it rises inside, so the smoothed
//! (and pixel-sampled) peak sits inside the edge and the steepest fall outside it: the edge
//! is taken halfway between them (on synthetic Hertz presses of a = 12.5-30 px: within 0.35
//! px, where the peak alone is 1.4 px short). The edge points of 90 rays outline the contact
//! region; a least-squares circle through them, refitted without outliers and re-centred
//! three times, is the contact circle.
//!
//! Measured on the 31 FOTS real ball presses against the hand-marked circles: median centre
//! error 3.9 px (0.20 mm at 19.58 px/mm), radius error +0.4 px median and 1.9 px mean
//! absolute (about 5% of a 40 px radius), 25 of 31 centres within 5 px
//! (`tests/integration/sim_to_real.rs`; `tactex compare` reports it per image).

use super::circle_fit::fit_circle;
use super::separable::{imageproc_gaussian_taps, separable_blur};
use super::slopes::{dark_level, is_dark};
use image::{ImageBuffer, Luma, RgbImage};
use imageproc::filter::filter3x3;
use serde::Serialize;

type FloatImage = ImageBuffer<Luma<f32>, Vec<f32>>;

/// The colour change is smoothed over this many px (sigma) before the rays read it, against
/// the camera's pixel noise.
const CHANGE_SIGMA_PX: f32 = 1.5;
/// How far past the peak the steepest fall is looked for.
const FALL_SEARCH_PX: f64 = 8.0;
/// The imprint's centre to start from: the peak of the colour change's texture (its gradient
/// magnitude) smoothed over a disc of about this sigma.
const START_SIGMA_PX: f32 = 8.0;
const RAYS: usize = 90;
const RAY_STEP_PX: f64 = 0.5;
/// Rays start this far out: at the centre the change's peak is the imprint's middle.
const RAY_START_PX: f64 = 4.0;
const REFITS: usize = 3;

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ContactCircle {
    /// Centre in image pixels (x along columns, y down).
    pub centre_px: [f64; 2],
    pub radius_px: f64,
    /// The contact region's outline: the edge point found on each ray that fits the circle.
    pub edge_px: Vec<[f64; 2]>,
    /// Area inside that outline (px^2): the contact region of an indenter that is not round.
    pub region_area_px2: f64,
    /// RMS distance of the outline from the circle (px): how round the contact is.
    pub rms_residual_px: f64,
}

/// The contact circle of `frame` against the no-contact `reference`, or None when the frames
/// differ in size or no plausible circle comes out (run the contact test first: a frame
/// without contact has no circle to find).
pub fn estimate_contact_circle(frame: &RgbImage, reference: &RgbImage) -> Option<ContactCircle> {
    if !readable(frame, reference) {
        return None;
    }
    let (w, h) = frame.dimensions();
    let change = colour_change(frame, reference);
    circle_of(&channel_norm(&change, w, h), imprint_starts(&change, w, h))
}

/// The contact circle found from a known middle of the imprint (px), as a reader that has
/// already located it asks: the start search's texture and its wide blur are skipped.
pub fn contact_circle_around(
    frame: &RgbImage,
    reference: &RgbImage,
    middle_px: (f64, f64),
) -> Option<ContactCircle> {
    if !readable(frame, reference) {
        return None;
    }
    let (w, h) = frame.dimensions();
    circle_of(
        &channel_norm(&colour_change(frame, reference), w, h),
        vec![middle_px],
    )
}

fn readable(frame: &RgbImage, reference: &RgbImage) -> bool {
    frame.dimensions() == reference.dimensions() && frame.width() >= 16 && frame.height() >= 16
}

/// From each start, fit and re-centre; the circle that most rays agree with.
fn circle_of(magnitude: &FloatImage, starts: Vec<(f64, f64)>) -> Option<ContactCircle> {
    let (w, h) = (magnitude.width() as f64, magnitude.height() as f64);
    let reach = 0.45 * w.min(h);
    let (centre, radius, edge) = starts
        .into_iter()
        .filter_map(|start| circle_from(magnitude, start, reach))
        .filter(|(_, radius, _)| (3.0..=0.5 * w.max(h)).contains(radius))
        .max_by_key(|(_, _, edge)| edge.len())?;
    let rms = (edge
        .iter()
        .map(|p| ((p[0] - centre[0]).hypot(p[1] - centre[1]) - radius).powi(2))
        .sum::<f64>()
        / edge.len() as f64)
        .sqrt();
    Some(ContactCircle {
        centre_px: centre,
        radius_px: radius,
        region_area_px2: polygon_area(&edge),
        edge_px: edge,
        rms_residual_px: rms,
    })
}

/// Per channel, frame minus reference, smoothed; marker dots (dark in either frame) carry no
/// shading and are filled from their neighbours (normalised convolution), so a moved dot does
/// not read as an edge. Saturated pixels are kept: their other channels still see the slope
/// (a deep press saturates red over thousands of pixels around the imprint on the FOTS frames).
/// Row-major, the frame's size. The weight and the three weighted channels are blurred in one
/// pass (imageproc's Gaussian to the bit, a quarter of the passes over the frame).
fn colour_change(frame: &RgbImage, reference: &RgbImage) -> Vec<[f32; 3]> {
    let (w, h) = (frame.width() as usize, frame.height() as usize);
    let level = dark_level(reference);
    let weighted: Vec<[f32; 4]> = frame
        .pixels()
        .zip(reference.pixels())
        .map(|(p, r)| {
            let shaded = !(is_dark(p, level) || is_dark(r, level));
            let weight = if shaded { 1.0f32 } else { 0.0 };
            let d = |c: usize| (p[c] as f32 - r[c] as f32) * weight;
            [weight, d(0), d(1), d(2)]
        })
        .collect();
    separable_blur(&weighted, w, h, &imageproc_gaussian_taps(CHANGE_SIGMA_PX))
        .into_iter()
        .map(|[wsum, c0, c1, c2]| {
            if wsum > 1e-3 {
                [c0 / wsum, c1 / wsum, c2 / wsum]
            } else {
                [0.0; 3]
            }
        })
        .collect()
}

/// The change's size per pixel (its three channels' Euclidean norm).
fn channel_norm(change: &[[f32; 3]], w: u32, h: u32) -> FloatImage {
    let norms = change
        .iter()
        .map(|c| c.iter().map(|v| v.powi(2)).sum::<f32>().sqrt())
        .collect();
    FloatImage::from_raw(w, h, norms).expect("one norm per pixel")
}

/// Fits from `start`, re-centring REFITS times.
fn circle_from(magnitude: &FloatImage, start: (f64, f64), reach: f64) -> Option<Circle> {
    let (mut cx, mut cy) = start;
    let mut found = None;
    for _ in 0..REFITS {
        let edge = ray_edges(magnitude, (cx, cy), reach);
        let Some(circle) = fit_without_outliers(&edge) else {
            break;
        };
        (cx, cy) = (circle.0[0], circle.0[1]);
        found = Some(circle);
    }
    found
}

/// Where to start looking for the imprint's middle, from the texture of the colour change
/// (its Sobel gradient; a smooth illumination drift between the frames has none): the
/// texture's peak, where the gel inside a real contact is rough, and the centroid of the
/// texture above half that peak, which is the middle also when only the rim is sharp (the
/// twin's smooth gel).
fn imprint_starts(change: &[[f32; 3]], w: u32, h: u32) -> Vec<(f64, f64)> {
    let sx: [f32; 9] = [-1.0, 0.0, 1.0, -2.0, 0.0, 2.0, -1.0, 0.0, 1.0];
    let sy: [f32; 9] = [-1.0, -2.0, -1.0, 0.0, 0.0, 0.0, 1.0, 2.0, 1.0];
    let mut texture = FloatImage::new(w, h);
    for c in 0..3 {
        let channel: Vec<f32> = change.iter().map(|p| p[c]).collect();
        let c = FloatImage::from_raw(w, h, channel).expect("one value per pixel");
        let gx: FloatImage = filter3x3(&c, &sx);
        let gy: FloatImage = filter3x3(&c, &sy);
        for (t, (a, b)) in texture.pixels_mut().zip(gx.pixels().zip(gy.pixels())) {
            t[0] += a[0] * a[0] + b[0] * b[0];
        }
    }
    let texture: Vec<[f32; 1]> = texture.pixels().map(|p| [p[0].sqrt()]).collect();
    let smooth = separable_blur(
        &texture,
        w as usize,
        h as usize,
        &imageproc_gaussian_taps(START_SIGMA_PX),
    );
    let smooth = FloatImage::from_raw(w, h, smooth.into_flattened()).expect("one per pixel");
    let (mut best, mut at) = (f32::MIN, (w as f64 / 2.0, h as f64 / 2.0));
    for (x, y, p) in smooth.enumerate_pixels() {
        if p[0] > best {
            best = p[0];
            at = (x as f64, y as f64);
        }
    }
    let (mut sum, mut sx, mut sy) = (0.0f64, 0.0f64, 0.0f64);
    for (x, y, p) in smooth.enumerate_pixels() {
        if p[0] >= 0.5 * best {
            let v = p[0] as f64;
            sum += v;
            sx += v * x as f64;
            sy += v * y as f64;
        }
    }
    let mut starts = vec![at];
    if sum > 0.0 {
        starts.push((sx / sum, sy / sum));
    }
    starts
}

/// On each ray from `centre`, the edge: halfway between the change's peak within `reach`
/// and its steepest fall just outside it. Rays still rising at the reach (a contact wider
/// than it, or a strip's length) follow on towards the frame's border until the change falls
/// below half its peak. Rays that leave the frame before half the reach, or before the fall,
/// or peak at the start, give none.
fn ray_edges(magnitude: &FloatImage, centre: (f64, f64), reach: f64) -> Vec<[f64; 2]> {
    let (w, h) = (magnitude.width() as f64, magnitude.height() as f64);
    let steps = ((reach - RAY_START_PX) / RAY_STEP_PX) as usize;
    let search = (FALL_SEARCH_PX / RAY_STEP_PX) as usize;
    let sample = |(dx, dy): (f64, f64), i: usize| {
        let r = RAY_START_PX + i as f64 * RAY_STEP_PX;
        let (x, y) = (centre.0 + r * dx, centre.1 + r * dy);
        (x >= 0.0 && y >= 0.0 && x <= w - 1.0 && y <= h - 1.0).then(|| bilinear(magnitude, x, y))
    };
    // Each ray within the reach: its direction, samples and peak.
    let rays: Vec<((f64, f64), Vec<f32>, usize)> = (0..RAYS)
        .filter_map(|k| {
            let angle = std::f64::consts::TAU * k as f64 / RAYS as f64;
            let direction = (angle.cos(), angle.sin());
            let samples: Vec<f32> = (0..steps).map_while(|i| sample(direction, i)).collect();
            let peak = samples
                .iter()
                .enumerate()
                .max_by(|a, b| a.1.total_cmp(b.1))
                .map_or(0, |(i, _)| i);
            (samples.len() >= steps / 2).then_some((direction, samples, peak))
        })
        .collect();
    // A peak within the fall's search of the reach has no room left to show its fall: its
    // ray is still rising as far as the reach can tell (an outline there is the reach's), so
    // it follows on; left out, the shorter rays alone would pull the circle in.
    let at_reach = |peak: usize| peak + search >= steps;
    let mut edges = Vec::with_capacity(RAYS);
    for (direction, mut samples, mut peak) in rays {
        if at_reach(peak) {
            let mut fell = false;
            while let Some(v) = sample(direction, samples.len()) {
                samples.push(v);
                if v < 0.5 * samples[peak] && samples.len() > peak + search {
                    fell = true;
                    break;
                }
                if v > samples[peak] {
                    peak = samples.len() - 1;
                }
            }
            if !fell {
                continue;
            }
        }
        if peak == 0 {
            continue;
        }
        // The steepest fall (central differences) within FALL_SEARCH_PX past the peak.
        let fall = (peak..(peak + search).min(samples.len() - 1))
            .map(|i| (i, samples[i + 1] - samples[i.max(1) - 1]))
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .map(|(i, _)| i);
        let Some(fall) = fall.filter(|&i| i > peak && i + 1 < samples.len()) else {
            continue;
        };
        let r = RAY_START_PX + (peak + fall) as f64 / 2.0 * RAY_STEP_PX;
        edges.push([centre.0 + r * direction.0, centre.1 + r * direction.1]);
    }
    edges
}

fn bilinear(image: &FloatImage, x: f64, y: f64) -> f32 {
    let (x0, y0) = (x.floor() as u32, y.floor() as u32);
    let (x1, y1) = (
        (x0 + 1).min(image.width() - 1),
        (y0 + 1).min(image.height() - 1),
    );
    let (fx, fy) = ((x - x0 as f64) as f32, (y - y0 as f64) as f32);
    let p = |x, y| image.get_pixel(x, y)[0];
    let top = p(x0, y0) * (1.0 - fx) + p(x1, y0) * fx;
    let bottom = p(x0, y1) * (1.0 - fx) + p(x1, y1) * fx;
    top * (1.0 - fy) + bottom * fy
}

type Circle = ([f64; 2], f64, Vec<[f64; 2]>);

/// The circle through `points`, refitted once without those further from it than twice the
/// median distance (rays that peaked on a glint or a fold rather than the edge).
fn fit_without_outliers(points: &[[f64; 2]]) -> Option<Circle> {
    // At least a fifth of the rays: fewer do not outline a contact.
    if points.len() < RAYS / 5 {
        return None;
    }
    let (centre, radius) = fit_circle(points)?;
    let distance = |p: &[f64; 2]| ((p[0] - centre[0]).hypot(p[1] - centre[1]) - radius).abs();
    let mut residuals: Vec<f64> = points.iter().map(distance).collect();
    residuals.sort_by(f64::total_cmp);
    let limit = (2.0 * residuals[residuals.len() / 2]).max(1.0);
    let kept: Vec<[f64; 2]> = points
        .iter()
        .filter(|p| distance(p) <= limit)
        .copied()
        .collect();
    if kept.len() < RAYS / 5 {
        return None;
    }
    let (centre, radius) = fit_circle(&kept)?;
    Some((centre, radius, kept))
}

impl ContactCircle {
    /// The contact region's semi-axes (px, wide then narrow): the ellipse of the outline's
    /// area with the aspect of its second moments (a uniform ellipse of semi-axes a, b has
    /// moments a^2/4 and b^2/4), so an elongated contact keeps its narrow side.
    pub fn semi_axes_px(&self) -> [f64; 2] {
        let p = &self.edge_px;
        let n = p.len();
        // Green's theorem over the outline: signed area, first and second moments.
        let (mut a, mut mx, mut my, mut ixx, mut iyy, mut ixy) = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
        for i in 0..n {
            let ([x0, y0], [x1, y1]) = (p[i], p[(i + 1) % n]);
            let cross = x0 * y1 - x1 * y0;
            a += cross / 2.0;
            mx += cross * (x0 + x1) / 6.0;
            my += cross * (y0 + y1) / 6.0;
            ixx += cross * (x0 * x0 + x0 * x1 + x1 * x1) / 12.0;
            iyy += cross * (y0 * y0 + y0 * y1 + y1 * y1) / 12.0;
            ixy += cross * (x0 * y1 + 2.0 * x0 * y0 + 2.0 * x1 * y1 + x1 * y0) / 24.0;
        }
        if n < 3 || a.abs() < 1e-9 {
            return [self.radius_px, self.radius_px];
        }
        let (cx, cy) = (mx / a, my / a);
        let (cxx, cyy, cxy) = (ixx / a - cx * cx, iyy / a - cy * cy, ixy / a - cx * cy);
        let mean = 0.5 * (cxx + cyy);
        let spread = (0.25 * (cxx - cyy).powi(2) + cxy * cxy).sqrt();
        let aspect = ((mean + spread) / (mean - spread).max(1e-12)).sqrt();
        let equal_area = (a.abs() / std::f64::consts::PI).sqrt();
        [equal_area * aspect.sqrt(), equal_area / aspect.sqrt()]
    }
}

/// Area of the outline (shoelace). Its points come in ray order, so in angle order about
/// the last ray origin, about which the outline is star-shaped.
fn polygon_area(points: &[[f64; 2]]) -> f64 {
    let twice: f64 = (0..points.len())
        .map(|i| {
            let (p, q) = (points[i], points[(i + 1) % points.len()]);
            p[0] * q[1] - q[0] * p[1]
        })
        .sum();
    twice.abs() / 2.0
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_elliptic_outline_gives_its_semi_axes() {
        // An ellipse of semi-axes 30 and 12 px turned 30 degrees, outlined by 90 points.
        let (c, s) = (30f64.to_radians().cos(), 30f64.to_radians().sin());
        let edge_px: Vec<[f64; 2]> = (0..90)
            .map(|k| {
                let t = std::f64::consts::TAU * k as f64 / 90.0;
                let (x, y) = (30.0 * t.cos(), 12.0 * t.sin());
                [100.0 + c * x - s * y, 80.0 + s * x + c * y]
            })
            .collect();
        let circle = ContactCircle {
            centre_px: [100.0, 80.0],
            radius_px: 19.0,
            region_area_px2: polygon_area(&edge_px),
            edge_px,
            rms_residual_px: 0.0,
        };
        let [a, b] = circle.semi_axes_px();
        // A 90-gon inscribed in the ellipse holds 0.08% less area.
        assert!(
            (a - 30.0).abs() < 0.05 && (b - 12.0).abs() < 0.05,
            "{a} {b}"
        );
    }

    /// Surface depth of a rigid sphere (radius `r_sphere`) pressed into an elastic half-space
    /// to contact radius `a` (Johnson, Contact Mechanics, eq. 3.42): inside the contact the
    /// sphere's cap, outside Hertz's decay; both px.
    fn hertz_depth(r: f64, a: f64, r_sphere: f64) -> f64 {
        let d = a * a / r_sphere;
        if r <= a {
            d - r * r / (2.0 * r_sphere)
        } else {
            let s = r / a;
            a * a / (std::f64::consts::PI * r_sphere)
                * ((2.0 - s * s) * (1.0 / s).asin() + (s * s - 1.0).sqrt())
        }
    }

    /// A GelSight-like frame: grey reference lit by three coloured lights from different
    /// directions, the frame shaded linearly in the surface slope of a Hertz press.
    fn hertz_press(
        size: (u32, u32),
        centre: (f64, f64),
        a: f64,
        r_sphere: f64,
    ) -> (RgbImage, RgbImage) {
        let lights = [(1.0, 0.0), (-0.5, 0.87), (-0.5, -0.87)];
        let reference = RgbImage::from_pixel(size.0, size.1, image::Rgb([120, 120, 120]));
        let frame = RgbImage::from_fn(size.0, size.1, |x, y| {
            let (dx, dy) = (x as f64 - centre.0, y as f64 - centre.1);
            let r = dx.hypot(dy).max(1e-6);
            let h = 1e-3;
            let slope =
                (hertz_depth(r + h, a, r_sphere) - hertz_depth(r - h, a, r_sphere)) / (2.0 * h);
            let (gx, gy) = (slope * dx / r, slope * dy / r);
            image::Rgb(std::array::from_fn(|c| {
                let (lx, ly) = lights[c];
                (120.0 + 150.0 * (lx * gx + ly * gy))
                    .clamp(0.0, 254.0)
                    .round() as u8
            }))
        });
        (frame, reference)
    }

    #[test]
    fn the_circle_of_a_hertz_press_is_its_contact_radius() {
        for (centre, a) in [
            ((60.0, 50.0), 20.0),
            ((47.3, 62.8), 12.5),
            ((70.0, 45.0), 30.0),
        ] {
            let (frame, reference) = hertz_press((128, 112), centre, a, 2.0 * a);
            let c = estimate_contact_circle(&frame, &reference).expect("a circle");
            let off = (c.centre_px[0] - centre.0).hypot(c.centre_px[1] - centre.1);
            assert!(off < 1.0, "centre {:?} vs {centre:?}", c.centre_px);
            assert!(
                (c.radius_px - a).abs() < 0.6,
                "radius {} vs {a}",
                c.radius_px
            );
            let disc = std::f64::consts::PI * a * a;
            assert!(
                (c.region_area_px2 / disc - 1.0).abs() < 0.1,
                "{}",
                c.region_area_px2
            );
        }
    }

    #[test]
    fn a_contact_wider_than_the_rays_reach_is_followed_to_its_edge() {
        // Reach 0.45 x 200 = 90 px: one contact inside the frame beyond it, one cut by the
        // frame's long sides (whose rays along the short side give no edge).
        for a in [94.0, 108.0] {
            let (frame, reference) = hertz_press((240, 200), (120.0, 100.0), a, 2.0 * a);
            let c = estimate_contact_circle(&frame, &reference).expect("a circle");
            assert!(
                (c.radius_px - a).abs() < 1.0,
                "radius {} vs {a}",
                c.radius_px
            );
        }
    }

    #[test]
    fn a_fall_just_past_the_reach_is_looked_for_there() {
        // Reach 0.45 x 200 = 90 px. The change peaks at 86 px, inside the edge (as the shading
        // flattens at steep slopes), eases off and falls at 94 px, within the fall's search of
        // the peak but past the reach: the edge, halfway between peak and fall, is at 90 px.
        // Looked for only within the reach, the fall was the easing off and the edge 87.7 px.
        let (w, h, centre) = (240u32, 200u32, (120.0, 100.0));
        let change = |r: f64| match r {
            r if r <= 86.0 => 100.0 * r / 86.0,
            r if r <= 93.0 => 100.0 - (r - 86.0),
            r if r <= 95.0 => 93.0 * (95.0 - r) / 2.0,
            _ => 0.0,
        };
        let lights = [(1.0, 0.0), (-0.5, 0.87), (-0.5, -0.87)];
        let reference = RgbImage::from_pixel(w, h, image::Rgb([120, 120, 120]));
        let frame = RgbImage::from_fn(w, h, |x, y| {
            let (dx, dy) = (x as f64 - centre.0, y as f64 - centre.1);
            let r = dx.hypot(dy).max(1e-6);
            image::Rgb(std::array::from_fn(|c| {
                let (lx, ly) = lights[c];
                (120.0 + change(r) * (lx * dx + ly * dy) / r).round() as u8
            }))
        });
        let c = estimate_contact_circle(&frame, &reference).expect("a circle");
        assert!((c.radius_px - 90.0).abs() < 1.0, "radius {}", c.radius_px);
    }

    #[test]
    fn marker_dots_that_move_do_not_pull_the_circle() {
        let (centre, a) = ((64.0, 56.0), 22.0);
        let (mut frame, mut reference) = hertz_press((128, 112), centre, a, 40.0);
        // A marker grid at 16 px pitch, each dot shifted 2 px in the frame (as shear would).
        let dot = |img: &mut RgbImage, cx: f64, cy: f64| {
            for y in 0..img.height() {
                for x in 0..img.width() {
                    if (x as f64 - cx).hypot(y as f64 - cy) <= 3.0 {
                        img.put_pixel(x, y, image::Rgb([30, 30, 30]));
                    }
                }
            }
        };
        for j in 0..8 {
            for i in 0..9 {
                let (x, y) = (8.0 + 16.0 * i as f64, 8.0 + 16.0 * j as f64);
                dot(&mut reference, x, y);
                dot(&mut frame, x + 2.0, y + 1.0);
            }
        }
        let c = estimate_contact_circle(&frame, &reference).expect("a circle");
        let off = (c.centre_px[0] - centre.0).hypot(c.centre_px[1] - centre.1);
        assert!(off < 1.5, "centre {:?}", c.centre_px);
        assert!((c.radius_px - a).abs() < 1.5, "radius {}", c.radius_px);
    }

    #[test]
    fn frames_of_other_sizes_have_no_circle() {
        let a = RgbImage::new(64, 48);
        let b = RgbImage::new(48, 64);
        assert!(estimate_contact_circle(&a, &b).is_none());
    }
}
