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
//! position_m = [0.0, 0.0, 0.70]     # where it stands, as measured by hand; or, instead of
//! look_at_m = [0.0, 0.0, 0.0]        # these two, calibration = "calib.toml" (`tactex handeye`)
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
use tactex_core::hand_eye::calibration_file::{PLACEMENT_LIMIT_M, load_camera_in_base};

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
    /// The camera in the world frame, from `camera.calibration` or `camera.position_m` and
    /// `camera.look_at_m` (set by `load`).
    #[serde(skip, default = "unset_pose")]
    camera_in_world: Pose,
}

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ArmConfig {
    pub addr: String,
    #[serde(deserialize_with = "tactex_core::serde_exact::array")]
    pub base_in_world_m: [f64; 3],
    #[serde(default, deserialize_with = "tactex_core::serde_exact::optional_array")]
    pub workspace_mm: Option<[f64; 6]>,
}

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraConfig {
    pub color: String,
    pub depth: String,
    pub depth_scale_m: f64,
    pub intrinsics: CameraIntrinsics,
    #[serde(default, deserialize_with = "tactex_core::serde_exact::optional_array")]
    pub position_m: Option<[f64; 3]>,
    #[serde(default, deserialize_with = "tactex_core::serde_exact::optional_array")]
    pub look_at_m: Option<[f64; 3]>,
    /// A hand-eye calibration file (`tactex handeye --out`), relative to devices.toml's
    /// folder: the camera's pose in the arm's base frame, instead of `position_m` and
    /// `look_at_m`.
    pub calibration: Option<PathBuf>,
}

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TactileConfig {
    pub device: String,
}

fn unset_pose() -> Pose {
    Pose::IDENTITY
}

impl DevicesConfig {
    /// Reads and checks the file; every problem names the file and the field.
    pub fn load(path: &Path) -> Result<DevicesConfig, DevicesError> {
        let text =
            tactex_core::text_file::read_to_string(path).map_err(|e| DevicesError::File {
                path: path.to_path_buf(),
                message: e.to_string(),
            })?;
        let mut config: DevicesConfig = toml::from_str(&text).map_err(|e| DevicesError::File {
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
        if let Some(w) = config.arm.workspace_mm {
            WorkspaceBox::from_bounds_mm(w).map_err(|e| field("arm.workspace_mm", &e))?;
        }
        // A place in the world: finite and within the limit a table-top rig stands in.
        let placed = |name: &str, at: &[f64; 3]| {
            if !at.iter().all(|v| v.is_finite()) {
                return Err(field(name, "must be finite"));
            }
            if at.iter().any(|v| v.abs() > PLACEMENT_LIMIT_M) {
                return Err(field(
                    name,
                    &format!(
                        "must be within {PLACEMENT_LIMIT_M} m of the world's origin on each axis"
                    ),
                ));
            }
            Ok(())
        };
        placed("arm.base_in_world_m", &config.arm.base_in_world_m)?;
        let c = &config.camera;
        config.camera_in_world = match (&c.calibration, c.position_m, c.look_at_m) {
            (Some(file), None, None) => {
                if file.as_os_str().is_empty() {
                    return Err(field(
                        "camera.calibration",
                        "is empty: give the calibration file's path",
                    ));
                }
                let folder = path.parent().unwrap_or(Path::new(""));
                let in_base = load_camera_in_base(&folder.join(file))
                    .map_err(|e| field("camera.calibration", &e.to_string()))?;
                // The arm's base frame has the world's axes (see `base_in_world_m`).
                Pose::new(
                    in_base.position + DVec3::from_array(config.arm.base_in_world_m),
                    in_base.rotation,
                )
            }
            (Some(_), _, _) => {
                return Err(field(
                    "camera.calibration",
                    "places the camera: leave out camera.position_m and camera.look_at_m",
                ));
            }
            (None, Some(at), Some(look_at)) => {
                placed("camera.position_m", &at)?;
                placed("camera.look_at_m", &look_at)?;
                Pose::camera_looking_at(DVec3::from_array(at), DVec3::from_array(look_at))
                    .ok_or_else(|| {
                        field("camera.look_at_m", "must differ from camera.position_m")
                    })?
            }
            (None, _, _) => {
                return Err(field(
                    "camera",
                    "needs position_m and look_at_m, or calibration = \"calib.toml\" (tactex handeye)",
                ));
            }
        };
        Ok(config)
    }

    /// Where the camera stands in the world frame (OpenCV's camera axes).
    pub fn camera_pose(&self) -> Pose {
        self.camera_in_world
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
        let pose = self.camera_pose();
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
