//! Sensor frames as the devices deliver them.

use image::{ImageBuffer, Luma, RgbImage};

/// Depth along the optical axis in metres; 0 marks an invalid pixel (as RealSense does).
pub type DepthImage = ImageBuffer<Luma<f32>, Vec<f32>>;

/// One aligned colour + depth capture.
#[derive(Clone, Debug)]
pub struct RgbdFrame {
    pub color: RgbImage,
    pub depth_m: DepthImage,
    /// Device time of the capture in seconds (simulated time on the twin).
    pub timestamp_s: f64,
}

/// One GelSight frame.
#[derive(Clone, Debug)]
pub struct TactileFrame {
    pub image: RgbImage,
    pub timestamp_s: f64,
}
