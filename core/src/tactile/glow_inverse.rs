//! The glow read backwards. A calibrated profile's glow replaces the shading's colour change S
//! by a sum of blurs of it mixed across channels (linear in S) plus terms of its magnitude and
//! of the gel's indentation. Reading a frame's change per pixel through the table as if it
//! were S takes the glow for slope (a wide bowl round every contact). The linear part is a
//! 3x3 matrix per spatial frequency, A(f) = sum_k M_k g_k(f), so S is recovered by a
//! regularised inverse per frequency (of the frame's mirror extension, so nothing wraps: its
//! cosine transform); the other terms are taken from the previous reading and subtracted.
//!
//! What the regulariser gives up (a colour the glow nearly cancels at a frequency) is taken
//! from a prior change when there is one: the table's change of a first reading's slopes.
//! Taken as zero, it is a colour no slope makes, and the slopes read from it shrink: the FOTS
//! profile, whose glow cancels much of a small contact's colour, read its own renders of a
//! ball pressed 0.3-0.6 mm about 30% shallow.

use crate::spectral::{dct2_2d, idct2_2d};
use crate::tactile::gel_glow::{GelGlow, GlowSource, gaussian_kernel};
use std::sync::{Arc, Mutex};

/// Tikhonov weight, relative to the zero-frequency gain: how much of a frequency the glow
/// nearly cancels is given up rather than amplified with the camera's noise.
const RIDGE: f64 = 0.01;

/// The linear part of a glow inverted for one frame size.
pub struct GlowInverse {
    width: usize,
    height: usize,
    /// Per frequency (u, v) of the cosine transform (at u h + v, as `dct2_2d` leaves it), the
    /// 3x3 regularised inverse, row-major.
    inverse: Vec<[f64; 9]>,
    /// Per frequency, the 3x3 share of a prior change the inverse keeps: ridge (A^T A +
    /// ridge I)^-1, so that a prior the glow's image of which is the observation comes back
    /// unchanged.
    toward_prior: Vec<[f64; 9]>,
    /// The glow's other terms (magnitude, indentation, indented change); None when it has none.
    rest: Option<GelGlow>,
}

/// The DFT of a symmetric kernel at the frequencies of a length-n signal.
fn kernel_response(kernel: &[f32], n: usize) -> Vec<f64> {
    let r = (kernel.len() / 2) as f64;
    (0..n)
        .map(|u| {
            let omega = 2.0 * std::f64::consts::PI * u as f64 / n as f64;
            kernel
                .iter()
                .enumerate()
                .map(|(i, k)| f64::from(*k) * (omega * (i as f64 - r)).cos())
                .sum()
        })
        .collect()
}

fn invert3(m: [f64; 9]) -> Option<[f64; 9]> {
    let [a, b, c, d, e, f, g, h, i] = m;
    let det = a * (e * i - f * h) - b * (d * i - f * g) + c * (d * h - e * g);
    if det.abs() < 1e-300 {
        return None;
    }
    let k = 1.0 / det;
    Some([
        (e * i - f * h) * k,
        (c * h - b * i) * k,
        (b * f - c * e) * k,
        (f * g - d * i) * k,
        (a * i - c * g) * k,
        (c * d - a * f) * k,
        (d * h - e * g) * k,
        (b * g - a * h) * k,
        (a * e - b * d) * k,
    ])
}

/// The response at frequency index `k` of a length-n signal of a Gaussian of `sigma_px`.
fn smoothing_response(sigma_px: f64, k: usize, n: usize) -> f64 {
    let signed = if k <= n / 2 {
        k as f64
    } else {
        k as f64 - n as f64
    };
    let omega = 2.0 * std::f64::consts::PI * signed / n as f64;
    (-0.5 * sigma_px * sigma_px * omega * omega).exp()
}

/// The inverses made last: a press reads every frame through one glow at one size.
static MADE: Mutex<Vec<Made>> = Mutex::new(Vec::new());
/// An inverse with the glow, frame size (width, height) and smoothing it was made for.
type Made = (GelGlow, usize, usize, u32, Arc<GlowInverse>);
const KEPT: usize = 4;

impl GlowInverse {
    /// The inverse for this glow, frame size and smoothing, made once and shared.
    pub fn shared(glow: &GelGlow, width: usize, height: usize, smoothing_px: f64) -> Arc<Self> {
        let key = (smoothing_px as f32).to_bits();
        let found = {
            let made = MADE.lock().unwrap_or_else(|e| e.into_inner());
            made.iter()
                .find(|(g, w, h, k, _)| g == glow && *w == width && *h == height && *k == key)
                .map(|(.., inverse)| inverse.clone())
        };
        if let Some(inverse) = found {
            return inverse;
        }
        let inverse = Arc::new(Self::new(glow, width, height, smoothing_px));
        let mut made = MADE.lock().unwrap_or_else(|e| e.into_inner());
        if made.len() >= KEPT {
            made.remove(0);
        }
        made.push((glow.clone(), width, height, key, inverse.clone()));
        inverse
    }

