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
    /// 1e-6: on the benched press it moves the gel surface by ~1 nm and the force by 3e-7
    /// relative (`tactex bench contact`, RMS gel vs converged), a thousandth of the default
    /// grid's own error, in two thirds of the steps that 1e-8 takes.
    fn default() -> Self {
        Self {
            tolerance: 1e-6,
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
    // u = K p, kept up to date: after a step that only moved cells already in contact
    // (no cell clipped to zero, none entered) it is u - tau K t, which saves one of the
    // iteration's two convolutions; otherwise it is convolved afresh.
    conv.convolve(&p, kernel, &mut u);
    while iterations < settings.max_iterations {
        iterations += 1;
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
        let mut clipped = false;
        for i in 0..n {
            if !active[i] {
                continue;
            }
            let old = p[i];
            let mut new = if old > 0.0 {
                let moved = old - tau * t[i];
                clipped |= moved < 0.0;
                moved.max(0.0)
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
        if overlap || clipped {
            conv.convolve(&p, kernel, &mut u);
        } else {
            for (u, r) in u.iter_mut().zip(&r) {
                *u -= tau * r;
            }
        }
    }
    // Final contact conditions, from a fresh convolution.
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::elastic::convolution::wrapped_kernel;
    use crate::elastic::influence::love_normal;

    /// A rigid sphere of radius 5 mm pressed 0.2 mm into a half-space of unit compliance on
    /// a 24x24 grid of 0.25 mm cells: the contact set grows, clips and settles, so the
    /// solve takes both the incremental and the fresh displacement updates.
    fn sphere_press(settings: Settings) -> (Vec<f64>, Vec<f64>, Outcome) {
        let (n, cell, radius, approach) = (24usize, 0.25, 5.0, 0.2);
        let centre = (n as f64 - 1.0) / 2.0;
        let separation: Vec<f64> = (0..n * n)
            .map(|k| {
                let (x, y) = ((k % n) as f64 - centre, (k / n) as f64 - centre);
                let r2 = (x * x + y * y) * cell * cell;
                radius - (radius * radius - r2).sqrt() - approach
            })
            .collect();
        let coefficient =
            |di: i64, dj: i64| love_normal(di as f64 * cell, dj as f64 * cell, cell / 2.0);
        let mut conv = Convolver::new(n, n);
        let kernel = conv.padded_spectrum(&wrapped_kernel(n, n, coefficient));
        let start = separation.iter().map(|s| (-s).max(0.0)).collect();
        let outcome = solve(&mut conv, &kernel, &separation, approach, start, settings);
        // The displacement by direct summation, independent of the FFT and of the
        // solver's running update.
        let displacement = (0..n * n)
            .map(|k| {
                let (i, j) = ((k % n) as i64, (k / n) as i64);
                (0..n * n)
                    .map(|q| {
                        let (p, r) = ((q % n) as i64, (q / n) as i64);
                        outcome.pressure[q] * coefficient(i - p, j - r)
                    })
                    .sum()
            })
            .collect();
        (separation, displacement, outcome)
    }

    #[test]
    fn the_solution_meets_the_contact_conditions_by_direct_summation() {
        let settings = Settings::default();
        let (separation, displacement, outcome) = sphere_press(settings);
        assert!(outcome.converged, "{} iterations", outcome.iterations);
        let approach = 0.2;
        let mut in_contact = 0;
        for ((s, u), p) in separation.iter().zip(&displacement).zip(&outcome.pressure) {
            let gap = u + s;
            assert!(*p >= 0.0);
            if *p > 0.0 {
                in_contact += 1;
                assert!(gap.abs() < 1e-4 * approach, "gap {gap} under pressure {p}");
            } else {
                assert!(gap > -1e-4 * approach, "overlap {gap} where free");
            }
        }
        assert!(in_contact > 20, "{in_contact} cells in contact");
    }

    #[test]
    fn a_looser_tolerance_stops_sooner_near_the_tight_answer() {
        let tight = sphere_press(Settings {
            tolerance: 1e-11,
            ..Settings::default()
        })
        .2;
        let loose = sphere_press(Settings::default()).2;
        assert!(tight.converged && loose.converged);
        assert!(loose.iterations < tight.iterations);
        let force = |p: &[f64]| p.iter().sum::<f64>();
        let (ft, fl) = (force(&tight.pressure), force(&loose.pressure));
        assert!((fl / ft - 1.0).abs() < 1e-5, "force {fl} vs {ft}");
    }
}
