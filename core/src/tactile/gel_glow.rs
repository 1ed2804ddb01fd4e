//! Light scattered in the gel: real GelSight frames show a coloured glow spreading round a
//! contact, wider than the gel's slopes reach, and a contact's inside darker than its slopes
//! shade (the object seen through the thinned gel). The glow is a sum of Gaussian blurs of
//! the shading's colour change (each mixed across channels), of its magnitude, of the gel's
//! indentation and of the change weighted by the indentation, fitted by least squares to
//! real presses in `tactex calibrate` and applied by both renderers.

use crate::scoped_map::map_on_cores;
use crate::tactile::separable::separable_blur;
use serde::{Deserialize, Serialize};

/// The largest blur a profile may ask for (pixels, 1 sigma): bounds the work per frame.
pub const MAX_SIGMA_PX: f32 = 128.0;
/// The most terms a profile may list.
pub const MAX_TERMS: usize = 16;

/// The glow model: the rendered change is replaced by the sum of its terms.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GelGlow {
    /// Blurs of the colour change, mixed across channels.
    #[serde(default)]
    pub colour: Vec<ColourGlow>,
    /// Blurs of the change's magnitude (grey levels), each adding a colour.
    #[serde(default)]
    pub magnitude: Vec<ScalarGlow>,
    /// Blurs of the gel's indentation (mm), each adding a colour.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub indentation: Vec<ScalarGlow>,
    /// Blurs of the colour change times the indentation (grey levels x mm), mixed across
    /// channels: how the change itself differs where the gel is pressed in.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub indented_colour: Vec<ColourGlow>,
}

#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ColourGlow {
    /// Blur (pixels, 1 sigma; 0: none).
    pub sigma_px: f32,
    /// Output channel c gains `mix[c][k]` times the blurred source's channel k.
    #[serde(deserialize_with = "crate::serde_exact::matrix")]
    pub mix: [[f32; 3]; 3],
}

/// A blurred one-channel source adding a colour.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ScalarGlow {
    pub sigma_px: f32,
    /// Grey levels added per channel per unit of the blurred source.
    #[serde(deserialize_with = "crate::serde_exact::array")]
    pub colour: [f32; 3],
}

/// What a term blurs: per pixel, from the shading's change and the gel's indentation.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GlowSource {
    /// The colour change (grey levels).
    Change,
    /// Its magnitude, in channel 0.
    Magnitude,
    /// The gel's indentation (mm), in channel 0.
    Indentation,
    /// The colour change times the indentation.
    IndentedChange,
}

impl GlowSource {
    /// The value the renderers blur at one pixel.
    pub fn at(self, change: [f32; 3], indentation_mm: f32) -> [f32; 3] {
        match self {
            GlowSource::Change => change,
            GlowSource::Magnitude => [
                (change[0] * change[0] + change[1] * change[1] + change[2] * change[2]).sqrt(),
                0.0,
                0.0,
            ],
            GlowSource::Indentation => [indentation_mm, 0.0, 0.0],
            GlowSource::IndentedChange => change.map(|v| v * indentation_mm),
        }
    }

    /// How many of the source's channels carry it.
    fn channels(self) -> usize {
        match self {
            GlowSource::Change | GlowSource::IndentedChange => 3,
            GlowSource::Magnitude | GlowSource::Indentation => 1,
        }
    }

    /// Its number in the shaders' `GlowTerm.source`.
    pub fn code(self) -> u32 {
        match self {
            GlowSource::Change => 0,
            GlowSource::Magnitude => 1,
            GlowSource::Indentation => 2,
            GlowSource::IndentedChange => 3,
        }
    }
}

/// One term as the renderers run it: a source, its blur, and a 3x3 mix into the output.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GlowTerm {
    pub source: GlowSource,
    pub sigma_px: f32,
    pub mix: [[f32; 3]; 3],
}

/// The blurs of a glow to fit, per source (pixels).
#[derive(Clone, Copy, Debug)]
pub struct GlowDesign<'a> {
    pub colour: &'a [f32],
    pub magnitude: &'a [f32],
    pub indentation: &'a [f32],
    pub indented_colour: &'a [f32],
}

