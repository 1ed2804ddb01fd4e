//! `devices.toml`: which real devices the hardware backend opens and where they stand.
//!
//! ```toml
//! [arm]                          # a uFactory xArm
//! addr = "192.168.1.185:502"
//! base_in_world_m = [-0.40, 0.0, 0.0]    # the arm base in the world frame (axes aligned)
//! workspace_mm = [100, 700, -400, 400, 50, 600]   # optional: X0,X1,Y0,Y1,Z0,Z1, base frame
//!
//! [camera]                       # a RealSense on V4L2
//! color = "/dev/video4"          # a path, or the driver's name for the node
//! depth = "/dev/video2"
//! depth_scale_m = 0.0001
//! intrinsics = { width = 640, height = 480, fx = 608.5, fy = 606.9, cx = 309.4, cy = 213.83 }
//! position_m = [0.0, 0.0, 0.70]
//! look_at_m = [0.0, 0.0, 0.0]
//!
//! [tactile]                      # a GelSight Mini on V4L2
//! device = "GelSight Mini"
//! ```

use crate::xarm::{WorkspaceBox, XArm, XArmConfig, XArmDevice};
use serde::Deserialize;
use std::path::{Path, PathBuf};
use tactex_core::devices::DeviceError;
use tactex_core::geometry::{CameraIntrinsics, Pose};
use tactex_core::glam::DVec3;

#[derive(Debug, thiserror::Error)]
pub enum DevicesError {
    #[error("{path}: {message}")]
    File { path: PathBuf, message: String },
    #[error("{path}: {field}: {message}")]
    Field {
        path: PathBuf,
        field: String,
        message: String,
    },
    #[error(transparent)]
    Device(#[from] DeviceError),
    #[error(transparent)]
    Arm(#[from] crate::xarm::XArmError),
}

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DevicesConfig {
    pub arm: ArmConfig,
    pub camera: CameraConfig,
    pub tactile: TactileConfig,
}

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ArmConfig {
    pub addr: String,
    pub base_in_world_m: [f64; 3],
    pub workspace_mm: Option<[f64; 6]>,
}

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraConfig {
    pub color: String,
    pub depth: String,
    pub depth_scale_m: f64,
    pub intrinsics: CameraIntrinsics,
    pub position_m: [f64; 3],
    pub look_at_m: [f64; 3],
}

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TactileConfig {
    pub device: String,
}

impl DevicesConfig {
    /// Reads and checks the file; every problem names the file and the field.
    pub fn load(path: &Path) -> Result<DevicesConfig, DevicesError> {
        let text = std::fs::read_to_string(path).map_err(|e| DevicesError::File {
            path: path.to_path_buf(),
            message: e.to_string(),
        })?;
        let config: DevicesConfig = toml::from_str(&text).map_err(|e| DevicesError::File {
            path: path.to_path_buf(),
            message: tactex_core::file_failure::toml_failure(&text, &e),
        })?;
        let field = |field: &str, message: &str| DevicesError::Field {
            path: path.to_path_buf(),
            field: field.into(),
            message: message.into(),
        };
        if !(config.camera.depth_scale_m.is_finite() && config.camera.depth_scale_m > 0.0) {
            return Err(field("camera.depth_scale_m", "must be a positive number"));
        }
        let k = &config.camera.intrinsics;
        if let Err(why) = k.check() {
            return Err(field("camera.intrinsics", &why));
        }
        if config.camera_pose().is_none() {
            return Err(field(
                "camera.look_at_m",
                "must differ from camera.position_m",
            ));
        }
        if let Some(w) = config.arm.workspace_mm {
            WorkspaceBox::from_bounds_mm(w).map_err(|e| field("arm.workspace_mm", &e))?;
        }
        if config.arm.base_in_world_m.iter().any(|v| !v.is_finite()) {
            return Err(field("arm.base_in_world_m", "must be finite"));
        }
        Ok(config)
    }

    pub fn camera_pose(&self) -> Option<Pose> {
        Pose::camera_looking_at(
            DVec3::from_array(self.camera.position_m),
            DVec3::from_array(self.camera.look_at_m),
        )
    }

    /// Connects to the arm and makes it ready to move (enable, position mode, start).
    pub fn open_arm(&self) -> Result<XArmDevice, DevicesError> {
        let mut config = XArmConfig::new(&self.arm.addr);
        if let Some(w) = self.arm.workspace_mm {
            config.workspace = WorkspaceBox::from_bounds_mm(w).expect("checked in load");
        }
        let arm = XArm::connect(config)?;
        arm.prepare()?;
        Ok(XArmDevice::new(
            arm,
            DVec3::from_array(self.arm.base_in_world_m),
        ))
    }

    #[cfg(all(target_os = "linux", feature = "v4l2"))]
    pub fn open_camera(&self) -> Result<crate::realsense::RealSense, DevicesError> {
        let c = &self.camera;
        let pose = self.camera_pose().expect("checked in load");
        Ok(crate::realsense::RealSense::open(
            &c.color,
            &c.depth,
            c.intrinsics,
            pose,
            c.depth_scale_m,
        )?)
    }

    #[cfg(all(target_os = "linux", feature = "v4l2"))]
    /// The GelSight, its frames read through `profile` (the sensor's calibrated spec).
    pub fn open_tactile(
        &self,
        profile: tactex_core::tactile::spec::TactileSpec,
    ) -> Result<crate::gelsight_mini::GelSightMini, DevicesError> {
        Ok(crate::gelsight_mini::GelSightMini::open(
            &self.tactile.device,
            profile,
        )?)
    }
}
