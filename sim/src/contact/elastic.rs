//! The `halfspace` and `layer` levels: frictionless contact of any shape, solved by
//! Polonsky-Keer conjugate gradient with DC-FFT. The two differ only in their influence
//! kernels: composite half-spaces, or the gel as a finite layer bonded to the acrylic,
//! which stiffens it and makes its surface move outward round the contact.

use super::fidelity::Fidelity;
use super::grid::Grid;
use super::influence;
use super::kernels::GridKernels;
use super::polonsky_keer;
use super::problem::ContactProblem;
use super::solution::{ContactSolution, FieldModel, GelFields};
use super::solver::ContactSolver;
use super::warm_start;
use tactex_core::hertz::Elastic;

pub(super) fn solve(
    solver: &mut ContactSolver,
    problem: &ContactProblem,
    fidelity: Fidelity,
    grid: Grid,
    separation: &[f64],
    warm: Option<&ContactSolution>,
    warnings: &mut Vec<String>,
) -> ContactSolution {
    let gel_c = Elastic {
        modulus_mpa: Some(problem.gel.modulus_mpa),
        poisson: problem.gel.poisson,
    }
    .compliance();
    let object_c = problem.object.compliance();
    let settings = solver.settings;
    let k = solver.kernels(&grid, &problem.gel, fidelity == Fidelity::Layer);
    // Cold start: the overlap over one cell's self-compliance, spread over the cells
    // across, so that the contact set starts as a superset and shrinks.
    let self_c = (gel_c + object_c)
        * influence::love_normal(0.0, 0.0, grid.cell_mm / 2.0)
        * (grid.nx.max(grid.ny) as f64);
    let cold = separation.iter().map(|s| {
        if s.is_finite() {
            (-s).max(0.0) / self_c
        } else {
            0.0
        }
    });
    // Warm start: the previous frame of a press grown the way a Hertz contact grows;
    // the cold guess when it had no contact to grow.
    let grown = warm
        .filter(|w| w.grid == grid && w.approach_mm > 0.0)
        .and_then(|w| {
            let ratio = problem.approach_mm / w.approach_mm;
            warm_start::hertz_grown(&grid, &w.pressure_mpa, ratio)
        });
    let start: Vec<f64> = grown.unwrap_or_else(|| cold.collect());
    let (conv, weighted) = k.weighted(gel_c, object_c);
    let outcome = polonsky_keer::solve(
        conv,
        &weighted.total_normal,
        &weighted.total_normal_preconditioner,
        separation,
        problem.approach_mm,
        start,
        settings,
    );
    if !outcome.converged {
        warnings.push(format!(
            "contact solver stopped after {} iterations without converging (residual {:.2e} of the approach)",
            outcome.iterations, outcome.residual
        ));
    }
    let p = outcome.pressure;
    // Pressure on the grid's rim, away from the pad edge, means the margin was too small.
    let r = grid.rect();
    let pad = problem.pad;
    let cut = [
        r.min.x <= pad.min.x + grid.cell_mm,
        r.max.x >= pad.max.x - grid.cell_mm,
        r.min.y <= pad.min.y + grid.cell_mm,
        r.max.y >= pad.max.y - grid.cell_mm,
    ];
    let on_rim = (0..grid.len()).any(|q| {
        let (i, j) = (q % grid.nx, q / grid.nx);
        p[q] > 0.0
            && ((i == 0 && !cut[0])
                || (i + 1 == grid.nx && !cut[1])
                || (j == 0 && !cut[2])
                || (j + 1 == grid.ny && !cut[3]))
    });
    if on_rim {
        warnings.push("the contact reached the edge of the solver grid".into());
    }
    let (gel, object_max) = kernel_fields(k, &grid, &p, gel_c, object_c, true);
    let mut s = ContactSolution::assemble(problem, fidelity, grid, p, gel, FieldModel::Kernel);
    s.object_max_indentation_mm = object_max;
    s.iterations = outcome.iterations;
    s.residual = outcome.residual;
    s
}

/// Gel normal and lateral fields from a pressure field by convolution with the kernels,
/// and (when `object_depth`) the object's largest indentation.
pub(super) fn kernel_fields(
    k: &mut GridKernels,
    grid: &Grid,
    pressure: &[f64],
    gel_c: f64,
    object_c: f64,
    object_depth: bool,
) -> (GelFields, f64) {
    let n = grid.len();
    let (conv, w) = k.weighted(gel_c, object_c);
    let spectrum = conv.spectrum(pressure);
    let (mut normal, mut lx, mut ly) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    conv.apply(&spectrum, &w.gel_normal, &mut normal);
    conv.apply(&spectrum, &w.gel_lateral[0], &mut lx);
    conv.apply(&spectrum, &w.gel_lateral[1], &mut ly);
    let object_max = match &w.object_normal {
        Some(kernel) if object_depth => {
            let mut object = vec![0.0; n];
            conv.apply(&spectrum, kernel, &mut object);
            object.into_iter().fold(0.0, f64::max)
        }
        _ => 0.0,
    };
    (
        GelFields {
            grid: *grid,
            normal_mm: normal,
            lateral_x_mm: lx,
            lateral_y_mm: ly,
        },
        object_max,
    )
}
