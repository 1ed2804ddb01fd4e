//! The sim devices behind core's traits: `SimCamera` (RGB-D with RealSense depth noise),
//! `SimArm` (moves with speed and acceleration limits in simulated time) and `SimGelSight`
//! (the contact solve at the pad's pose, rendered).

pub mod arm;
pub mod camera;
pub mod depth_noise;
pub mod gelsight;
