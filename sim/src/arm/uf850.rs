//! The UFACTORY 850's kinematic chain.
//!
//! Source: UFACTORY's "Kinematic and Dynamic Parameters of UFACTORY 850"
//! (github.com/xArm-Developer/ufactory_docs, support_articles/developer/
//! kinematic-and-dynamic-parameters/ufactory-850.md, commit 67f37bb), table 1, modified
//! (Craig) D-H parameters; joint limits from xarm_ros2's uf850 description
//! (xarm_description/urdf/uf850/uf850.urdf.xacro). The flange frame is frame 6; lengths in
//! mm, angles in radians unless a name says degrees.
//!
//! Inverse kinematics is damped least squares (Levenberg-Marquardt) on the 6-D pose error,
//! started from the current joints: it converges to the solution nearest to them, the
//! branch the controller keeps, and a pose it cannot reach within tolerance is refused.
//! A closed form exists for this wrist but would need the branch choice made by hand; the
//! iteration is cheap beside a move's duration.

use glam::{DMat3, DMat4, DVec3};
use std::f64::consts::TAU;

/// One row of the modified D-H table: the frame i-1 -> i transform is
/// RotX(alpha_{i-1}) TransX(a_{i-1}) RotZ(theta_i + offset_i) TransZ(d_i).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ModifiedDh {
    pub alpha_deg: f64,
    pub a_mm: f64,
    pub theta_offset_deg: f64,
    pub d_mm: f64,
}

/// The UF850's table (UFACTORY's table 1, joint 1 to 6).
pub const UF850_DH: [ModifiedDh; 6] = [
    ModifiedDh {
        alpha_deg: 0.0,
        a_mm: 0.0,
        theta_offset_deg: 0.0,
        d_mm: 364.0,
    },
    ModifiedDh {
        alpha_deg: 90.0,
        a_mm: 0.0,
        theta_offset_deg: 90.0,
        d_mm: 0.0,
    },
    ModifiedDh {
        alpha_deg: 180.0,
        a_mm: 390.0,
        theta_offset_deg: 90.0,
        d_mm: 0.0,
    },
    ModifiedDh {
        alpha_deg: -90.0,
        a_mm: 150.0,
        theta_offset_deg: 0.0,
        d_mm: 426.0,
    },
    ModifiedDh {
        alpha_deg: -90.0,
        a_mm: 0.0,
        theta_offset_deg: 0.0,
        d_mm: 0.0,
    },
    ModifiedDh {
        alpha_deg: 90.0,
        a_mm: 0.0,
        theta_offset_deg: 0.0,
        d_mm: 90.0,
    },
];

/// Joint limits (rad), from xarm_ros2's uf850 description.
pub const UF850_LIMITS_RAD: [[f64; 2]; 6] = [
    [-2.0 * std::f64::consts::PI, 2.0 * std::f64::consts::PI],
    [-2.3038346, 2.3038346],
    [-4.2236968, 0.061087],
    [-2.0 * std::f64::consts::PI, 2.0 * std::f64::consts::PI],
    [-2.1642, 2.1642],
    [-2.0 * std::f64::consts::PI, 2.0 * std::f64::consts::PI],
];

/// Where the flange is and how it is turned, in the base frame (mm).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FlangePose {
    pub position_mm: DVec3,
    pub rotation: DMat3,
}

impl FlangePose {
    /// Roll, pitch, yaw (degrees) as the xArm reports them: the rotation is
    /// Rz(yaw) Ry(pitch) Rx(roll), fixed axes X, then Y, then Z.
    pub fn rpy_deg(&self) -> [f64; 3] {
        let r = self.rotation;
        // Column-major: r.x_axis is the first column.
        let (r20, r21, r22) = (r.x_axis.z, r.y_axis.z, r.z_axis.z);
        let (r00, r10) = (r.x_axis.x, r.x_axis.y);
        let pitch = (-r20).clamp(-1.0, 1.0).asin();
        let (roll, yaw) = if r20.abs() < 1.0 - 1e-12 {
            (r21.atan2(r22), r10.atan2(r00))
        } else {
            // Gimbal lock: yaw and roll share one axis; put it all in yaw.
            (0.0, (-r.y_axis.x).atan2(r.y_axis.y))
        };
        [roll.to_degrees(), pitch.to_degrees(), yaw.to_degrees()]
    }

