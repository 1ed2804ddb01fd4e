//! The 2-D cosine and sine transforms tactile perception filters a frame with (the glow read
//! backwards, the slopes integrated): on the frame's mirror extension, so nothing wraps
//! round its edges, and a quarter of the size of that extension's FFT.

use rustdct::DctPlanner;

thread_local! {
    /// Plans are kept per thread: a frame's reading runs several transforms of one size.
    static DCT_PLANNER: std::cell::RefCell<DctPlanner<f64>> = std::cell::RefCell::new(DctPlanner::new());
}

/// How an axis of an array is extended past its ends: mirrored (a cosine transform) or
/// mirrored with its sign flipped (a sine transform).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mirror {
    Even,
    Odd,
}

/// One axis's type-II transform of every line of `lines` (each `n` long) in place: the
/// cosine's sum x cos(pi u (2i + 1) / 2n), or the sine's sum x sin(pi u (2i + 1) / 2n), at
/// u = 0..n (the sine's u = 0 is zero, its u = n left out).
fn transform_lines(lines: &mut [f64], n: usize, mirror: Mirror) {
    let plan = DCT_PLANNER.with_borrow_mut(|planner| match mirror {
        Mirror::Even => planner.plan_dct2(n),
        Mirror::Odd => planner.plan_dst2(n),
    });
    let mut scratch = vec![0.0; plan.get_scratch_len()];
    for line in lines.chunks_exact_mut(n) {
        match mirror {
            Mirror::Even => plan.process_dct2_with_scratch(line, &mut scratch),
            Mirror::Odd => {
                plan.process_dst2_with_scratch(line, &mut scratch);
                // The sine transform's output j is frequency j + 1.
                line.rotate_right(1);
                line[0] = 0.0;
            }
        }
    }
}

/// The 2-D type-II transform of a row-major `nx` x `ny` array extended by `along_x` past its
/// left and right ends and by `along_y` past its top and bottom (unnormalised), left
/// transposed: coefficient (u, v) at `u * ny + v`. Frequency (u, v) is frequency (u, v) of
/// the FFT of the array's mirror extension (2 nx x 2 ny), up to a phase, so a filter real and
/// even in frequency acts on each coefficient alone, at a quarter of the transform's size.
pub fn mirror_transform(
    data: &[f64],
    nx: usize,
    ny: usize,
    along_x: Mirror,
    along_y: Mirror,
) -> Vec<f64> {
    let mut along = data.to_vec();
    transform_lines(&mut along, nx, along_x);
    let mut out = vec![0.0; data.len()];
    transpose::transpose(&along, &mut out, nx, ny);
    transform_lines(&mut out, ny, along_y);
    out
}

/// The 2-D DCT-II of a row-major `nx` x `ny` array (`mirror_transform` of an array mirrored
/// evenly both ways).
pub fn dct2_2d(data: &[f64], nx: usize, ny: usize) -> Vec<f64> {
    mirror_transform(data, nx, ny, Mirror::Even, Mirror::Even)
}

/// The inverse of `dct2_2d`: its transposed coefficients back to the row-major array.
pub fn idct2_2d(coefficients: &[f64], nx: usize, ny: usize) -> Vec<f64> {
    let (rows, columns) =
        DCT_PLANNER.with_borrow_mut(|planner| (planner.plan_dct3(nx), planner.plan_dct3(ny)));
    let mut along = coefficients.to_vec();
    let mut scratch = vec![0.0; rows.get_scratch_len().max(columns.get_scratch_len())];
    for column in along.chunks_exact_mut(ny) {
        columns.process_dct3_with_scratch(column, &mut scratch);
    }
    let mut out = vec![0.0; coefficients.len()];
    transpose::transpose(&along, &mut out, ny, nx);
    // A DCT-III after a DCT-II gives N / 2 times the signal along each axis.
    let scale = 4.0 / (nx * ny) as f64;
    for row in out.chunks_exact_mut(nx) {
        rows.process_dct3_with_scratch(row, &mut scratch);
        row.iter_mut().for_each(|v| *v *= scale);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use rustdct::rustfft::num_complex::Complex;

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

    /// The DFT of `data`'s mirror extension (odd or even across its left and right ends, even
    /// across top and bottom) at (u, v) < (nx, ny), at u * ny + v, with the half-sample phase
    /// e^(-i pi (u / 2nx + v / 2ny)) taken out.
    fn mirror_spectrum(data: &[f64], nx: usize, ny: usize, along_x: Mirror) -> Vec<Complex<f64>> {
        let mut mirrored = vec![Complex::new(0.0, 0.0); 4 * nx * ny];
        for y in 0..2 * ny {
            for x in 0..2 * nx {
                let sign = if x >= nx && along_x == Mirror::Odd {
                    -1.0
                } else {
                    1.0
                };
                let (xx, yy) = (x.min(2 * nx - 1 - x), y.min(2 * ny - 1 - y));
                mirrored[y * 2 * nx + x] = Complex::new(sign * data[yy * nx + xx], 0.0);
            }
        }
        let spectrum = dft2(&mirrored, 2 * nx, 2 * ny);
        let tau = 2.0 * std::f64::consts::PI;
        let mut out = Vec::with_capacity(nx * ny);
        for u in 0..nx {
            for v in 0..ny {
                let phase = tau * (u as f64 / (4 * nx) as f64 + v as f64 / (4 * ny) as f64);
                out.push(spectrum[v * 2 * nx + u] * Complex::new(phase.cos(), -phase.sin()));
            }
        }
        out
    }

    #[test]
    fn a_cosine_transform_is_the_mirror_extensions_fft_and_comes_back() {
        let (nx, ny) = (6, 5);
        let data = signal(nx, ny, 0.9);
        let coefficients = dct2_2d(&data, nx, ny);
        let spectrum = mirror_spectrum(&data, nx, ny, Mirror::Even);
        for u in 0..nx {
            for v in 0..ny {
                // X(u, v) = 4 e^(i pi u / 2nx) e^(i pi v / 2ny) C(u, v).
                let want = spectrum[u * ny + v];
                let got = 4.0 * coefficients[u * ny + v];
                assert!((want - got).norm() < 1e-9, "({u}, {v}): {want} vs {got}");
            }
        }
        for (a, b) in idct2_2d(&coefficients, nx, ny).iter().zip(&data) {
            assert!((a - b).abs() < 1e-12);
        }
    }

    #[test]
    fn a_sine_transform_is_the_odd_mirror_extensions_fft() {
        let (nx, ny) = (5, 4);
        let data = signal(nx, ny, 1.7);
        let coefficients = mirror_transform(&data, nx, ny, Mirror::Odd, Mirror::Even);
        let spectrum = mirror_spectrum(&data, nx, ny, Mirror::Odd);
        for u in 0..nx {
            for v in 0..ny {
                // X(u, v) = -2i e^(i pi u / 2nx) 2 e^(i pi v / 2ny) S(u, v).
                let want = spectrum[u * ny + v];
                let got = Complex::new(0.0, -4.0 * coefficients[u * ny + v]);
                assert!((want - got).norm() < 1e-9, "({u}, {v}): {want} vs {got}");
            }
        }
    }
}
