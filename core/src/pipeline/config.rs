//! What a question runs with (PipelineConfig) and how it can fail (PipelineError).

use crate::devices::DeviceError;
use crate::ground::detect::DetectError;
use crate::press::protocol::PressProtocol;
use crate::query::QueryError;

#[derive(Clone, Debug)]
pub struct PipelineConfig {
    /// Depth frames whose per-pixel median feeds the centroids (the paper: 10).
    pub depth_frames: usize,
    /// The press (the paper's: 0.25 mm steps, 8 frames from the first contact on, the one
    /// contact criterion); its search gives up after `max_search_mm` of descent.
    pub press: PressProtocol,
    /// The search for contact starts this far above the surface the camera saw.
    pub approach_clearance_mm: f64,
    pub max_search_mm: f64,
    pub safe_height_m: f64,
    pub travel_speed_m_s: f64,
    pub press_speed_m_s: f64,
    /// Record wall-clock times (off for byte-reproducible output).
    pub measure_wall_time: bool,
}

impl Default for PipelineConfig {
    fn default() -> Self {
        Self {
            depth_frames: 10,
            press: PressProtocol::default(),
            approach_clearance_mm: 4.0,
            max_search_mm: 20.0,
            safe_height_m: 0.20,
            travel_speed_m_s: 0.15,
            press_speed_m_s: 0.005,
            measure_wall_time: true,
        }
    }
}

#[derive(Debug, thiserror::Error)]
pub enum PipelineError {
    #[error(transparent)]
    Query(#[from] QueryError),
    /// A model's reading failed and the rules refused the prompt too.
    #[error("{error} ({notice})")]
    Unread {
        #[source]
        error: QueryError,
        notice: String,
    },
    #[error(transparent)]
    Device(#[from] DeviceError),
    #[error("camera: {0}")]
    Camera(String),
    #[error(transparent)]
    Detect(#[from] DetectError),
    #[error("hardness: {0}")]
    Estimator(String),
}
