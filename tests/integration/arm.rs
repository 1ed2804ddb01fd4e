//! `tactex arm` against the fake xArm controller (tactex-hw) running in this test process.

use crate::cli::one_line_error;
use serde_json::Value;
use std::process::{Command, Output};
use tactex_hw::xarm::fake_controller::FakeController;

fn tactex_arm(f: &FakeController, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_tactex"))
        .args(["arm", "--addr", &f.addr.to_string(), "--timeout-s", "2"])
        .args(args)
        .output()
        .expect("runs tactex")
}

#[test]
fn pose_move_and_home_work_against_the_fake_controller() {
    let f = FakeController::start().unwrap();
    f.with(|s| s.time_scale = 0.02);

    let out = tactex_arm(&f, &["pose", "--json"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let pose: Value = serde_json::from_slice(&out.stdout).unwrap();
    for (key, want) in [
        ("x_mm", 300.0),
        ("y_mm", 0.0),
        ("z_mm", 300.0),
        ("roll_deg", 180.0),
        ("pitch_deg", 0.0),
        ("yaw_deg", 0.0),
    ] {
        let got = pose[key]
            .as_f64()
            .unwrap_or_else(|| panic!("{key} in {pose}"));
        assert!((got - want).abs() < 1e-3, "{key}: {got}");
    }

    let out = tactex_arm(
        &f,
        &[
            "move", "350", "-50", "250", "180", "0", "30", "--speed", "100",
        ],
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let reached = f.with(|s| s.pose);
    assert!((reached.y_mm + 50.0).abs() < 1e-3 && (reached.z_mm - 250.0).abs() < 1e-3);
    assert!((reached.yaw_rad - 30f64.to_radians()).abs() < 1e-5);
    // Speed travels in mm/s, angles in radians, as the SDK sends them.
    let sent = f.with(|s| {
        s.requests
            .iter()
            .find(|r| r.0 == 21)
            .map(|r| tactex_hw::xarm::frame::f32_values(&r.1))
            .unwrap()
    });
    assert!((sent[6] - 100.0).abs() < 1e-4 && (sent[3] - std::f64::consts::PI).abs() < 1e-5);

    let out = tactex_arm(&f, &["home"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!((f.with(|s| s.pose.z_mm) - 300.0).abs() < 1e-3);
    f.with(|s| assert!(s.violations.is_empty(), "{:?}", s.violations));
}

#[test]
fn a_move_outside_the_workspace_is_refused_and_the_arm_is_not_touched() {
    let f = FakeController::start().unwrap();
    let out = tactex_arm(&f, &["move", "350", "0", "-20", "180", "0", "0"]);
    let stderr = one_line_error(&out);
    assert!(stderr.contains("outside the workspace box"), "{stderr}");
    assert!(f.with(|s| s.requests.is_empty()), "nothing was sent");
    let out = tactex_arm(&f, &["--workspace-mm", "0,1,2", "pose"]);
    assert!(one_line_error(&out).contains("--workspace-mm"));
}

#[test]
fn controller_errors_and_a_missing_controller_are_one_line_errors() {
    let f = FakeController::start().unwrap();
    f.with(|s| s.faults.error_on_move = Some(22));
    let out = tactex_arm(&f, &["move", "350", "0", "250", "180", "0", "0"]);
    let stderr = one_line_error(&out);
    assert!(
        stderr.contains("controller error 22: self-collision"),
        "{stderr}"
    );

    let addr = f.addr.to_string();
    drop(f);
    let out = Command::new(env!("CARGO_BIN_EXE_tactex"))
        .args(["arm", "--addr", &addr, "pose"])
        .output()
        .unwrap();
    let stderr = one_line_error(&out);
    assert!(
        stderr.contains(&format!("xarm {addr}: cannot connect")),
        "{stderr}"
    );
}

#[test]
fn a_controller_reporting_a_pose_that_is_not_a_number_is_a_one_line_error() {
    let f = FakeController::start().unwrap();
    f.with(|s| s.pose.z_mm = f64::NAN);
    let stderr = one_line_error(&tactex_arm(&f, &["pose", "--json"]));
    assert!(stderr.contains("not a number"), "{stderr}");
    f.with(|s| s.pose.z_mm = f64::INFINITY);
    let stderr = one_line_error(&tactex_arm(&f, &["pose"]));
    assert!(stderr.contains("not a number (inf)"), "{stderr}");
}
