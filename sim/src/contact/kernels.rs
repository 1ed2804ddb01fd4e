//! Spectra of the unit-compliance influence coefficients for one grid, cached by the solver:
//! the half-space normal and lateral responses and, for the layer, its corrections.

use super::convolution::{Convolver, Spectrum, wrapped_kernel};
use super::grid::Grid;
use super::influence::{CellResponse, LayerCorrection, half_space_cells, layer_cell_correction};
use super::polonsky_keer;
use rayon::prelude::*;
use rustfft::num_complex::Complex;

/// The spectra for one grid shape and cell, one Poisson ratio, and optionally one layer.
pub struct GridKernels {
    pub conv: Convolver,
    pub half_space_normal: Spectrum,
    pub half_space_lateral: [Spectrum; 2],
    /// Layer minus half-space, when the gel is a bonded layer.
    pub layer_normal: Option<Spectrum>,
    pub layer_lateral: Option<[Spectrum; 2]>,
    /// The spectra weighted by the last pair of compliances asked for: every frame of a
    /// press asks for the same pair, and weighting them anew cost as much as a convolution.
    weighted: Option<Weighted>,
}

/// The influence spectra times one pair of compliances (1/MPa).
pub struct Weighted {
    key: (u64, u64),
    /// Gap closure per unit pressure, gel and object together: what the solve inverts.
    pub total_normal: Spectrum,
    /// Its reciprocal, which preconditions the solve.
    pub total_normal_preconditioner: Spectrum,
    pub gel_normal: Spectrum,
    pub gel_lateral: [Spectrum; 2],
    /// The object's own indentation; None for a rigid object.
    pub object_normal: Option<Spectrum>,
}

/// Identifies a `GridKernels`: grid shape, cell and material (bits of the f64s).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct KernelKey {
    nx: usize,
    ny: usize,
    cell: u64,
    poisson: u64,
    thickness: Option<u64>,
}

impl KernelKey {
    pub fn new(grid: &Grid, poisson: f64, thickness_mm: Option<f64>) -> Self {
        Self {
            nx: grid.nx,
            ny: grid.ny,
            cell: grid.cell_mm.to_bits(),
            poisson: poisson.to_bits(),
            thickness: thickness_mm.map(f64::to_bits),
        }
    }
}

/// Evaluates the responses for all offsets once, using their symmetry: normal even in both
/// axes, lateral x odd in x and even in y, lateral y the reverse. The layer's part is what
/// it adds to the half-space's.
fn responses(
    grid: &Grid,
    poisson: f64,
    layer: Option<&LayerCorrection>,
) -> (Vec<CellResponse>, Vec<CellResponse>) {
    let (nx, ny, cell) = (grid.nx, grid.ny, grid.cell_mm);
    let half_space = half_space_cells(nx, ny, cell, poisson);
    let with_layer = match layer {
        Some(layer) => (0..nx * ny)
            .into_par_iter()
            .map(|k| {
                let (x, y) = ((k % nx) as f64 * cell, (k / nx) as f64 * cell);
                layer_cell_correction(x, y, cell, layer)
            })
            .collect(),
        None => Vec::new(),
    };
    (half_space, with_layer)
}

fn spectra(conv: &mut Convolver, table: &[CellResponse]) -> (Spectrum, [Spectrum; 2]) {
    let (nx, ny) = (conv.nx, conv.ny);
    let at = |di: i64, dj: i64| table[dj.unsigned_abs() as usize * nx + di.unsigned_abs() as usize];
    let normal = wrapped_kernel(nx, ny, |di, dj| at(di, dj).normal);
    let lx = wrapped_kernel(nx, ny, |di, dj| di.signum() as f64 * at(di, dj).lateral_x);
    let ly = wrapped_kernel(nx, ny, |di, dj| dj.signum() as f64 * at(di, dj).lateral_y);
    (
        conv.padded_spectrum(&normal),
        [conv.padded_spectrum(&lx), conv.padded_spectrum(&ly)],
    )
}

impl GridKernels {
    pub fn new(grid: &Grid, poisson: f64, layer: Option<&LayerCorrection>) -> Self {
        let mut conv = Convolver::new(grid.nx, grid.ny);
        let (half_space, with_layer) = responses(grid, poisson, layer);
        let (half_space_normal, half_space_lateral) = spectra(&mut conv, &half_space);
        let (layer_normal, layer_lateral) = if layer.is_some() {
            let (n, l) = spectra(&mut conv, &with_layer);
            (Some(n), Some(l))
        } else {
            (None, None)
        };
        Self {
            conv,
            half_space_normal,
            half_space_lateral,
            layer_normal,
            layer_lateral,
            weighted: None,
        }
    }

    /// The spectra for gel compliance `gel_c` and object compliance `object_c`, with the
    /// FFT plans to apply them.
    pub fn weighted(&mut self, gel_c: f64, object_c: f64) -> (&mut Convolver, &Weighted) {
        let key = (gel_c.to_bits(), object_c.to_bits());
        if self.weighted.as_ref().is_none_or(|w| w.key != key) {
            let layer = |base: &Spectrum, correction: Option<&Spectrum>| match correction {
                Some(c) => combine(&[(gel_c, base), (gel_c, c)]),
                None => combine(&[(gel_c, base)]),
            };
            let mut total = vec![(gel_c + object_c, &self.half_space_normal)];
            if let Some(l) = &self.layer_normal {
                total.push((gel_c, l));
            }
            let lateral = self.layer_lateral.as_ref();
            let total_normal = combine(&total);
            self.weighted = Some(Weighted {
                key,
                total_normal_preconditioner: polonsky_keer::preconditioner(&total_normal),
                total_normal,
                gel_normal: layer(&self.half_space_normal, self.layer_normal.as_ref()),
                gel_lateral: [
                    layer(&self.half_space_lateral[0], lateral.map(|l| &l[0])),
                    layer(&self.half_space_lateral[1], lateral.map(|l| &l[1])),
                ],
                object_normal: (object_c > 0.0)
                    .then(|| combine(&[(object_c, &self.half_space_normal)])),
            });
        }
        (
            &mut self.conv,
            self.weighted.as_ref().expect("weighted above"),
        )
    }
}

/// sum_i w_i S_i over spectra of one shape.
fn combine(terms: &[(f64, &Spectrum)]) -> Spectrum {
    let len = terms[0].1.0.len();
    let mut out = vec![Complex::default(); len];
    for (w, s) in terms {
        if *w == 0.0 {
            continue;
        }
        for (o, v) in out.iter_mut().zip(&s.0) {
            *o += v * *w;
        }
    }
    Spectrum(out)
}
