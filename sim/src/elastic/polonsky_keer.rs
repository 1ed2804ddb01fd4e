//! Frictionless elastic contact at a prescribed approach by the constrained conjugate
//! gradient of Polonsky & Keer (Wear 231, 1999), displacement-controlled variant (no load
//! balance step): find p >= 0 with gap g = K p + h0 - delta >= 0 and p g = 0, the
//! convolutions done by DC-FFT.

use super::convolution::{Convolver, Spectrum};

/// Convergence of the iteration.
#[derive(Clone, Copy, Debug)]
pub struct Settings {
    /// Stop when the relative change of the pressure field falls below this.
    pub tolerance: f64,
    pub max_iterations: usize,
}

impl Default for Settings {
    fn default() -> Self {
        Self {
            tolerance: 1e-8,
            max_iterations: 2000,
        }
    }
}

pub struct Outcome {
    pub pressure: Vec<f64>,
    pub iterations: usize,
    /// RMS violation of the contact conditions (gap where pressed, overlap where free) over
    /// the cells in contact, relative to the approach.
    pub residual: f64,
    pub converged: bool,
}

/// Solves for the pressure given `separation` = h0 - delta per cell (infinite where the
/// object is absent), the total compliance kernel, and a starting pressure.
pub fn solve(
    conv: &mut Convolver,
    kernel: &Spectrum,
    separation: &[f64],
    approach_mm: f64,
    start: Vec<f64>,
    settings: Settings,
) -> Outcome {
    let n = separation.len();
    let active: Vec<bool> = separation.iter().map(|s| s.is_finite()).collect();
    let mut p = start;
    for (p, a) in p.iter_mut().zip(&active) {
        if !a || !p.is_finite() || *p < 0.0 {
            *p = 0.0;
        }
    }
    let mut u = vec![0.0; n];
    let mut gap = vec![0.0; n];
    let mut t = vec![0.0; n];
    let mut r = vec![0.0; n];
    let mut g_old = 1.0;
    let mut conjugate = false;
    let mut iterations = 0;
    let mut converged = false;
    while iterations < settings.max_iterations {
        iterations += 1;
        conv.convolve(&p, kernel, &mut u);
        let mut g_sum = 0.0;
        for i in 0..n {
            gap[i] = if active[i] {
                u[i] + separation[i]
            } else {
                f64::INFINITY
            };
            if p[i] > 0.0 {
                g_sum += gap[i] * gap[i];
            }
        }
        let ratio = if conjugate { g_sum / g_old } else { 0.0 };
        for i in 0..n {
            t[i] = if p[i] > 0.0 {
                gap[i] + ratio * t[i]
            } else {
                0.0
            };
        }
        g_old = g_sum;
        conv.convolve(&t, kernel, &mut r);
        let (mut num, mut den) = (0.0, 0.0);
        for i in 0..n {
            if p[i] > 0.0 {
                num += gap[i] * t[i];
                den += r[i] * t[i];
            }
        }
        let tau = if den > 0.0 { num / den } else { 0.0 };
        let (mut change, mut total) = (0.0, 0.0);
        let mut overlap = false;
        for i in 0..n {
            if !active[i] {
                continue;
            }
            let old = p[i];
            let mut new = if old > 0.0 {
                (old - tau * t[i]).max(0.0)
            } else {
                0.0
            };
            // Cells out of contact that overlap the object enter it (before any cell is in
            // contact there is no step length yet: the overlap itself seeds them).
            if new == 0.0 && gap[i] < 0.0 {
                new = -gap[i] * if tau > 0.0 { tau } else { 1.0 };
                overlap = true;
            }
            p[i] = new;
            change += (new - old).abs();
            total += new;
        }
        conjugate = !overlap;
        if total == 0.0 || change <= settings.tolerance * total {
            converged = true;
            break;
        }
    }
    // Final contact conditions.
    conv.convolve(&p, kernel, &mut u);
    let (mut violation, mut count) = (0.0, 0usize);
    for i in 0..n {
        if !active[i] {
            continue;
        }
        let g = u[i] + separation[i];
        if p[i] > 0.0 {
            violation += g * g;
            count += 1;
        } else if g < 0.0 {
            violation += g * g;
        }
    }
    let residual = if count == 0 || approach_mm <= 0.0 {
        0.0
    } else {
        (violation / count as f64).sqrt() / approach_mm
    };
    Outcome {
        pressure: p,
        iterations,
        residual,
        converged,
    }
}
