//! Lateral surface displacement of the gel layer from its normal indentation, through the
//! bonded layer's per-mode response (core's `layer_compliance`).

use rustfft::num_complex::Complex;
use tactex_core::layer_compliance::lateral_ratio;
use tactex_core::spectral::fft2;

/// Lateral surface displacement (x, y) of the layer for the normal indentation field
/// `normal` (row-major nx x ny, cell `cell_mm`), periodic.
pub fn lateral_displacement(
    normal: &[f64],
    nx: usize,
    ny: usize,
    cell_mm: f64,
    thickness_mm: f64,
    nu: f64,
) -> (Vec<f64>, Vec<f64>) {
    let mut spectrum: Vec<Complex<f64>> = normal.iter().map(|v| Complex::new(*v, 0.0)).collect();
    fft2(&mut spectrum, nx, ny, false);
    let freq = |i: usize, n: usize| {
        let i = if i < n.div_ceil(2) {
            i as f64
        } else {
            i as f64 - n as f64
        };
        2.0 * std::f64::consts::PI * i / (n as f64 * cell_mm)
    };
    let mut ux = vec![Complex::default(); nx * ny];
    let mut uy = vec![Complex::default(); nx * ny];
    for j in 0..ny {
        let ky = freq(j, ny);
        for i in 0..nx {
            let kx = freq(i, nx);
            let k = kx.hypot(ky);
            if k == 0.0 {
                continue;
            }
            // u = -i T (k_vec / |k|) w_hat: a cosine bump moves material along +sin.
            let t = lateral_ratio(k * thickness_mm, nu);
            let w = spectrum[j * nx + i];
            let rotated = Complex::new(w.im, -w.re) * t;
            ux[j * nx + i] = rotated * (kx / k);
            uy[j * nx + i] = rotated * (ky / k);
        }
    }
    fft2(&mut ux, nx, ny, true);
    fft2(&mut uy, nx, ny, true);
    let norm = 1.0 / (nx * ny) as f64;
    (
        ux.iter().map(|c| c.re * norm).collect(),
        uy.iter().map(|c| c.re * norm).collect(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_bump_on_a_thin_incompressible_layer_pushes_material_outward() {
        let n = 64;
        let cell = 0.1;
        let normal: Vec<f64> = (0..n * n)
            .map(|k| {
                let (x, y) = ((k % n) as f64 - 32.0, (k / n) as f64 - 32.0);
                0.1 * (-(x * x + y * y) * cell * cell / 0.5).exp()
            })
            .collect();
        let (ux, uy) = lateral_displacement(&normal, n, n, cell, 1.0, 0.49);
        assert!(
            ux[32 * n + 40] > 0.0 && ux[32 * n + 24] < 0.0,
            "outward along x"
        );
        assert!(
            uy[40 * n + 32] > 0.0 && uy[24 * n + 32] < 0.0,
            "outward along y"
        );
    }
}
