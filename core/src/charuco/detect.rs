//! Finding a board in a camera image: what a detector backend gives (each corner it names,
//! where it saw it) and the trait the backends implement. A board not in the image is a
//! sighting with no corners, not an error.

use super::CharucoBoard;
use image::RgbImage;

/// One inner corner found: its id (`CharucoBoard::corners` index) and where it was seen
/// (px, sub-pixel; pixel x spans [x, x + 1), as the twin's renderers and
/// `CameraIntrinsics::project` have it).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SeenCorner {
    pub id: usize,
    pub px: [f64; 2],
}

/// What a detector found of a board in one image.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct BoardSighting {
    /// Markers decoded.
    pub markers: usize,
    /// Inner corners named and located, by id.
    pub corners: Vec<SeenCorner>,
}

/// A detector that could not look at an image at all (its library failed); a board it does
/// not find is an empty sighting instead.
#[derive(Debug, thiserror::Error)]
#[error("board detection: {0}")]
pub struct DetectError(pub String);

/// Finds a ChArUco board's corners in a colour image.
pub trait BoardDetector {
    /// The detector's name in reports ("opencv-4.6.0 aruco").
    fn name(&self) -> String;

    fn detect(&self, image: &RgbImage, board: &CharucoBoard) -> Result<BoardSighting, DetectError>;
}
