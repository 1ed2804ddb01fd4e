//! The sim-to-real comparison image: real | rendered | difference.

use image::RgbImage;

/// real | rendered | difference around mid-grey (4x), side by side.
pub fn side_by_side(real: &RgbImage, rendered: &RgbImage) -> RgbImage {
    let (w, h) = real.dimensions();
    RgbImage::from_fn(3 * w, h, |x, y| {
        let (i, k) = (x % w, x / w);
        match k {
            0 => *real.get_pixel(i, y),
            1 => *rendered.get_pixel(i, y),
            _ => {
                let (p, q) = (real.get_pixel(i, y), rendered.get_pixel(i, y));
                image::Rgb(std::array::from_fn(|c| {
                    (128.0 + 4.0 * (p[c] as f64 - q[c] as f64)).clamp(0.0, 255.0) as u8
                }))
            }
        }
    })
}
