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

/// Centre displacement of the bonded layer under a Hertz pressure of contact radius a,
/// relative to the half-space's, for a / h = `contact_over_thickness`. This is how much
/// stiffer a thin gel is than the half-space formula thinks, at the contact size in play.
///
/// The Hankel transform of p0 sqrt(1 - r^2/a^2) is p0 a^2 j1(ka) / (ka), whose integral over
/// k is p0 a pi / 4, so the ratio is 1 - (4 / pi) int_0^inf j1(x)/x (1 - K(x h/a)) dx: the
/// layer's surface (`layer_surface_under_hertz`) at the centre.
fn hertz_centre_compliance_ratio(contact_over_thickness: f64, nu: f64) -> f64 {
    let aoh = contact_over_thickness;
    if aoh.is_nan() || aoh <= 0.0 {
        return 1.0;
    }
    layer_surface_under_hertz(0.0, aoh, nu)
}

/// Bessel's J0 (Abramowitz and Stegun 9.4.1 and 9.4.3: within 5e-8 for |x| <= 3, 1.6e-8
/// of the amplitude beyond).
fn bessel_j0(x: f64) -> f64 {
    let ax = x.abs();
    if ax <= 3.0 {
        let y = (x / 3.0).powi(2);
        1.0 + y
            * (-2.2499997
                + y * (1.2656208
                    + y * (-0.3163866 + y * (0.0444479 + y * (-0.0039444 + y * 0.0002100)))))
    } else {
        let y = 3.0 / ax;
        let f0 = 0.79788456
            + y * (-0.00000077
                + y * (-0.00552740
                    + y * (-0.00009512 + y * (0.00137237 + y * (-0.00072805 + y * 0.00014476)))));
        let t0 = ax - std::f64::consts::FRAC_PI_4
            + y * (-0.04166397
                + y * (-0.00003954
                    + y * (0.00262573 + y * (-0.00054125 + y * (-0.00029333 + y * 0.00013558)))));
        f0 * t0.cos() / ax.sqrt()
    }
}

/// The half-space's surface under a Hertz pressure at r = rho a, over its centre's
/// (Johnson 1985, 3.41): 1 - rho^2 / 2 inside the contact, and outside
/// ((2 - rho^2) asin(1 / rho) + sqrt(rho^2 - 1)) / pi.
fn hertz_half_space_surface(rho: f64) -> f64 {
    if rho <= 1.0 {
        1.0 - 0.5 * rho * rho
    } else {
        ((2.0 - rho * rho) * (1.0 / rho).asin() + (rho * rho - 1.0).sqrt()) / std::f64::consts::PI
    }
}

/// The bonded layer's surface under a Hertz pressure of contact radius a, at each r = rho a
/// of `rhos`, over its centre's, for a / h = `contact_over_thickness`: below zero where a
/// near-incompressible gel rises round the contact (the volume it is pressed out of goes
/// there).
pub fn hertz_surface_profile(rhos: &[f64], contact_over_thickness: f64, nu: f64) -> Vec<f64> {
    let aoh = contact_over_thickness;
    if aoh.is_nan() || aoh <= 0.0 {
        return rhos
            .iter()
            .map(|r| hertz_half_space_surface(r.abs()))
            .collect();
    }
    let centre = layer_surface_under_hertz(0.0, aoh, nu);
    rhos.iter()
        .map(|&rho| layer_surface_under_hertz(rho.abs(), aoh, nu) / centre)
        .collect()
}

/// The layer's surface at r = rho a, over the half-space's centre displacement. In the Hankel
/// domain it is the half-space's with each mode scaled by K(kh): H(rho) - (4 / pi)
/// int_0^inf j1(x)/x (1 - K(x h / a)) J0(x rho) dx, H the half-space's profile.
fn layer_surface_under_hertz(rho: f64, aoh: f64, nu: f64) -> f64 {
    let j1_over_x = |x: f64| {
        if x < 1e-3 {
            1.0 / 3.0 - x * x / 30.0
        } else {
            (x.sin() / (x * x) - x.cos() / x) / x
        }
    };
    let f =
        |x: f64| j1_over_x(x) * (1.0 - normal_compliance_ratio(x / aoh, nu)) * bessel_j0(x * rho);
    // 1 - K decays like e^(-2kh): the integral stops at kh = 15 (e^-30 of its start).
    let end = 15.0 * aoh;
    // Simpson's rule at 40 nodes or more per period of j1 and of J0(x rho).
    let step = 0.15f64.min(0.15 / rho.max(1e-9));
    let n = ((end / step).ceil() as usize).clamp(400, 200_000) & !1;
    let dx = end / n as f64;
    let mut sum = f(0.0) + f(end);
    for i in 1..n {
        sum += if i % 2 == 1 { 4.0 } else { 2.0 } * f(i as f64 * dx);
    }
    hertz_half_space_surface(rho) - 4.0 / std::f64::consts::PI * sum * dx / 3.0
}

