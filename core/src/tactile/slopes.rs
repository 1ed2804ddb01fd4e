//! Gel surface slopes from a tactile frame: the sensor's shading inverted per pixel against
//! the no-contact reference frame (its analytic lights, or the calibrated table of a real
//! sensor's profile read backwards). Marker dots and saturated pixels carry no shading and
//! are left out.

use crate::tactile::depth::integrate_slopes;
use crate::tactile::gel_glow::{GelGlow, blur};
use crate::tactile::glow_inverse::GlowInverse;
use crate::tactile::half_resolution::HalfResolution;
use crate::tactile::photometric::PhotometricModel;
use crate::tactile::shading_table::{ShadingTable, frame_position};
use crate::tactile::spec::TactileSpec;
use image::RgbImage;

/// Slopes dw/dx and dw/dy (mm per mm) per pixel, in image axes (x along columns, y down).
#[derive(Clone, Debug)]
pub struct SlopeField {
    pub width: usize,
    pub height: usize,
    /// The gel's size of one of its pixels: the frame's, or twice it where the frame was
    /// read at half its resolution.
    pub mm_per_px: f64,
    pub gx: Vec<f32>,
    pub gy: Vec<f32>,
    pub valid: Vec<bool>,
    /// The colour drift taken out of the frame (grey levels per channel), where it was read
    /// through a glow.
    pub drift: Option<[f32; 3]>,
}

/// A frame's colour drift from its reference: real frames drift from shot to shot far from
/// any contact. A frame's own untouched gel carries a wide imprint's glow too, so a press's
/// deeper frames take the drift its first frame (the least imprint, the least glow) shows:
/// the frames of one press are taken within seconds, under the same light.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ColourDrift {
    /// Measured on the frame's own gel that a first reading calls untouched.
    Measured,
    /// Given (grey levels per channel).
    Given([f32; 3]),
}

impl ColourDrift {
    /// What a press's next frame takes, after a frame read with `self` took out `taken`: the
    /// first frame's drift, once there is one.
    pub fn for_next_frame(self, taken: Option<[f32; 3]>) -> ColourDrift {
        match (self, taken) {
            (ColourDrift::Measured, Some(d)) => ColourDrift::Given(d),
            _ => self,
        }
    }
}

impl SlopeField {
    /// An unread field on the 2 x 2 blocks of this one's frame: a block is readable where
    /// all four of its pixels are.
    fn halved(&self, half: &HalfResolution) -> SlopeField {
        let n = half.coarse_width() * half.coarse_height();
        SlopeField {
            width: half.coarse_width(),
            height: half.coarse_height(),
            mm_per_px: 2.0 * self.mm_per_px,
            gx: vec![0.0; n],
            gy: vec![0.0; n],
            valid: half.down_valid(&self.valid),
            drift: None,
        }
    }
}

/// Below this sum of the three channels a pixel is a marker dot's, and carries no shading:
/// 210 (70 grey levels a channel), or 0.45 of the no-contact frame's median where that is
/// dimmer, since a dim sensor's lit gel itself sits near 70 (a dot takes 60-85% of the light
/// away, so its middle stays below 0.45 of the gel's).
pub(crate) fn dark_level(reference: &RgbImage) -> u32 {
    let mut sums: Vec<u32> = reference
        .pixels()
        .step_by(7)
        .map(|p| p[0] as u32 + p[1] as u32 + p[2] as u32)
        .collect();
    if sums.is_empty() {
        return 3 * 70;
    }
    let mid = sums.len() / 2;
    let median = *sums.select_nth_unstable(mid).1;
    (3 * 70).min(median * 45 / 100)
}

/// A marker dot's pixel, against a frame's `dark_level`.
pub(crate) fn is_dark(p: &image::Rgb<u8>, level: u32) -> bool {
    (p[0] as u32 + p[1] as u32 + p[2] as u32) < level
}

