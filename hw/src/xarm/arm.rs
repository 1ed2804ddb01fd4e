//! The xArm behind core's `Arm` trait: world poses (m, quaternions) to the controller's base
//! frame (mm, roll-pitch-yaw), given where the arm's base stands in the world.

use super::client::{TcpPose, XArm, XArmError};
use tactex_core::devices::{Arm, DeviceError};
use tactex_core::geometry::Pose;
use tactex_core::glam::{DQuat, DVec3, EulerRot};

/// A world pose as the controller's TCP pose, for an arm whose base frame is the world frame
/// shifted to `base_in_world_m` (axes aligned).
fn tcp_pose_of(pose: &Pose, base_in_world_m: DVec3) -> TcpPose {
    let p = (pose.position - base_in_world_m) * 1e3;
    // R = Rz(yaw) Ry(pitch) Rx(roll): intrinsic Z-Y-X, which glam calls EulerRot::ZYX.
    let (yaw, pitch, roll) = pose.rotation.to_euler(EulerRot::ZYX);
    TcpPose {
        x_mm: p.x,
        y_mm: p.y,
        z_mm: p.z,
        roll_rad: roll,
        pitch_rad: pitch,
        yaw_rad: yaw,
    }
}

fn pose_of(tcp: &TcpPose, base_in_world_m: DVec3) -> Pose {
    Pose::new(
        DVec3::new(tcp.x_mm, tcp.y_mm, tcp.z_mm) * 1e-3 + base_in_world_m,
        DQuat::from_euler(EulerRot::ZYX, tcp.yaw_rad, tcp.pitch_rad, tcp.roll_rad),
    )
}

/// An xArm placed in the world.
pub struct XArmDevice {
    pub arm: XArm,
    pub base_in_world_m: DVec3,
    name: String,
}

impl XArmDevice {
    pub fn new(arm: XArm, base_in_world_m: DVec3) -> Self {
        let name = format!("xarm {}", arm.addr());
        Self {
            arm,
            base_in_world_m,
            name,
        }
    }

    fn failure(&self, e: XArmError) -> DeviceError {
        match e {
            XArmError::Refused { reason, .. } => DeviceError::UnsafeMove {
                device: self.name.clone(),
                reason,
            },
            e => DeviceError::Failure {
                device: self.name.clone(),
                // The error already names the arm's address.
                message: e.to_string().replacen(&format!("{}: ", self.name), "", 1),
            },
        }
    }
}

impl Arm for XArmDevice {
    fn name(&self) -> &str {
        &self.name
    }

    fn pose(&self) -> Result<Pose, DeviceError> {
        let tcp = self.arm.tcp_pose().map_err(|e| self.failure(e))?;
        Ok(pose_of(&tcp, self.base_in_world_m))
    }

    fn move_linear(&mut self, target: &Pose, speed_m_s: f64) -> Result<(), DeviceError> {
        let tcp = tcp_pose_of(target, self.base_in_world_m);
        self.arm
            .move_line(&tcp, speed_m_s * 1e3)
            .map_err(|e| self.failure(e))
    }

    fn stop(&mut self) -> Result<(), DeviceError> {
        self.arm.set_state(4).map_err(|e| self.failure(e))
    }
}
