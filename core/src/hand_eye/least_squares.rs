//! The one nonlinear least-squares solver of hand-eye calibration: Levenberg-Marquardt over a
//! fixed number of parameters, central-difference Jacobian, steps damped on the diagonal
//! (Marquardt's scaling), used for the board's pose and for the camera and board together.

use crate::geometry::Pose;
use glam::{DQuat, DVec3};

/// `pose` turned by the rotation vector `p[0..3]` and shifted by `p[3..6]` (m): the six
/// increments a fit searches over for each pose it refines.
pub(crate) fn nudged(pose: &Pose, p: &[f64]) -> Pose {
    Pose::new(
        pose.position + DVec3::new(p[3], p[4], p[5]),
        DQuat::from_scaled_axis(DVec3::new(p[0], p[1], p[2])) * pose.rotation,
    )
}

/// Steps tried at most.
const MAX_ITERATIONS: usize = 100;

/// Where the steps ended: the parameters, their residuals, how many steps were taken, and
/// whether they stopped for want of a better step (a minimum) rather than at the limit.
pub(crate) struct Fit<const P: usize> {
    pub parameters: [f64; P],
    pub residuals: Vec<f64>,
    pub iterations: usize,
    pub converged: bool,
}

/// Minimises the sum of squares of `residuals` from all-zero parameters (each caller's
/// parameters are increments on its starting point).
pub(crate) fn levenberg_marquardt<const P: usize>(
    residuals: &dyn Fn(&[f64; P]) -> Vec<f64>,
) -> Fit<P> {
    let cost = |r: &[f64]| r.iter().map(|v| v * v).sum::<f64>();
    let mut p = [0.0f64; P];
    let mut r = residuals(&p);
    let mut err = cost(&r);
    let mut damping = 1e-3;
    let (mut iterations, mut converged) = (0, false);
    while iterations < MAX_ITERATIONS {
        iterations += 1;
        let jacobian = jacobian(residuals, &p, r.len());
        // Normal equations J^T J d = -J^T r, damped on the diagonal.
        let mut jtj = [[0.0f64; P]; P];
        let mut jtr = [0.0f64; P];
        for (row, ri) in jacobian.iter().zip(&r) {
            for a in 0..P {
                jtr[a] += row[a] * ri;
                for b in 0..P {
                    jtj[a][b] += row[a] * row[b];
                }
            }
        }
        let (mut improved, mut solvable) = (false, false);
        for _ in 0..10 {
            let mut damped = jtj;
            for (a, row) in damped.iter_mut().enumerate() {
                row[a] *= 1.0 + damping;
            }
            let Some(step) = solve(damped, jtr.map(|v| -v)) else {
                damping *= 10.0;
                continue;
            };
            solvable = true;
            let trial: [f64; P] = std::array::from_fn(|k| p[k] + step[k]);
            let tr = residuals(&trial);
            let te = cost(&tr);
            if te < err {
                let small = err - te < 1e-12 * err.max(1e-300);
                (p, r, err) = (trial, tr, te);
                damping = (damping / 10.0).max(1e-12);
                improved = !small;
                break;
            }
            damping *= 10.0;
        }
        if !improved {
            // No step lowers the error, or only by rounding: a minimum; but where no damping
            // made the equations solvable the parameters are not fixed, which is no minimum.
            converged = solvable;
            break;
        }
    }
    Fit {
        parameters: p,
        residuals: r,
        iterations,
        converged,
    }
}

fn jacobian<const P: usize>(
    residuals: &dyn Fn(&[f64; P]) -> Vec<f64>,
    p: &[f64; P],
    rows: usize,
) -> Vec<[f64; P]> {
    // 1e-7 rad and 1e-7 m: far above f64's rounding of a metre, far below a pixel's worth.
    let h = 1e-7;
    let mut jacobian = vec![[0.0f64; P]; rows];
    for k in 0..P {
        let (mut plus, mut minus) = (*p, *p);
        plus[k] += h;
        minus[k] -= h;
        let (rp, rm) = (residuals(&plus), residuals(&minus));
        for (row, (a, b)) in jacobian.iter_mut().zip(rp.iter().zip(&rm)) {
            row[k] = (a - b) / (2.0 * h);
        }
    }
    jacobian
}

/// `a x = b` by Gaussian elimination with partial pivoting; None when `a` is singular.
pub(crate) fn solve<const N: usize>(mut a: [[f64; N]; N], mut b: [f64; N]) -> Option<[f64; N]> {
    let scale = a.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
    for col in 0..N {
        let pivot = (col..N).max_by(|&i, &j| a[i][col].abs().total_cmp(&a[j][col].abs()))?;
        if a[pivot][col].abs() <= 1e-14 * scale {
            return None;
        }
        a.swap(col, pivot);
        b.swap(col, pivot);
        for row in col + 1..N {
            let f = a[row][col] / a[col][col];
            let pivot_row = a[col];
            for (x, p) in a[row].iter_mut().zip(pivot_row).skip(col) {
                *x -= f * p;
            }
            b[row] -= f * b[col];
        }
    }
    let mut x = [0.0f64; N];
    for row in (0..N).rev() {
        let tail: f64 = (row + 1..N).map(|k| a[row][k] * x[k]).sum();
        x[row] = (b[row] - tail) / a[row][row];
    }
    Some(x)
}
