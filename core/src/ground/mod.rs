//! Grounding: from RGB-D frames to the fruit on the table. Detection (the `Detector` trait
//! and the classical depth + colour detector, with the splits that tell touching fruit
//! apart), mask refinement, the depth-median centroid and colour names. It works on real
//! frames as on the twin's.

pub mod centroid;
pub mod colour_name;
pub mod detect;
pub mod grounding;
pub mod height_split;
pub mod mask;
pub mod neck_split;

// The stage's face: its trait and what it hands on.
pub use detect::{ClassicalDetector, DetectError, Detection, Detector, RgbdView};
pub use grounding::{Located, locate};
