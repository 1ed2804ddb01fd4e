//! The xArm client against a fake controller on 127.0.0.1 that checks every frame: moves
//! arrive in the SDK's units and layout, unsafe moves never leave the client, and faults
//! (silence, a dropped connection mid-move, controller errors and warnings, a wrong
//! protocol) become typed errors or are recovered from.

use std::f64::consts::PI;
use std::io::{Read, Write};
use std::time::Duration;
use tactex_core::devices::{Arm, DeviceError};
use tactex_core::geometry::Pose;
use tactex_core::glam::DVec3;
use tactex_hw::xarm::fake_controller::{FakeController, Faults};
use tactex_hw::xarm::frame::{self, Register};
use tactex_hw::xarm::{MotionState, TcpPose, XArm, XArmConfig, XArmDevice, XArmError};

fn fake() -> FakeController {
    let f = FakeController::start().expect("fake controller listens");
    // Moves take 1/50 of their real time.
    f.with(|s| s.time_scale = 0.02);
    f
}

fn client(f: &FakeController) -> XArm {
    let mut config = XArmConfig::new(f.addr.to_string());
    config.reply_timeout = Duration::from_millis(400);
    config.poll_interval = Duration::from_millis(5);
    config.move_timeout = Duration::from_secs(20);
    XArm::connect(config).expect("connects")
}

fn target() -> TcpPose {
    TcpPose {
        x_mm: 350.0,
        y_mm: 50.0,
        z_mm: 250.0,
        roll_rad: PI,
        pitch_rad: 0.0,
        yaw_rad: 0.5,
    }
}

fn close(a: &TcpPose, b: &TcpPose) -> bool {
    a.to_array()
        .iter()
        .zip(b.to_array())
        .all(|(x, y)| (x - y).abs() < 1e-4 * y.abs().max(1.0))
}

#[test]
fn a_move_arrives_in_the_sdk_layout_and_units_and_the_arm_ends_there() {
    let f = fake();
    let arm = client(&f);
    arm.prepare().unwrap();
    arm.move_line(&target(), 100.0).unwrap();
    let pose = arm.tcp_pose().unwrap();
    assert!(close(&pose, &target()), "{pose:?}");
    assert_eq!(arm.motion_state().unwrap(), MotionState::Ready);

    f.with(|s| {
        assert!(s.violations.is_empty(), "{:?}", s.violations);
        let registers: Vec<u8> = s.requests.iter().map(|r| r.0).collect();
        // Enable all joints (axis 8), position mode, start; then the move.
        assert_eq!(&registers[..4], &[11, 19, 12, 21]);
        assert_eq!(s.requests[0].1, [8, 1]);
        assert_eq!(s.requests[1].1, [0]);
        assert_eq!(s.requests[2].1, [0]);
        let sent = frame::f32_values(&s.requests[3].1);
        let want = [350.0, 50.0, 250.0, PI, 0.0, 0.5, 100.0, 2000.0, 0.0];
        for (a, b) in sent.iter().zip(want) {
            assert!((a - b).abs() < 1e-4, "{sent:?}");
        }
        // Then the state is polled until the arm rests.
        assert!(registers[4..].contains(&13));
    });
}

#[test]
fn a_move_outside_the_workspace_box_or_too_fast_is_refused_before_anything_is_sent() {
    let f = fake();
    let arm = client(&f);
    arm.prepare().unwrap();
    let sent = f.with(|s| s.requests.len());
    let mut low = target();
    low.z_mm = 10.0;
    let mut nan = target();
    nan.x_mm = f64::NAN;
    for (pose, speed, says) in [
        (low, 100.0, "z = 10.0 mm is outside the workspace box"),
        (nan, 100.0, "not a number"),
        (target(), 0.0, "speed 0 mm/s"),
        (target(), 5000.0, "speed 5000 mm/s"),
    ] {
        let e = arm.move_line(&pose, speed).unwrap_err();
        assert!(matches!(e, XArmError::Refused { .. }), "{e}");
        assert!(e.to_string().contains(says), "{e}");
    }
    assert_eq!(
        f.with(|s| s.requests.len()),
        sent,
        "nothing reached the arm"
    );
}

#[test]
fn a_controller_error_during_a_move_names_its_cause() {
    let f = fake();
    f.with(|s| s.faults.error_on_move = Some(35));
    let arm = client(&f);
    arm.prepare().unwrap();
    let e = arm.move_line(&target(), 100.0).unwrap_err();
    match &e {
        XArmError::Controller { code, title, .. } => {
            assert_eq!(*code, 35);
            assert!(title.contains("safety boundary"), "{e}");
        }
        other => panic!("{other}"),
    }
    // After the operator clears it, the arm is ready again.
    f.with(|s| s.faults.error_on_move = None);
    arm.clean_error().unwrap();
    arm.prepare().unwrap();
    arm.move_line(&target(), 100.0).unwrap();
}

#[test]
fn a_warning_in_reply_to_a_move_is_a_refusal_naming_the_warning() {
    let f = fake();
    f.with(|s| s.faults.warning_on_move = Some(14));
    let arm = client(&f);
    arm.prepare().unwrap();
    let e = arm.move_line(&target(), 100.0).unwrap_err();
    assert!(matches!(e, XArmError::Warning { code: 14, .. }), "{e}");
    assert!(e.to_string().contains("no solution"), "{e}");
}

