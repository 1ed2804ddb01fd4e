//! The reference renderer: the shader stages in plain Rust, f32, the same operations in
//! the same order for each pixel. A frame goes through all four stages row by row, rows in
//! parallel (pixels are independent, so the bytes do not depend on the thread count); with a
//! glow, which spreads light across rows, the frame is shaded whole before the dots and noise.

use super::noise::gaussian3_row;
use super::{GelGlow, GelRenderer, PressFrame, RenderError, RenderParams, SensorOptics, Shading};
use image::RgbImage;
use rayon::prelude::*;
use std::sync::{Arc, Mutex};

#[derive(Clone, Copy, Debug, Default)]
pub struct CpuRenderer;

/// Stage 1: slopes by central differences, one-sided at the edge (gel_slopes.wgsl).
fn slopes(p: &RenderParams, heights: &[f32]) -> Vec<[f32; 2]> {
    let w = p.width as usize;
    let mut out = vec![[0.0f32; 2]; w * p.height as usize];
    out.par_chunks_mut(w)
        .enumerate()
        .for_each(|(y, row)| slopes_at(p, heights, y, row));
    out
}

/// Row `y` of the slopes.
fn slopes_at(p: &RenderParams, heights: &[f32], y: usize, out: &mut [[f32; 2]]) {
    let (w, h) = (p.width as usize, p.height as usize);
    let (y0, y1) = (y.saturating_sub(1), (y + 1).min(h - 1));
    let rows = [
        &heights[y0 * w..][..w],
        &heights[y * w..][..w],
        &heights[y1 * w..][..w],
    ];
    slopes_row(rows, p.mm_per_px, ((y1 - y0) as f32) * p.mm_per_px, out);
}

/// One row of slopes from the rows above, at and below it (`dy_mm` apart); the edge
/// columns one-sided, the rest in a branch-free loop that vectorises.
#[multiversion::multiversion(targets("x86_64+avx2"))]
fn slopes_row(rows: [&[f32]; 3], mm_per_px: f32, dy_mm: f32, out: &mut [[f32; 2]]) {
    let [above, here, below] = rows;
    let w = out.len();
    let column = |x: usize| {
        let (x0, x1) = (x.saturating_sub(1), (x + 1).min(w - 1));
        [
            (here[x1] - here[x0]) / ((x1 - x0) as f32 * mm_per_px),
            (below[x] - above[x]) / dy_mm,
        ]
    };
    out[0] = column(0);
    out[w - 1] = column(w - 1);
    let dx_mm = 2.0 * mm_per_px;
    let inner = out[1..w - 1].iter_mut().zip(&here[..w - 2]).zip(&here[2..]);
    for (((g, left), right), (a, b)) in inner.zip(above[1..].iter().zip(&below[1..])) {
        *g = [(right - left) / dx_mm, (b - a) / dy_mm];
    }
}

/// The analytic lights of a frame: each channel's light direction and its gain on a flat
/// gel, the divisor that makes a flat gel show the background.
struct Lit {
    lights: [[f32; 3]; 3],
    flat: [f32; 3],
    ambient: f32,
    light_gain: f32,
}

impl Lit {
    fn new(p: &RenderParams) -> Self {
        Lit {
            lights: p.lights.map(|l| [l[0], l[1], l[2]]),
            flat: p.lights.map(|l| p.ambient + p.light_gain * l[2]),
            ambient: p.ambient,
            light_gain: p.light_gain,
        }
    }
}

/// One row of the analytic shading with vignetting: `fade[x]` is the row's vignetting gain.
/// Branch-free over the row so that it vectorises (AVX2 where the CPU has it; same bits).
#[multiversion::multiversion(targets("x86_64+avx2"))]
fn shade_row_lit(
    lit: &Lit,
    slopes: &[[f32; 2]],
    bg: &[[f32; 3]],
    fade: &[f32],
    out: &mut [[f32; 3]],
) {
    for (((px, g), b), f) in out.iter_mut().zip(slopes).zip(bg).zip(fade) {
        // The unit normal of the surface z = h(x, y) is (-hx, -hy, 1) / |.|.
        let inv = 1.0 / ((g[0] * g[0] + g[1] * g[1]) + 1.0).sqrt();
        let n = [-g[0] * inv, -g[1] * inv, inv];
        for c in 0..3 {
            let l = lit.lights[c];
            let cos = ((n[0] * l[0] + n[1] * l[1]) + n[2] * l[2]).max(0.0);
            let gain = (lit.ambient + lit.light_gain * cos) / lit.flat[c];
            px[c] = b[c] * gain * f;
        }
    }
}

