//! The session manifest and the errors of reading and writing sessions.

use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use tactex_core::geometry::{CameraIntrinsics, Pose};
use tactex_core::tactile::spec::TactileSpec;

pub const FORMAT: &str = "tactex-session/1";
pub const MANIFEST: &str = "manifest.json";
/// Depth PNG units: 0.1 mm, as a RealSense D405 reports (up to 6.55 m).
pub const DEPTH_SCALE_M: f64 = 1e-4;

/// Where a session is written until it is finished: `DIR.partial` beside `DIR`.
pub fn partial_dir(dir: &Path) -> PathBuf {
    let mut name = dir.as_os_str().to_owned();
    name.push(".partial");
    PathBuf::from(name)
}

#[derive(Debug, thiserror::Error)]
pub enum SessionError {
    /// No session where one was named.
    #[error("{path}: {message}")]
    Missing { path: PathBuf, message: String },
    #[error("{path}: {message}")]
    File { path: PathBuf, message: String },
    #[error("{path}: {field}: {message}")]
    Field {
        path: PathBuf,
        field: String,
        message: String,
    },
}

impl SessionError {
    pub fn file(path: &Path, message: impl std::fmt::Display) -> SessionError {
        SessionError::File {
            path: path.to_path_buf(),
            message: message.to_string(),
        }
    }
}

#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Manifest {
    pub format: String,
    /// The program that wrote it.
    pub created_by: String,
    /// The devices recorded: "sim", or the hardware backend's name.
    pub backend: String,
    pub prompt: String,
    pub camera: CameraRecord,
    pub tactile: TactileRecord,
    pub arm: ArmRecord,
    /// The answer given while recording (the `ask --json` object), when there was one.
    pub answer: Option<serde_json::Value>,
    /// What the twin needs to rebuild the recorded presses (`tactex compare --session`):
    /// written by the sim backend; a real session gets its objects from `--scene` instead.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub twin: Option<TwinRecord>,
}

/// The sim world a session was recorded in.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TwinRecord {
    /// The scene file's text as it was read: objects, their poses and hardness, camera, table.
    pub scene_toml: String,
    /// Where it was read from; relative mesh paths in it resolve against its folder.
    pub scene_path: String,
    /// The seed of the sim devices (sensor noise).
    pub seed: u64,
    /// The sim GelSight's contact physics (rigid, hertz, halfspace, layer).
    #[serde(default)]
    pub fidelity: Option<String>,
    /// The sim GelSight's sensor profile.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sensor: Option<tactex_core::tactile::sensor_profile::ProfileId>,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraRecord {
    pub name: String,
    pub intrinsics: CameraIntrinsics,
    /// Camera-to-world pose (OpenCV camera axes).
    pub pose: Pose,
    pub depth_scale_m: f64,
    pub frames: Vec<RgbdRecord>,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RgbdRecord {
    pub color: String,
    pub depth: String,
    pub timestamp_s: f64,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TactileRecord {
    pub name: String,
    pub spec: TactileSpec,
    pub frames: Vec<TactileFrameRecord>,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TactileFrameRecord {
    pub image: String,
    pub timestamp_s: f64,
    /// The arm's pose when the frame was taken (sensor pad, world frame).
    pub arm_pose: Pose,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ArmRecord {
    pub name: String,
    pub start_pose: Pose,
    /// The robot's own clock at the start (the twin's simulated time), if it has one.
    pub start_time_s: Option<f64>,
    pub moves: Vec<MoveRecord>,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MoveRecord {
    pub target: Pose,
    pub speed_m_s: f64,
    /// Where the arm came to rest.
    pub reached: Pose,
    pub time_s: Option<f64>,
    /// The device's refusal or failure, when the move did not happen.
    pub error: Option<String>,
}
