//! tactex-core: everything TactEx needs that does not depend on a backend.
//!
//! Types (poses, intrinsics, frames), the device traits that the simulated (`tactex-sim`),
//! real (`tactex-hw`) and replay backends implement, the fruit catalog and scene format,
//! Hertz contact theory, perception (detection, mask refinement, centroids, tactile
//! helpers), hardness estimation, explanation (template, groundedness check, LLM prompt) and
//! the question pipeline that is generic over the device traits. Nothing in here knows which
//! backend it runs against,
//! and nothing here runs a neural network: learned models live in `tactex-learned`.

#![forbid(unsafe_code)]

pub mod ball_calibration;
pub mod catalog;
pub mod devices;
pub mod dir_claim;
pub mod estimate;
pub mod explain;
pub mod file_failure;
pub mod frames;
pub mod gel_glow;
pub mod gel_share_fit;
pub mod geometry;
pub mod hardness;
pub mod hertz;
pub mod image_file;
pub mod indentation_estimator;
pub mod interval_calibration;
pub mod layer_compliance;
pub mod perception;
pub mod photometric;
pub mod pipeline;
pub mod press;
pub mod printable;
pub mod query;
pub mod scene;
pub mod sensor_profile;
pub mod shading_table;
pub mod spectral;
pub mod stats;
pub mod tactile_spec;

pub use glam;
pub use image;
