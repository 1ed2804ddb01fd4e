//! Camera vision backends for what the core's traits leave to a library: with the `opencv`
//! feature, `CharucoDetector` finds a ChArUco board's corners with OpenCV's ArUco module
//! (markers decoded, corners interpolated from them and refined to sub-pixel), implementing
//! `tactex_core::charuco::BoardDetector`. Without the feature the crate offers nothing, so
//! the workspace builds on a machine without OpenCV.

#[cfg(feature = "opencv")]
mod charuco_opencv;

#[cfg(feature = "opencv")]
pub use charuco_opencv::CharucoDetector;