    /// The pose from a position and the xArm's roll, pitch, yaw (degrees).
    pub fn from_rpy_deg(position_mm: DVec3, rpy_deg: [f64; 3]) -> Self {
        let [roll, pitch, yaw] = rpy_deg.map(f64::to_radians);
        Self {
            position_mm,
            rotation: DMat3::from_rotation_z(yaw)
                * DMat3::from_rotation_y(pitch)
                * DMat3::from_rotation_x(roll),
        }
    }
}

/// Why inverse kinematics gave no joints.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum KinematicsError {
    /// No joints within tolerance reach the pose (out of the arm's reach, or only through a
    /// singular wrist from these joints).
    #[error(
        "the pose is out of the arm's reach (nearest: {position_mm:.2} mm, {angle_deg:.3} degrees off)"
    )]
    Unreachable { position_mm: f64, angle_deg: f64 },
    /// The nearest joints that reach the pose put joint `joint` (1-based) past its limit.
    #[error("joint {joint} would be at {angle_deg:.2} degrees, past its limit")]
    PastLimit { joint: usize, angle_deg: f64 },
}

/// The flange pose at `joints` (rad): the product of the table's transforms.
pub fn forward(joints: [f64; 6]) -> FlangePose {
    let mut t = DMat4::IDENTITY;
    for (row, q) in UF850_DH.iter().zip(joints) {
        t = t
            * DMat4::from_rotation_x(row.alpha_deg.to_radians())
            * DMat4::from_translation(DVec3::new(row.a_mm, 0.0, 0.0))
            * DMat4::from_rotation_z(q + row.theta_offset_deg.to_radians())
            * DMat4::from_translation(DVec3::new(0.0, 0.0, row.d_mm));
    }
    FlangePose {
        position_mm: t.w_axis.truncate(),
        rotation: DMat3::from_mat4(t),
    }
}

/// Whether every joint lies within its limit; else the first (1-based) that does not.
pub fn past_limit(joints: [f64; 6]) -> Option<usize> {
    joints
        .iter()
        .zip(UF850_LIMITS_RAD)
        .position(|(q, [lo, hi])| !(lo..=hi).contains(q))
        .map(|i| i + 1)
}

/// How far one pose is from another: the position (mm) and the rotation vector taking
/// `from` to `to` (rad), in the base frame.
fn pose_error(from: &FlangePose, to: &FlangePose) -> [f64; 6] {
    let dp = to.position_mm - from.position_mm;
    let dr = rotation_vector(to.rotation * from.rotation.transpose());
    [dp.x, dp.y, dp.z, dr.x, dr.y, dr.z]
}

/// The axis times the angle of a rotation matrix.
fn rotation_vector(r: DMat3) -> DVec3 {
    let q = glam::DQuat::from_mat3(&r).normalize();
    let q = if q.w < 0.0 { -q } else { q };
    let (axis, angle) = q.to_axis_angle();
    if angle.abs() < 1e-15 {
        DVec3::ZERO
    } else {
        axis * angle
    }
}

/// A millimetre of position weighs as much as this many radians of rotation in the fit:
/// one radian at the flange is about as large an error as 100 mm at the arm's reach.
const RAD_PER_MM: f64 = 0.01;
/// Reached: within these of the target.
const POSITION_TOLERANCE_MM: f64 = 1e-6;
const ANGLE_TOLERANCE_RAD: f64 = 1e-9;
const MAX_ITERATIONS: usize = 200;