/// One press a glow is fitted to: the rendered change without glow, the gel's indentation
/// (mm), the real change (the real frame minus the rendered no-contact frame), and the
/// pixel box `[x0, y0, x1, y1)` to fit over.
pub struct GlowPress<'a> {
    pub change: &'a [[f32; 3]],
    pub indentation_mm: &'a [f32],
    pub target: &'a [[f32; 3]],
    pub window: [u32; 4],
}

#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum GlowError {
    #[error("{field}: {message}")]
    Invalid { field: String, message: String },
    #[error("no pixels to fit the glow to")]
    NoPixels,
    #[error("the glow's least-squares system is singular")]
    Singular,
}

/// A normalised Gaussian over `-r..=r`, r = ceil(3 sigma); one tap of 1 for sigma 0.
pub fn gaussian_kernel(sigma_px: f32) -> Vec<f32> {
    if sigma_px <= 0.0 {
        return vec![1.0];
    }
    let r = (3.0 * sigma_px).ceil() as i32;
    let raw: Vec<f64> = (-r..=r)
        .map(|i| (-(i * i) as f64 / (2.0 * (sigma_px as f64).powi(2))).exp())
        .collect();
    let sum: f64 = raw.iter().sum();
    raw.iter().map(|v| (v / sum) as f32).collect()
}

/// The block size (px) a blur of `sigma_px` averages its source over before it blurs: 1 (every
/// pixel) below 8 px, else a quarter of sigma. A wide Gaussian changes little across a
/// quarter of its sigma, so the source is averaged over such blocks, blurred on the grid of
/// blocks by the Gaussian that, with the block's own spread, makes sigma, and interpolated
/// back: the work per pixel no longer grows with sigma, and the result stays within 0.2% of
/// the source's range of every pixel's taps even at a sharp edge (the tests).
pub fn blur_factor(sigma_px: f32) -> usize {
    ((sigma_px / 4.0) as usize).max(1)
}

/// The kernel a blur of `sigma_px` sums on its grid of blocks (`blur_factor`): a Gaussian of
/// sigma's variance less a block's, in blocks.
pub fn blur_kernel(sigma_px: f32) -> Vec<f32> {
    let d = blur_factor(sigma_px);
    if d == 1 {
        return gaussian_kernel(sigma_px);
    }
    let d = d as f64;
    let variance = f64::from(sigma_px).powi(2) - (d * d - 1.0) / 12.0;
    gaussian_kernel((variance.sqrt() / d) as f32)
}

/// The blocks of size `d` along an axis of `len` pixels: one outside each end (the edge
/// extended) and those covering the axis, the last perhaps partial.
fn block_count(len: usize, d: usize) -> usize {
    len.div_ceil(d) + 2
}

/// For each pixel along an axis of `len` pixels, the two blocks of size `d` (of `blocks`)
/// whose centres lie either side of it and the weight of the second. The numerator and
/// denominator are whole numbers, so every renderer gets the same weight.
fn between_blocks(len: usize, d: usize, blocks: usize) -> Vec<(usize, usize, f32)> {
    (0..len)
        .map(|p| {
            // Block i covers pixels (i - 1) d .. i d - 1, centred at (i - 1) d + (d - 1) / 2:
            // in half pixels, 2 p + 1 + d from block 0's centre.
            let from_first = 2 * p as i64 + 1 + d as i64;
            let i = (from_first / (2 * d as i64)) as usize;
            if i + 1 >= blocks {
                return (blocks - 1, blocks - 1, 0.0);
            }
            let t = (from_first - 2 * (d * i) as i64) as f32 / (2 * d) as f32;
            (i, i + 1, t)
        })
        .collect()
}

/// The mean of each `d` x `d` block of `block_count`'s grid (edges extended) of the
/// `width` x `height` source whose pixel i is `at(i)`, each block's pixels summed row by row.
fn block_means<const N: usize>(
    at: impl Fn(usize) -> [f32; N],
    width: usize,
    height: usize,
    d: usize,
) -> Vec<[f32; N]> {
    let (cw, ch) = (block_count(width, d), block_count(height, d));
    let area = (d * d) as f32;
    let inside = |i: usize, len: usize| (i.saturating_sub(d)).min(len - 1);
    let mut out = vec![[0.0f32; N]; cw * ch];
    for (by, row_out) in out.chunks_exact_mut(cw).enumerate() {
        for dy in 0..d {
            let row = inside(by * d + dy, height) * width;
            for (bx, o) in row_out.iter_mut().enumerate() {
                for dx in 0..d {
                    let v = at(row + inside(bx * d + dx, width));
                    for c in 0..N {
                        o[c] += v[c];
                    }
                }
            }
        }
        for o in row_out.iter_mut() {
            for v in o.iter_mut() {
                *v /= area;
            }
        }
    }
    out
}

