//! A calibration board as a pinhole camera sees it: each pixel's rays (a 6 x 6 grid across
//! the pixel, pixel x spanning [x, x + 1) as the scene renderers sample it) meet the board's
//! plane, and the printed face's colour there is averaged. The board's pose may be anything
//! the camera can see; rays that miss the sheet, or meet its back, see what lies behind:
//! a plain background (`board_view`) or the scene's render (`SheetInCamera::over_render`,
//! the board the twin's arm holds, hidden where the scene is nearer).

use crate::render::scene::InstanceImage;
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

/// The board's sheet placed in a camera's frame: where a ray meets it and the grey it sees.
pub struct SheetInCamera<'a> {
    face: &'a BoardFace,
    look: &'a SheetLook,
    to_board: Pose,
    normal: DVec3,
    origin: DVec3,
    size_mm: (f64, f64),
}

impl<'a> SheetInCamera<'a> {
    /// The sheet printed with `face`, its board frame at `board_in_camera` (OpenCV's camera
    /// frame).
    pub fn new(face: &'a BoardFace, board_in_camera: &Pose, look: &'a SheetLook) -> Self {
        Self {
            face,
            look,
            to_board: board_in_camera.inverse(),
            normal: board_in_camera.rotation * DVec3::Z,
            origin: board_in_camera.position,
            size_mm: face.board().size_mm(),
        }
    }

    /// The grey (0-255) and camera z (m) where the ray through image point (u, v) meets the
    /// sheet's printed side, if it does.
    fn hit(&self, k: &CameraIntrinsics, u: f64, v: f64) -> Option<(f64, f64)> {
        let ray = DVec3::new((u - k.cx) / k.fx, (v - k.cy) / k.fy, 1.0);
        let facing = self.normal.dot(ray);
        // The printed face looks along -z of the board frame: a ray meeting it runs along +z
        // (into the board).
        if facing <= 1e-12 {
            return None;
        }
        let t = self.normal.dot(self.origin) / facing;
        if t <= 0.0 {
            return None;
        }
        let p = self.to_board.transform_point(ray * t) * 1000.0;
        let (w_mm, h_mm) = self.size_mm;
        let m = self.look.margin_mm;
        if !((-m..w_mm + m).contains(&p.x) && (-m..h_mm + m).contains(&p.y)) {
            return None;
        }
        let grey = if self.face.is_white(p.x, p.y) {
            self.look.white
        } else {
            self.look.black
        };
        // The ray's z component is 1, so its length parameter is the camera z.
        Some((grey, t))
    }

    /// Pixel (x, y)'s colour (each channel 0-255) over `behind` (what the pixel shows where
    /// a ray misses the sheet, or meets it further than `behind_z_m`, 0 for nothing there),
    /// and the sheet's camera z at the pixel's centre if it is in front there; None where no
    /// ray sees the sheet.
    fn pixel(
        &self,
        k: &CameraIntrinsics,
        x: u32,
        y: u32,
        behind: [f64; 3],
        behind_z_m: f64,
    ) -> Option<([f64; 3], Option<f64>)> {
        let in_front = |z: f64| behind_z_m <= 0.0 || z < behind_z_m;
        let mut sum = [0.0f64; 3];
        let mut hits = 0;
        for j in 0..RAYS {
            for i in 0..RAYS {
                let u = x as f64 - 0.5 + (i as f64 + 0.5) / RAYS as f64;
                let v = y as f64 - 0.5 + (j as f64 + 0.5) / RAYS as f64;
                match self.hit(k, u, v).filter(|(_, z)| in_front(*z)) {
                    Some((g, _)) => {
                        hits += 1;
                        sum.iter_mut().for_each(|s| *s += g);
                    }
                    None => sum.iter_mut().zip(behind).for_each(|(s, b)| *s += b),
                }
            }
        }
        let centre = self
            .hit(k, x as f64, y as f64)
            .map(|(_, z)| z)
            .filter(|z| in_front(*z));
        (hits > 0).then(|| (sum.map(|s| s / (RAYS * RAYS) as f64), centre))
    }

    /// The sheet drawn into a scene's clean render (`color` linear in [0, 1], `depth_m`
    /// camera z, 0 where nothing is seen), hidden where the scene is nearer; pixels it covers
    /// take its depth and `sheet_instance`.
    pub fn over_render(
        &self,
        k: &CameraIntrinsics,
        color: &mut [[f64; 3]],
        depth_m: &mut [f64],
        specular: &mut [f64],
        instances: &mut InstanceImage,
        sheet_instance: u16,
    ) {
        let w = k.width;
        for (i, ((c, d), s)) in color
            .iter_mut()
            .zip(depth_m.iter_mut())
            .zip(specular.iter_mut())
            .enumerate()
        {
            let (x, y) = (i as u32 % w, i as u32 / w);
            // Rays that miss every part of the pixel's 3 px box round the sheet skip the
            // supersampling: most of the frame.
            if self.hit(k, x as f64, y as f64).is_none()
                && [(-1.5, -1.5), (1.5, -1.5), (-1.5, 1.5), (1.5, 1.5)]
                    .iter()
                    .all(|(du, dv)| self.hit(k, x as f64 + du, y as f64 + dv).is_none())
            {
                continue;
            }
            let behind = c.map(|v| v * 255.0);
            let Some((seen, centre)) = self.pixel(k, x, y, behind, *d) else {
                continue;
            };
            *c = seen.map(|v| v / 255.0);
            if let Some(z) = centre {
                *d = z;
                *s = 0.0;
                instances.put_pixel(x, y, image::Luma([sheet_instance]));
            }
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
    let sheet = SheetInCamera::new(face, board_in_camera, look);
    let behind = background.map(f64::from);
    RgbImage::from_fn(intrinsics.width, intrinsics.height, |x, y| {
        let seen = sheet
            .pixel(intrinsics, x, y, behind, 0.0)
            .map_or(behind, |(c, _)| c);
        Rgb(seen.map(|s| s.round().clamp(0.0, 255.0) as u8))
    })
}
