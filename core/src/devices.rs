//! The device traits every backend implements: simulated, real hardware, or replay.
//!
//! The pipeline is generic over these and never asks which backend it has. Moves and captures
//! are blocking: a call returns when the device has done it.

use crate::frames::{RgbdFrame, TactileFrame};
use crate::geometry::{CameraIntrinsics, Pose};
use crate::tactile::spec::TactileSpec;

#[derive(Debug, thiserror::Error)]
pub enum DeviceError {
    #[error("{device}: {message}")]
    Failure { device: String, message: String },
    #[error("{device}: move refused: {reason}")]
    UnsafeMove { device: String, reason: String },
}

/// A colour + depth camera with known intrinsics and extrinsics.
pub trait RgbdCamera {
    fn name(&self) -> &str;
    fn intrinsics(&self) -> CameraIntrinsics;
    /// Camera-to-world pose (OpenCV camera axes).
    fn pose(&self) -> Pose;
    fn capture(&mut self) -> Result<RgbdFrame, DeviceError>;
}

/// A vision-based tactile sensor such as the GelSight Mini.
pub trait TactileSensor {
    fn name(&self) -> &str;
    fn spec(&self) -> &TactileSpec;
    fn capture(&mut self) -> Result<TactileFrame, DeviceError>;
}

/// A robot arm carrying the tactile sensor; poses are of the sensor pad (tool centre point
/// on the gel surface, tool z along the sensing direction).
pub trait Arm {
    fn name(&self) -> &str;
    fn pose(&self) -> Result<Pose, DeviceError>;
    /// Straight-line Cartesian move at `speed_m_s`, returning once the arm is there.
    fn move_linear(&mut self, target: &Pose, speed_m_s: f64) -> Result<(), DeviceError>;
    fn stop(&mut self) -> Result<(), DeviceError>;
    /// The robot's clock in seconds where it has one of its own (the twin's simulated time);
    /// None for real hardware, whose time is wall time.
    fn sim_time_s(&self) -> Option<f64> {
        None
    }
}