/// A separable Gaussian blur of an image of N channels, edges extended. Below 8 px at every
/// pixel; wider, on the means of `blur_factor`-sized blocks with `blur_kernel`, then
/// interpolated bilinearly back to every pixel (as the GPU's glow stages do).
pub fn blur<const N: usize>(
    src: &[[f32; N]],
    width: usize,
    height: usize,
    sigma_px: f32,
) -> Vec<[f32; N]> {
    let rows = BlurRows::of(|i| src[i], width, height, sigma_px);
    let mut out = Vec::with_capacity(src.len());
    let mut scratch = vec![[0.0f32; N]; width];
    for y in 0..height {
        out.extend_from_slice(rows.row(y, &mut scratch));
    }
    out
}

/// A blur's result, row by row: a whole frame (a blur at every pixel), or a wide blur's
/// block rows already interpolated across, each pixel row made between its two when asked.
/// A caller that sums blurs row by row so never holds a frame per wide blur.
enum BlurRows<const N: usize> {
    Frame {
        values: Vec<[f32; N]>,
        width: usize,
    },
    Blocks {
        across: Vec<[f32; N]>,
        down: Vec<(usize, usize, f32)>,
        width: usize,
    },
}

impl<const N: usize> BlurRows<N> {
    /// The blur of the `width` x `height` source whose pixel i is `at(i)`.
    fn of(at: impl Fn(usize) -> [f32; N], width: usize, height: usize, sigma_px: f32) -> Self {
        let k = blur_kernel(sigma_px);
        let d = blur_factor(sigma_px);
        if k.len() == 1 || d == 1 || width == 0 || height == 0 {
            let src: Vec<[f32; N]> = (0..width * height).map(at).collect();
            let values = if k.len() == 1 || src.is_empty() {
                src
            } else {
                separable_blur(&src, width, height, &k)
            };
            return Self::Frame { values, width };
        }
        let (cw, ch) = (block_count(width, d), block_count(height, d));
        let coarse = separable_blur(&block_means(at, width, height, d), cw, ch, &k);
        // Each block row across to every column; the pixel rows between them come in `row`.
        let between = between_blocks(width, d, cw);
        let mut across = vec![[0.0f32; N]; width * ch];
        for (a, row_out) in coarse.chunks_exact(cw).zip(across.chunks_exact_mut(width)) {
            for (o, &(x0, x1, tx)) in row_out.iter_mut().zip(&between) {
                for c in 0..N {
                    o[c] = a[x0][c] * (1.0 - tx) + a[x1][c] * tx;
                }
            }
        }
        Self::Blocks {
            across,
            down: between_blocks(height, d, ch),
            width,
        }
    }

    /// Row `y` of the blur; a wide blur's is made in `scratch` (a row long).
    fn row<'a>(&'a self, y: usize, scratch: &'a mut [[f32; N]]) -> &'a [[f32; N]] {
        match self {
            Self::Frame { values, width } => &values[y * width..][..*width],
            Self::Blocks {
                across,
                down,
                width,
            } => {
                let (y0, y1, ty) = down[y];
                let top = across[y0 * width..][..*width].as_flattened();
                let bottom = across[y1 * width..][..*width].as_flattened();
                for ((o, t), b) in scratch.as_flattened_mut().iter_mut().zip(top).zip(bottom) {
                    *o = t * (1.0 - ty) + b * ty;
                }
                scratch
            }
        }
    }
}

/// A term's source over a whole frame, blurred: a one-channel source alone (a third of the
/// work, and no frame of zeros to mix), the others in all three channels; an unblurred
/// source is read where it is mixed.
enum BlurredSource {
    Unblurred,
    One(BlurRows<1>),
    Three(BlurRows<3>),
}