/// Stage 2: shading and vignetting (gel_shading.wgsl).
fn shade(p: &RenderParams, optics: &SensorOptics, slopes: &[[f32; 2]]) -> Vec<[f32; 3]> {
    let w = p.width as usize;
    let mut out = vec![[0.0f32; 3]; w * p.height as usize];
    let frame = ShadedFrame::new(p, optics);
    out.par_chunks_mut(w).enumerate().for_each_init(
        || vec![0.0f32; w],
        |fade, (y, row)| frame.shade_row(y, &slopes[y * w..][..w], None, fade, row),
    );
    out
}

/// What shading needs of a frame beyond its slopes.
struct ShadedFrame<'a> {
    p: &'a RenderParams,
    optics: &'a SensorOptics,
    lit: Lit,
    /// Pixel-centre x in [-1/2, 1/2] across the frame, for vignetting.
    us: Vec<f32>,
    /// The same in the table's [-1, 1].
    table_us: Vec<f32>,
}

impl<'a> ShadedFrame<'a> {
    fn new(p: &'a RenderParams, optics: &'a SensorOptics) -> Self {
        let w = p.width as usize;
        Self {
            p,
            optics,
            lit: Lit::new(p),
            us: (0..w).map(|x| (x as f32 + 0.5) / w as f32 - 0.5).collect(),
            table_us: (0..w)
                .map(|x| 2.0 * ((x as f32 + 0.5) / w as f32 - 0.5))
                .collect(),
        }
    }

    /// Row `y` of the shading from that row's slopes; `fade` is scratch of the row's width.
    /// Where `flat` (the flat gel's shading of the row) is given, a table's untouched pixels
    /// take it rather than look the table up again: the same operations made it, so the
    /// bytes are the same.
    fn shade_row(
        &self,
        y: usize,
        g: &[[f32; 2]],
        flat: Option<&[[f32; 3]]>,
        fade: &mut [f32],
        row: &mut [[f32; 3]],
    ) {
        let (w, h) = (self.p.width as usize, self.p.height as usize);
        let v = (y as f32 + 0.5) / h as f32 - 0.5;
        for (f, u) in fade.iter_mut().zip(&self.us) {
            *f = 1.0 - self.p.vignette * (u * u + v * v);
        }
        let bg = &self.optics.background[y * w..][..w];
        match &self.optics.shading {
            Shading::Lights(_) => shade_row_lit(&self.lit, g, bg, fade, row),
            Shading::Table(table) => {
                // The row's changes first (into `row`), then each pixel's colour from its own.
                table.lookup_row(2.0 * v).changes(g, &self.table_us, row);
                for x in 0..w {
                    if let Some(flat) = flat.filter(|_| g[x] == [0.0, 0.0]) {
                        row[x] = flat[x];
                        continue;
                    }
                    let d = row[x];
                    row[x] = std::array::from_fn(|c| (bg[x][c] + d[c]) * fade[x]);
                }
            }
        }
    }
}

/// The shading of a flat gel: what the glow's change is taken against.
pub(crate) fn flat_shading(p: &RenderParams, optics: &SensorOptics) -> Vec<[f32; 3]> {
    shade(
        p,
        optics,
        &vec![[0.0; 2]; p.width as usize * p.height as usize],
    )
}

/// Stages 1-2 as the flat gel's shading and the frame's change from it: what a glow spreads.
fn shading_change(
    p: &RenderParams,
    optics: &SensorOptics,
    heights: &[f32],
) -> (Arc<Vec<[f32; 3]>>, Vec<[f32; 3]>) {
    let flat = shared_flat_shading(optics);
    let w = p.width as usize;
    let g = slopes(p, heights);
    let frame = ShadedFrame::new(p, optics);
    let mut change = vec![[0.0f32; 3]; w * p.height as usize];
    change.par_chunks_mut(w).enumerate().for_each_init(
        || vec![0.0f32; w],
        |fade, (y, row)| {
            let flat = &flat[y * w..][..w];
            frame.shade_row(y, &g[y * w..][..w], Some(flat), fade, row);
            for (s, f) in row.iter_mut().zip(flat) {
                *s = std::array::from_fn(|c| s[c] - f[c]);
            }
        },
    );
    (flat, change)
}

/// Optics whose flat shading was made, and it; a few kept.
type FlatMade = (SensorOptics, Arc<Vec<[f32; 3]>>);
static FLAT_MADE: Mutex<Vec<FlatMade>> = Mutex::new(Vec::new());
const FLAT_KEPT: usize = 2;

/// The flat gel's shading of these optics, made once and shared: every frame through a
/// glow is its flat shading plus the glow of its change, and through a table the flat
/// shading costs a full frame of lookups (the arm's search for contact renders dozens).
fn shared_flat_shading(optics: &SensorOptics) -> Arc<Vec<[f32; 3]>> {
    let found = {
        let made = FLAT_MADE.lock().unwrap_or_else(|e| e.into_inner());
        made.iter()
            .find(|(o, _)| o == optics)
            .map(|(_, flat)| flat.clone())
    };
    if let Some(flat) = found {
        return flat;
    }
    let flat = Arc::new(flat_shading(&RenderParams::new(optics, 1), optics));
    let mut made = FLAT_MADE.lock().unwrap_or_else(|e| e.into_inner());
    if made.len() >= FLAT_KEPT {
        made.remove(0);
    }
    made.push((optics.clone(), flat.clone()));
    flat
}

