//! uFactory xArm (the paper's xArm 850) over the controller's private TCP protocol on port
//! 502, byte for byte as the vendor's Python SDK (xArm-Developer/xArm-Python-SDK) speaks it.

pub mod arm;
pub mod client;
pub mod codes;
pub mod fake_controller;
pub mod frame;

pub use arm::XArmDevice;
pub use client::{MotionState, TcpPose, WorkspaceBox, XArm, XArmConfig, XArmError};
