//! The 2-D FFT both sides need: the twin's layer transfer functions (sim) and the slope
//! integration of tactile perception (core).

use rustfft::FftPlanner;
use rustfft::num_complex::Complex;

thread_local! {
    /// Plans are kept per thread: a frame's reading runs several transforms of one size.
    static PLANNER: std::cell::RefCell<FftPlanner<f64>> = std::cell::RefCell::new(FftPlanner::new());
}

/// 2-D FFT in place (row-major nx x ny); the inverse is unnormalised. The columns are
/// transformed as rows of the transposed array, all in one call: a column walked in place
/// touches a cache line per element.
pub fn fft2(data: &mut [Complex<f64>], nx: usize, ny: usize, inverse: bool) {
    let (row, col) = PLANNER.with_borrow_mut(|planner| {
        if inverse {
            (planner.plan_fft_inverse(nx), planner.plan_fft_inverse(ny))
        } else {
            (planner.plan_fft_forward(nx), planner.plan_fft_forward(ny))
        }
    });
    let scratch_len = row
        .get_inplace_scratch_len()
        .max(col.get_inplace_scratch_len());
    let mut scratch = vec![Complex::default(); scratch_len];
    row.process_with_scratch(data, &mut scratch);
    let mut columns = vec![Complex::default(); data.len()];
    transpose::transpose(data, &mut columns, nx, ny);
    col.process_with_scratch(&mut columns, &mut scratch);
    transpose::transpose(&columns, data, ny, nx);
}

/// The spectra at index `k` of two real arrays `a` and `b` from the spectrum `f` of `a + i b`
/// (row-major nx x ny): A[k] = (F[k] + conj F[-k]) / 2 and B[k] = (F[k] - conj F[-k]) / 2i.
/// Two real transforms for the price of one.
pub fn real_pair_at(
    f: &[Complex<f64>],
    nx: usize,
    ny: usize,
    k: usize,
) -> (Complex<f64>, Complex<f64>) {
    let (u, v) = (k % nx, k / nx);
    let mirror = ((ny - v) % ny) * nx + (nx - u) % nx;
    let (fk, fm) = (f[k], f[mirror].conj());
    let a = (fk + fm) * 0.5;
    let d = (fk - fm) * 0.5;
    // d / i = -i d
    (a, Complex::new(d.im, -d.re))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The direct DFT, for checking the fast one against.
    fn dft2(data: &[Complex<f64>], nx: usize, ny: usize) -> Vec<Complex<f64>> {
        let tau = 2.0 * std::f64::consts::PI;
        (0..nx * ny)
            .map(|k| {
                let (u, v) = ((k % nx) as f64, (k / nx) as f64);
                data.iter()
                    .enumerate()
                    .map(|(i, d)| {
                        let (x, y) = ((i % nx) as f64, (i / nx) as f64);
                        let phase = -tau * (u * x / nx as f64 + v * y / ny as f64);
                        d * Complex::new(phase.cos(), phase.sin())
                    })
                    .sum()
            })
            .collect()
    }

    fn signal(nx: usize, ny: usize, seed: f64) -> Vec<f64> {
        (0..nx * ny)
            .map(|i| (i as f64 * 0.37 + seed).sin() * 3.0 + (i as f64 * seed).cos())
            .collect()
    }

    #[test]
    fn fft2_matches_the_direct_dft_on_a_rectangle() {
        let (nx, ny) = (6, 10);
        let data: Vec<Complex<f64>> = signal(nx, ny, 1.3)
            .into_iter()
            .zip(signal(nx, ny, 0.7))
            .map(|(re, im)| Complex::new(re, im))
            .collect();
        let direct = dft2(&data, nx, ny);
        let mut fast = data.clone();
        fft2(&mut fast, nx, ny, false);
        for (a, b) in fast.iter().zip(&direct) {
            assert!((a - b).norm() < 1e-9, "{a} vs {b}");
        }
        fft2(&mut fast, nx, ny, true);
        for (a, b) in fast.iter().zip(&data) {
            assert!((a / (nx * ny) as f64 - b).norm() < 1e-12);
        }
    }

    #[test]
    fn a_pair_of_real_arrays_is_split_from_one_transform() {
        let (nx, ny) = (8, 5);
        let (a, b) = (signal(nx, ny, 2.1), signal(nx, ny, 0.4));
        let mut packed: Vec<Complex<f64>> = a
            .iter()
            .zip(&b)
            .map(|(&re, &im)| Complex::new(re, im))
            .collect();
        fft2(&mut packed, nx, ny, false);
        let real = |s: &[f64]| s.iter().map(|&v| Complex::new(v, 0.0)).collect::<Vec<_>>();
        let (fa, fb) = (dft2(&real(&a), nx, ny), dft2(&real(&b), nx, ny));
        for k in 0..nx * ny {
            let (sa, sb) = real_pair_at(&packed, nx, ny, k);
            assert!((sa - fa[k]).norm() < 1e-9 && (sb - fb[k]).norm() < 1e-9);
        }
    }
}
