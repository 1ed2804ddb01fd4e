//! What one tactile frame says about the gel: its indentation map (slopes read through the
//! sensor's optics against the no-contact frame, integrated), the imprint's peak depth, the
//! contact's semi-axes (from the contact circle's outline where the frame shows a round
//! contact, else from the half-depth region), and whether the imprint lies within the frame.
//! The indentation estimator reads every frame of a press this way; `tactex read` shows one.

use crate::tactile::contact_circle::contact_circle_around;
use crate::tactile::depth::integrate_slopes;
use crate::tactile::slopes::{ColourDrift, recover_slopes};
use crate::tactile::spec::TactileSpec;
use image::RgbImage;
use std::f64::consts::PI;

/// An outline further from its circle than this share of the radius (rms) is not a round
/// contact's edge: real ball presses lie within 0.14, a contact cut by the frame 0.3 and more.
const MAX_OUTLINE_RMS_SHARE: f64 = 0.2;

/// One frame read.
#[derive(Clone, Debug)]
pub struct FrameReading {
    pub width: usize,
    pub height: usize,
    /// Indentation (mm, into the gel) per pixel, row-major; zero on the undisturbed gel.
    pub indentation_mm: Vec<f64>,
    /// Pixels whose shading could be read (marker dots and saturated pixels cannot).
    pub valid: Vec<bool>,
    /// The imprint's depth: the mean of its 20 deepest pixels.
    pub peak_mm: f64,
    /// The contact's semi-axes (mm, wide then narrow): the outline of where the slope peaks
    /// (`contact_circle`), or the half-depth region where that outline is not round.
    pub contact_axes_mm: [f64; 2],
    /// That outline (px of this reading) where the frame shows a round contact.
    pub contact_outline_px: Option<Vec<[f64; 2]>>,
    /// The imprint's half-depth region stays off the frame's border and the border is level.
    pub within_frame: bool,
    /// The middle of the imprint's half-depth region (px of this reading); None without one.
    pub imprint_middle_px: Option<[f64; 2]>,
    /// The gel's size of one pixel of this reading (mm): the frame's, or twice it where the
    /// frame was read on 2 x 2 blocks.
    pub mm_per_px: f64,
    /// The colour drift taken out (grey levels per channel), where the frame was read through
    /// a glow: a press's first frame's is given to its deeper ones.
    pub drift: Option<[f32; 3]>,
}

impl FrameReading {
    /// The radius of the circle of the contact's area (mm).
    pub fn contact_radius_mm(&self) -> f64 {
        (self.contact_axes_mm[0] * self.contact_axes_mm[1]).sqrt()
    }

    /// Where the contact's size was taken: "outline" (the round outline where the gel's slope
    /// peaks) or "half_depth" (the region deeper than half the peak).
    pub fn contact_edge(&self) -> &'static str {
        match self.contact_outline_px {
            Some(_) => "outline",
            None => "half_depth",
        }
    }

    /// Whether a pixel lies in the contact region its size is taken from: inside the
    /// outline, or in the half-depth region.
    pub fn in_contact(&self, i: usize) -> bool {
        match &self.contact_outline_px {
            Some(outline) => {
                let (x, y) = ((i % self.width) as f64, (i / self.width) as f64);
                inside_polygon(outline, x, y)
            }
            None => self.peak_mm > 0.0 && self.indentation_mm[i] > 0.5 * self.peak_mm,
        }
    }
}

/// Whether (x, y) lies inside the polygon (even-odd crossings of a ray along +x).
fn inside_polygon(points: &[[f64; 2]], x: f64, y: f64) -> bool {
    let mut inside = false;
    for (k, &[x0, y0]) in points.iter().enumerate() {
        let [x1, y1] = points[(k + 1) % points.len()];
        if (y0 > y) != (y1 > y) && x < x0 + (y - y0) / (y1 - y0) * (x1 - x0) {
            inside = !inside;
        }
    }
    inside
}

