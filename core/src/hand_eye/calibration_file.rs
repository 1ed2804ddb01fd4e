//! The camera's pose as a hand-eye calibration file states it (`tactex handeye`'s
//! `calib.toml`, section `[camera]`): written by the command, read by the twin's
//! `--camera-calibration` and by the hardware backend's `devices.toml`. The file's other
//! sections (how the pose was found) are for people and are not read back.

use crate::geometry::Pose;
use glam::{DQuat, DVec3};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// How far a quaternion's length may be off 1 (rounding in the file) before it is taken for
/// a mistake.
const UNIT_TOLERANCE: f64 = 1e-3;

/// `[camera]`: the camera in the arm's base frame. `rotation_xyzw` turns OpenCV's camera axes
/// (x right, y down the image, z along the view) into the base frame's.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraInBase {
    #[serde(deserialize_with = "crate::serde_exact::array")]
    pub position_m: [f64; 3],
    #[serde(deserialize_with = "crate::serde_exact::array")]
    pub rotation_xyzw: [f64; 4],
}

/// How far a table-top rig's camera may stand from the arm's base, or the base from the
/// world's origin, on each axis (m): a metre or two in practice; past this a number is a
/// mistake (or overflows the world pose).
pub const PLACEMENT_LIMIT_M: f64 = 10.0;

impl CameraInBase {
    /// The section for `pose`, to nine decimals (a nanometre; a rotation to 1e-9), so the file
    /// reads as a person would write it.
    pub fn of(pose: &Pose) -> Self {
        let round9 = |v: f64| (v * 1e9).round() / 1e9;
        Self {
            position_m: pose.position.to_array().map(round9),
            rotation_xyzw: pose.rotation.to_array().map(round9),
        }
    }

    /// The pose it states, or which field is wrong and why.
    pub fn pose(&self) -> Result<Pose, (&'static str, String)> {
        if !self.position_m.iter().all(|v| v.is_finite()) {
            return Err(("camera.position_m", "must be finite".into()));
        }
        if self.position_m.iter().any(|v| v.abs() > PLACEMENT_LIMIT_M) {
            return Err((
                "camera.position_m",
                format!("must be within {PLACEMENT_LIMIT_M} m of the arm's base on each axis"),
            ));
        }
        let q = DQuat::from_array(self.rotation_xyzw);
        let length = q.length();
        if !length.is_finite() || (length - 1.0).abs() > UNIT_TOLERANCE {
            return Err((
                "camera.rotation_xyzw",
                format!("has length {length:.4}; a rotation's quaternion has length 1"),
            ));
        }
        Ok(Pose::new(DVec3::from_array(self.position_m), q / length))
    }
}

/// Why a calibration file could not be read; each names the file, and the field where one
/// is wrong.
#[derive(Debug, thiserror::Error)]
pub enum CalibrationFileError {
    #[error("{}: cannot read calibration: {source}", path.display())]
    Read {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{}: {message}", path.display())]
    Format { path: PathBuf, message: String },
    #[error("{}: {field} {message}", path.display())]
    Field {
        path: PathBuf,
        field: &'static str,
        message: String,
    },
}

#[derive(Serialize, Deserialize)]
struct Sections {
    camera: CameraInBase,
}

/// The camera's pose in the arm's base frame from a calibration file.
pub fn load_camera_in_base(path: &Path) -> Result<Pose, CalibrationFileError> {
    let text =
        crate::text_file::read_to_string(path).map_err(|source| CalibrationFileError::Read {
            path: path.to_path_buf(),
            source,
        })?;
    camera_in_base_of_text(&text, path)
}

/// The same from the file's text (`path` names it in errors).
pub fn camera_in_base_of_text(text: &str, path: &Path) -> Result<Pose, CalibrationFileError> {
    let sections: Sections = toml::from_str(text).map_err(|e| CalibrationFileError::Format {
        path: path.to_path_buf(),
        message: crate::file_failure::toml_failure(text, &e),
    })?;
    sections
        .camera
        .pose()
        .map_err(|(field, message)| CalibrationFileError::Field {
            path: path.to_path_buf(),
            field,
            message,
        })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_written_pose_reads_back_to_a_nanometre() {
        let pose = Pose::new(
            DVec3::new(0.41, -0.023, 0.695),
            DQuat::from_euler(glam::EulerRot::XYZ, 3.0, 0.2, -1.1),
        );
        let text = toml::to_string(&Sections {
            camera: CameraInBase::of(&pose),
        })
        .unwrap();
        let read = camera_in_base_of_text(&text, Path::new("calib.toml")).unwrap();
        assert!((read.position - pose.position).length() < 1e-9);
        assert!(read.rotation.angle_between(pose.rotation) < 1e-8);
    }

    #[test]
    fn a_wrong_field_is_named_with_the_file() {
        let at = Path::new("calib.toml");
        let e = camera_in_base_of_text(
            "[camera]\nposition_m = [0.0, 0.0, 0.7]\nrotation_xyzw = [0.5, 0.0, 0.0, 0.5]\n",
            at,
        )
        .unwrap_err()
        .to_string();
        assert!(
            e.starts_with("calib.toml: camera.rotation_xyzw has length 0.7071"),
            "{e}"
        );
        let e = camera_in_base_of_text("[camera]\nposition_m = [0.0, 0.0]\n", at)
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("calib.toml: "), "{e}");
        assert!(!e.contains('\n'), "{e}");
        let e = camera_in_base_of_text("[arm]\n", at)
            .unwrap_err()
            .to_string();
        assert!(e.contains("camera"), "{e}");
        // A list longer than the field is refused, not cut; a far-off number is a mistake.
        for text in [
            "[camera]\nposition_m = [0.0, 0.0, 0.7, 5.0]\nrotation_xyzw = [1.0, 0.0, 0.0, 0.0]\n",
            "[camera]\nposition_m = [0.0, 0.0, 0.7]\nrotation_xyzw = [1.0, 0.0, 0.0, 0.0, 0.0]\n",
        ] {
            let e = camera_in_base_of_text(text, at).unwrap_err().to_string();
            assert!(e.contains("exactly"), "{e}");
        }
        let e = camera_in_base_of_text(
            "[camera]\nposition_m = [1e308, 0.0, 0.7]\nrotation_xyzw = [1.0, 0.0, 0.0, 0.0]\n",
            at,
        )
        .unwrap_err()
        .to_string();
        assert!(
            e.starts_with("calib.toml: camera.position_m must be within 10 m"),
            "{e}"
        );
    }
}