fn blur_source(
    term: &GlowTerm,
    change: &[[f32; 3]],
    indentation_mm: &[f32],
    width: usize,
    height: usize,
) -> BlurredSource {
    let at = |i: usize| term.source.at(change[i], indentation_mm[i]);
    if blur_kernel(term.sigma_px).len() == 1 {
        BlurredSource::Unblurred
    } else if term.source.channels() == 1 {
        BlurredSource::One(BlurRows::of(|i| [at(i)[0]], width, height, term.sigma_px))
    } else {
        BlurredSource::Three(BlurRows::of(at, width, height, term.sigma_px))
    }
}

/// The term's blurred source in channel 0 of three, the others zero, as the shaders hold it.
fn blurred_source(
    term: &GlowTerm,
    change: &[[f32; 3]],
    indentation_mm: &[f32],
    width: usize,
    height: usize,
) -> Vec<[f32; 3]> {
    let at = |i: usize| term.source.at(change[i], indentation_mm[i]);
    if term.source.channels() == 1 {
        let src: Vec<[f32; 1]> = (0..change.len()).map(|i| [at(i)[0]]).collect();
        blur(&src, width, height, term.sigma_px)
            .into_iter()
            .map(|[v]| [v, 0.0, 0.0])
            .collect()
    } else {
        let src: Vec<[f32; 3]> = (0..change.len()).map(at).collect();
        blur(&src, width, height, term.sigma_px)
    }
}

impl GelGlow {
    /// A glow with the design's blurs, its weights taken in `terms()` order from `next`, one
    /// call per source channel (a column of the mix; a scalar term's colour).
    fn from_design(design: &GlowDesign, next: &mut dyn FnMut() -> [f32; 3]) -> Self {
        fn colour(sigmas: &[f32], next: &mut dyn FnMut() -> [f32; 3]) -> Vec<ColourGlow> {
            sigmas
                .iter()
                .map(|&sigma_px| {
                    let columns = [next(), next(), next()];
                    ColourGlow {
                        sigma_px,
                        mix: std::array::from_fn(|c| std::array::from_fn(|k| columns[k][c])),
                    }
                })
                .collect()
        }
        fn scalar(sigmas: &[f32], next: &mut dyn FnMut() -> [f32; 3]) -> Vec<ScalarGlow> {
            sigmas
                .iter()
                .map(|&sigma_px| ScalarGlow {
                    sigma_px,
                    colour: next(),
                })
                .collect()
        }
        // Fields in `terms()` order: the unknowns are taken in that order.
        let colour_terms = colour(design.colour, next);
        let magnitude = scalar(design.magnitude, next);
        let indentation = scalar(design.indentation, next);
        let indented_colour = colour(design.indented_colour, next);
        GelGlow {
            colour: colour_terms,
            magnitude,
            indentation,
            indented_colour,
        }
    }

    /// Its terms in the order the renderers sum them: colour, magnitude, indentation, then
    /// indented colour terms.
    pub fn terms(&self) -> Vec<GlowTerm> {
        let colour = |source, terms: &[ColourGlow]| -> Vec<GlowTerm> {
            terms
                .iter()
                .map(|t| GlowTerm {
                    source,
                    sigma_px: t.sigma_px,
                    mix: t.mix,
                })
                .collect()
        };
        let scalar = |source, terms: &[ScalarGlow]| -> Vec<GlowTerm> {
            terms
                .iter()
                .map(|t| GlowTerm {
                    source,
                    sigma_px: t.sigma_px,
                    mix: t.colour.map(|v| [v, 0.0, 0.0]),
                })
                .collect()
        };
        [
            colour(GlowSource::Change, &self.colour),
            scalar(GlowSource::Magnitude, &self.magnitude),
            scalar(GlowSource::Indentation, &self.indentation),
            colour(GlowSource::IndentedChange, &self.indented_colour),
        ]
        .concat()
    }

    /// The same glow on a frame of half the resolution: every blur half as wide in pixels.
    pub fn at_half_resolution(&self) -> GelGlow {
        let colour = |t: &ColourGlow| ColourGlow {
            sigma_px: 0.5 * t.sigma_px,
            ..*t
        };
        let scalar = |t: &ScalarGlow| ScalarGlow {
            sigma_px: 0.5 * t.sigma_px,
            ..*t
        };
        GelGlow {
            colour: self.colour.iter().map(colour).collect(),
            magnitude: self.magnitude.iter().map(scalar).collect(),
            indentation: self.indentation.iter().map(scalar).collect(),
            indented_colour: self.indented_colour.iter().map(colour).collect(),
        }
    }