/// Reads `frame` against the no-contact `reference` through the sensor's optics. None when
/// their sizes differ.
pub fn read_frame(
    frame: &RgbImage,
    reference: &RgbImage,
    spec: &TactileSpec,
    drift: ColourDrift,
) -> Option<FrameReading> {
    let slopes = recover_slopes(frame, reference, spec, drift)?;
    let depth = integrate_slopes(&slopes);
    let p = peak(&depth);
    let deep = |d: f64| d > 0.5 * p;
    // The contact's edge is where the gel's slope peaks, which the colour change shows
    // directly (`contact_circle`); the half-depth region where the frame shows no round
    // contact (a first touch of a few pixels, an imprint cut by the frame's edge).
    // The circle is in the frame's pixels; a fine frame's slopes are read on blocks, so a
    // frame pixel is this many of the reading's.
    let frame_px = slopes.width as f64 / frame.width() as f64;
    let middle = region_middle(&depth, slopes.width, deep);
    let circle = middle
        .and_then(|(x, y)| {
            let middle = ((x + 0.5) / frame_px - 0.5, (y + 0.5) / frame_px - 0.5);
            contact_circle_around(frame, reference, middle)
        })
        .filter(|c| c.rms_residual_px <= MAX_OUTLINE_RMS_SHARE * c.radius_px);
    let (contact_axes_mm, contact_outline_px) = match circle {
        Some(circle) => (
            circle
                .semi_axes_px()
                .map(|a| a * slopes.mm_per_px * frame_px),
            Some(
                circle
                    .edge_px
                    .iter()
                    .map(|p| p.map(|v| (v + 0.5) * frame_px - 0.5))
                    .collect(),
            ),
        ),
        None => (
            contact_ellipse(&depth, slopes.width, deep, slopes.mm_per_px),
            None,
        ),
    };
    let within_frame = imprint_within_frame(&depth, &slopes.valid, slopes.width, slopes.height, p);
    Some(FrameReading {
        width: slopes.width,
        height: slopes.height,
        indentation_mm: depth,
        valid: slopes.valid,
        peak_mm: p,
        contact_axes_mm,
        contact_outline_px,
        within_frame,
        imprint_middle_px: middle.map(|(x, y)| [x, y]),
        mm_per_px: slopes.mm_per_px,
        drift: slopes.drift,
    })
}

/// The peak of an indentation map: the mean of its 20 deepest pixels, which averages out the
/// integration's pixel noise while staying within the contact's centre.
fn peak(depth: &[f64]) -> f64 {
    let mut sorted: Vec<f64> = depth.to_vec();
    let n = sorted.len().min(20);
    let k = sorted.len() - n;
    sorted.select_nth_unstable_by(k, f64::total_cmp);
    sorted[k..].iter().sum::<f64>() / n as f64
}

/// The middle (px) of the region where `inside` holds; None when it is empty.
fn region_middle(depth: &[f64], w: usize, inside: impl Fn(f64) -> bool) -> Option<(f64, f64)> {
    let (mut n, mut sx, mut sy) = (0.0, 0.0, 0.0);
    for (i, d) in depth.iter().enumerate() {
        if inside(*d) {
            n += 1.0;
            sx += (i % w) as f64;
            sy += (i / w) as f64;
        }
    }
    (n > 0.0).then(|| (sx / n, sy / n))
}

/// The contact's semi-axes (mm, wide then narrow) from the imprint's half-depth region (where
/// `inside` holds), taken
/// as the half-depth ellipse of a Hertz dimple: its area fixes the scale (the half-depth
/// ellipse's axes are 0.866 of the contact's) and its second moments the aspect, so an
/// elongated imprint (a banana's) keeps its narrow side. Empty: [0, 0].
fn contact_ellipse(
    depth: &[f64],
    w: usize,
    inside: impl Fn(f64) -> bool,
    mm_per_px: f64,
) -> [f64; 2] {
    let (mut n, mut sx, mut sy, mut sxx, mut syy, mut sxy) = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    for (i, d) in depth.iter().enumerate() {
        if inside(*d) {
            let (x, y) = ((i % w) as f64, (i / w) as f64);
            n += 1.0;
            sx += x;
            sy += y;
            sxx += x * x;
            syy += y * y;
            sxy += x * y;
        }
    }
    if n == 0.0 {
        return [0.0, 0.0];
    }
    let (mx, my) = (sx / n, sy / n);
    let (cxx, cyy, cxy) = (sxx / n - mx * mx, syy / n - my * my, sxy / n - mx * my);
    let mean = 0.5 * (cxx + cyy);
    let spread = (0.25 * (cxx - cyy).powi(2) + cxy * cxy).sqrt();
    // Eigenvalues of the covariance; a pixel's own 1/12 keeps a one-pixel line finite.
    let (wide, narrow) = (
        mean + spread + 1.0 / 12.0,
        (mean - spread).max(0.0) + 1.0 / 12.0,
    );
    let aspect = (wide / narrow).sqrt();
    let equal_area_radius = (n / PI).sqrt() * mm_per_px / 0.866;
    [
        equal_area_radius * aspect.sqrt(),
        equal_area_radius / aspect.sqrt(),
    ]
}

/// The frame's outermost two pixels, row-major indices.
fn border(w: usize, h: usize) -> impl Iterator<Item = usize> {
    (0..h).flat_map(move |y| {
        (0..w)
            .filter(move |x| *x < 2 || y < 2 || x + 2 >= w || y + 2 >= h)
            .map(move |x| y * w + x)
    })
}

