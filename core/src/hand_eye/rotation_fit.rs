//! The camera's rotation R_X from the motions' rotations, R_A R_X = R_X R_B, two ways.

use super::{HandEyeError, MIN_SECOND_AXIS_SHARE, Motion};
use glam::{DMat3, DQuat, DVec3};

/// Tsai-Lenz: with a and b the vector parts of R_A's and R_B's quaternions (sin of half the
/// turn times the axis, signs chosen with a positive scalar part), the quaternion algebra of
/// q_A q_X = q_X q_B gives [a + b]x P = b - a for P = tan(half R_X's turn) times its axis,
/// linear in P and stacked over the motions. At a half turn of R_X every [a + b]x shares its
/// axis as null vector (a camera looking straight down is one), so the system is solved for
/// X' = X R0^-1 (A X' = X' R0 B R0^-1) with R0 the best conditioned of no turn and quarter
/// turns about x, y and z (with z, no R_X is a half turn for all four: a camera turned a half
/// turn about z is one for the first three).
pub(super) fn tsai_lenz(motions: &[Motion]) -> Result<DQuat, HandEyeError> {
    use std::f64::consts::FRAC_PI_2;
    let offsets = [
        DQuat::IDENTITY,
        DQuat::from_rotation_x(FRAC_PI_2),
        DQuat::from_rotation_y(FRAC_PI_2),
        DQuat::from_rotation_z(FRAC_PI_2),
    ];
    let (conditioning, normal, rhs, offset) = offsets
        .into_iter()
        .map(|r0| {
            let mut normal = DMat3::ZERO;
            let mut rhs = DVec3::ZERO;
            for m in motions {
                let b_turned = r0 * m.b.rotation * r0.inverse();
                let (a, b) = (vector_part(m.a.rotation), vector_part(b_turned));
                let s = skew(a + b);
                normal += s.transpose() * s;
                rhs += s.transpose() * (b - a);
            }
            let [largest, _, smallest] = symmetric_eigen(normal).0;
            (smallest / largest.max(1e-300), normal, rhs, r0)
        })
        .max_by(|x, y| x.0.total_cmp(&y.0))
        .expect("four offsets");
    if conditioning <= MIN_SECOND_AXIS_SHARE {
        return Err(HandEyeError::OneAxis);
    }
    let p = normal.inverse() * rhs;
    Ok(DQuat::from_xyzw(p.x, p.y, p.z, 1.0).normalize() * offset)
}

/// Park-Martin: the rotations' logarithms satisfy log R_A = R_X log R_B, so R_X is the
/// rotation that best turns the B logarithms onto the A ones (orthogonal Procrustes, a
/// proper rotation even when the turns span only two axes).
pub(super) fn park_martin(motions: &[Motion]) -> Result<DQuat, HandEyeError> {
    // H = sum b a^T; R_X = sum over singular pairs v_k u_k^T, the third pair the cross
    // products of the first two (which keeps det R_X = +1).
    let mut h = DMat3::ZERO;
    for m in motions {
        let (a, b) = (logarithm(m.a.rotation), logarithm(m.b.rotation));
        h += outer(b, a);
    }
    let (values, vectors) = symmetric_eigen(h.transpose() * h);
    if values[1] <= MIN_SECOND_AXIS_SHARE * values[0] {
        return Err(HandEyeError::OneAxis);
    }
    let (v1, v2) = (vectors[0], vectors[1]);
    let u1 = (h * v1).normalize();
    let u2 = {
        let hv = h * v2;
        (hv - u1 * u1.dot(hv)).normalize()
    };
    // H = U S V^T with U's columns u_k = H v_k / s_k; the rotation taking b onto a is V U^T.
    let r = outer(v1, u1) + outer(v2, u2) + outer(v1.cross(v2), u1.cross(u2));
    Ok(DQuat::from_mat3(&r).normalize())
}

fn vector_part(q: DQuat) -> DVec3 {
    let q = if q.w < 0.0 { -q } else { q };
    DVec3::new(q.x, q.y, q.z)
}

/// The rotation vector: turn (radians, 0 to pi) times axis.
pub(super) fn logarithm(q: DQuat) -> DVec3 {
    let q = if q.w < 0.0 { -q } else { q };
    let (axis, angle) = q.to_axis_angle();
    axis * angle
}

fn skew(v: DVec3) -> DMat3 {
    DMat3::from_cols(
        DVec3::new(0.0, v.z, -v.y),
        DVec3::new(-v.z, 0.0, v.x),
        DVec3::new(v.y, -v.x, 0.0),
    )
}

/// a b^T.
fn outer(a: DVec3, b: DVec3) -> DMat3 {
    DMat3::from_cols(a * b.x, a * b.y, a * b.z)
}

/// A symmetric 3 x 3 matrix's eigenvalues and unit eigenvectors, largest first (cyclic
/// Jacobi rotations until the off-diagonal vanishes).
pub(super) fn symmetric_eigen(m: DMat3) -> ([f64; 3], [DVec3; 3]) {
    // a[i][j] and v[i][j]: row i, column j (m is symmetric, so its columns are its rows).
    let mut a = m.to_cols_array_2d();
    let mut v = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    for _ in 0..50 {
        let off = a[0][1].powi(2) + a[0][2].powi(2) + a[1][2].powi(2);
        if off <= 1e-30 * (a[0][0].powi(2) + a[1][1].powi(2) + a[2][2].powi(2)).max(1e-300) {
            break;
        }
        for (p, q) in [(0, 1), (0, 2), (1, 2)] {
            if a[p][q] == 0.0 {
                continue;
            }
            let theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
            let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
            let c = 1.0 / (t * t + 1.0).sqrt();
            let s = t * c;
            // A <- J^T A J with J the rotation in the (p, q) plane; V <- V J.
            for row in a.iter_mut() {
                let (akp, akq) = (row[p], row[q]);
                row[p] = c * akp - s * akq;
                row[q] = s * akp + c * akq;
            }
            let (rp, rq) = (a[p], a[q]);
            a[p] = std::array::from_fn(|k| c * rp[k] - s * rq[k]);
            a[q] = std::array::from_fn(|k| s * rp[k] + c * rq[k]);
            for row in v.iter_mut() {
                let (vp, vq) = (row[p], row[q]);
                row[p] = c * vp - s * vq;
                row[q] = s * vp + c * vq;
            }
        }
    }
    // The columns of V are the eigenvectors.
    let mut pairs: Vec<(f64, DVec3)> = (0..3)
        .map(|k| (a[k][k], DVec3::new(v[0][k], v[1][k], v[2][k])))
        .collect();
    pairs.sort_by(|x, y| y.0.total_cmp(&x.0));
    (
        [pairs[0].0, pairs[1].0, pairs[2].0],
        [pairs[0].1, pairs[1].1, pairs[2].1],
    )
}
