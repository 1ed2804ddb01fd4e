//! Gel surface slopes from a tactile frame: the photometric model inverted per pixel against
//! the no-contact reference frame. Marker dots and saturated pixels carry no shading and are
//! left out.

use crate::photometric::PhotometricModel;
use image::RgbImage;

/// Slopes dw/dx and dw/dy (mm per mm) per pixel, in image axes (x along columns, y down).
#[derive(Clone, Debug)]
pub struct SlopeField {
    pub width: usize,
    pub height: usize,
    pub gx: Vec<f32>,
    pub gy: Vec<f32>,
    pub valid: Vec<bool>,
}

/// A marker dot's pixel: it carries no shading.
pub(crate) fn is_dark(p: &image::Rgb<u8>) -> bool {
    (p[0] as u32 + p[1] as u32 + p[2] as u32) < 3 * 70
}

/// Inverts `model` against `reference`. Pixels dark in either frame (markers) are invalid, and
/// so is a 2 px ring around them where the dot's soft edge mixes with the shading.
pub fn recover_slopes(
    frame: &RgbImage,
    reference: &RgbImage,
    model: &PhotometricModel,
) -> Option<SlopeField> {
    if frame.dimensions() != reference.dimensions() {
        return None;
    }
    let (w, h) = (frame.width() as usize, frame.height() as usize);
    let mut dark = vec![false; w * h];
    for (i, (p, r)) in frame.pixels().zip(reference.pixels()).enumerate() {
        dark[i] = is_dark(p) || is_dark(r) || p.0.contains(&255);
    }
    let mut valid = vec![true; w * h];
    for y in 0..h {
        for x in 0..w {
            if dark[y * w + x] {
                for yy in y.saturating_sub(2)..(y + 3).min(h) {
                    for xx in x.saturating_sub(2)..(x + 3).min(w) {
                        valid[yy * w + xx] = false;
                    }
                }
            }
        }
    }
    let mut gx = vec![0.0f32; w * h];
    let mut gy = vec![0.0f32; w * h];
    for (i, (p, r)) in frame.pixels().zip(reference.pixels()).enumerate() {
        if !valid[i] {
            continue;
        }
        let gain = std::array::from_fn(|c| p[c] as f64 / (r[c] as f64).max(1.0));
        match model.slope_for_gain(gain) {
            Some((sx, sy)) => {
                gx[i] = sx as f32;
                gy[i] = sy as f32;
            }
            None => valid[i] = false,
        }
    }
    Some(SlopeField {
        width: w,
        height: h,
        gx,
        gy,
        valid,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use image::Rgb;

    #[test]
    fn recovers_a_uniform_tilt() {
        let model = PhotometricModel::default();
        let reference = RgbImage::from_pixel(16, 12, Rgb([150, 140, 130]));
        let g = model.gain_for_slope(0.2, -0.1);
        let frame = RgbImage::from_fn(16, 12, |_, _| {
            Rgb(std::array::from_fn(|c| {
                (reference.get_pixel(0, 0)[c] as f64 * g[c]).round() as u8
            }))
        });
        let s = recover_slopes(&frame, &reference, &model).unwrap();
        let i = 6 * 16 + 8;
        assert!(s.valid[i]);
        // 8-bit quantisation of ~150 levels limits the slope to about 1/100.
        assert!(
            (s.gx[i] - 0.2).abs() < 0.02 && (s.gy[i] + 0.1).abs() < 0.02,
            "{} {}",
            s.gx[i],
            s.gy[i]
        );
    }
}
