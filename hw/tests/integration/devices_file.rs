//! `devices.toml`'s camera placed by a hand-eye calibration file instead of by hand: the
//! file's pose (in the arm's base frame) moved by the arm's base, and each way of getting it
//! wrong named with its field.

use std::path::Path;
use tactex_core::glam::{DQuat, DVec3};
use tactex_hw::devices_toml::DevicesConfig;

const ARM_AND_TACTILE: &str = r#"
[arm]
addr = "127.0.0.1:502"
base_in_world_m = [-0.40, 0.05, 0.0]

[tactile]
device = "GelSight Mini"
"#;

const CAMERA: &str = r#"
[camera]
color = "/dev/video4"
depth = "/dev/video2"
depth_scale_m = 0.0001
intrinsics = { width = 640, height = 480, fx = 608.5, fy = 606.9, cx = 309.4, cy = 213.83 }
"#;

/// Writes devices.toml with `camera_lines` after the camera's fixed fields, and calib.toml
/// beside it with `calib`, and loads it.
fn load(dir: &Path, camera_lines: &str, calib: &str) -> Result<DevicesConfig, String> {
    std::fs::write(dir.join("calib.toml"), calib).unwrap();
    let path = dir.join("devices.toml");
    std::fs::write(&path, format!("{ARM_AND_TACTILE}{CAMERA}{camera_lines}")).unwrap();
    DevicesConfig::load(&path).map_err(|e| e.to_string())
}

const CALIB: &str = "# tactex handeye\n[camera]\nposition_m = [0.41, 0.02, 0.69]\nrotation_xyzw = [1.0, 0.0, 0.0, 0.0]\n\n[fit]\nrms_px = 0.2\n";

#[test]
fn a_calibration_places_the_camera_from_the_arms_base() {
    let dir = tempfile::tempdir().unwrap();
    let config = load(dir.path(), "calibration = \"calib.toml\"\n", CALIB).unwrap();
    let pose = config.camera_pose();
    let want = DVec3::new(0.41 - 0.40, 0.02 + 0.05, 0.69);
    assert!(
        (pose.position - want).length() < 1e-12,
        "{:?}",
        pose.position
    );
    // Half a turn about x: the camera looks straight down, image y along -y of the world.
    assert!(
        pose.rotation
            .angle_between(DQuat::from_rotation_x(std::f64::consts::PI))
            < 1e-12
    );
}

#[test]
fn a_camera_placed_twice_or_not_at_all_is_refused_naming_the_field() {
    let dir = tempfile::tempdir().unwrap();
    let both = load(
        dir.path(),
        "calibration = \"calib.toml\"\nposition_m = [0.0, 0.0, 0.7]\nlook_at_m = [0.0, 0.0, 0.0]\n",
        CALIB,
    )
    .unwrap_err();
    assert!(
        both.contains("devices.toml: camera.calibration: places the camera"),
        "{both}"
    );
    let neither = load(dir.path(), "", CALIB).unwrap_err();
    assert!(
        neither.contains("devices.toml: camera: needs position_m and look_at_m"),
        "{neither}"
    );
    let half = load(dir.path(), "position_m = [0.0, 0.0, 0.7]\n", CALIB).unwrap_err();
    assert!(half.contains("camera: needs"), "{half}");
    // Hand-measured numbers are read exactly: a fourth is refused, not dropped.
    let long = load(
        dir.path(),
        "position_m = [0.0, 0.0, 0.7, 9.0]\nlook_at_m = [0.0, 0.0, 0.0]\n",
        CALIB,
    )
    .unwrap_err();
    assert!(long.contains("exactly 3"), "{long}");
}

#[test]
fn a_bad_calibration_file_is_named_through_the_field_that_names_it() {
    let dir = tempfile::tempdir().unwrap();
    let lines = "calibration = \"calib.toml\"\n";
    let skewed = load(
        dir.path(),
        lines,
        "[camera]\nposition_m = [0.0, 0.0, 0.7]\nrotation_xyzw = [0.5, 0.0, 0.0, 0.5]\n",
    )
    .unwrap_err();
    assert!(skewed.contains("camera.calibration: "), "{skewed}");
    assert!(
        skewed.contains("calib.toml: camera.rotation_xyzw has length 0.7071"),
        "{skewed}"
    );
    let missing = load(dir.path(), "calibration = \"nowhere.toml\"\n", CALIB).unwrap_err();
    assert!(
        missing.contains("nowhere.toml: cannot read calibration"),
        "{missing}"
    );
    let long = load(
        dir.path(),
        lines,
        "[camera]\nposition_m = [0.0, 0.0, 0.7]\nrotation_xyzw = [1.0, 0.0, 0.0, 0.0, 0.0]\n",
    )
    .unwrap_err();
    assert!(long.contains("exactly 4"), "{long}");
    let far = load(
        dir.path(),
        lines,
        "[camera]\nposition_m = [1e308, 0.0, 0.7]\nrotation_xyzw = [1.0, 0.0, 0.0, 0.0]\n",
    )
    .unwrap_err();
    assert!(
        far.contains("camera.position_m must be within 10 m"),
        "{far}"
    );
    let empty = load(dir.path(), "calibration = \"\"\n", CALIB).unwrap_err();
    assert!(empty.contains("camera.calibration: is empty"), "{empty}");
    for e in [skewed, missing, long, far, empty] {
        assert!(!e.contains('\n'), "{e}");
    }
}
