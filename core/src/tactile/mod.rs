//! The tactile sensor and its frames: what a GelSight is (`spec`, `sensor_profile`, the
//! shading models `photometric` and `shading_table`, the `gel_glow`), how a profile is fitted
//! from ball presses (`ball_calibration`), and reading its frames: SSIM, markers and their
//! grid, the contact criterion, the contact circle, surface slopes (a table read backwards in
//! `shading_inverse`) and the indentation map.

pub mod ball_calibration;
pub mod circle_fit;
mod closing;
pub mod contact;
pub mod contact_circle;
pub mod depth;
pub mod frame_reading;
pub mod gel_glow;
pub mod glow_inverse;
pub mod half_resolution;
pub mod marker_grid;
pub mod markers;
pub mod photometric;
pub mod sensor_profile;
pub mod separable;
pub mod shading_inverse;
pub mod shading_table;
pub mod slopes;
pub mod spec;
pub mod ssim;

// The stage's face: what a sensor is and what a frame reads as.
pub use frame_reading::{FrameReading, read_frame};
pub use sensor_profile::{ProfileError, ProfileId, SensorProfile, Shading};
pub use spec::{GelSpec, MarkerGrid, TactileSpec};
