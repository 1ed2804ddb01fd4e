//! The controller's joint view of the pad's pose: the UF850's chain (`tactex_sim::arm::uf850`)
//! between the SDK's TCP pose (mm, radians; the TCP at the flange, no tool offset) and its
//! joints (radians, a seventh reading zero on this six-axis arm), for `get_servo_angle`,
//! `get_forward_kinematics` and `get_inverse_kinematics`.

use super::controller::TcpPoseMm;
use glam::DVec3;
use tactex_hw::xarm::frame::{f32_params, f32_values};
use tactex_sim::arm::uf850::{self, FlangePose, KinematicsError};

/// Where the joint reading starts: the arm's zero folded pose, from which the branch that
/// holds the pad down over the table is the nearest.
pub(super) const HOME_SEED: [f64; 6] = [0.0; 6];

/// The flange pose of an SDK pose.
fn flange(pose: &TcpPoseMm) -> FlangePose {
    FlangePose::from_rpy_deg(
        DVec3::new(pose[0], pose[1], pose[2]),
        [pose[3], pose[4], pose[5]].map(f64::to_degrees),
    )
}

/// The SDK pose at `joints`.
pub(super) fn pose_at(joints: [f64; 6]) -> TcpPoseMm {
    let f = uf850::forward(joints);
    let [roll, pitch, yaw] = f.rpy_deg().map(f64::to_radians);
    let p = f.position_mm;
    [p.x, p.y, p.z, roll, pitch, yaw]
}

/// How far `joints` tilt the flange's axis from straight down (degrees).
pub(super) fn tilt_deg(joints: [f64; 6]) -> f64 {
    let down = -uf850::forward(joints).rotation.z_axis.z;
    down.clamp(-1.0, 1.0).acos().to_degrees()
}

/// The joints nearest to `from` that hold the flange at `pose`.
pub(super) fn joints_for(pose: &TcpPoseMm, from: [f64; 6]) -> Result<[f64; 6], KinematicsError> {
    if pose.iter().any(|v| !v.is_finite()) {
        return Err(KinematicsError::Unreachable {
            position_mm: f64::INFINITY,
            angle_deg: f64::INFINITY,
        });
    }
    uf850::inverse(&flange(pose), from)
}

/// Whether `joints` hold the flange at `pose` (to a micrometre and a microradian): a
/// reading that already holds the pose is kept rather than solved for again.
pub(super) fn hold(joints: [f64; 6], pose: &TcpPoseMm) -> bool {
    let at = uf850::forward(joints);
    let want = flange(pose);
    (at.position_mm - want.position_mm).length() < 1e-3
        && (at.rotation.transpose() * want.rotation - glam::DMat3::IDENTITY)
            .to_cols_array()
            .iter()
            .all(|v| v.abs() < 1e-6)
}

/// Joints as the controller sends them: seven floats, the seventh zero.
pub(super) fn params(joints: &[f64; 6]) -> Vec<u8> {
    let mut seven = joints.to_vec();
    seven.push(0.0);
    f32_params(&seven)
}

/// `get_ik`'s parameters: the pose (6 floats), then optionally whether to keep to the limits
/// (one byte) and the reference joints to start from (7 floats).
pub(super) fn ik_params(params: &[u8]) -> Option<(TcpPoseMm, Option<[f64; 6]>)> {
    let pose = f32_values(params.get(..24)?);
    let pose = [pose[0], pose[1], pose[2], pose[3], pose[4], pose[5]];
    match params.len() {
        24 | 25 => Some((pose, None)),
        53 => {
            let q = f32_values(&params[25..53]);
            Some((pose, Some([q[0], q[1], q[2], q[3], q[4], q[5]])))
        }
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::xarm_twin::controller::HOME;

    #[test]
    fn the_home_pose_has_joints_and_they_hold_it() {
        let q = joints_for(&HOME, HOME_SEED).expect("home is within reach");
        let back = pose_at(q);
        for i in 0..3 {
            assert!((back[i] - HOME[i]).abs() < 1e-3, "{back:?}");
        }
        // Tool down: roll +-pi, pitch and yaw 0.
        assert!(
            (back[3].abs() - std::f64::consts::PI).abs() < 1e-6,
            "{back:?}"
        );
        assert!(back[4].abs() < 1e-6 && back[5].abs() < 1e-6, "{back:?}");
    }
}
