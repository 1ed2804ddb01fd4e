//! Surface response of an elastic layer of thickness h bonded to a rigid base, with a
//! frictionless top, to normal surface loading, per Fourier mode of wavenumber k.
//!
//! Derived from the plane-strain Airy stress function f(z) = (A + Bz) cosh kz + (C + Dz) sinh kz
//! with u = w = 0 at the base and sigma_zz = -p cos kx, sigma_xz = 0 on top (derivation
//! checked symbolically). With s = sinh kh, c = cosh kh:
//!
//! * lateral / normal surface displacement (positive = away from the indentation):
//!   T(kh) = [(kh)^2 - (1 - 2nu)(3 - 4nu) s^2] / [2 (1 - nu) ((3 - 4nu) s c - kh)]
//! * normal compliance relative to the half-space 2 (1 - nu^2) / (E k):
//!   K(kh) = ((3 - 4nu) s c - kh) / ((kh)^2 + 4 (1 - nu)^2 c^2 - (1 - 2nu)^2 s^2)
//!
//! For kh -> infinity both reach the half-space: T -> -(1 - 2nu) / (2 (1 - nu)) (Johnson's
//! inward surface motion) and K -> 1. A thin near-incompressible gel squeezes outwards
//! (T > 1 near kh ~ 0.3 for nu = 0.49): that is why real GelSight markers move outward.
//! Both are evaluated with tanh and sech^2 so that large kh cannot overflow.

use rustfft::num_complex::Complex;
use tactex_core::spectral::fft2;

fn tanh_sech2(kh: f64) -> (f64, f64) {
    let e = (-2.0 * kh).exp();
    ((1.0 - e) / (1.0 + e), 4.0 * e / ((1.0 + e) * (1.0 + e)))
}

/// Lateral-to-normal surface displacement ratio of the bonded layer.
pub fn lateral_ratio(kh: f64, nu: f64) -> f64 {
    if kh <= 0.0 {
        return 0.0;
    }
    let (th, sech2) = tanh_sech2(kh);
    let num = kh * kh * sech2 - (1.0 - 2.0 * nu) * (3.0 - 4.0 * nu) * th * th;
    let den = 2.0 * (1.0 - nu) * ((3.0 - 4.0 * nu) * th - kh * sech2);
    if den.abs() < 1e-300 { 0.0 } else { num / den }
}

/// Normal compliance of the bonded layer relative to the half-space.
pub fn normal_compliance_ratio(kh: f64, nu: f64) -> f64 {
    if kh <= 0.0 {
        return 0.0;
    }
    let (th, sech2) = tanh_sech2(kh);
    let num = (3.0 - 4.0 * nu) * th - kh * sech2;
    let den = kh * kh * sech2 + 4.0 * (1.0 - nu).powi(2) - (1.0 - 2.0 * nu).powi(2) * th * th;
    num / den
}

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
    fn thick_layer_tends_to_the_half_space() {
        for nu in [0.0, 0.3, 0.49] {
            let half_space = -(1.0 - 2.0 * nu) / (2.0 * (1.0 - nu));
            assert!(
                (lateral_ratio(60.0, nu) - half_space).abs() < 1e-9,
                "nu {nu}"
            );
            assert!((normal_compliance_ratio(60.0, nu) - 1.0).abs() < 1e-9);
            assert!(
                lateral_ratio(1e6, nu).is_finite() && normal_compliance_ratio(1e6, nu).is_finite()
            );
        }
    }

    #[test]
    fn matches_the_symbolic_solution_at_sample_points() {
        // Values from the sympy solution of the layer problem (see module docs).
        let cases = [
            (0.3, 0.5, 0.06979279783946649, 0.20664248636698512),
            (0.49, 1.0, 1.0747896366951155, 0.25482692515035976),
            (0.49, 2.0, 0.2996801461380801, 0.6511919568440806),
        ];
        for (nu, kh, t, k) in cases {
            assert!((lateral_ratio(kh, nu) - t).abs() < 1e-9, "T({kh}, {nu})");
            assert!(
                (normal_compliance_ratio(kh, nu) - k).abs() < 1e-9,
                "K({kh}, {nu})"
            );
        }
    }

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