    /// Checks every term; Err is the field (`glow`, `glow.colour[0].sigma_px`) and what is
    /// wrong with it.
    pub fn validate(&self) -> Result<(), (String, String)> {
        let count = self.terms().len();
        if count == 0 || count > MAX_TERMS {
            return Err((
                "glow".into(),
                format!("{count} terms, expected 1..={MAX_TERMS}"),
            ));
        }
        let sigma_ok = |s: f32| s.is_finite() && (0.0..=MAX_SIGMA_PX).contains(&s);
        let weight_ok = |v: &f32| v.is_finite() && v.abs() <= 100.0;
        let check = |list: &str, i: usize, sigma: f32, weights: &[f32], what: &str| {
            if !sigma_ok(sigma) {
                return Err((
                    format!("glow.{list}[{i}].sigma_px"),
                    format!("{sigma}, expected 0..={MAX_SIGMA_PX} px"),
                ));
            }
            if !weights.iter().all(weight_ok) {
                return Err((
                    format!("glow.{list}[{i}].{what}"),
                    "weights must be finite and within +-100".into(),
                ));
            }
            Ok(())
        };
        for (list, terms) in [
            ("colour", &self.colour),
            ("indented_colour", &self.indented_colour),
        ] {
            for (i, t) in terms.iter().enumerate() {
                check(list, i, t.sigma_px, t.mix.as_flattened(), "mix")?;
            }
        }
        for (list, terms) in [
            ("magnitude", &self.magnitude),
            ("indentation", &self.indentation),
        ] {
            for (i, t) in terms.iter().enumerate() {
                check(list, i, t.sigma_px, &t.colour, "colour")?;
            }
        }
        Ok(())
    }

    /// The glowing change of a frame's change and the gel's indentation (mm; both row-major,
    /// width x height).
    pub fn apply(
        &self,
        change: &[[f32; 3]],
        indentation_mm: &[f32],
        width: usize,
        height: usize,
    ) -> Vec<[f32; 3]> {
        let terms = self.terms();
        // The blurs are independent: made on the cores, then summed in the terms' order
        // row by row, the rows shared out over the cores.
        let blurred = map_on_cores(&terms, |term| {
            blur_source(term, change, indentation_mm, width, height)
        });
        if width == 0 {
            return Vec::new();
        }
        let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
        let band = height.div_ceil(cores).max(1);
        let bands: Vec<usize> = (0..height).step_by(band).collect();
        let mixed = map_on_cores(&bands, |&y0| {
            let rows = y0..(y0 + band).min(height);
            let mut out = vec![[0.0f32; 3]; rows.len() * width];
            let (mut one, mut three) = (vec![[0.0f32; 1]; width], vec![[0.0f32; 3]; width]);
            for (y, out_row) in rows.zip(out.chunks_exact_mut(width)) {
                for (term, blurred) in terms.iter().zip(&blurred) {
                    // The shaders' sum with the zero channels left out: the same bits.
                    let mix_one = |o: &mut [f32; 3], v: f32| {
                        for (c, row) in term.mix.iter().enumerate() {
                            o[c] += row[0] * v;
                        }
                    };
                    let mix_three = |o: &mut [f32; 3], b: [f32; 3]| {
                        for (c, row) in term.mix.iter().enumerate() {
                            o[c] += row[0] * b[0] + row[1] * b[1] + row[2] * b[2];
                        }
                    };
                    match blurred {
                        BlurredSource::Unblurred => {
                            for (x, o) in out_row.iter_mut().enumerate() {
                                let i = y * width + x;
                                let v = term.source.at(change[i], indentation_mm[i]);
                                if term.source.channels() == 1 {
                                    mix_one(o, v[0]);
                                } else {
                                    mix_three(o, v);
                                }
                            }
                        }
                        BlurredSource::One(b) => {
                            for (o, [v]) in out_row.iter_mut().zip(b.row(y, &mut one)) {
                                mix_one(o, *v);
                            }
                        }
                        BlurredSource::Three(b) => {
                            for (o, v) in out_row.iter_mut().zip(b.row(y, &mut three)) {
                                mix_three(o, *v);
                            }
                        }
                    }
                }
            }
            out
        });
        mixed.concat()
    }

