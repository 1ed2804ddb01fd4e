//! `ask --backend hw` on a machine without the devices: a bad devices.toml names its file
//! and field, the real sensor's profile is required, a missing camera is named and the arm is
//! not enabled, and misused flags are one-line errors.

use crate::cli::one_line_error;
use std::process::{Command, Output};
use tactex_hw::xarm::fake_controller::FakeController;

fn ask(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_tactex"))
        .arg("ask")
        .args(args)
        .arg("How hard is the kiwi?")
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("runs tactex")
}

/// The built-in GelSight Mini profile written to `dir/mini.toml` (what a user edits or
/// `tactex calibrate` replaces).
fn mini_profile(dir: &std::path::Path) -> String {
    let out = Command::new(env!("CARGO_BIN_EXE_tactex"))
        .args(["sensor", "show", "--toml"])
        .output()
        .expect("runs tactex");
    assert!(out.status.success());
    let path = dir.join("mini.toml");
    std::fs::write(&path, out.stdout).unwrap();
    path.to_str().unwrap().to_string()
}

fn devices_toml(addr: &str, extra: &str) -> String {
    format!(
        r#"[arm]
addr = "{addr}"
base_in_world_m = [-0.4, 0.0, 0.0]
{extra}
[camera]
color = "/dev/video-tactex-none"
depth = "/dev/video-tactex-none-2"
depth_scale_m = 0.0001
intrinsics = {{ width = 640, height = 480, fx = 608.5, fy = 606.9, cx = 309.4, cy = 213.83 }}
position_m = [0.0, 0.0, 0.7]
look_at_m = [0.0, 0.0, 0.0]

[tactile]
device = "GelSight Mini"
"#
    )
}

#[test]
fn a_missing_camera_is_named_and_the_arm_is_left_alone() {
    let f = FakeController::start().unwrap();
    let tmp = tempfile::tempdir().unwrap();
    let file = tmp.path().join("devices.toml");
    std::fs::write(&file, devices_toml(&f.addr.to_string(), "")).unwrap();
    // Without the sensor's profile the real frames cannot be read: said before anything opens.
    let stderr = one_line_error(&ask(&[
        "--backend",
        "hw",
        "--devices",
        file.to_str().unwrap(),
    ]));
    assert!(stderr.contains("--sensor"), "{stderr}");
    let profile = mini_profile(tmp.path());
    let stderr = one_line_error(&ask(&[
        "--backend",
        "hw",
        "--devices",
        file.to_str().unwrap(),
        "--sensor",
        &profile,
    ]));
    // Built without the V4L2 feature there are no cameras to open: that is said instead.
    let says = if cfg!(feature = "v4l2") {
        "realsense colour: /dev/video-tactex-none: no such video device"
    } else {
        "built without V4L2"
    };
    assert!(stderr.contains(says), "{stderr}");
    assert!(f.with(|s| s.requests.is_empty()), "the arm was not touched");
}

#[test]
fn a_bad_devices_file_names_the_file_and_field() {
    let tmp = tempfile::tempdir().unwrap();
    let file = tmp.path().join("devices.toml");
    let path = file.to_str().unwrap();
    for (extra, says) in [
        ("speed = 3", "unknown field `speed`"),
        (
            "workspace_mm = [700, 100, -400, 400, 50, 600]",
            "arm.workspace_mm",
        ),
    ] {
        std::fs::write(&file, devices_toml("127.0.0.1:502", extra)).unwrap();
        let stderr = one_line_error(&ask(&["--backend", "hw", "--devices", path]));
        assert!(stderr.contains(path), "{stderr}");
        assert!(stderr.contains(says), "{stderr}");
    }
    let stderr = one_line_error(&ask(&["--backend", "hw"]));
    assert!(stderr.contains("--devices"), "{stderr}");
    let stderr = one_line_error(&ask(&["--devices", path]));
    assert!(stderr.contains("only with --backend hw"), "{stderr}");
    // The twin's camera rig is refused on real devices: their camera is placed in the file.
    std::fs::write(&file, devices_toml("127.0.0.1:502", "")).unwrap();
    for (flag, value) in [
        ("--camera-calibration", "calib.toml"),
        ("--camera-error-mm", "20"),
        ("--camera-error-deg", "2"),
    ] {
        let stderr = one_line_error(&ask(&["--backend", "hw", "--devices", path, flag, value]));
        assert!(
            stderr.contains(&format!("{flag}: only with --backend sim")),
            "{stderr}"
        );
    }
    let stderr = one_line_error(&ask(&[
        "--backend",
        "hw",
        "--devices",
        "no/such/devices.toml",
    ]));
    assert!(stderr.contains("no/such/devices.toml"), "{stderr}");
}
