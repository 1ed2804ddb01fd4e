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

/// frame | indentation map, side by side, the contact outlined in red on both. A reading
/// made at a coarser resolution than the frame's (a fine sensor read on 2 x 2 blocks) is
/// shown at the frame's, each of its pixels as a block.
pub fn indentation_view(frame: &RgbImage, reading: &FrameReading) -> RgbImage {
    let (fw, fh) = (frame.width() as usize, frame.height() as usize);
    let (w, h) = (reading.width, reading.height);
    // The reading's pixel under a frame pixel.
    let at = |x: usize, y: usize| ((y * h / fh).min(h - 1), (x * w / fw).min(w - 1));
    let inside = |x: usize, y: usize| {
        let (ry, rx) = at(x, y);
        reading.in_contact(ry * w + rx)
    };
    let top = reading.peak_mm.max(1e-9);
    let edge = |x: usize, y: usize| {
        inside(x, y)
            && [(0, -1), (0, 1), (-1, 0), (1, 0)].iter().any(|(dx, dy)| {
                let (xx, yy) = (x as i64 + dx, y as i64 + dy);
                xx < 0
                    || yy < 0
                    || xx >= fw as i64
                    || yy >= fh as i64
                    || !inside(xx as usize, yy as usize)
            })
    };
    RgbImage::from_fn(2 * fw as u32, fh as u32, |x, y| {
        let (i, left) = ((x as usize) % fw, (x as usize) < fw);
        let y = y as usize;
        if edge(i, y) {
            return OUTLINE;
        }
        if left {
            return *frame.get_pixel(i as u32, y as u32);
        }
        let (ry, rx) = at(i, y);
        viridis(reading.indentation_mm[ry * w + rx] / top)
    })
}