    /// The glow with the design's blurs that best maps the rendered changes onto the real
    /// ones inside the presses' windows (least squares, with a light ridge towards no glow).
    pub fn fit(
        presses: &[GlowPress],
        width: usize,
        height: usize,
        design: &GlowDesign,
    ) -> Result<Self, GlowError> {
        let terms = Self::from_design(design, &mut || [0.0; 3]).terms();
        let n: usize = terms.iter().map(|t| t.source.channels()).sum();
        let mut normal = vec![0.0f64; n * n];
        let mut rhs = vec![[0.0f64; 3]; n];
        let mut pixels = 0usize;
        let mut row = vec![0.0f64; n];
        for press in presses {
            let features: Vec<(usize, Vec<[f32; 3]>)> = terms
                .iter()
                .map(|t| {
                    let b = blurred_source(t, press.change, press.indentation_mm, width, height);
                    (t.source.channels(), b)
                })
                .collect();
            let [x0, y0, x1, y1] = press.window;
            for y in y0 as usize..(y1 as usize).min(height) {
                for x in x0 as usize..(x1 as usize).min(width) {
                    let p = y * width + x;
                    let mut k = 0;
                    for (channels, f) in &features {
                        for &v in &f[p][..*channels] {
                            row[k] = f64::from(v);
                            k += 1;
                        }
                    }
                    let target = press.target[p].map(f64::from);
                    for (i, (ri, rhs_i)) in row.iter().zip(rhs.iter_mut()).enumerate() {
                        for (nij, rj) in normal[i * n..][..=i].iter_mut().zip(&row) {
                            *nij += ri * rj;
                        }
                        for (r, t) in rhs_i.iter_mut().zip(target) {
                            *r += ri * t;
                        }
                    }
                    pixels += 1;
                }
            }
        }
        if pixels == 0 {
            return Err(GlowError::NoPixels);
        }
        for i in 0..n {
            for j in 0..i {
                normal[j * n + i] = normal[i * n + j];
            }
        }
        // A ridge scaled to each unknown's own data keeps terms the presses cannot tell
        // apart small, whatever their units (grey levels, mm).
        for i in 0..n {
            normal[i * n + i] = normal[i * n + i] * (1.0 + 1e-6) + 1e-12;
        }
        let x = crate::tactile::shading_table::solve_spd(&mut normal, n, &rhs)
            .ok_or(GlowError::Singular)?;
        let mut unknowns = x.iter().map(|v| v.map(|w| w as f32));
        let glow = Self::from_design(design, &mut || {
            unknowns.next().expect("one unknown per source channel")
        });
        glow.validate()
            .map_err(|(field, message)| GlowError::Invalid { field, message })?;
        Ok(glow)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn spot(w: usize, h: usize) -> Vec<[f32; 3]> {
        (0..w * h)
            .map(|p| {
                let (x, y) = ((p % w) as f32 - 20.0, (p / w) as f32 - 15.0);
                let d = (-(x * x + y * y) / 18.0).exp();
                [30.0 * d, -10.0 * d, 5.0 * x.signum() * d]
            })
            .collect()
    }

    #[test]
    fn the_kernel_is_normalised_and_three_sigma_wide() {
        let k = gaussian_kernel(2.5);
        assert_eq!(k.len(), 2 * 8 + 1);
        assert!((k.iter().sum::<f32>() - 1.0).abs() < 1e-6);
        assert_eq!(gaussian_kernel(0.0), vec![1.0]);
    }

    #[test]
    fn a_blur_keeps_a_constant_image_and_the_sum_away_from_edges() {
        let (w, h) = (40, 30);
        let flat = vec![[7.0f32, -3.0, 0.5]; w * h];
        for v in blur(&flat, w, h, 3.0) {
            for c in 0..3 {
                assert!((v[c] - flat[0][c]).abs() < 1e-4, "{v:?}");
            }
        }
        // A blurred spot in the middle keeps its integral (the kernel is normalised) and
        // spreads: its peak drops.
        let s = spot(w, h);
        let b = blur(&s, w, h, 2.0);
        let total = |img: &[[f32; 3]]| img.iter().map(|v| v[0] as f64).sum::<f64>();
        assert!((total(&s) - total(&b)).abs() < 1e-3 * total(&s));
        let peak = |img: &[[f32; 3]]| img.iter().map(|v| v[0]).fold(0.0f32, f32::max);
        assert!(peak(&b) < 0.8 * peak(&s));
    }

    /// The blur every pixel sums its taps for, as `blur` did before it sampled large blurs.
    fn direct_blur(src: &[f32], w: usize, h: usize, sigma: f32) -> Vec<f32> {
        let k = gaussian_kernel(sigma);
        let r = k.len() as i64 / 2;
        let along = |get: &dyn Fn(i64) -> f32| -> f32 {
            k.iter()
                .enumerate()
                .map(|(i, w)| w * get(i as i64 - r))
                .sum()
        };
        let at = |x: i64, y: i64| src[y as usize * w + x as usize];
        let clamp = |v: i64, n: usize| v.clamp(0, n as i64 - 1);
        let rows: Vec<f32> = (0..w * h)
            .map(|p| {
                let (x, y) = ((p % w) as i64, (p / w) as i64);
                along(&|d| at(clamp(x + d, w), y))
            })
            .collect();
        (0..w * h)
            .map(|p| {
                let (x, y) = ((p % w) as i64, (p / w) as i64);
                along(&|d| rows[clamp(y + d, h) as usize * w + x as usize])
            })
            .collect()
    }

    #[test]
    fn a_wide_blur_on_blocks_is_within_a_fifth_of_a_percent_of_every_pixels_taps() {
        // A sharp edge and a narrow spot are the hardest sources for the blocks and the
        // interpolation; the sizes are no multiple of any block, so the last ones are partial.
        let (w, h) = (97, 131);
        let src: Vec<f32> = (0..w * h)
            .map(|p| {
                let (x, y) = ((p % w) as f32, (p / w) as f32);
                let edge = if x + 0.3 * y > 60.0 { 100.0 } else { 0.0 };
                let spot = 100.0 * (-((x - 30.0).powi(2) + (y - 90.0).powi(2)) / 8.0).exp();
                edge + spot
            })
            .collect();
        let range = 200.0f32;
        for sigma in [8.0f32, 9.0, 13.5, 16.0, 27.0, 50.0, 81.0] {
            assert!(blur_factor(sigma) > 1);
            let fast: Vec<f32> = blur(&src.iter().map(|&v| [v]).collect::<Vec<_>>(), w, h, sigma)
                .into_iter()
                .map(|[v]| v)
                .collect();
            let slow = direct_blur(&src, w, h, sigma);
            let worst = fast
                .iter()
                .zip(&slow)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0f32, f32::max);
            assert!(worst < 0.002 * range, "sigma {sigma}: {worst}");
        }
    }

