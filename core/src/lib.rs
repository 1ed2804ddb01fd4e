//! tactex-core: everything TactEx needs that does not depend on a backend.
//!
//! One folder per pipeline stage: `query` (prompt -> Query), `ground` (RGB-D frames -> the
//! fruit on the table), `press` (where to press, and the press protocol every backend runs),
//! `tactile` (the sensor, its profile, and reading its frames), `hardness` (scales and
//! estimators with measured intervals), `explain` (template, groundedness check, LLM
//! prompt) and `pipeline` (the stages in order, generic over the device traits); `stats`
//! holds the tests and intervals the evaluations use. At the root: the device traits
//! (`devices`) that the simulated (`tactex-sim`), real (`tactex-hw`) and replay backends
//! implement, frames and geometry, the fruit catalog and scene format, Hertz theory, and the
//! input and output helpers every crate shares. Nothing in here knows which backend it runs
//! against, and nothing here runs a neural network: learned models live in `tactex-learned`.

#![forbid(unsafe_code)]

pub mod catalog;
pub mod charuco;
pub mod devices;
pub mod dir_claim;
pub mod dummy;
pub mod explain;
pub mod file_failure;
pub mod frames;
pub mod geometry;
pub mod ground;
pub mod hand_eye;
pub mod hardness;
pub mod hertz;
pub mod image_file;
pub mod pipeline;
pub mod press;
pub mod printable;
pub mod query;
pub mod scene;
pub mod scoped_map;
pub mod serde_exact;
pub mod spectral;
pub mod stats;
pub mod tactile;
pub mod text_file;

pub use glam;
pub use image;