/// The joints nearest to `from` (rad) that put the flange at `target`.
pub fn inverse(target: &FlangePose, from: [f64; 6]) -> Result<[f64; 6], KinematicsError> {
    let weight = [
        1.0,
        1.0,
        1.0,
        1.0 / RAD_PER_MM,
        1.0 / RAD_PER_MM,
        1.0 / RAD_PER_MM,
    ];
    let mut q = from;
    let mut lambda = 1e-3;
    let cost = |e: &[f64; 6]| -> f64 { e.iter().zip(weight).map(|(v, w)| (v * w).powi(2)).sum() };
    let mut e = pose_error(&forward(q), target);
    let mut c = cost(&e);
    for _ in 0..MAX_ITERATIONS {
        let reached = DVec3::new(e[0], e[1], e[2]).length() <= POSITION_TOLERANCE_MM
            && DVec3::new(e[3], e[4], e[5]).length() <= ANGLE_TOLERANCE_RAD;
        if reached {
            break;
        }
        // The Jacobian of the weighted error by central differences.
        let mut jac = [[0.0; 6]; 6];
        for k in 0..6 {
            let h = 1e-7;
            let (mut qp, mut qm) = (q, q);
            qp[k] += h;
            qm[k] -= h;
            let ep = pose_error(&forward(qp), target);
            let em = pose_error(&forward(qm), target);
            for r in 0..6 {
                // d(error)/dq: the error shrinks as the pose moves towards the target.
                jac[r][k] = -(ep[r] - em[r]) / (2.0 * h) * weight[r];
            }
        }
        let rhs: [f64; 6] = std::array::from_fn(|r| e[r] * weight[r]);
        // (J^T J + lambda diag(J^T J)) dq = J^T e
        let mut a = [[0.0; 6]; 6];
        let mut b = [0.0; 6];
        for i in 0..6 {
            for j in 0..6 {
                a[i][j] = (0..6).map(|r| jac[r][i] * jac[r][j]).sum();
            }
            b[i] = (0..6).map(|r| jac[r][i] * rhs[r]).sum();
        }
        let mut improved = false;
        for _ in 0..20 {
            let mut damped = a;
            for (i, row) in damped.iter_mut().enumerate() {
                row[i] += lambda * (a[i][i] + 1e-9);
            }
            let Some(dq) = solve6(damped, b) else {
                lambda *= 10.0;
                continue;
            };
            let trial: [f64; 6] = std::array::from_fn(|i| q[i] + dq[i]);
            let et = pose_error(&forward(trial), target);
            let ct = cost(&et);
            if ct < c {
                (q, e, c) = (trial, et, ct);
                lambda = (lambda / 10.0).max(1e-12);
                improved = true;
                break;
            }
            lambda *= 10.0;
        }
        if !improved {
            break;
        }
    }
    let position_mm = DVec3::new(e[0], e[1], e[2]).length();
    let angle = DVec3::new(e[3], e[4], e[5]).length();
    // Reached to within what a controller resolves (1e-4 mm, 1e-6 rad).
    if position_mm > 1e-4 || angle > 1e-6 {
        return Err(KinematicsError::Unreachable {
            position_mm,
            angle_deg: angle.to_degrees(),
        });
    }
    // Turns a whole revolution apart hold the same pose: of them, the one nearest to where
    // the arm is that lies within the joint's limits (the descent may have wandered a
    // revolution off, or started from a joint that wound past one).
    for (j, [lo, hi]) in UF850_LIMITS_RAD.iter().enumerate() {
        let nearest = q[j] + ((from[j] - q[j]) / TAU).round() * TAU;
        let within = |v: f64| (*lo..=*hi).contains(&v);
        q[j] = [nearest, nearest - TAU, nearest + TAU, q[j]]
            .into_iter()
            .find(|v| within(*v))
            .unwrap_or(q[j]);
    }
    if let Some(joint) = past_limit(q) {
        return Err(KinematicsError::PastLimit {
            joint,
            angle_deg: q[joint - 1].to_degrees(),
        });
    }
    Ok(q)
}

