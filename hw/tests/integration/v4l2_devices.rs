//! The V4L2 devices on a machine without them: opening by a path that does not exist or a
//! name no device has is a one-line error naming the device, not a panic.
#![cfg(all(target_os = "linux", feature = "v4l2"))]

use tactex_core::geometry::{CameraIntrinsics, Pose};
use tactex_core::tactile::spec::TactileSpec;
use tactex_hw::gelsight_mini::GelSightMini;
use tactex_hw::realsense::RealSense;

#[test]
fn a_missing_gelsight_is_an_error_naming_it() {
    let e = GelSightMini::open("/dev/video-tactex-none", TactileSpec::gelsight_mini())
        .err()
        .expect("no device");
    let text = e.to_string();
    assert!(
        text.starts_with("gelsight mini: /dev/video-tactex-none"),
        "{text}"
    );
    let e = GelSightMini::open("No Such Sensor 9000", TactileSpec::gelsight_mini())
        .err()
        .expect("no device");
    assert!(
        e.to_string()
            .contains("no video device named like 'No Such Sensor 9000'"),
        "{e}"
    );
    assert_eq!(e.to_string().lines().count(), 1);
}

#[test]
fn a_missing_realsense_is_an_error_naming_the_stream() {
    let e = RealSense::open(
        "/dev/video-tactex-none",
        "/dev/video-tactex-none-2",
        CameraIntrinsics::default(),
        Pose::IDENTITY,
        1e-4,
    )
    .err()
    .expect("no device");
    assert!(
        e.to_string()
            .starts_with("realsense colour: /dev/video-tactex-none"),
        "{e}"
    );
}

#[test]
fn the_example_devices_file_is_valid() {
    let example = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../devices.example.toml");
    let config = tactex_hw::devices_toml::DevicesConfig::load(&example).unwrap();
    assert_eq!(config.arm.addr, "192.168.1.185:502");
    assert_eq!(config.camera.intrinsics, CameraIntrinsics::default());
    let pose = config.camera_pose();
    // Looking straight down from 0.7 m.
    assert!((pose.position.z - 0.7).abs() < 1e-12);
}