/// The same ratio under an elliptical Hertz pressure p0 sqrt(1 - x^2/a^2 - y^2/b^2) of semi-axes
/// a and b (`semi_axes_over_thickness` = [a / h, b / h]): an elongated contact (a banana's)
/// is governed by its narrow side, so it stiffens the layer less than the circle of its area.
///
/// The ellipse's transform is the unit disc's at q = k s(phi), s = sqrt(a^2 cos^2 phi +
/// b^2 sin^2 phi), so the k-integral of each direction is the circular one at radius s and
/// the ratio is their mean over phi weighted by 1 / s; for a = b it is the circular ratio.
pub fn hertz_ellipse_centre_compliance_ratio(semi_axes_over_thickness: [f64; 2], nu: f64) -> f64 {
    let [a, b] = semi_axes_over_thickness;
    if !(a > 0.0 && b > 0.0) {
        return 1.0;
    }
    if (a - b).abs() <= 1e-9 * a.max(b) {
        return hertz_centre_compliance_ratio(a, nu);
    }
    // A quarter turn holds every direction (the ellipse is symmetric in x and y); the midpoint
    // rule on 24 angles is within 1e-4 of the converged ratio up to an aspect of 10.
    const ANGLES: usize = 24;
    let (mut weighted, mut weights) = (0.0, 0.0);
    for i in 0..ANGLES {
        let phi = (i as f64 + 0.5) / ANGLES as f64 * std::f64::consts::FRAC_PI_2;
        let s = (a * a * phi.cos().powi(2) + b * b * phi.sin().powi(2)).sqrt();
        weighted += hertz_centre_compliance_ratio(s, nu) / s;
        weights += 1.0 / s;
    }
    weighted / weights
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
    fn hertz_centre_compliance_matches_scipy_quadrature() {
        // scipy.integrate.quad of 1 - (4/pi) int j1(x)/x (1 - K(x h/a)) dx (see the docs).
        let cases = [
            (0.49, 0.25, 0.8180783614733576),
            (0.49, 1.0, 0.3878658882784619),
            (0.49, 3.0, 0.06734959252061612),
            (0.3, 1.0, 0.5015370284261629),
            (0.45, 0.5, 0.6717513466004917),
        ];
        for (nu, aoh, want) in cases {
            let got = hertz_centre_compliance_ratio(aoh, nu);
            assert!(
                (got - want).abs() < 1e-6,
                "a/h {aoh}, nu {nu}: {got} vs {want}"
            );
        }
    }

    #[test]
    fn elliptical_contact_matches_scipy_over_the_wavevector_plane() {
        // scipy.integrate.quad over (k, phi) of the ellipse's transform times 1 - K, against
        // the half-space's, without the circular reduction (tests/reference/layer_ellipse.py).
        let cases = [
            ([2.0, 0.5], 0.49, 0.39147564622719766),
            ([1.0, 0.25], 0.49, 0.6258949002510353),
            ([3.0, 1.0], 0.45, 0.2432736629932748),
            ([1.5, 1.5], 0.49, 0.2294594346226565),
        ];
        for (axes, nu, want) in cases {
            let got = hertz_ellipse_centre_compliance_ratio(axes, nu);
            assert!(
                (got - want).abs() < 2e-4,
                "axes {axes:?}, nu {nu}: {got} vs {want}"
            );
        }
        // Between the circles of its narrow and its wide side.
        let (narrow, wide) = (
            hertz_centre_compliance_ratio(0.5, 0.49),
            hertz_centre_compliance_ratio(2.0, 0.49),
        );
        let r = hertz_ellipse_centre_compliance_ratio([2.0, 0.5], 0.49);
        assert!(wide < r && r < narrow, "{wide} < {r} < {narrow}");
    }

    #[test]
    fn the_layer_surface_is_the_half_spaces_on_a_thick_gel_and_keeps_its_volume_on_a_thin_one() {
        let surface = |rho: f64, aoh: f64, nu: f64| hertz_surface_profile(&[rho], aoh, nu)[0];
        // J0 against tabulated values (Abramowitz and Stegun, table 9.1).
        for (x, j0) in [
            (0.0, 1.0),
            (1.0, 0.7651976866),
            (2.5, -0.0483837765),
            (10.0, -0.2459357645),
        ] {
            assert!((bessel_j0(x) - j0).abs() < 1e-7, "J0({x})");
        }
        // A contact small against the gel: Johnson's half-space profile.
        for rho in [0.0, 0.5, 1.0, 1.5, 3.0] {
            let got = surface(rho, 1e-3, 0.49);
            assert!(
                (got - hertz_half_space_surface(rho)).abs() < 2e-3,
                "rho {rho}: {got}"
            );
        }
        // An incompressible layer keeps its volume: the rise round the contact holds what
        // the contact presses in, int w(r) r dr = 0 (nu = 0.5), and it rises (w < 0) outside.
        let aoh = 1.0;
        let (mut total, mut inside) = (0.0, 0.0);
        let dr = 0.01;
        for i in 0..2000 {
            let rho = (i as f64 + 0.5) * dr;
            let w = surface(rho, aoh, 0.5) * rho * dr;
            total += w;
            if rho < 1.0 {
                inside += w;
            }
        }
        assert!(total.abs() < 0.01 * inside, "{total} of {inside}");
        assert!(surface(2.0, aoh, 0.49) < 0.0);
        assert!((surface(0.0, aoh, 0.49) - 1.0).abs() < 1e-9);
    }

    #[test]
    fn a_small_contact_on_a_thick_layer_sees_the_half_space() {
        assert!((hertz_centre_compliance_ratio(1e-3, 0.49) - 1.0).abs() < 2e-3);
        assert_eq!(hertz_centre_compliance_ratio(0.0, 0.49), 1.0);
        let mut last = 1.0;
        for aoh in [0.1, 0.3, 1.0, 3.0, 10.0] {
            let r = hertz_centre_compliance_ratio(aoh, 0.49);
            assert!(
                r > 0.0 && r < last,
                "stiffer as the contact outgrows the layer"
            );
            last = r;
        }
    }
}
