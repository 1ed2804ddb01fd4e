//! tactex-hw: the real-device backends behind tactex-core's traits (uFactory xArm over its
//! TCP protocol, GelSight Mini and RealSense over V4L2, recorded-session replay).
//!
//! Here: the xArm client (`xarm`, with a fake controller for tests and bring-up) and
//! recorded sessions (`session`: record any backend's devices, replay them). The V4L2
//! cameras follow.

pub mod devices_toml;
pub mod gelsight_mini;
pub mod realsense;
pub mod session;
#[cfg(target_os = "linux")]
pub mod v4l2_capture;
pub mod xarm;