    #[test]
    fn each_pixel_lies_between_the_centres_of_its_two_blocks() {
        // Blocks of 4 over 10 pixels: centres at -2.5 (outside), 1.5, 5.5, 9.5 (the last
        // block partial) and 13.5 (outside).
        assert_eq!(block_count(10, 4), 5);
        let b = between_blocks(10, 4, 5);
        assert_eq!(b[0], (0, 1, 0.625));
        assert_eq!(b[1], (0, 1, 0.875));
        assert_eq!(b[2], (1, 2, 0.125));
        assert_eq!(b[5], (1, 2, 0.875));
        assert_eq!(b[6], (2, 3, 0.125));
        assert_eq!(b[9], (2, 3, 0.875));
        assert_eq!(blur_factor(7.9), 1);
        assert_eq!(blur_factor(81.0), 20);
    }

    #[test]
    fn a_one_channel_blur_is_channel_zero_of_the_three_channel_blur_bit_for_bit() {
        let (w, h) = (40, 30);
        let s = spot(w, h);
        let three: Vec<[f32; 3]> = s.iter().map(|v| [v[0], 0.0, 0.0]).collect();
        let one: Vec<[f32; 1]> = s.iter().map(|v| [v[0]]).collect();
        for sigma in [0.0, 1.5, 9.0, 30.0] {
            let (a, b) = (blur(&three, w, h, sigma), blur(&one, w, h, sigma));
            assert!(
                a.iter()
                    .zip(&b)
                    .all(|(a, b)| a[0].to_bits() == b[0].to_bits())
            );
        }
    }

