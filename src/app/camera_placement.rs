//! Where the twin's scene camera really stands against where its user believes it does: a
//! rig placed with an error (moved and turned in directions drawn from a seed), and the
//! belief taken from the scene or from a hand-eye calibration file (`tactex handeye`'s
//! `calib.toml`). `ask`, `serve`, the evaluations and `handeye` itself share it.

use anyhow::{Context, Result, bail};
use glam::{DQuat, DVec3};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};
use serde::Deserialize;
use std::path::Path;
use tactex_core::geometry::Pose;
use tactex_sim::SimDevices;

/// How far a quaternion's length may be off 1 in a calibration file (rounding) before it is
/// taken for a mistake.
const UNIT_TOLERANCE: f64 = 1e-3;

/// The camera's misplacement and what its user believes.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CameraPlacement {
    /// How far the camera stands from the scene's pose (mm).
    pub error_mm: f64,
    /// How far it is turned from it (degrees).
    pub error_deg: f64,
    /// Draws the directions of the move and of the turn's axis.
    pub error_seed: u64,
    /// The pose a calibration found, believed instead of the scene's.
    pub calibrated: Option<Pose>,
}

/// The largest camera misplacement the twin takes (mm): past it the table leaves the view.
pub const CAMERA_ERROR_MM_MAX: f64 = 200.0;
/// The largest camera turn the twin takes (degrees).
pub const CAMERA_ERROR_DEG_MAX: f64 = 20.0;

impl CameraPlacement {
    /// A placement from its flags (`--camera-error-mm`, `--camera-error-deg`,
    /// `--camera-error-seed`, `--camera-calibration`), each checked, the calibration read.
    pub fn checked(
        error_mm: f64,
        error_deg: f64,
        error_seed: u64,
        calibration: Option<&Path>,
    ) -> Result<Self> {
        for (flag, value, hi) in [
            ("--camera-error-mm", error_mm, CAMERA_ERROR_MM_MAX),
            ("--camera-error-deg", error_deg, CAMERA_ERROR_DEG_MAX),
        ] {
            if !(0.0..=hi).contains(&value) {
                bail!("{flag}: must be in [0, {hi}]; got {value}");
            }
        }
        // + 0.0 turns a -0 given on the command line into 0.
        Ok(Self {
            error_mm: error_mm + 0.0,
            error_deg: error_deg + 0.0,
            error_seed,
            calibrated: calibration.map(load_calibrated_camera).transpose()?,
        })
    }

    /// Whether the camera stands where it is believed to by the scene: nothing to do.
    pub fn is_exact(&self) -> bool {
        self.error_mm == 0.0 && self.error_deg == 0.0 && self.calibrated.is_none()
    }

    /// Where the camera really stands, for a scene that puts it at `scene_pose`.
    pub fn truth(&self, scene_pose: &Pose) -> Pose {
        misplaced(scene_pose, self.error_mm, self.error_deg, self.error_seed)
    }

    /// Places the devices' camera: rendering from the truth, reporting the belief.
    pub fn apply(&self, sim: &mut SimDevices) {
        if self.is_exact() {
            return;
        }
        let scene_pose = sim.world.lock().expect("world lock").camera_pose;
        let believed = self.calibrated.unwrap_or(scene_pose);
        sim.place_camera(self.truth(&scene_pose), believed);
    }
}

/// `pose` moved by `mm` in a direction and turned by `deg` about an axis, both drawn from
/// `seed`.
pub fn misplaced(pose: &Pose, mm: f64, deg: f64, seed: u64) -> Pose {
    let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0x4a4d_e7e5);
    let mut unit = || {
        let v = DVec3::new(
            StandardNormal.sample(&mut rng),
            StandardNormal.sample(&mut rng),
            StandardNormal.sample(&mut rng),
        );
        v.normalize_or(DVec3::X)
    };
    let (shift, axis) = (unit(), unit());
    Pose::new(
        pose.position + shift * mm * 1e-3,
        (DQuat::from_axis_angle(axis, deg.to_radians()) * pose.rotation).normalize(),
    )
}

#[derive(Deserialize)]
struct CalibrationFile {
    camera: CameraSection,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct CameraSection {
    position_m: [f64; 3],
    rotation_xyzw: [f64; 4],
}

/// The camera's pose from a hand-eye calibration file (`[camera] position_m` and
/// `rotation_xyzw`); the rest of the file (how it was found) is not read.
pub fn load_calibrated_camera(path: &Path) -> Result<Pose> {
    super::file_input::present(path, "file: cannot read calibration")?;
    let text = std::fs::read_to_string(path)
        .with_context(|| format!("{}: cannot read calibration", path.display()))?;
    let file: CalibrationFile = toml::from_str(&text).map_err(|e| {
        anyhow::anyhow!(
            "{}: {}",
            path.display(),
            e.message().lines().next().unwrap_or("not a calibration")
        )
    })?;
    let [x, y, z] = file.camera.position_m;
    let [qx, qy, qz, qw] = file.camera.rotation_xyzw;
    if ![x, y, z].iter().all(|v| v.is_finite()) {
        bail!("{}: camera.position_m must be finite", path.display());
    }
    let q = DQuat::from_xyzw(qx, qy, qz, qw);
    let length = q.length();
    if !length.is_finite() || (length - 1.0).abs() > UNIT_TOLERANCE {
        bail!(
            "{}: camera.rotation_xyzw has length {length:.4}; a rotation's quaternion has length 1",
            path.display()
        );
    }
    Ok(Pose::new(DVec3::new(x, y, z), q / length))
}