    /// The inverse followed by a Gaussian of `smoothing_px` (free here, as a product per
    /// frequency), so that the camera's noise is not read backwards into slope.
    pub fn new(glow: &GelGlow, width: usize, height: usize, smoothing_px: f64) -> Self {
        let (n, m) = (2 * width, 2 * height);
        let colour: Vec<_> = glow
            .terms()
            .into_iter()
            .filter(|t| t.source == GlowSource::Change)
            .map(|t| {
                let k = gaussian_kernel(t.sigma_px);
                (kernel_response(&k, n), kernel_response(&k, m), t.mix)
            })
            .collect();
        let gain_at = |u: usize, v: usize| {
            let mut a = [0.0f64; 9];
            for (gx, gy, mix) in &colour {
                let g = gx[u] * gy[v];
                for (c, row) in mix.iter().enumerate() {
                    for (k, w) in row.iter().enumerate() {
                        a[3 * c + k] += g * f64::from(*w);
                    }
                }
            }
            a
        };
        let zero = gain_at(0, 0);
        let ridge = RIDGE * zero.iter().map(|v| v * v).sum::<f64>() / 3.0;
        // The mirror extension's frequencies a cosine transform keeps: the first half of each
        // axis.
        let mut inverse = Vec::with_capacity(width * height);
        let mut toward_prior = Vec::with_capacity(width * height);
        for u in 0..width {
            for v in 0..height {
                let a = gain_at(u, v);
                // (A^T A + ridge I)^-1 A^T
                let mut ata = [0.0f64; 9];
                for i in 0..3 {
                    for j in 0..3 {
                        ata[3 * i + j] = (0..3).map(|c| a[3 * c + i] * a[3 * c + j]).sum();
                    }
                    ata[4 * i] += ridge;
                }
                let inv = invert3(ata).unwrap_or([0.0; 9]);
                let mut b = [0.0f64; 9];
                for i in 0..3 {
                    for c in 0..3 {
                        b[3 * i + c] = (0..3).map(|j| inv[3 * i + j] * a[3 * c + j]).sum();
                    }
                }
                let smooth =
                    smoothing_response(smoothing_px, u, n) * smoothing_response(smoothing_px, v, m);
                b.iter_mut().for_each(|x| *x *= smooth);
                inverse.push(b);
                toward_prior.push(inv.map(|x| x * ridge * smooth));
            }
        }
        let rest = GelGlow {
            colour: Vec::new(),
            ..glow.clone()
        };
        Self {
            width,
            height,
            inverse,
            toward_prior,
            rest: (!rest.terms().is_empty()).then_some(rest),
        }
    }

    /// Whether the glow has terms beyond the linear ones (they need the gel's indentation).
    pub fn has_rest(&self) -> bool {
        self.rest.is_some()
    }

    /// The glow's other terms for a shading change and indentation (mm).
    pub fn rest(&self, change: &[[f32; 3]], indentation_mm: &[f32]) -> Vec<[f32; 3]> {
        match &self.rest {
            Some(g) => g.apply(change, indentation_mm, self.width, self.height),
            None => vec![[0.0; 3]; change.len()],
        }
    }

    /// The shading change whose linear glow is `observed` (row-major, width x height), with
    /// what the glow leaves undetermined taken as no change.
    pub fn solve(&self, observed: &[[f32; 3]]) -> Vec<[f32; 3]> {
        self.solve_from(observed, None)
    }

    /// As `solve`, with what the glow leaves undetermined taken from `prior` (a change of the
    /// same size) instead.
    pub fn solve_toward(&self, observed: &[[f32; 3]], prior: &[[f32; 3]]) -> Vec<[f32; 3]> {
        self.solve_from(observed, Some(prior))
    }