/// Solves a 6 x 6 system by Gaussian elimination with partial pivoting; None if singular.
fn solve6(mut a: [[f64; 6]; 6], mut b: [f64; 6]) -> Option<[f64; 6]> {
    for col in 0..6 {
        let pivot = (col..6).max_by(|&i, &j| a[i][col].abs().total_cmp(&a[j][col].abs()))?;
        if a[pivot][col].abs() < 1e-300 {
            return None;
        }
        a.swap(col, pivot);
        b.swap(col, pivot);
        let pivot_row = a[col];
        for row in col + 1..6 {
            let f = a[row][col] / pivot_row[col];
            for (x, p) in a[row][col..].iter_mut().zip(&pivot_row[col..]) {
                *x -= f * p;
            }
            b[row] -= f * b[col];
        }
    }
    let mut x = [0.0; 6];
    for row in (0..6).rev() {
        let s: f64 = (row + 1..6).map(|k| a[row][k] * x[k]).sum();
        x[row] = (b[row] - s) / a[row][row];
    }
    x.iter().all(|v| v.is_finite()).then_some(x)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_zero_pose_is_the_tables_lengths_stacked_with_the_tool_down() {
        // All joints at zero: the upper arm up (364 + 390 mm), the forearm's 150 mm offset
        // out along x, then the forearm (426 mm) and the wrist (90 mm) back down.
        let p = forward([0.0; 6]);
        let expected = DVec3::new(150.0, 0.0, 364.0 + 390.0 - 426.0 - 90.0);
        assert!(
            (p.position_mm - expected).length() < 1e-9,
            "{:?}",
            p.position_mm
        );
        let [roll, pitch, yaw] = p.rpy_deg();
        assert!((roll.abs() - 180.0).abs() < 1e-9 && pitch.abs() < 1e-9 && yaw.abs() < 1e-9);
    }

    #[test]
    fn inverse_kinematics_returns_to_the_joints_it_started_near() {
        let mut rng = 12345u64;
        let mut next = || {
            rng = rng
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (rng >> 11) as f64 / (1u64 << 53) as f64
        };
        for _ in 0..100 {
            // Joints well inside the limits and away from the wrist's singularity (q5 = 0).
            let q: [f64; 6] = std::array::from_fn(|i| {
                let [lo, hi] = UF850_LIMITS_RAD[i];
                let (lo, hi) = (lo.max(-3.0) * 0.8, hi.min(3.0) * 0.8);
                lo + (hi - lo) * next()
            });
            if q[4].abs() < 0.2 {
                continue;
            }
            let target = forward(q);
            let from: [f64; 6] = std::array::from_fn(|i| q[i] + 0.05 * (next() - 0.5));
            let back = inverse(&target, from).expect("a reachable pose");
            let reached = forward(back);
            assert!((reached.position_mm - target.position_mm).length() < 1e-3);
            for i in 0..6 {
                assert!(
                    (back[i] - q[i]).abs() < 1e-5,
                    "joint {i}: {back:?} vs {q:?}"
                );
            }
        }
    }

    #[test]
    fn a_pose_out_of_reach_and_a_joint_past_its_limit_are_refused() {
        let far = FlangePose::from_rpy_deg(DVec3::new(3000.0, 0.0, 0.0), [180.0, 0.0, 0.0]);
        assert!(matches!(
            inverse(&far, [0.0, 0.0, -1.0, 0.0, 1.0, 0.0]),
            Err(KinematicsError::Unreachable { .. })
        ));
        assert_eq!(past_limit([0.0, 2.5, 0.0, 0.0, 0.0, 0.0]), Some(2));
        assert_eq!(past_limit([0.0, 0.0, -1.0, 0.0, 0.0, 0.0]), None);
    }

    #[test]
    fn roll_pitch_yaw_read_back_as_given() {
        for rpy in [
            [180.0, 0.0, 0.0],
            [170.0, -20.0, 35.0],
            [-90.0, 45.0, -120.0],
        ] {
            let pose = FlangePose::from_rpy_deg(DVec3::ZERO, rpy);
            let back = pose.rpy_deg();
            for k in 0..3 {
                let d = (back[k] - rpy[k] + 540.0).rem_euclid(360.0) - 180.0;
                assert!(d.abs() < 1e-9, "{rpy:?} -> {back:?}");
            }
        }
    }
}
