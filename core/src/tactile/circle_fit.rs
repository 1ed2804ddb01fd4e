//! Kasa's least-squares circle, shared by the marker centres and the contact circle.

/// The circle x^2 + y^2 + D x + E y + F = 0 closest to `points` in the algebraic sense
/// (Kasa 1976): its centre and radius. Solved about the points' mean, where F decouples and
/// D, E come from a 2x2 system, for conditioning. None for fewer than 3 points, collinear
/// points or a degenerate fit; callers that need more points to trust a fit ask for them.
pub fn fit_circle(points: &[[f64; 2]]) -> Option<([f64; 2], f64)> {
    if points.len() < 3 {
        return None;
    }
    let n = points.len() as f64;
    let mx = points.iter().map(|p| p[0]).sum::<f64>() / n;
    let my = points.iter().map(|p| p[1]).sum::<f64>() / n;
    let (mut sxx, mut sxy, mut syy, mut sxz, mut syz, mut sz) = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    for p in points {
        let (x, y) = (p[0] - mx, p[1] - my);
        let z = x * x + y * y;
        sxx += x * x;
        sxy += x * y;
        syy += y * y;
        sxz += x * z;
        syz += y * z;
        sz += z;
    }
    let det = sxx * syy - sxy * sxy;
    if det.abs() < 1e-9 {
        return None;
    }
    let a = (sxz * syy - syz * sxy) / (2.0 * det);
    let b = (syz * sxx - sxz * sxy) / (2.0 * det);
    let r2 = a * a + b * b + sz / n;
    (r2.is_finite() && r2 > 0.0).then(|| ([a + mx, b + my], r2.sqrt()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn points_on_a_circle_give_that_circle() {
        let points: Vec<[f64; 2]> = (0..7)
            .map(|k| {
                let t = 0.4 + 0.7 * k as f64;
                [12.5 + 3.25 * t.cos(), -4.0 + 3.25 * t.sin()]
            })
            .collect();
        let ([x, y], r) = fit_circle(&points).unwrap();
        assert!((x - 12.5).abs() < 1e-9 && (y + 4.0).abs() < 1e-9 && (r - 3.25).abs() < 1e-9);
    }

    #[test]
    fn collinear_points_have_no_circle() {
        let points = [[0.0, 0.0], [1.0, 1.0], [2.0, 2.0], [3.0, 3.0]];
        assert!(fit_circle(&points).is_none());
    }
}