#[test]
fn a_move_before_the_arm_is_enabled_is_not_ready() {
    let f = fake();
    let arm = client(&f);
    let e = arm.move_line(&target(), 100.0).unwrap_err();
    assert!(matches!(e, XArmError::NotReady { .. }), "{e}");
}

#[test]
fn a_silent_controller_is_a_timeout_and_the_next_request_reconnects() {
    let f = fake();
    f.with(|s| s.faults.silent = Some(Register::GetTcpPose));
    let arm = client(&f);
    let e = arm.tcp_pose().unwrap_err();
    assert!(matches!(e, XArmError::Timeout { .. }), "{e}");
    assert!(e.to_string().contains("GetTcpPose"), "{e}");
    f.with(|s| s.faults = Faults::default());
    let pose = arm.tcp_pose().unwrap();
    assert!((pose.z_mm - 300.0).abs() < 1e-3);
    assert_eq!(f.with(|s| s.connections), 2);
}

#[test]
fn a_connection_dropped_mid_move_is_reopened_and_the_move_completes() {
    let f = fake();
    f.with(|s| s.faults.drop_after_move = true);
    let arm = client(&f);
    arm.prepare().unwrap();
    arm.move_line(&target(), 100.0).unwrap();
    assert!(close(&arm.tcp_pose().unwrap(), &target()));
    assert_eq!(f.with(|s| s.connections), 2);
}

#[test]
fn a_controller_that_stops_mid_move_is_an_error() {
    let f = fake();
    // Slow moves, so that the stop lands while the arm moves.
    f.with(|s| s.time_scale = 1.0);
    let arm = std::sync::Arc::new(client(&f));
    arm.prepare().unwrap();
    let stopper = {
        let state = f.state.clone();
        std::thread::spawn(move || {
            std::thread::sleep(Duration::from_millis(150));
            let mut s = state.lock().unwrap();
            s.state = 4;
            s.moving_to = None;
        })
    };
    let e = arm.move_line(&target(), 100.0).unwrap_err();
    stopper.join().unwrap();
    assert!(
        matches!(
            e,
            XArmError::Stopped {
                state: MotionState::Stopped,
                ..
            }
        ),
        "{e}"
    );
}

#[test]
fn nothing_listening_is_a_connect_error_naming_the_address() {
    let port = {
        let l = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
        l.local_addr().unwrap().port()
    };
    let addr = format!("127.0.0.1:{port}");
    let e = XArm::connect(XArmConfig::new(addr.clone()))
        .err()
        .expect("refused");
    assert!(matches!(e, XArmError::Connect { .. }), "{e}");
    assert!(e.to_string().contains(&addr), "{e}");
    let e = XArm::connect(XArmConfig::new("no-such-host.invalid:502"))
        .err()
        .expect("unresolvable");
    assert!(e.to_string().contains("no-such-host.invalid:502"), "{e}");
}

#[test]
fn a_reply_in_another_protocol_is_a_protocol_error() {
    let listener = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
    let addr = listener.local_addr().unwrap();
    let server = std::thread::spawn(move || {
        let (mut s, _) = listener.accept().unwrap();
        let mut request = [0u8; 7];
        s.read_exact(&mut request).unwrap();
        // Standard Modbus (protocol id 0) instead of the private protocol.
        let reply = frame::reply(
            u16::from_be_bytes([request[0], request[1]]),
            0,
            41,
            0,
            &[0; 24],
        );
        s.write_all(&reply).unwrap();
    });
    let arm = XArm::connect(XArmConfig::new(addr.to_string())).unwrap();
    let e = arm.tcp_pose().unwrap_err();
    server.join().unwrap();
    assert!(matches!(e, XArmError::Protocol { .. }), "{e}");
    assert!(e.to_string().contains("protocol id 0x0000"), "{e}");
}

#[test]
fn the_arm_trait_moves_in_world_metres_about_the_arm_base() {
    let f = fake();
    let arm = client(&f);
    arm.prepare().unwrap();
    // The base stands 0.4 m behind the world origin, 0.05 m below the table top.
    let base = DVec3::new(-0.4, 0.0, -0.05);
    let mut device = XArmDevice::new(arm, base);
    let goal = Pose::tool_down(DVec3::new(-0.05, 0.05, 0.2));
    device.move_linear(&goal, 0.1).unwrap();
    let tcp = f.with(|s| s.pose);
    let want = TcpPose {
        x_mm: 350.0,
        y_mm: 50.0,
        z_mm: 250.0,
        roll_rad: PI,
        pitch_rad: 0.0,
        yaw_rad: 0.0,
    };
    assert!(close(&tcp, &want), "{tcp:?}");
    let back = device.pose().unwrap();
    assert!((back.position - goal.position).length() < 1e-6);
    assert!(back.rotation.angle_between(goal.rotation) < 1e-6);
    // Outside the box is an unsafe move for the pipeline, naming the arm.
    let e = device
        .move_linear(&Pose::tool_down(DVec3::new(0.0, 0.0, -0.2)), 0.1)
        .unwrap_err();
    assert!(matches!(e, DeviceError::UnsafeMove { .. }), "{e}");
    assert!(e.to_string().starts_with("xarm 127.0.0.1:"), "{e}");
}
