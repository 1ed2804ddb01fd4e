//! The `rigid` level: the object's heightmap clipped at the gel surface and smoothed, the
//! gel taking the whole approach (what TACTO, Taxim and FOTS do); pressure from a Winkler
//! bed p = E_gel w / h. Hardness-blind: the baseline to beat.

use super::fidelity::Fidelity;
use super::grid::Grid;
use super::problem::ContactProblem;
use super::solution::{ContactSolution, FieldModel, GelFields};

/// Smoothing of the `rigid` level's imprint (mm), of the order the peers' Gaussian kernels.
pub const RIGID_SMOOTHING_MM: f64 = 0.25;
pub(super) fn solve(problem: &ContactProblem, grid: Grid, separation: &[f64]) -> ContactSolution {
    let imprint: Vec<f64> = separation
        .iter()
        .map(|s| if s.is_finite() { (-s).max(0.0) } else { 0.0 })
        .collect();
    let normal = gaussian_blur(
        &imprint,
        grid.nx,
        grid.ny,
        RIGID_SMOOTHING_MM / grid.cell_mm,
    );
    let stiffness = problem.gel.modulus_mpa / problem.gel.thickness_mm;
    let pressure: Vec<f64> = imprint.iter().map(|w| stiffness * w).collect();
    let zeros = vec![0.0; grid.len()];
    let gel = GelFields {
        grid,
        normal_mm: normal,
        lateral_x_mm: zeros.clone(),
        lateral_y_mm: zeros,
    };
    ContactSolution::assemble(
        problem,
        Fidelity::Rigid,
        grid,
        pressure,
        gel,
        FieldModel::Embedded,
    )
}

/// Separable Gaussian blur with zero padding.
fn gaussian_blur(field: &[f64], nx: usize, ny: usize, sigma_cells: f64) -> Vec<f64> {
    if sigma_cells < 1e-3 {
        return field.to_vec();
    }
    let radius = ((3.0 * sigma_cells).ceil() as usize).min(nx.max(ny));
    let taps: Vec<f64> = (0..=radius)
        .map(|k| (-(k as f64).powi(2) / (2.0 * sigma_cells * sigma_cells)).exp())
        .collect();
    let norm = taps[0] + 2.0 * taps[1..].iter().sum::<f64>();
    let blur = |src: &[f64], len: usize, stride: usize, count: usize, step: usize| {
        let mut out = vec![0.0; src.len()];
        for line in 0..count {
            for i in 0..len {
                let mut acc = 0.0;
                for (k, w) in taps.iter().enumerate() {
                    if i >= k {
                        acc += w * src[line * step + (i - k) * stride];
                    }
                    if k > 0 && i + k < len {
                        acc += w * src[line * step + (i + k) * stride];
                    }
                }
                out[line * step + i * stride] = acc / norm;
            }
        }
        out
    };
    let rows = blur(field, nx, 1, ny, nx);
    blur(&rows, ny, nx, nx, 1)
}
