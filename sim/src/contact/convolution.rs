//! DC-FFT (Liu, Wang & Liu 2000): the linear, non-periodic convolution of a field on an
//! nx x ny grid with influence coefficients, by zero-padding both to 2nx x 2ny and
//! multiplying spectra. Real-to-complex FFTs along rows (realfft) and complex FFTs along
//! the columns of the half spectrum, stored transposed so the column transforms are
//! contiguous.

use realfft::{ComplexToReal, RealFftPlanner, RealToComplex};
use rustfft::num_complex::Complex;
use rustfft::{Fft, FftPlanner};
use std::sync::Arc;

/// A spectrum on the padded grid: (nx + 1) half-spectrum columns, each 2ny long.
#[derive(Clone)]
pub struct Spectrum(pub Vec<Complex<f64>>);

/// FFT plans and scratch for one grid size.
pub struct Convolver {
    pub nx: usize,
    pub ny: usize,
    r2c: Arc<dyn RealToComplex<f64>>,
    c2r: Arc<dyn ComplexToReal<f64>>,
    col_fwd: Arc<dyn Fft<f64>>,
    col_inv: Arc<dyn Fft<f64>>,
    row: Vec<f64>,
    half: Vec<Complex<f64>>,
    /// Row-major half spectra of the ny field rows, (nx + 1) each.
    half_rows: Vec<Complex<f64>>,
    work: Vec<Complex<f64>>,
    scratch: Vec<Complex<f64>>,
}

impl Convolver {
    pub fn new(nx: usize, ny: usize) -> Self {
        let mut real = RealFftPlanner::<f64>::new();
        let mut complex = FftPlanner::<f64>::new();
        let r2c = real.plan_fft_forward(2 * nx);
        let c2r = real.plan_fft_inverse(2 * nx);
        let col_fwd = complex.plan_fft_forward(2 * ny);
        let col_inv = complex.plan_fft_inverse(2 * ny);
        let scratch_len = col_fwd
            .get_inplace_scratch_len()
            .max(col_inv.get_inplace_scratch_len())
            .max(r2c.get_scratch_len())
            .max(c2r.get_scratch_len());
        Self {
            nx,
            ny,
            row: vec![0.0; 2 * nx],
            half: vec![Complex::default(); nx + 1],
            half_rows: vec![Complex::default(); (nx + 1) * ny],
            work: vec![Complex::default(); (nx + 1) * 2 * ny],
            scratch: vec![Complex::default(); scratch_len],
            r2c,
            c2r,
            col_fwd,
            col_inv,
        }
    }

    fn columns(&self) -> usize {
        self.nx + 1
    }

    /// Spectrum of a field given on the padded 2nx x 2ny grid (row-major), e.g. wrapped
    /// influence coefficients.
    pub fn padded_spectrum(&mut self, padded: &[f64]) -> Spectrum {
        let (nx2, ny2) = (2 * self.nx, 2 * self.ny);
        assert_eq!(padded.len(), nx2 * ny2);
        self.forward_rows(|row, j| row.copy_from_slice(&padded[j * nx2..(j + 1) * nx2]));
        Spectrum(self.work.clone())
    }

    /// Spectrum of a field on the nx x ny grid, zero-padded.
    pub fn spectrum(&mut self, field: &[f64]) -> Spectrum {
        let mut out = Spectrum(Vec::new());
        self.spectrum_into(field, &mut out);
        out
    }

    fn spectrum_into(&mut self, field: &[f64], out: &mut Spectrum) {
        self.forward_field(field);
        out.0.clone_from(&self.work);
    }

    /// The zero-padded field's spectrum into `work`: real FFTs of the ny field rows (the
    /// padding rows are zero), a blocked transpose, then the column FFTs.
    fn forward_field(&mut self, field: &[f64]) {
        let (nx, ny) = (self.nx, self.ny);
        assert_eq!(field.len(), nx * ny);
        let columns = nx + 1;
        for j in 0..ny {
            let src = &field[j * nx..(j + 1) * nx];
            let dst = &mut self.half_rows[j * columns..(j + 1) * columns];
            if src.iter().all(|v| *v == 0.0) {
                dst.fill(Complex::default());
                continue;
            }
            self.row[..nx].copy_from_slice(src);
            self.row[nx..].fill(0.0);
            self.r2c
                .process_with_scratch(&mut self.row, dst, &mut self.scratch)
                .expect("buffer sizes come from the plan");
        }
        let ny2 = 2 * ny;
        transpose(&self.half_rows, columns, &mut self.work, ny2, ny, columns);
        for c in 0..columns {
            self.work[c * ny2 + ny..(c + 1) * ny2].fill(Complex::default());
        }
        self.col_fwd
            .process_with_scratch(&mut self.work, &mut self.scratch);
    }

    /// Linear convolution of `field` with `kernel` without keeping the field's spectrum.
    pub fn convolve(&mut self, field: &[f64], kernel: &Spectrum, out: &mut [f64]) {
        self.forward_field(field);
        for (w, b) in self.work.iter_mut().zip(&kernel.0) {
            *w *= b;
        }
        self.inverse_into(out);
    }