/// Stages 1-2 and the glow (gel_glow_*.wgsl): the flat gel's shading plus the glow of the
/// frame's change from it and of the gel's indentation.
fn glowing(
    p: &RenderParams,
    optics: &SensorOptics,
    glow: &GelGlow,
    heights: &[f32],
) -> Vec<[f32; 3]> {
    // Every source of the glow is zero on an untouched gel: its frame is the flat shading,
    // bit for bit, without the blurs (the arm's search for contact renders many such).
    if heights.iter().all(|&h| h == 0.0) {
        return shared_flat_shading(optics).to_vec();
    }
    let (flat, change) = shading_change(p, optics, heights);
    let mut out = glow.apply(&change, heights, p.width as usize, p.height as usize);
    for (o, f) in out.iter_mut().zip(flat.iter()) {
        *o = std::array::from_fn(|c| f[c] + o[c]);
    }
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

/// The pixel box a dot can darken: columns `x0..x1`, rows `y0..y1`.
struct DotReach {
    centre: [f32; 2],
    x0: usize,
    x1: usize,
    y0: usize,
    y1: usize,
}

/// Each dot's box, in marker order; dots wholly off the frame are dropped.
fn dot_reaches(p: &RenderParams, centres: &[[f32; 2]]) -> Vec<DotReach> {
    let (w, h) = (p.width as f32, p.height as f32);
    let reach = p.marker_radius_px + 0.5;
    centres
        .iter()
        .filter_map(|&c| {
            let (x0, x1) = (
                (c[0] - reach).floor().max(0.0),
                (c[0] + reach).ceil().min(w),
            );
            let (y0, y1) = (
                (c[1] - reach).floor().max(0.0),
                (c[1] + reach).ceil().min(h),
            );
            (x0 < x1 && y0 < y1).then_some(DotReach {
                centre: c,
                x0: x0 as usize,
                x1: x1 as usize,
                y0: y0 as usize,
                y1: y1 as usize,
            })
        })
        .collect()
}

/// Stage 4 on one row: marker dots, exposure gain, noise, quantisation (sensor_exposure.wgsl).
/// A pixel takes its dots' factors in marker order.
fn expose_row(
    p: &RenderParams,
    dots: &[DotReach],
    seed: u32,
    y: usize,
    shaded: &mut [[f32; 3]],
    noise: &mut [[f32; 3]],
    out: &mut [u8],
) {
    let w = p.width as usize;
    let reach = p.marker_radius_px + 0.5;
    for dot in dots.iter().filter(|d| (d.y0..d.y1).contains(&y)) {
        for (x, px) in shaded.iter_mut().enumerate().take(dot.x1).skip(dot.x0) {
            let (dx, dy) = (
                x as f32 + 0.5 - dot.centre[0],
                y as f32 + 0.5 - dot.centre[1],
            );
            let d = (dx * dx + dy * dy).sqrt();
            if d < reach {
                let f = 1.0 - p.marker_darkness * (reach - d).min(1.0);
                *px = px.map(|v| v * f);
            }
        }
    }
    // The same product as the shader's, after the dots: the two paths keep equal bits.
    if p.exposure != 1.0 {
        for px in shaded.iter_mut() {
            *px = px.map(|v| v * p.exposure);
        }
    }
    // No noise asked for: the draws would be multiplied by zero anyway.
    if p.noise_sigma != 0.0 {
        gaussian3_row(seed, (y * w) as u32, noise);
    }
    quantise_row(
        shaded.as_flattened(),
        noise.as_flattened(),
        p.noise_sigma,
        out,
    );
}

/// One row of channel values plus sigma times their draws, to bytes. Over the flat channel
/// values so that it vectorises (AVX2 where the CPU has it; the same bits either way).
#[multiversion::multiversion(targets("x86_64+avx2"))]
fn quantise_row(shaded: &[f32], draws: &[f32], sigma: f32, out: &mut [u8]) {
    for ((o, s), n) in out.iter_mut().zip(shaded).zip(draws) {
        let noisy = s + sigma * n;
        // floor(x + 1/2) clamped to [0, 255] (NaN to 0, as a saturating cast would give).
        // A float cast to an integer does not vectorise (it saturates lane by lane), so
        // the whole number is read from the mantissa: adding 2^23 to an integer below 2^23
        // is exact and leaves it in the low bits.
        // max/min, not clamp: clamp keeps a NaN, whose bits would then be read.
        #[allow(clippy::manual_clamp)]
        let level = (noisy + 0.5).max(0.0).min(255.0).floor();
        *o = (level + 8_388_608.0).to_bits() as u8;
    }
}

/// One worker's row buffers, reused from row to row.
struct RowScratch {
    slopes: Vec<[f32; 2]>,
    fade: Vec<f32>,
    shaded: Vec<[f32; 3]>,
    noise: Vec<[f32; 3]>,
}

impl RowScratch {
    fn new(w: usize) -> Self {
        Self {
            slopes: vec![[0.0; 2]; w],
            fade: vec![0.0; w],
            shaded: vec![[0.0; 3]; w],
            noise: vec![[0.0; 3]; w],
        }
    }
}

impl CpuRenderer {
    /// The four stages row by row: a row goes from heights to bytes while it is in cache,
    /// and no frame-sized intermediate is written.
    pub fn render_one(&self, optics: &SensorOptics, frame: &PressFrame) -> RgbImage {
        let p = RenderParams::new(optics, 1);
        let f = frame.fields;
        let w = p.width as usize;
        let centres = marker_centres(&p, optics, &f.lateral_x_mm, &f.lateral_y_mm);
        let dots = dot_reaches(&p, &centres);
        let mut bytes = vec![0u8; w * p.height as usize * 3];
        if let Some(glow) = &optics.glow {
            // The glow spreads light across rows: the whole frame is shaded first.
            let mut shaded = glowing(&p, optics, glow, &f.normal_mm);
            bytes
                .par_chunks_mut(3 * w)
                .zip(shaded.par_chunks_mut(w))
                .enumerate()
                .for_each_init(
                    || vec![[0.0f32; 3]; w],
                    |noise, (y, (row, shaded))| {
                        expose_row(&p, &dots, frame.seed, y, shaded, noise, row)
                    },
                );
            return RgbImage::from_raw(p.width, p.height, bytes).expect("sized from the frame");
        }
        let shading = ShadedFrame::new(&p, optics);
        bytes.par_chunks_mut(3 * w).enumerate().for_each_init(
            || RowScratch::new(w),
            |s, (y, row)| {
                slopes_at(&p, &f.normal_mm, y, &mut s.slopes);
                shading.shade_row(y, &s.slopes, None, &mut s.fade, &mut s.shaded);
                expose_row(&p, &dots, frame.seed, y, &mut s.shaded, &mut s.noise, row);
            },
        );
        RgbImage::from_raw(p.width, p.height, bytes).expect("sized from the frame")
    }

    /// The flat gel's shading and a frame's change from it (slopes + shading + vignetting,
    /// no glow, dots or noise; grey levels): what `calibrate` fits a glow to.
    pub fn shading_change(
        &self,
        optics: &SensorOptics,
        fields: &super::GelImageFields,
    ) -> (Vec<[f32; 3]>, Vec<[f32; 3]>) {
        let (flat, change) =
            shading_change(&RenderParams::new(optics, 1), optics, &fields.normal_mm);
        (flat.to_vec(), change)
    }

    /// The shading stage alone (slopes + shading + vignetting, and the glow when the optics
    /// have one): the frame before marker dots and noise, in grey levels.
    pub fn shade_only(&self, optics: &SensorOptics, frame: &PressFrame) -> Vec<[f32; 3]> {
        let p = RenderParams::new(optics, 1);
        match &optics.glow {
            Some(glow) => glowing(&p, optics, glow, &frame.fields.normal_mm),
            None => shade(&p, optics, &slopes(&p, &frame.fields.normal_mm)),
        }
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
        Ok(frames
            .par_iter()
            .map(|f| self.render_one(optics, f))
            .collect())
    }
}

#[cfg(test)]
mod tests {
    use super::quantise_row;

    #[test]
    fn quantising_rounds_half_up_and_saturates() {
        let values = [
            -3.0,
            0.49,
            0.5,
            1.5,
            2.5,
            127.49,
            254.5,
            300.0,
            f32::NAN,
            f32::INFINITY,
            f32::NEG_INFINITY,
        ];
        let expected = [0u8, 0, 1, 2, 3, 127, 255, 255, 0, 255, 0];
        // Row lengths past the vector width, with no noise and with noise that cancels.
        let row: Vec<f32> = values
            .iter()
            .cycle()
            .take(3 * values.len())
            .copied()
            .collect();
        let mut out = vec![0u8; row.len()];
        quantise_row(&row, &vec![0.0; row.len()], 0.0, &mut out);
        let want: Vec<u8> = expected.iter().cycle().take(row.len()).copied().collect();
        assert_eq!(out, want);
        let shifted: Vec<f32> = row.iter().map(|v| v - 2.0).collect();
        quantise_row(&shifted, &vec![1.0; row.len()], 2.0, &mut out);
        assert_eq!(out, want);
    }
}
