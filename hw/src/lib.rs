//! tactex-hw: the real-device backends behind tactex-core's traits (uFactory xArm over its
//! TCP protocol, GelSight Mini and RealSense over V4L2, recorded-session replay).
//!
//! Here: the xArm client (`xarm`, with a fake controller for tests and bring-up), recorded
//! sessions (`session`: record any backend's devices, replay them), and the cameras' frame
//! decoding. Opening the cameras over V4L2 takes the `v4l2` feature (libclang for bindgen).

pub mod devices_toml;
pub mod gelsight_mini;
pub mod realsense;
pub mod session;
#[cfg(all(target_os = "linux", feature = "v4l2"))]
pub mod v4l2_capture;
pub mod xarm;