    fn forward_rows(&mut self, fill: impl Fn(&mut [f64], usize)) {
        let ny2 = 2 * self.ny;
        let columns = self.columns();
        for j in 0..ny2 {
            fill(&mut self.row, j);
            if self.row.iter().all(|v| *v == 0.0) {
                for c in 0..columns {
                    self.work[c * ny2 + j] = Complex::default();
                }
                continue;
            }
            self.r2c
                .process_with_scratch(&mut self.row, &mut self.half, &mut self.scratch)
                .expect("buffer sizes come from the plan");
            for (c, v) in self.half.iter().enumerate() {
                self.work[c * ny2 + j] = *v;
            }
        }
        self.col_fwd
            .process_with_scratch(&mut self.work, &mut self.scratch);
    }

    /// The product of spectra transformed back and cropped to the nx x ny grid, written to
    /// `out`: the linear convolution of the field with the kernel.
    pub fn apply(&mut self, field: &Spectrum, kernel: &Spectrum, out: &mut [f64]) {
        for ((w, a), b) in self.work.iter_mut().zip(&field.0).zip(&kernel.0) {
            *w = a * b;
        }
        self.inverse_into(out);
    }

    fn inverse_into(&mut self, out: &mut [f64]) {
        let (nx, ny) = (self.nx, self.ny);
        let (ny2, columns) = (2 * ny, nx + 1);
        self.col_inv
            .process_with_scratch(&mut self.work, &mut self.scratch);
        // Only the first ny rows of the padded result are the linear convolution.
        transpose(&self.work, ny2, &mut self.half_rows, columns, columns, ny);
        let norm = 1.0 / (4 * nx * ny) as f64;
        for j in 0..ny {
            let half = &mut self.half_rows[j * columns..(j + 1) * columns];
            // The half spectrum of a real signal has real DC and Nyquist bins; rounding can
            // leave a tiny imaginary part that realfft rejects.
            half[0].im = 0.0;
            half[nx].im = 0.0;
            self.c2r
                .process_with_scratch(half, &mut self.row, &mut self.scratch)
                .expect("buffer sizes come from the plan");
            for (o, v) in out[j * nx..(j + 1) * nx].iter_mut().zip(&self.row) {
                *o = v * norm;
            }
        }
    }
}

/// dst[c * dst_stride + r] = src[r * src_stride + c] for r < rows, c < cols, in tiles
/// that stay in cache.
fn transpose(
    src: &[Complex<f64>],
    src_stride: usize,
    dst: &mut [Complex<f64>],
    dst_stride: usize,
    rows: usize,
    cols: usize,
) {
    const TILE: usize = 16;
    for r0 in (0..rows).step_by(TILE) {
        for c0 in (0..cols).step_by(TILE) {
            for r in r0..(r0 + TILE).min(rows) {
                for c in c0..(c0 + TILE).min(cols) {
                    dst[c * dst_stride + r] = src[r * src_stride + c];
                }
            }
        }
    }
}

/// Lays out influence coefficients `coefficient(di, dj)` for offsets |di| < nx, |dj| < ny in
/// the wrap-around order DC-FFT needs (offset -d at index 2n - d; index n stays zero).
pub fn wrapped_kernel(nx: usize, ny: usize, coefficient: impl Fn(i64, i64) -> f64) -> Vec<f64> {
    let (nx2, ny2) = (2 * nx, 2 * ny);
    let mut out = vec![0.0; nx2 * ny2];
    for j in 0..ny2 {
        if j == ny {
            continue;
        }
        let dj = if j < ny {
            j as i64
        } else {
            j as i64 - ny2 as i64
        };
        for i in 0..nx2 {
            if i == nx {
                continue;
            }
            let di = if i < nx {
                i as i64
            } else {
                i as i64 - nx2 as i64
            };
            out[j * nx2 + i] = coefficient(di, dj);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn matches_a_direct_linear_convolution() {
        let (nx, ny) = (5, 3);
        let field: Vec<f64> = (0..nx * ny).map(|k| ((k * 7) % 5) as f64 - 1.5).collect();
        let coefficient =
            |di: i64, dj: i64| 1.0 / (1.0 + (di * di + 2 * dj * dj) as f64) + 0.1 * di as f64;
        let mut conv = Convolver::new(nx, ny);
        let kernel = conv.padded_spectrum(&wrapped_kernel(nx, ny, coefficient));
        let mut out = vec![0.0; nx * ny];
        conv.convolve(&field, &kernel, &mut out);
        for j in 0..ny {
            for i in 0..nx {
                let mut direct = 0.0;
                for q in 0..ny {
                    for p in 0..nx {
                        direct += field[q * nx + p]
                            * coefficient(i as i64 - p as i64, j as i64 - q as i64);
                    }
                }
                assert!((out[j * nx + i] - direct).abs() < 1e-12, "({i},{j})");
            }
        }
    }
}
