//! Light scattered in the gel: real GelSight frames show a coloured glow spreading round a
//! contact, wider than the gel's slopes reach. The glow is a sum of Gaussian blurs of the
//! shading's colour change (each mixed across channels) and of its magnitude, fitted by
//! least squares to real presses in `tactex calibrate` and applied by both renderers.

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
    /// Blurs of the change's magnitude, each adding a colour.
    #[serde(default)]
    pub magnitude: Vec<MagnitudeGlow>,
}

#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ColourGlow {
    /// Blur (pixels, 1 sigma; 0: none).
    pub sigma_px: f32,
    /// Output channel c gains `mix[c][k]` times the blurred change of channel k.
    pub mix: [[f32; 3]; 3],
}

#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MagnitudeGlow {
    pub sigma_px: f32,
    /// Grey levels added per grey level of blurred change magnitude, per channel.
    pub colour: [f32; 3],
}

/// One term as the renderers run it: a source (the change, or its magnitude in channel 0),
/// its blur, and a 3x3 mix into the output.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GlowTerm {
    pub magnitude: bool,
    pub sigma_px: f32,
    pub mix: [[f32; 3]; 3],
}

/// One press a glow is fitted to: the rendered change without glow, the real change (the
/// real frame minus the rendered no-contact frame), and the pixel box `[x0, y0, x1, y1)` to
/// fit over.
pub struct GlowPress<'a> {
    pub change: &'a [[f32; 3]],
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

/// A separable blur of an RGB image, edges extended (rows first, then columns; taps summed
/// in order from -r to r, as the GPU's glow stages do).
pub fn blur(src: &[[f32; 3]], width: usize, height: usize, sigma_px: f32) -> Vec<[f32; 3]> {
    let k = gaussian_kernel(sigma_px);
    if k.len() == 1 {
        return src.to_vec();
    }
    let r = k.len() / 2;
    let mut rows = vec![[0.0f32; 3]; src.len()];
    let mut padded = vec![[0.0f32; 3]; width + 2 * r];
    for (row_in, row_out) in src.chunks_exact(width).zip(rows.chunks_exact_mut(width)) {
        padded[..r].fill(row_in[0]);
        padded[r..r + width].copy_from_slice(row_in);
        padded[r + width..].fill(row_in[width - 1]);
        for (x, out) in row_out.iter_mut().enumerate() {
            let mut s = [0.0f32; 3];
            for (w, p) in k.iter().zip(&padded[x..x + 2 * r + 1]) {
                for c in 0..3 {
                    s[c] += w * p[c];
                }
            }
            *out = s;
        }
    }
    let mut out = vec![[0.0f32; 3]; src.len()];
    for (y, row_out) in out.chunks_exact_mut(width).enumerate() {
        let row_out = row_out.as_flattened_mut();
        for (i, w) in k.iter().enumerate() {
            let yy = (y + i).saturating_sub(r).min(height - 1);
            let row_in = rows[yy * width..][..width].as_flattened();
            for (o, v) in row_out.iter_mut().zip(row_in) {
                *o += w * v;
            }
        }
    }
    out
}

/// The change's magnitude (grey levels) in channel 0.
fn magnitude(change: &[[f32; 3]]) -> Vec<[f32; 3]> {
    change
        .iter()
        .map(|c| [(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]).sqrt(), 0.0, 0.0])
        .collect()
}

impl GelGlow {
    /// Its terms in the order the renderers sum them: colour terms, then magnitude terms.
    pub fn terms(&self) -> Vec<GlowTerm> {
        let colour = self.colour.iter().map(|t| GlowTerm {
            magnitude: false,
            sigma_px: t.sigma_px,
            mix: t.mix,
        });
        let magnitude = self.magnitude.iter().map(|t| GlowTerm {
            magnitude: true,
            sigma_px: t.sigma_px,
            mix: t.colour.map(|v| [v, 0.0, 0.0]),
        });
        colour.chain(magnitude).collect()
    }

    /// Checks every term; Err is the field (under `optics.glow`) and what is wrong with it.
    pub fn validate(&self) -> Result<(), (String, String)> {
        let count = self.colour.len() + self.magnitude.len();
        if count == 0 || count > MAX_TERMS {
            return Err((
                "optics.glow".into(),
                format!("{count} terms, expected 1..={MAX_TERMS}"),
            ));
        }
        let sigma_ok = |s: f32| s.is_finite() && (0.0..=MAX_SIGMA_PX).contains(&s);
        let weight_ok = |v: &f32| v.is_finite() && v.abs() <= 100.0;
        for (i, t) in self.colour.iter().enumerate() {
            if !sigma_ok(t.sigma_px) {
                return Err((
                    format!("optics.glow.colour[{i}].sigma_px"),
                    format!("{}, expected 0..={MAX_SIGMA_PX} px", t.sigma_px),
                ));
            }
            if !t.mix.as_flattened().iter().all(weight_ok) {
                return Err((
                    format!("optics.glow.colour[{i}].mix"),
                    "weights must be finite and within +-100".into(),
                ));
            }
        }
        for (i, t) in self.magnitude.iter().enumerate() {
            if !sigma_ok(t.sigma_px) {
                return Err((
                    format!("optics.glow.magnitude[{i}].sigma_px"),
                    format!("{}, expected 0..={MAX_SIGMA_PX} px", t.sigma_px),
                ));
            }
            if !t.colour.iter().all(weight_ok) {
                return Err((
                    format!("optics.glow.magnitude[{i}].colour"),
                    "weights must be finite and within +-100".into(),
                ));
            }
        }
        Ok(())
    }