/// A calibrated table's colour change further than this (rms grey levels) from every slope's
/// is not gel shading: a table fits real presses to about 5-9 grey levels.
const TABLE_MAX_RMS: f32 = 25.0;
/// How much a calibrated table's reading prefers gentle slopes (grey levels^2 per unit
/// slope^2; see `ShadingRow::slope_for_change`): a unit of slope must buy back about 3.7
/// grey levels of residual in each channel. Chosen on the FOTS profile's read-back of
/// rendered presses (tails of 1.5 slope units without it, 0.45 with it).
const TABLE_SLOPE_PRIOR: f32 = 40.0;

/// Inverts the sensor's shading against `reference`. Pixels dark in either frame (markers) are
/// invalid, and so is a 2 px ring around them where the dot's soft edge mixes with the
/// shading.
pub fn recover_slopes(
    frame: &RgbImage,
    reference: &RgbImage,
    spec: &TactileSpec,
    drift: ColourDrift,
) -> Option<SlopeField> {
    if frame.dimensions() != reference.dimensions() {
        return None;
    }
    let (w, h) = (frame.width() as usize, frame.height() as usize);
    let level = dark_level(reference);
    let mut dark = vec![false; w * h];
    for (i, (p, r)) in frame.pixels().zip(reference.pixels()).enumerate() {
        dark[i] = is_dark(p, level) || is_dark(r, level) || p.0.contains(&255);
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
    let mut field = SlopeField {
        width: w,
        height: h,
        mm_per_px: spec.mm_per_px,
        gx: vec![0.0; w * h],
        gy: vec![0.0; w * h],
        valid,
        drift: None,
    };
    let Some(table) = &spec.table else {
        for (i, (p, r)) in frame.pixels().zip(reference.pixels()).enumerate() {
            if !field.valid[i] {
                continue;
            }
            match lit_slope(&spec.photometric, p, r) {
                Some((sx, sy)) => {
                    field.gx[i] = sx as f32;
                    field.gy[i] = sy as f32;
                }
                None => field.valid[i] = false,
            }
        }
        fill_slope_holes(&mut field, spec);
        return Some(field);
    };
    let observed: Vec<[f32; 3]> = frame
        .pixels()
        .zip(reference.pixels())
        .zip(&field.valid)
        .map(|((p, r), ok)| match ok {
            true => std::array::from_fn(|c| f32::from(p[c]) - f32::from(r[c])),
            false => [0.0; 3],
        })
        .collect();
    // Pixels finer than the noise smoothing carry nothing it leaves: such a frame (R1.5's
    // 640 x 480) is read on 2 x 2 blocks, a quarter of the work.
    let half = HalfResolution::of(w, h).filter(|_| 2.0 * spec.mm_per_px <= NOISE_SMOOTHING_MM);
    let (mut field, observed, glow) = match half {
        Some(half) => (
            field.halved(&half),
            half.down(&observed),
            spec.glow.as_ref().map(GelGlow::at_half_resolution),
        ),
        None => (field, observed, spec.glow.clone()),
    };
    match &glow {
        Some(glow) => {
            let taken = read_through_glow(table, glow, spec, observed, &mut field, drift);
            field.drift = Some(taken);
        }
        None => {
            read_table(table, &observed, &mut field);
            fill_slope_holes(&mut field, spec);
        }
    }
    Some(field)
}

/// A frame's change read through a table and its glow: the marker dots' holes filled, the
/// drift removed; a first reading at half the resolution (the glow's linear part inverted,
/// the table read backwards, integrated) places the imprint, so the drift is measured again
/// away from it, and gives the indentation the glow's other terms are computed from; those
/// terms subtracted, the change is read at full resolution, with what the glow's linear part
/// leaves undetermined taken from the first reading's change.
fn read_through_glow(
    table: &ShadingTable,
    glow: &GelGlow,
    spec: &TactileSpec,
    observed: Vec<[f32; 3]>,
    field: &mut SlopeField,
    drift_given: ColourDrift,
) -> [f32; 3] {
    let (w, h) = (field.width, field.height);
    let band = outer_band(&field.valid, w, h);
    // The glow is read backwards over the whole frame, so the marker dots' holes are filled
    // from the shading round them (zeros there would read as flat gel inside a contact) and
    // read like the rest.
    let hole = hole_px(spec, field);
    let observed = fill_holes(&observed, &mut field.valid, w, h, hole);
    let first_drift = match drift_given {
        ColourDrift::Measured => drift(&observed, &band),
        ColourDrift::Given(d) => d,
    };
    let first = without_drift(&observed, &field.valid, first_drift);
    let smoothing_px = NOISE_SMOOTHING_MM / field.mm_per_px;
    let inverse = GlowInverse::shared(glow, w, h, smoothing_px);
    let first_reading = match HalfResolution::of(w, h) {
        Some(half) => FirstReading::at_half(table, glow, &half, &first, field),
        None => FirstReading::at_full(table, &inverse, &first, field),
    };
    // A large press reaches the band (a fruit's contact spans most of the frame): its
    // shading there is not drift, and taken for it the whole imprint reads shallow.
    let depth = &first_reading.indentation_mm;
    let peak = depth.iter().copied().fold(0.0f32, f32::max);
    let taken = match drift_given {
        ColourDrift::Measured => {
            let untouched: Vec<usize> = band
                .iter()
                .copied()
                .filter(|i| depth[*i] < UNTOUCHED_SHARE * peak)
                .collect();
            drift(&observed, &untouched)
        }
        ColourDrift::Given(d) => d,
    };
    let observed = without_drift(&observed, &field.valid, taken);
    let linear: Vec<[f32; 3]> = match &first_reading.rest {
        Some(rest) => observed
            .iter()
            .zip(rest)
            .map(|(o, r)| std::array::from_fn(|c| o[c] - r[c]))
            .collect(),
        None => observed,
    };
    read_table(
        table,
        &inverse.solve_toward(&linear, &first_reading.change),
        field,
    );
    take_out_tilt(field, depth, peak);
    taken
}

/// The drift is measured over gel the contact's glow and rise still reach, so round a wide
/// contact it is off by a few grey levels, which the table reads as a tilt of the whole gel:
/// a mango-like press through R1.5 read 4x deep. The gel's true ends are level along a row
/// (column) whose two ends the first reading calls untouched, whatever the contact does in
/// between, so the median of those lines' mean slope is that tilt, taken out; a contact
/// that runs off a side leaves its lines out. Fewer than a quarter of the lines: none taken.
fn take_out_tilt(field: &mut SlopeField, first_mm: &[f32], peak_mm: f32) {
    let (w, h) = (field.width, field.height);
    let untouched = |i: usize| first_mm[i] < UNTOUCHED_SHARE * peak_mm;
    let valid = &field.valid;
    let line_mean = |g: &[f32], line: &mut dyn Iterator<Item = usize>| {
        let (mut sum, mut n) = (0.0f64, 0usize);
        for i in line.filter(|i| valid[*i]) {
            sum += g[i] as f64;
            n += 1;
        }
        (n > 0).then(|| sum / n as f64)
    };
    let tilt = |mut means: Vec<f64>, lines: usize| -> f32 {
        if means.len() * 4 < lines {
            return 0.0;
        }
        let k = means.len() / 2;
        *means.select_nth_unstable_by(k, f64::total_cmp).1 as f32
    };
    let rows: Vec<f64> = (0..h)
        .filter(|y| untouched(y * w) && untouched(y * w + w - 1))
        .filter_map(|y| line_mean(&field.gx, &mut (y * w..(y + 1) * w)))
        .collect();
    let cols: Vec<f64> = (0..w)
        .filter(|x| untouched(*x) && untouched((h - 1) * w + x))
        .filter_map(|x| line_mean(&field.gy, &mut (0..h).map(|y| y * w + x)))
        .collect();
    let (tx, ty) = (tilt(rows, h), tilt(cols, w));
    for i in 0..w * h {
        if field.valid[i] {
            field.gx[i] -= tx;
            field.gy[i] -= ty;
        }
    }
}

/// The reading's first pass, on every pixel of the frame: its indentation (mm), the table's
/// change of its slopes (the prior of what the glow leaves undetermined), and the glow's
/// terms beyond the linear ones (None when the glow has none).
struct FirstReading {
    indentation_mm: Vec<f32>,
    change: Vec<[f32; 3]>,
    rest: Option<Vec<[f32; 3]>>,
}

impl FirstReading {
    /// Read on the frame's half and interpolated back.
    fn at_half(
        table: &ShadingTable,
        glow: &GelGlow,
        half: &HalfResolution,
        change: &[[f32; 3]],
        full: &SlopeField,
    ) -> Self {
        let mut field = full.halved(half);
        let inverse = GlowInverse::shared(
            &glow.at_half_resolution(),
            field.width,
            field.height,
            NOISE_SMOOTHING_MM / field.mm_per_px,
        );
        read_table(table, &inverse.solve(&half.down(change)), &mut field);
        let depth: Vec<f32> = integrate_slopes(&field)
            .into_iter()
            .map(|d| d as f32)
            .collect();
        let up = |image: &[[f32; 3]]| -> Vec<[f32; 3]> {
            let channels: [Vec<f64>; 3] =
                std::array::from_fn(|c| half.up(&image.iter().map(|r| r[c]).collect::<Vec<_>>()));
            (0..half.width * half.height)
                .map(|i| std::array::from_fn(|c| channels[c][i] as f32))
                .collect()
        };
        let change = modelled_change(table, &field);
        let rest = inverse
            .has_rest()
            .then(|| up(&inverse.rest(&change, &depth)));
        Self {
            indentation_mm: half.up(&depth).into_iter().map(|d| d as f32).collect(),
            change: up(&change),
            rest,
        }
    }

    /// Read on every pixel (a frame too small to halve); `field` keeps this reading.
    fn at_full(
        table: &ShadingTable,
        inverse: &GlowInverse,
        change: &[[f32; 3]],
        field: &mut SlopeField,
    ) -> Self {
        read_table(table, &inverse.solve(change), field);
        let depth: Vec<f32> = integrate_slopes(field)
            .into_iter()
            .map(|d| d as f32)
            .collect();
        let change = modelled_change(table, field);
        let rest = inverse.has_rest().then(|| inverse.rest(&change, &depth));
        Self {
            indentation_mm: depth,
            change,
            rest,
        }
    }
}

/// The shading change the table gives for a field's slopes.
fn modelled_change(table: &ShadingTable, field: &SlopeField) -> Vec<[f32; 3]> {
    let (w, h) = (field.width, field.height);
    (0..w * h)
        .map(|i| {
            let (u, v) = frame_position((i % w) as u32, (i / w) as u32, w as u32, h as u32);
            table.change(field.gx[i], field.gy[i], u, v)
        })
        .collect()
}

/// The camera's noise read backwards through a table is not zero-mean in slope where the
/// table is nearly flat: the R1.5 profile read a noise-only frame as a 0.1 mm imprint at the
/// frame's edge. A Gaussian of this sigma (mm on the gel) over the change first takes most of
/// the noise and leaves a contact's shading, millimetres wide, as it is.
const NOISE_SMOOTHING_MM: f64 = 0.06;

/// Where a first reading's indentation is below this share of its peak, the gel counts as
/// untouched for measuring the drift.
const UNTOUCHED_SHARE: f32 = 0.1;

/// The valid pixels of the frame's outer band (a sixteenth of its shorter side).
fn outer_band(valid: &[bool], w: usize, h: usize) -> Vec<usize> {
    let band = (w.min(h) / 16).max(2);
    (0..w * h)
        .filter(|i| {
            let (x, y) = (i % w, i / w);
            valid[*i] && (x < band || y < band || x + band >= w || y + band >= h)
        })
        .collect()
}

/// Real frames drift in colour from shot to shot far from any contact (FOTS: up to 30 grey
/// levels in blue), which the table would read as a tilt of the whole gel: the change's
/// median over untouched gel is taken as that drift; none where too little gel is untouched.
fn drift(observed: &[[f32; 3]], untouched: &[usize]) -> [f32; 3] {
    if untouched.len() < 16 {
        return [0.0; 3];
    }
    std::array::from_fn(|c| {
        let mut v: Vec<f32> = untouched.iter().map(|i| observed[*i][c]).collect();
        let k = v.len() / 2;
        *v.select_nth_unstable_by(k, f32::total_cmp).1
    })
}

/// The drift taken from the pixels that carry shading; those that carry none stay zero.
fn without_drift(observed: &[[f32; 3]], valid: &[bool], drift: [f32; 3]) -> Vec<[f32; 3]> {
    observed
        .iter()
        .zip(valid)
        .map(|(o, ok)| match ok {
            true => std::array::from_fn(|c| o[c] - drift[c]),
            false => *o,
        })
        .collect()
}

/// A marker dot's hole in the shading, as a blur's sigma (px): the dot's radius and the ring
/// of 2 px left out around it.
fn hole_px(spec: &TactileSpec, field: &SlopeField) -> f32 {
    ((spec.markers.radius_mm / field.mm_per_px) as f32 + 2.0).max(1.0)
}

/// The slopes under the marker dots (and saturated pixels), read as if flat they pull a
/// press's integrated depth short by the dots' share of the imprint (the stock Mini read a
/// steel ball 12% shallow), filled from the slopes round them as the glow's reading fills the
/// colour change.
fn fill_slope_holes(field: &mut SlopeField, spec: &TactileSpec) {
    let (w, h) = (field.width, field.height);
    let slopes: Vec<[f32; 2]> = field
        .gx
        .iter()
        .zip(&field.gy)
        .map(|(&gx, &gy)| [gx, gy])
        .collect();
    let hole = hole_px(spec, field);
    let filled = fill_holes(&slopes, &mut field.valid, w, h, hole);
    for ((gx, gy), [fx, fy]) in field.gx.iter_mut().zip(field.gy.iter_mut()).zip(filled) {
        (*gx, *gy) = (fx, fy);
    }
}

/// Pixels that carry no shading filled by normalised convolution (a Gaussian of `sigma_px`
/// over the valid pixels, divided by the same blur of the mask); they become valid where
/// enough valid pixels lie near.
fn fill_holes<const N: usize>(
    values: &[[f32; N]],
    valid: &mut [bool],
    w: usize,
    h: usize,
    sigma_px: f32,
) -> Vec<[f32; N]> {
    let kept: Vec<[f32; N]> = values
        .iter()
        .zip(valid.iter())
        .map(|(v, ok)| if *ok { *v } else { [0.0; N] })
        .collect();
    let mask: Vec<[f32; 1]> = valid.iter().map(|ok| [f32::from(u8::from(*ok))]).collect();
    let (spread, weight) = (blur(&kept, w, h, sigma_px), blur(&mask, w, h, sigma_px));
    values
        .iter()
        .zip(valid.iter_mut())
        .zip(spread.iter().zip(&weight))
        .map(|((v, ok), (b, [weight]))| {
            if *ok {
                *v
            } else if *weight > 0.05 {
                *ok = true;
                b.map(|c| c / weight)
            } else {
                [0.0; N]
            }
        })
        .collect()
}

/// A calibrated table read backwards at every valid pixel of a shading change; a pixel no
/// slope explains becomes invalid.
fn read_table(table: &ShadingTable, change: &[[f32; 3]], field: &mut SlopeField) {
    let (w, h) = (field.width, field.height);
    // Bands of rows on scoped threads of their own, not a rayon pool's: the pipeline reads a
    // press on its own thread while rayon's workers wait for it, and a job queued behind
    // them would never run. Rows are independent, so the bytes do not depend on the bands.
    let threads = std::thread::available_parallelism()
        .map_or(1, |n| n.get())
        .min(h.max(1));
    let rows_per_band = h.div_ceil(threads).max(1);
    let band = rows_per_band * w;
    std::thread::scope(|scope| {
        let bands = field
            .gx
            .chunks_mut(band)
            .zip(field.gy.chunks_mut(band))
            .zip(field.valid.chunks_mut(band))
            .zip(change.chunks(band))
            .enumerate();
        for (k, (((gx, gy), valid), change)) in bands {
            scope.spawn(move || {
                let first_row = k * rows_per_band;
                for (r, (((gx, gy), valid), change)) in gx
                    .chunks_mut(w)
                    .zip(gy.chunks_mut(w))
                    .zip(valid.chunks_mut(w))
                    .zip(change.chunks(w))
                    .enumerate()
                {
                    read_row(table, change, first_row + r, w, h, gx, gy, valid);
                }
            });
        }
    });
}

/// One row, left to right, so that a pixel's descent can start from its left neighbour's
/// slope.
#[allow(clippy::too_many_arguments)]
fn read_row(
    table: &ShadingTable,
    change: &[[f32; 3]],
    y: usize,
    w: usize,
    h: usize,
    gx: &mut [f32],
    gy: &mut [f32],
    valid: &mut [bool],
) {
    let mut near = None;
    let (_, v) = frame_position(0, y as u32, w as u32, h as u32);
    let row = table.row(v);
    for x in 0..w {
        if !valid[x] {
            near = None;
            continue;
        }
        let (u, _) = frame_position(x as u32, y as u32, w as u32, h as u32);
        let read = row.slope_for_change(change[x], u, TABLE_SLOPE_PRIOR, TABLE_MAX_RMS, near);
        (gx[x], gy[x]) = read.map_or((0.0, 0.0), |s| (s.gx, s.gy));
        valid[x] = read.is_some();
        near = read;
    }
}

fn lit_slope(
    model: &PhotometricModel,
    p: &image::Rgb<u8>,
    r: &image::Rgb<u8>,
) -> Option<(f64, f64)> {
    let gain = std::array::from_fn(|c| p[c] as f64 / (r[c] as f64).max(1.0));
    model.slope_for_gain(gain)
}

#[cfg(test)]
mod tests {
    use super::*;
    use image::Rgb;

    #[test]
    fn recovers_a_uniform_tilt() {
        let spec = TactileSpec::gelsight_mini();
        let model = spec.photometric;
        let reference = RgbImage::from_pixel(16, 12, Rgb([150, 140, 130]));
        let g = model.gain_for_slope(0.2, -0.1);
        let frame = RgbImage::from_fn(16, 12, |_, _| {
            Rgb(std::array::from_fn(|c| {
                (reference.get_pixel(0, 0)[c] as f64 * g[c]).round() as u8
            }))
        });
        let s = recover_slopes(&frame, &reference, &spec, ColourDrift::Measured).unwrap();
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

    #[test]
    fn a_dim_sensors_lit_gel_is_shading_and_its_dots_are_not() {
        // Gel at 75 grey levels a channel (a dim sensor), dots taking 60% of its light.
        let mut dim = RgbImage::from_pixel(20, 20, Rgb([80, 70, 75]));
        dim.put_pixel(5, 5, Rgb([32, 28, 30]));
        let level = dark_level(&dim);
        assert!(!is_dark(dim.get_pixel(0, 0), level));
        assert!(
            !is_dark(&Rgb([60, 55, 58]), level),
            "a shaded slope of the gel"
        );
        assert!(is_dark(dim.get_pixel(5, 5), level));
        // A bright sensor keeps the fixed level: 70 grey levels a channel.
        let bright = RgbImage::from_pixel(20, 20, Rgb([170, 160, 150]));
        assert_eq!(dark_level(&bright), 210);
    }

    #[test]
    fn a_frame_finer_than_the_noise_smoothing_is_read_on_blocks_at_their_size() {
        // A spherical cap (radius 4 mm, 0.3 mm deep) shaded through a table on a 240 x 180
        // frame of 0.025 mm pixels: read on 2 x 2 blocks of 0.05 mm, and integrated at that
        // size it gives the cap's depth.
        let table = crate::tactile::shading_table::tests::lights_table();
        let (w, h, px) = (240u32, 180u32, 0.025f64);
        let mut spec = TactileSpec::gelsight_mini();
        (spec.width_px, spec.height_px, spec.mm_per_px) = (w, h, px);
        spec.table = Some(table.clone());
        spec.glow = None;
        let (radius, depth) = (4.0f64, 0.3f64);
        let reference = RgbImage::from_pixel(w, h, Rgb([140, 140, 140]));
        let frame = RgbImage::from_fn(w, h, |x, y| {
            let (dx, dy) = (
                (x as f64 + 0.5 - w as f64 / 2.0) * px,
                (y as f64 + 0.5 - h as f64 / 2.0) * px,
            );
            let r2 = dx * dx + dy * dy;
            // Slopes of the indentation depth - r^2 / 2R inside the contact, flat outside.
            let (gx, gy) = match r2 < 2.0 * radius * depth {
                true => (-dx / radius, -dy / radius),
                false => (0.0, 0.0),
            };
            let (u, v) = frame_position(x, y, w, h);
            let change = table.change(gx as f32, gy as f32, u, v);
            Rgb(change.map(|c| (140.0 + c).round().clamp(0.0, 255.0) as u8))
        });
        let field =
            recover_slopes(&frame, &reference, &spec, ColourDrift::Measured).expect("same sizes");
        assert_eq!((field.width, field.height), (120, 90));
        assert_eq!(field.mm_per_px, 2.0 * px);
        let read = integrate_slopes(&field);
        let peak = read.iter().copied().fold(0.0f64, f64::max);
        assert!(
            (peak / depth - 1.0).abs() < 0.1,
            "peak {peak} mm for {depth}"
        );
    }

    /// A dome's slopes (peak 1 mm, radius `r` px, centre `cx`) with `tilt` added to every gx.
    fn dome(w: usize, h: usize, cx: f64, r: f64, tilt: f32) -> (SlopeField, Vec<f32>) {
        let mut field = SlopeField {
            width: w,
            height: h,
            mm_per_px: 0.1,
            gx: vec![tilt; w * h],
            gy: vec![0.0; w * h],
            valid: vec![true; w * h],
            drift: None,
        };
        let mut depth = vec![0.0f32; w * h];
        let cy = h as f64 / 2.0;
        for y in 0..h {
            for x in 0..w {
                let (dx, dy) = (x as f64 - cx, y as f64 - cy);
                let q = 1.0 - (dx * dx + dy * dy) / (r * r);
                if q > 0.0 {
                    let i = y * w + x;
                    depth[i] = q as f32;
                    // d/dx of 1 - (dx^2 + dy^2) / r^2, per mm.
                    field.gx[i] += (-2.0 * dx / (r * r) / 0.1) as f32;
                    field.gy[i] = (-2.0 * dy / (r * r) / 0.1) as f32;
                }
            }
        }
        (field, depth)
    }

    #[test]
    fn a_tilt_of_the_whole_gel_is_taken_out_and_a_contact_off_the_side_is_left_as_it_is() {
        // A contact inside the frame, the whole gel tilted by 0.05: the tilt goes, the
        // contact's own slopes stay.
        let (mut field, depth) = dome(64, 48, 32.0, 18.0, 0.05);
        let (before_x, before_y) = (field.gx.clone(), field.gy.clone());
        take_out_tilt(&mut field, &depth, 1.0);
        for i in 0..64 * 48 {
            assert!((field.gx[i] - (before_x[i] - 0.05)).abs() < 2e-3, "{i}");
            assert!((field.gy[i] - before_y[i]).abs() < 2e-3, "{i}");
        }
        // A contact running off the right side, the gel level: its rows are left out, the
        // rows above and below it are level, so nothing is taken out.
        let (mut field, depth) = dome(64, 48, 58.0, 14.0, 0.0);
        let before = field.gx.clone();
        take_out_tilt(&mut field, &depth, 1.0);
        assert_eq!(field.gx, before);
        // Lines with untouched ends too few to measure on: nothing is taken out.
        let (mut field, depth) = dome(64, 48, 32.0, 60.0, 0.05);
        let before = field.gx.clone();
        take_out_tilt(&mut field, &depth, 1.0);
        assert_eq!(field.gx, before);
    }
}
