//! tactex-hw: the real-device backends behind tactex-core's traits (uFactory xArm over its
//! TCP protocol, GelSight Mini and RealSense over V4L2, recorded-session replay).
//!
//! The walking skeleton runs on the simulated twin only; the devices land here with issue 8,
//! and the `tactex` binary selects them with `--backend`. Until then this crate has no
//! backend to offer and the binary says so rather than pretending.