    /// The glowing change of a frame's change (both row-major, width x height).
    pub fn apply(&self, change: &[[f32; 3]], width: usize, height: usize) -> Vec<[f32; 3]> {
        let mut out = vec![[0.0f32; 3]; change.len()];
        let mags = (!self.magnitude.is_empty()).then(|| magnitude(change));
        for term in self.terms() {
            let src = if term.magnitude {
                mags.as_deref()
                    .expect("computed when there are magnitude terms")
            } else {
                change
            };
            let blurred = blur(src, width, height, term.sigma_px);
            for (o, b) in out.iter_mut().zip(&blurred) {
                for (c, row) in term.mix.iter().enumerate() {
                    o[c] += row[0] * b[0] + row[1] * b[1] + row[2] * b[2];
                }
            }
        }
        out
    }

    /// The glow with the given blurs that best maps the rendered changes onto the real ones
    /// inside the presses' windows (least squares, with a light ridge towards no glow beyond
    /// the unblurred change).
    pub fn fit(
        presses: &[GlowPress],
        width: usize,
        height: usize,
        colour_sigmas: &[f32],
        magnitude_sigmas: &[f32],
    ) -> Result<Self, GlowError> {
        let n = 3 * colour_sigmas.len() + magnitude_sigmas.len();
        let mut normal = vec![0.0f64; n * n];
        let mut rhs = vec![[0.0f64; 3]; n];
        let mut pixels = 0usize;
        let mut row = vec![0.0f64; n];
        for press in presses {
            let features: Vec<Vec<[f32; 3]>> = colour_sigmas
                .iter()
                .map(|&s| blur(press.change, width, height, s))
                .chain({
                    let m = magnitude(press.change);
                    magnitude_sigmas
                        .iter()
                        .map(move |&s| blur(&m, width, height, s))
                })
                .collect();
            let [x0, y0, x1, y1] = press.window;
            for y in y0 as usize..(y1 as usize).min(height) {
                for x in x0 as usize..(x1 as usize).min(width) {
                    let p = y * width + x;
                    for (k, f) in features.iter().take(colour_sigmas.len()).enumerate() {
                        for c in 0..3 {
                            row[3 * k + c] = f64::from(f[p][c]);
                        }
                    }
                    for (k, f) in features.iter().skip(colour_sigmas.len()).enumerate() {
                        row[3 * colour_sigmas.len() + k] = f64::from(f[p][0]);
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
        // A ridge scaled to the data keeps terms the presses cannot tell apart small.
        let trace: f64 = (0..n).map(|i| normal[i * n + i]).sum::<f64>() / n as f64;
        for i in 0..n {
            normal[i * n + i] += 1e-6 * trace.max(1e-12);
        }
        let x = crate::tactile::shading_table::solve_spd(&mut normal, n, &rhs)
            .ok_or(GlowError::Singular)?;
        let glow = GelGlow {
            colour: colour_sigmas
                .iter()
                .enumerate()
                .map(|(k, &sigma_px)| ColourGlow {
                    sigma_px,
                    mix: std::array::from_fn(|c| std::array::from_fn(|j| x[3 * k + j][c] as f32)),
                })
                .collect(),
            magnitude: magnitude_sigmas
                .iter()
                .enumerate()
                .map(|(k, &sigma_px)| MagnitudeGlow {
                    sigma_px,
                    colour: x[3 * colour_sigmas.len() + k].map(|v| v as f32),
                })
                .collect(),
        };
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

    #[test]
    fn a_fit_recovers_the_glow_that_made_the_target() {
        let (w, h) = (40, 30);
        let change = spot(w, h);
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
            magnitude: vec![MagnitudeGlow {
                sigma_px: 6.0,
                colour: [0.2, 0.1, -0.1],
            }],
        };
        let target = truth.apply(&change, w, h);
        let fitted = GelGlow::fit(
            &[GlowPress {
                change: &change,
                target: &target,
                window: [0, 0, w as u32, h as u32],
            }],
            w,
            h,
            &[0.0, 4.0],
            &[6.0],
        )
        .unwrap();
        let again = fitted.apply(&change, w, h);
        let worst = again
            .iter()
            .zip(&target)
            .flat_map(|(a, b)| (0..3).map(move |c| (a[c] - b[c]).abs()))
            .fold(0.0f32, f32::max);
        assert!(worst < 0.05, "worst residual {worst} grey levels");
    }

    #[test]
    fn bad_terms_are_named() {
        let mut g = GelGlow {
            colour: vec![ColourGlow {
                sigma_px: 1.0,
                mix: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
            }],
            magnitude: vec![],
        };
        assert!(g.validate().is_ok());
        g.colour[0].sigma_px = f32::NAN;
        assert_eq!(
            g.validate().unwrap_err().0,
            "optics.glow.colour[0].sigma_px"
        );
        g.colour[0].sigma_px = 1.0;
        g.colour[0].mix[1][2] = f32::INFINITY;
        assert_eq!(g.validate().unwrap_err().0, "optics.glow.colour[0].mix");
        g.colour.clear();
        assert_eq!(g.validate().unwrap_err().0, "optics.glow");
    }
}
