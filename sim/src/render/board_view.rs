//! A calibration board as a pinhole camera sees it: each pixel's rays (a 6 x 6 grid across
//! the pixel, pixel x spanning [x, x + 1) as the scene renderers sample it) meet the board's
//! plane, and the printed face's colour there is averaged. The board's pose may be anything
//! the camera can see; rays that miss the sheet, or meet its back, see the background.

use glam::DVec3;
use image::{Rgb, RgbImage};
use tactex_core::charuco::BoardFace;
use tactex_core::geometry::{CameraIntrinsics, Pose};

/// Rays per pixel side.
const RAYS: usize = 6;

/// How the board's sheet looks: its white paper and black ink as 8-bit grey levels under the
/// scene's light, and the white margin round the printed board (mm).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SheetLook {
    pub white: f64,
    pub black: f64,
    pub margin_mm: f64,
}

impl Default for SheetLook {
    /// Matte paper under the table's light: white 220, ink 25, a 10 mm margin (what `tactex
    /// board` prints).
    fn default() -> Self {
        Self {
            white: 220.0,
            black: 25.0,
            margin_mm: 10.0,
        }
    }
}

/// The board (printed face `face`, its frame at `board_in_camera`, OpenCV's camera frame) seen
/// through `intrinsics`, over `background`.
pub fn board_view(
    face: &BoardFace,
    board_in_camera: &Pose,
    intrinsics: &CameraIntrinsics,
    look: &SheetLook,
    background: [u8; 3],
) -> RgbImage {
    let k = intrinsics;
    let to_board = board_in_camera.inverse();
    let normal = board_in_camera.rotation * DVec3::Z;
    let origin = board_in_camera.position;
    let (w_mm, h_mm) = face.board().size_mm();
    let m = look.margin_mm;
    RgbImage::from_fn(k.width, k.height, |x, y| {
        let mut sum = [0.0f64; 3];
        for j in 0..RAYS {
            for i in 0..RAYS {
                let u = x as f64 + (i as f64 + 0.5) / RAYS as f64;
                let v = y as f64 + (j as f64 + 0.5) / RAYS as f64;
                let ray = DVec3::new((u - k.cx) / k.fx, (v - k.cy) / k.fy, 1.0);
                let facing = normal.dot(ray);
                // The printed face looks along -z of the board frame: a ray meeting it runs
                // along +z (into the board).
                let hit = (facing > 1e-12)
                    .then(|| normal.dot(origin) / facing)
                    .filter(|t| *t > 0.0)
                    .map(|t| to_board.transform_point(ray * t) * 1000.0)
                    .filter(|p| (-m..w_mm + m).contains(&p.x) && (-m..h_mm + m).contains(&p.y));
                match hit {
                    Some(p) => {
                        let g = if face.is_white(p.x, p.y) {
                            look.white
                        } else {
                            look.black
                        };
                        sum.iter_mut().for_each(|s| *s += g);
                    }
                    None => sum
                        .iter_mut()
                        .zip(background)
                        .for_each(|(s, b)| *s += b as f64),
                }
            }
        }
        Rgb(sum.map(|s| (s / (RAYS * RAYS) as f64).round().clamp(0.0, 255.0) as u8))
    })
}
