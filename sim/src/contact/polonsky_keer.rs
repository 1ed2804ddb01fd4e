//! Frictionless elastic contact at a prescribed approach by the constrained conjugate
//! gradient of Polonsky & Keer (Wear 231, 1999), displacement-controlled variant (no load
//! balance step): find p >= 0 with gap g = K p + h0 - delta >= 0 and p g = 0, the
//! convolutions done by DC-FFT, the conjugate gradient preconditioned by the kernel's
//! inverse spectrum restricted to the contact (Vollebregt 2014).

use super::convolution::{Convolver, Spectrum};

/// Convergence of the iteration.
#[derive(Clone, Copy, Debug)]
pub struct Settings {
    /// Stop when the relative change of the pressure field falls below this.
    pub tolerance: f64,
    pub max_iterations: usize,
    /// Precondition the conjugate gradient with the inverse of the kernel's spectrum
    /// (`preconditioner`), restricted to the contact set.
    pub preconditioned: bool,
}

impl Default for Settings {
    /// 1e-6: on the benched press it leaves the gel surface ~0.01 nm from the converged one
    /// (`tactex bench contact`, RMS gel vs converged), far below the default grid's own
    /// 1 um error, in 9.4 steps a frame against 12 at 1e-8.
    fn default() -> Self {
        Self {
            tolerance: 1e-6,
            max_iterations: 2000,
            preconditioned: true,
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

const LANES: usize = 4;

// The passes over the grid below are a third of the solve beside its FFTs. Each sums in
// four interleaved running sums, a fixed order (the same bytes every run) that the
// compiler can vectorise, and is compiled for AVX2 too, picked at run time: without FMA
// contraction (Rust never contracts) both builds give the same bits.

/// gap = u + separation everywhere; returns the sum of gap^2 over the cells in contact.
#[multiversion::multiversion(targets("x86_64+avx2"))]
fn gaps(u: &[f64], separation: &[f64], p: &[f64], gap: &mut [f64]) -> f64 {
    let mut lanes = [0.0; LANES];
    let mut lane = |l: usize, g: &mut f64, u: f64, s: f64, p: f64| {
        *g = u + s;
        lanes[l] += if p > 0.0 { *g * *g } else { 0.0 };
    };
    let (gc, gr) = gap.as_chunks_mut::<LANES>();
    let (uc, ur) = u.as_chunks::<LANES>();
    let (sc, sr) = separation.as_chunks::<LANES>();
    let (pc, pr) = p.as_chunks::<LANES>();
    for (((g, u), s), p) in gc.iter_mut().zip(uc).zip(sc).zip(pc) {
        for l in 0..LANES {
            lane(l, &mut g[l], u[l], s[l], p[l]);
        }
    }
    for (l, (((g, u), s), p)) in gr.iter_mut().zip(ur).zip(sr).zip(pr).enumerate() {
        lane(l, g, *u, *s, *p);
    }
    lanes.iter().sum()
}

/// The conjugate direction t = gap + ratio t on the contact, zero off it.
#[multiversion::multiversion(targets("x86_64+avx2"))]
fn directions(gap: &[f64], p: &[f64], ratio: f64, t: &mut [f64]) {
    for ((t, g), p) in t.iter_mut().zip(gap).zip(p) {
        *t = if *p > 0.0 { g + ratio * *t } else { 0.0 };
    }
}

/// (sum of gap t, sum of r t) over the contact: the step length's numerator and
/// denominator (t is zero off the contact, where the gap may be infinite).
#[multiversion::multiversion(targets("x86_64+avx2"))]
fn step_sums(gap: &[f64], t: &[f64], r: &[f64], p: &[f64]) -> (f64, f64) {
    let (mut num, mut den) = ([0.0; LANES], [0.0; LANES]);
    let mut lane = |l: usize, g: f64, t: f64, r: f64, p: f64| {
        num[l] += if p > 0.0 { g * t } else { 0.0 };
        den[l] += r * t;
    };
    let (gc, gr) = gap.as_chunks::<LANES>();
    let (tc, tr) = t.as_chunks::<LANES>();
    let (rc, rr) = r.as_chunks::<LANES>();
    let (pc, pr) = p.as_chunks::<LANES>();
    for (((g, t), r), p) in gc.iter().zip(tc).zip(rc).zip(pc) {
        for l in 0..LANES {
            lane(l, g[l], t[l], r[l], p[l]);
        }
    }
    for (l, (((g, t), r), p)) in gr.iter().zip(tr).zip(rr).zip(pr).enumerate() {
        lane(l, *g, *t, *r, *p);
    }
    (num.iter().sum(), den.iter().sum())
}

/// What one step did to the pressure.
struct Stepped {
    change: f64,
    total: f64,
    /// A cell in contact was clipped to zero.
    clipped: bool,
    /// A cell out of contact overlapped the object and entered.
    entered: bool,
}

/// p = max(p - tau t, 0), then cells out of contact that overlap the object enter with
/// -gap * `entry`.
#[multiversion::multiversion(targets("x86_64+avx2"))]
fn step(p: &mut [f64], t: &[f64], gap: &[f64], tau: f64, entry: f64) -> Stepped {
    let (mut change, mut total) = ([0.0; LANES], [0.0; LANES]);
    let (mut clipped, mut entered) = ([false; LANES], [false; LANES]);
    let mut lane = |l: usize, p: &mut f64, t: f64, gap: f64| {
        let old = *p;
        // Off the contact t = 0, so this leaves such cells at zero.
        let moved = old - tau * t;
        clipped[l] |= moved < 0.0;
        let kept = moved.max(0.0);
        let enters = kept == 0.0 && gap < 0.0;
        entered[l] |= enters;
        let new = if enters { -gap * entry } else { kept };
        *p = new;
        change[l] += (new - old).abs();
        total[l] += new;
    };
    let (pc, pr) = p.as_chunks_mut::<LANES>();
    let (tc, tr) = t.as_chunks::<LANES>();
    let (gc, gr) = gap.as_chunks::<LANES>();
    for ((p, t), g) in pc.iter_mut().zip(tc).zip(gc) {
        for l in 0..LANES {
            lane(l, &mut p[l], t[l], g[l]);
        }
    }
    for (l, ((p, t), g)) in pr.iter_mut().zip(tr).zip(gr).enumerate() {
        lane(l, p, *t, *g);
    }
    Stepped {
        change: change.iter().sum(),
        total: total.iter().sum(),
        clipped: clipped.iter().any(|c| *c),
        entered: entered.iter().any(|e| *e),
    }
}

/// The preconditioner of `kernel`'s solve: the reciprocal of its spectrum (real, as the
/// kernel is even in both axes), floored at a millionth of its peak so that it stays
/// positive definite. On the padded grid this inverts the kernel's circulant embedding,
/// a close approximation of the inverse of the operator restricted to the contact
/// (Vollebregt, J. Optim. Theory Appl. 162, 2014).
pub fn preconditioner(kernel: &Spectrum) -> Spectrum {
    let peak = kernel.0.iter().map(|c| c.re).fold(0.0, f64::max);
    let floor = peak * 1e-6;
    Spectrum(
        kernel
            .0
            .iter()
            .map(|c| (1.0 / c.re.max(floor)).into())
            .collect(),
    )
}

/// The diagonal of the circulant operator with half spectrum `spectrum` on the padded
/// 2nx x 2ny grid: the mean of its full spectrum (columns 1..nx-1 of the half stand for two).
fn circulant_diagonal(spectrum: &Spectrum, nx: usize, ny: usize) -> f64 {
    let column = 2 * ny;
    let sum: f64 = spectrum
        .0
        .chunks(column)
        .enumerate()
        .map(|(c, col)| {
            let weight = if c == 0 || c == nx { 1.0 } else { 2.0 };
            weight * col.iter().map(|v| v.re).sum::<f64>()
        })
        .sum();
    sum / (4 * nx * ny) as f64
}

/// Solves for the pressure given `separation` = h0 - delta per cell (infinite where the
/// object is absent), the total compliance kernel with its `preconditioner`, and a
/// starting pressure.
pub fn solve(
    conv: &mut Convolver,
    kernel: &Spectrum,
    preconditioner: &Spectrum,
    separation: &[f64],
    approach_mm: f64,
    start: Vec<f64>,
    settings: Settings,
) -> Outcome {
    let n = separation.len();
    let active: Vec<bool> = separation.iter().map(|s| s.is_finite()).collect();
    // Outside the object the separation is +inf, so the gap is too and such a cell can
    // never enter: the loops below need no mask of their own.
    let separation: Vec<f64> = separation
        .iter()
        .map(|s| if s.is_finite() { *s } else { f64::INFINITY })
        .collect();
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
    // The preconditioned gap z = P M P gap (P: restriction to the contact), and P gap.
    let (mut z, mut gap_on_contact) = if settings.preconditioned {
        (vec![0.0; n], vec![0.0; n])
    } else {
        (Vec::new(), Vec::new())
    };
    let entry_scale = if settings.preconditioned {
        circulant_diagonal(preconditioner, conv.nx, conv.ny)
    } else {
        1.0
    };
    let self_compliance = circulant_diagonal(kernel, conv.nx, conv.ny);
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
        let mut g_sum = gaps(&u, &separation, &p, &mut gap);
        let descent = if settings.preconditioned {
            directions(&gap, &p, 0.0, &mut gap_on_contact);
            conv.convolve(&gap_on_contact, preconditioner, &mut z);
            // The sum of gap z over the contact: the second of step_sums' sums, with the
            // masked gap in the place of the direction and z in that of K t.
            g_sum = step_sums(&gap, &gap_on_contact, &z, &p).1;
            &z
        } else {
            &gap
        };
        let ratio = if conjugate { g_sum / g_old } else { 0.0 };
        directions(descent, &p, ratio, &mut t);
        g_old = g_sum;
        conv.convolve(&t, kernel, &mut r);
        let (num, den) = step_sums(&gap, &t, &r, &p);
        let tau = if den > 0.0 { num / den } else { 0.0 };
        // A free cell that overlaps enters at its overlap times the step length in pressure
        // per gap: tau itself for the plain gradient, tau times the preconditioner's own
        // per-cell weight (its diagonal) for the preconditioned one. Before any cell is in
        // contact there is no step length yet: a cell's overlap over its own compliance
        // seeds the contact.
        let entry = if tau > 0.0 {
            tau * entry_scale
        } else {
            1.0 / self_compliance
        };
        let stepped = step(&mut p, &t, &gap, tau, entry);
        conjugate = !stepped.entered;
        if stepped.total == 0.0 || stepped.change <= settings.tolerance * stepped.total {
            converged = true;
            break;
        }
        if stepped.entered || stepped.clipped {
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
    use crate::contact::convolution::wrapped_kernel;
    use crate::contact::influence::love_normal;

    /// A rigid sphere of radius 5 mm pressed 0.2 mm into a half-space of unit compliance on
    /// a 24x24 grid of 0.25 mm cells: the contact set grows, clips and settles, so the
    /// solve takes both the incremental and the fresh displacement updates.
    fn sphere_press(settings: Settings) -> (Vec<f64>, Vec<f64>, Outcome) {
        sphere_press_with(settings, 1.0, false)
    }

    /// The same press on a half-space `compliance` times as compliant, started from the
    /// overlap over the compliance, or from no pressure at all (every cell then enters).
    fn sphere_press_with(
        settings: Settings,
        compliance: f64,
        from_nothing: bool,
    ) -> (Vec<f64>, Vec<f64>, Outcome) {
        let (n, cell, radius, approach) = (24usize, 0.25, 5.0, 0.2);
        let centre = (n as f64 - 1.0) / 2.0;
        let separation: Vec<f64> = (0..n * n)
            .map(|k| {
                let (x, y) = ((k % n) as f64 - centre, (k / n) as f64 - centre);
                let r2 = (x * x + y * y) * cell * cell;
                radius - (radius * radius - r2).sqrt() - approach
            })
            .collect();
        let coefficient = |di: i64, dj: i64| {
            compliance * love_normal(di as f64 * cell, dj as f64 * cell, cell / 2.0)
        };
        let mut conv = Convolver::new(n, n);
        let kernel = conv.padded_spectrum(&wrapped_kernel(n, n, coefficient));
        let start = separation
            .iter()
            .map(|s| {
                if from_nothing {
                    0.0
                } else {
                    (-s).max(0.0) / compliance
                }
            })
            .collect();
        let outcome = solve(
            &mut conv,
            &kernel,
            &preconditioner(&kernel),
            &separation,
            approach,
            start,
            settings,
        );
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
        for preconditioned in [true, false] {
            meets_the_contact_conditions(Settings {
                preconditioned,
                ..Settings::default()
            });
        }
    }

    fn meets_the_contact_conditions(settings: Settings) {
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

    #[test]
    fn preconditioning_reaches_the_same_contact_in_fewer_steps() {
        let settings = |preconditioned| Settings {
            preconditioned,
            tolerance: 1e-10,
            ..Settings::default()
        };
        let plain = sphere_press(settings(false)).2;
        let pre = sphere_press(settings(true)).2;
        assert!(plain.converged && pre.converged);
        assert!(
            pre.iterations < plain.iterations,
            "{} steps preconditioned, {} plain",
            pre.iterations,
            plain.iterations
        );
        let peak = plain.pressure.iter().cloned().fold(0.0, f64::max);
        for (a, b) in plain.pressure.iter().zip(&pre.pressure) {
            assert!((a - b).abs() < 1e-6 * peak, "{a} vs {b}");
        }
    }

    /// Displacement control with one compliance: the contact set does not depend on its
    /// scale and the pressure goes as its inverse. A free cell entering the contact must
    /// take a pressure in the kernel's units, or a soft contact diverges (as the
    /// preconditioned solve did when an entry took its overlap times the dimensionless step).
    #[test]
    fn the_solve_is_the_same_at_any_compliance_scale() {
        for preconditioned in [true, false] {
            let settings = Settings {
                preconditioned,
                ..Settings::default()
            };
            let unit = sphere_press_with(settings, 1.0, true).2;
            for compliance in [1e-5, 1e5] {
                let scaled = sphere_press_with(settings, compliance, true).2;
                assert!(scaled.converged, "compliance {compliance}");
                let steps = scaled.iterations.abs_diff(unit.iterations);
                assert!(steps <= 1, "compliance {compliance}: {steps} steps apart");
                let peak = unit.pressure.iter().cloned().fold(0.0, f64::max);
                for (a, b) in unit.pressure.iter().zip(&scaled.pressure) {
                    assert!((a - b * compliance).abs() < 1e-9 * peak, "{a} vs {b}");
                }
            }
        }
    }
}