    /// A ball's imprint: 0.4 mm deep at the middle of the spot.
    fn dent(w: usize, h: usize) -> Vec<f32> {
        (0..w * h)
            .map(|p| {
                let (x, y) = ((p % w) as f32 - 20.0, (p / w) as f32 - 15.0);
                (0.4 - 0.01 * (x * x + y * y)).max(0.0)
            })
            .collect()
    }

    #[test]
    fn a_fit_recovers_the_glow_that_made_the_target() {
        let (w, h) = (40, 30);
        let (change, dent) = (spot(w, h), dent(w, h));
        let truth = GelGlow {
            colour: vec![
                ColourGlow {
                    sigma_px: 0.0,
                    mix: [[0.8, 0.0, 0.1], [0.0, 0.9, 0.0], [0.05, 0.0, 1.0]],
                },
                ColourGlow {
                    sigma_px: 4.0,
                    mix: [[0.4, 0.1, 0.0], [0.0, 0.3, 0.0], [0.0, 0.0, 0.5]],
                },
            ],
            magnitude: vec![ScalarGlow {
                sigma_px: 6.0,
                colour: [0.2, 0.1, -0.1],
            }],
            indentation: vec![ScalarGlow {
                sigma_px: 0.0,
                colour: [-20.0, -8.0, -6.0],
            }],
            indented_colour: vec![ColourGlow {
                sigma_px: 0.0,
                mix: [[0.5, 0.0, 0.0], [0.0, -0.3, 0.1], [0.0, 0.0, 0.2]],
            }],
        };
        let target = truth.apply(&change, &dent, w, h);
        let fitted = GelGlow::fit(
            &[GlowPress {
                change: &change,
                indentation_mm: &dent,
                target: &target,
                window: [0, 0, w as u32, h as u32],
            }],
            w,
            h,
            &GlowDesign {
                colour: &[0.0, 4.0],
                magnitude: &[6.0],
                indentation: &[0.0],
                indented_colour: &[0.0],
            },
        )
        .unwrap();
        let again = fitted.apply(&change, &dent, w, h);
        let worst = again
            .iter()
            .zip(&target)
            .flat_map(|(a, b)| (0..3).map(move |c| (a[c] - b[c]).abs()))
            .fold(0.0f32, f32::max);
        assert!(worst < 0.05, "worst residual {worst} grey levels");
        let colour = fitted.indentation[0].colour;
        assert!(
            (colour[0] + 20.0).abs() < 0.5,
            "indentation colour {colour:?}"
        );
    }

    #[test]
    fn the_indentation_darkens_only_where_the_gel_is_pressed_in() {
        let (w, h) = (40, 30);
        let glow = GelGlow {
            colour: vec![],
            magnitude: vec![],
            indentation: vec![ScalarGlow {
                sigma_px: 0.0,
                colour: [-20.0, -8.0, -6.0],
            }],
            indented_colour: vec![],
        };
        let out = glow.apply(&vec![[0.0; 3]; w * h], &dent(w, h), w, h);
        assert_eq!(out[0], [0.0; 3], "the corner is not pressed in");
        let middle = out[15 * w + 20];
        assert!((middle[0] + 8.0).abs() < 1e-4, "{middle:?}");
    }

    #[test]
    fn bad_terms_are_named() {
        let mut g = GelGlow {
            colour: vec![ColourGlow {
                sigma_px: 1.0,
                mix: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
            }],
            magnitude: vec![],
            indentation: vec![],
            indented_colour: vec![],
        };
        assert!(g.validate().is_ok());
        g.colour[0].sigma_px = f32::NAN;
        assert_eq!(g.validate().unwrap_err().0, "glow.colour[0].sigma_px");
        g.colour[0].sigma_px = 1.0;
        g.colour[0].mix[1][2] = f32::INFINITY;
        assert_eq!(g.validate().unwrap_err().0, "glow.colour[0].mix");
        g.colour[0].mix[1][2] = 0.0;
        g.indentation.push(ScalarGlow {
            sigma_px: 0.0,
            colour: [-300.0, 0.0, 0.0],
        });
        assert_eq!(g.validate().unwrap_err().0, "glow.indentation[0].colour");
        g.indentation.clear();
        g.colour.clear();
        assert_eq!(g.validate().unwrap_err().0, "glow");
    }
}