/// Whether an imprint of this peak lies within the frame: its half-depth region stays off
/// the border, and the border is level (its deepest 5% lie less than half the peak below its
/// shallowest 5%). The map's zero is the border's median, so a border pressed in on one side
/// (a broad fruit whose contact outgrows the pad) lowers the zero and the peak reads short
/// while the half-depth region, measured from that same zero, never reaches the edge.
fn imprint_within_frame(depth: &[f64], valid: &[bool], w: usize, h: usize, peak: f64) -> bool {
    if border(w, h).any(|i| depth[i] > 0.5 * peak) {
        return false;
    }
    let mut edge: Vec<f64> = border(w, h)
        .filter(|i| valid[*i])
        .map(|i| depth[i])
        .collect();
    if edge.len() < 20 {
        return true;
    }
    edge.sort_by(f64::total_cmp);
    let at = |q: f64| edge[((edge.len() - 1) as f64 * q).round() as usize];
    at(0.95) - at(0.05) <= 0.5 * peak
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A Gaussian dimple of depth 1 centred at (cx, cy) px with width `sigma` on a 160 x 120
    /// frame, over a gel lowered by `tilt` at the top edge and not at the bottom (a broad
    /// contact beyond the top edge), zeroed as `integrate_slopes` zeroes: the border's median.
    fn imprint(cx: f64, cy: f64, sigma: f64, tilt: f64) -> Vec<f64> {
        let (w, h) = (160usize, 120usize);
        let mut depth: Vec<f64> = (0..w * h)
            .map(|i| {
                let (x, y) = ((i % w) as f64 - cx, (i / w) as f64 - cy);
                let lowered = tilt * (1.0 - (i / w) as f64 / (h - 1) as f64);
                (-(x * x + y * y) / (2.0 * sigma * sigma)).exp() + lowered
            })
            .collect();
        let mut edge: Vec<f64> = border(w, h).map(|i| depth[i]).collect();
        edge.sort_by(f64::total_cmp);
        let zero = edge[edge.len() / 2];
        depth.iter_mut().for_each(|d| *d -= zero);
        depth
    }

    #[test]
    fn an_imprint_that_outgrows_the_pad_on_one_side_is_not_within_the_frame() {
        let valid = vec![true; 160 * 120];
        let within = |d: &[f64]| imprint_within_frame(d, &valid, 160, 120, peak(d));
        // A small imprint in the middle leaves the border level, and a slightly lowered
        // side is tolerated.
        assert!(within(&imprint(80.0, 60.0, 12.0, 0.0)));
        assert!(within(&imprint(80.0, 60.0, 12.0, 0.3)));
        // The gel pressed in along the top edge by 0.7 of the imprint's depth: its
        // half-depth region, measured from the border's lowered median, stays off the edge
        // (the case the half-depth test alone missed), yet the zero is wrong.
        let broad = imprint(80.0, 60.0, 12.0, 0.7);
        let p = peak(&broad);
        assert!(!border(160, 120).any(|i| broad[i] > 0.5 * p));
        assert!(!within(&broad));
        // An imprint whose half-depth region reaches the edge is cut as before.
        assert!(!within(&imprint(3.0, 60.0, 12.0, 0.0)));
    }

    #[test]
    fn an_elongated_turned_imprint_keeps_its_two_semi_axes() {
        // A paraboloid dimple 1 - (x'/A)^2 - (y'/B)^2 turned 30 degrees: its half-depth ellipse
        // has semi-axes A/sqrt 2 and B/sqrt 2, the contact's are those over 0.866.
        let (w, h, big, small) = (160usize, 120usize, 40.0f64, 12.0f64);
        let (c, s) = (30f64.to_radians().cos(), 30f64.to_radians().sin());
        let depth: Vec<f64> = (0..w * h)
            .map(|i| {
                let (x, y) = ((i % w) as f64 - 80.0, (i / w) as f64 - 60.0);
                let (xr, yr) = (c * x + s * y, -s * x + c * y);
                (1.0 - (xr / big).powi(2) - (yr / small).powi(2)).max(0.0)
            })
            .collect();
        let [a, b] = contact_ellipse(&depth, w, |d| d > 0.5, 0.1);
        let want = |axis: f64| axis / 2f64.sqrt() * 0.1 / 0.866;
        assert!((a / want(big) - 1.0).abs() < 0.02, "{a} vs {}", want(big));
        assert!(
            (b / want(small) - 1.0).abs() < 0.03,
            "{b} vs {}",
            want(small)
        );
        assert_eq!(contact_ellipse(&[0.0; 4], 2, |d| d > 0.5, 0.1), [0.0, 0.0]);
    }
}
