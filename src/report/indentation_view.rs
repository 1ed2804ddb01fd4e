//! The picture of a frame read: the frame beside its indentation map (viridis, zero to the
//! peak) with the contact's half-depth outline drawn on both.

use image::{Rgb, RgbImage};
use tactex_core::tactile::frame_reading::FrameReading;

const OUTLINE: Rgb<u8> = Rgb([255, 64, 64]);

/// Viridis at nine even stops (matplotlib's table), interpolated linearly: perceptually even,
/// readable in grey.
const VIRIDIS: [[f32; 3]; 9] = [
    [68.0, 1.0, 84.0],
    [71.0, 44.0, 122.0],
    [59.0, 81.0, 139.0],
    [44.0, 113.0, 142.0],
    [33.0, 144.0, 141.0],
    [39.0, 173.0, 129.0],
    [92.0, 200.0, 99.0],
    [170.0, 220.0, 50.0],
    [253.0, 231.0, 37.0],
];

fn viridis(t: f64) -> Rgb<u8> {
    let x = t.clamp(0.0, 1.0) as f32 * (VIRIDIS.len() - 1) as f32;
    let k = (x.floor() as usize).min(VIRIDIS.len() - 2);
    let f = x - k as f32;
    Rgb(std::array::from_fn(|c| {
        (VIRIDIS[k][c] + f * (VIRIDIS[k + 1][c] - VIRIDIS[k][c])).round() as u8
    }))
}

/// frame | indentation map, side by side, the contact outlined in red on both.
pub fn indentation_view(frame: &RgbImage, reading: &FrameReading) -> RgbImage {
    let (w, h) = (reading.width, reading.height);
    let top = reading.peak_mm.max(1e-9);
    let edge = |x: usize, y: usize| {
        let i = y * w + x;
        reading.in_contact(i)
            && [(0, -1), (0, 1), (-1, 0), (1, 0)].iter().any(|(dx, dy)| {
                let (xx, yy) = (x as i64 + dx, y as i64 + dy);
                xx < 0
                    || yy < 0
                    || xx >= w as i64
                    || yy >= h as i64
                    || !reading.in_contact(yy as usize * w + xx as usize)
            })
    };
    RgbImage::from_fn(2 * w as u32, h as u32, |x, y| {
        let (i, left) = ((x as usize) % w, (x as usize) < w);
        let y = y as usize;
        if edge(i, y) {
            return OUTLINE;
        }
        if left {
            return *frame.get_pixel(i as u32, y as u32);
        }
        let d = reading.indentation_mm[y * w + i];
        viridis(d / top)
    })
}
