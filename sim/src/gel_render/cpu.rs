//! The reference renderer: the four shader stages in plain Rust, f32, the same operations in
//! the same order, rows in parallel (pixels are independent, so the bytes do not depend on
//! the thread count).

use super::noise::gaussian3;
use super::{GelRenderer, PressFrame, RenderError, RenderParams, SensorOptics, Shading};
use image::RgbImage;
use rayon::prelude::*;

#[derive(Clone, Copy, Debug, Default)]
pub struct CpuRenderer;

/// Stage 1: slopes by central differences, one-sided at the edge (gel_slopes.wgsl).
fn slopes(p: &RenderParams, heights: &[f32]) -> Vec<[f32; 2]> {
    let (w, h) = (p.width as usize, p.height as usize);
    let mut out = vec![[0.0f32; 2]; w * h];
    out.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
        let (y0, y1) = (y.saturating_sub(1), (y + 1).min(h - 1));
        for (x, g) in row.iter_mut().enumerate() {
            let (x0, x1) = (x.saturating_sub(1), (x + 1).min(w - 1));
            g[0] = (heights[y * w + x1] - heights[y * w + x0]) / ((x1 - x0) as f32 * p.mm_per_px);
            g[1] = (heights[y1 * w + x] - heights[y0 * w + x]) / ((y1 - y0) as f32 * p.mm_per_px);
        }
    });
    out
}

/// Stage 2: shading and vignetting (gel_shading.wgsl).
fn shade(p: &RenderParams, optics: &SensorOptics, slopes: &[[f32; 2]]) -> Vec<[f32; 3]> {
    let (w, h) = (p.width as usize, p.height as usize);
    let mut out = vec![[0.0f32; 3]; w * h];
    out.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
        let v = (y as f32 + 0.5) / h as f32 - 0.5;
        for (x, px) in row.iter_mut().enumerate() {
            let k = y * w + x;
            let g = slopes[k];
            let bg = optics.background[k];
            let u = (x as f32 + 0.5) / w as f32 - 0.5;
            let colour: [f32; 3] = match &optics.shading {
                Shading::Lights(_) => {
                    let n = glam::Vec3::new(-g[0], -g[1], 1.0).normalize();
                    std::array::from_fn(|c| {
                        let l = glam::Vec3::from_slice(&p.lights[c][..3]);
                        let gain = (p.ambient + p.light_gain * n.dot(l).max(0.0))
                            / (p.ambient + p.light_gain * l.z);
                        bg[c] * gain
                    })
                }
                Shading::Table(table) => {
                    let d = table.change(g[0], g[1], 2.0 * u, 2.0 * v);
                    std::array::from_fn(|c| bg[c] + d[c])
                }
            };
            let fade = 1.0 - p.vignette * (u * u + v * v);
            *px = colour.map(|c| c * fade);
        }
    });
    out
}

/// Stage 3: marker centres moved by the lateral field (marker_displacement.wgsl).
fn marker_centres(
    p: &RenderParams,
    optics: &SensorOptics,
    lx: &[f32],
    ly: &[f32],
) -> Vec<[f32; 2]> {
    let (w, h) = (p.width as usize, p.height as usize);
    let sample = |field: &[f32], q: [f32; 2]| -> f32 {
        let qx = (q[0] - 0.5).clamp(0.0, (w - 1) as f32);
        let qy = (q[1] - 0.5).clamp(0.0, (h - 1) as f32);
        let i0 = (qx.floor() as usize).min(w - 2);
        let j0 = (qy.floor() as usize).min(h - 2);
        let (fx, fy) = (qx - i0 as f32, qy - j0 as f32);
        let k = j0 * w + i0;
        (field[k] * (1.0 - fx) + field[k + 1] * fx) * (1.0 - fy)
            + (field[k + w] * (1.0 - fx) + field[k + w + 1] * fx) * fy
    };
    optics
        .markers
        .iter()
        .map(|&rest| {
            [
                rest[0] + sample(lx, rest) / p.mm_per_px,
                rest[1] + sample(ly, rest) / p.mm_per_px,
            ]
        })
        .collect()
}

/// Stage 4: marker dots, noise, quantisation (sensor_exposure.wgsl). Each dot only visits
/// the pixels it can reach; a pixel still takes its dots' factors in marker order.
fn expose(
    p: &RenderParams,
    mut shaded: Vec<[f32; 3]>,
    centres: &[[f32; 2]],
    seed: u32,
) -> RgbImage {
    let (w, h) = (p.width as usize, p.height as usize);
    let reach = p.marker_radius_px + 0.5;
    for c in centres {
        let (x0, x1) = (
            (c[0] - reach).floor().max(0.0),
            (c[0] + reach).ceil().min(w as f32),
        );
        let (y0, y1) = (
            (c[1] - reach).floor().max(0.0),
            (c[1] + reach).ceil().min(h as f32),
        );
        if !(x0 < x1 && y0 < y1) {
            continue;
        }
        for y in y0 as usize..y1 as usize {
            for x in x0 as usize..x1 as usize {
                let (dx, dy) = (x as f32 + 0.5 - c[0], y as f32 + 0.5 - c[1]);
                let d = (dx * dx + dy * dy).sqrt();
                if d < reach {
                    let f = 1.0 - p.marker_darkness * (reach - d).min(1.0);
                    shaded[y * w + x] = shaded[y * w + x].map(|v| v * f);
                }
            }
        }
    }
    let mut bytes = vec![0u8; w * h * 3];
    bytes
        .par_chunks_mut(3 * w)
        .enumerate()
        .for_each(|(y, row)| {
            for x in 0..w {
                // No noise asked for: the draws would be multiplied by zero anyway.
                let noise = if p.noise_sigma == 0.0 {
                    [0.0; 3]
                } else {
                    gaussian3(seed, (y * w + x) as u32)
                };
                for c in 0..3 {
                    let noisy = shaded[y * w + x][c] + p.noise_sigma * noise[c];
                    // floor(x + 1/2) clamped to [0, 255]: on that range the saturating cast's
                    // truncation is the floor, without a libm call per channel.
                    row[3 * x + c] = (noisy + 0.5).clamp(0.0, 255.0) as u8;
                }
            }
        });
    RgbImage::from_raw(p.width, p.height, bytes).expect("sized from the frame")
}

impl CpuRenderer {
    pub fn render_one(&self, optics: &SensorOptics, frame: &PressFrame) -> RgbImage {
        let p = RenderParams::new(optics, 1);
        let f = frame.fields;
        let g = slopes(&p, &f.normal_mm);
        let shaded = shade(&p, optics, &g);
        let centres = marker_centres(&p, optics, &f.lateral_x_mm, &f.lateral_y_mm);
        expose(&p, shaded, &centres, frame.seed)
    }

    /// The shading stage alone (slopes + shading + vignetting), for timing it on its own.
    pub fn shade_only(&self, optics: &SensorOptics, frame: &PressFrame) -> Vec<[f32; 3]> {
        let p = RenderParams::new(optics, 1);
        shade(&p, optics, &slopes(&p, &frame.fields.normal_mm))
    }
}

impl GelRenderer for CpuRenderer {
    fn name(&self) -> String {
        "cpu".into()
    }

    fn render_batch(
        &mut self,
        optics: &SensorOptics,
        frames: &[PressFrame],
    ) -> Result<Vec<RgbImage>, RenderError> {
        optics.check_frames(frames)?;
        Ok(frames.iter().map(|f| self.render_one(optics, f)).collect())
    }
}