    /// Each channel of the observation (and the prior) to its cosine transform, mixed per
    /// frequency, and back.
    fn solve_from(&self, observed: &[[f32; 3]], prior: Option<&[[f32; 3]]>) -> Vec<[f32; 3]> {
        let (w, h) = (self.width, self.height);
        let transform = |image: &[[f32; 3]], c: usize| {
            let channel: Vec<f64> = image.iter().map(|p| f64::from(p[c])).collect();
            dct2_2d(&channel, w, h)
        };
        let o: [Vec<f64>; 3] = std::array::from_fn(|c| transform(observed, c));
        let p: Option<[Vec<f64>; 3]> = prior.map(|p| std::array::from_fn(|c| transform(p, c)));
        let mut s: [Vec<f64>; 3] = std::array::from_fn(|_| vec![0.0; w * h]);
        for (k, b) in self.inverse.iter().enumerate() {
            let ok = [o[0][k], o[1][k], o[2][k]];
            let mut sk: [f64; 3] = std::array::from_fn(|i| {
                ok[0] * b[3 * i] + ok[1] * b[3 * i + 1] + ok[2] * b[3 * i + 2]
            });
            if let Some(p) = &p {
                let pk = [p[0][k], p[1][k], p[2][k]];
                let t = &self.toward_prior[k];
                for (i, s) in sk.iter_mut().enumerate() {
                    *s += pk[0] * t[3 * i] + pk[1] * t[3 * i + 1] + pk[2] * t[3 * i + 2];
                }
            }
            for (c, v) in sk.into_iter().enumerate() {
                s[c][k] = v;
            }
        }
        let back: [Vec<f64>; 3] = std::array::from_fn(|c| idct2_2d(&s[c], w, h));
        (0..w * h)
            .map(|i| std::array::from_fn(|c| back[c][i] as f32))
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tactile::gel_glow::ColourGlow;

    #[test]
    fn a_colour_the_glow_cancels_is_taken_from_the_prior() {
        let (w, h) = (40, 30);
        // Red and green mixed alike at every frequency: their difference never reaches the
        // frame, so nothing observed can restore it.
        let glow = GelGlow {
            colour: vec![
                ColourGlow {
                    sigma_px: 0.0,
                    mix: [[0.5, 0.5, 0.0], [0.5, 0.5, 0.0], [0.0, 0.0, 1.0]],
                },
                ColourGlow {
                    sigma_px: 3.0,
                    mix: [[0.3, 0.3, 0.0], [0.3, 0.3, 0.0], [0.0, 0.0, 0.5]],
                },
            ],
            magnitude: Vec::new(),
            indentation: Vec::new(),
            indented_colour: Vec::new(),
        };
        let change: Vec<[f32; 3]> = (0..w * h)
            .map(|p| {
                let (x, y) = ((p % w) as f32 - 20.0, (p / w) as f32 - 15.0);
                let d = (-(x * x + y * y) / 30.0).exp();
                [25.0 * d, -10.0 * d, 6.0 * d]
            })
            .collect();
        let glowing = glow.apply(&change, &vec![0.0; w * h], w, h);
        let inverse = GlowInverse::new(&glow, w, h, 0.0);
        let worst = |back: &[[f32; 3]]| {
            change
                .iter()
                .zip(back)
                .flat_map(|(a, b)| (0..3).map(move |c| (a[c] - b[c]).abs()))
                .fold(0.0f32, f32::max)
        };
        // Without a prior the red-green difference (35 grey levels at the centre) is lost.
        assert!(worst(&inverse.solve(&glowing)) > 10.0);
        // A prior that is the change itself comes back whole.
        let back = inverse.solve_toward(&glowing, &change);
        assert!(worst(&back) < 0.05, "worst {}", worst(&back));
    }

    #[test]
    fn a_colour_glow_is_undone() {
        let (w, h) = (48, 36);
        let glow = GelGlow {
            colour: vec![
                ColourGlow {
                    sigma_px: 0.0,
                    mix: [[0.8, 0.1, 0.0], [0.0, 0.7, 0.1], [0.1, 0.0, 0.9]],
                },
                ColourGlow {
                    sigma_px: 4.0,
                    mix: [[0.5, 0.0, 0.2], [0.1, 0.4, 0.0], [0.0, 0.3, 0.6]],
                },
            ],
            magnitude: Vec::new(),
            indentation: Vec::new(),
            indented_colour: Vec::new(),
        };
        let change: Vec<[f32; 3]> = (0..w * h)
            .map(|p| {
                let (x, y) = ((p % w) as f32 - 24.0, (p / w) as f32 - 18.0);
                let d = (-(x * x + y * y) / 40.0).exp();
                [30.0 * d, -12.0 * d * x.signum(), 8.0 * d]
            })
            .collect();
        let glowing = glow.apply(&change, &vec![0.0; w * h], w, h);
        let back = GlowInverse::new(&glow, w, h, 0.0).solve(&glowing);
        let worst = change
            .iter()
            .zip(&back)
            .flat_map(|(a, b)| (0..3).map(move |c| (a[c] - b[c]).abs()))
            .fold(0.0f32, f32::max);
        // The ridge gives up a little of every frequency; 30 grey levels come back within 2.
        assert!(worst < 2.0, "worst {worst} grey levels");
    }
}
