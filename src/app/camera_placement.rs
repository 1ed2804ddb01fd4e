//! Where the twin's scene camera really stands against where its user believes it does: a
//! rig placed with an error (moved and turned in directions drawn from a seed), and the
//! belief taken from the scene or from a hand-eye calibration file (`tactex handeye`'s
//! `calib.toml`). `ask`, `serve`, the evaluations and `handeye` itself share it.

use anyhow::{Result, bail};
use glam::{DQuat, DVec3};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};
use std::path::Path;
use tactex_core::geometry::Pose;
use tactex_core::hand_eye::calibration_file;
use tactex_sim::SimDevices;

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

/// The camera's pose from a hand-eye calibration file (`[camera] position_m` and
/// `rotation_xyzw`, in the arm's base frame, which is the twin's world); the rest of the file
/// (how it was found) is not read.
pub fn load_calibrated_camera(path: &Path) -> Result<Pose> {
    super::file_input::present(path, "file: cannot read calibration")?;
    Ok(calibration_file::load_camera_in_base(path)?)
}
