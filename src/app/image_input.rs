//! Colour images given on the command line (frames, backgrounds, camera shots).

use anyhow::Result;
use image::RgbImage;
use std::path::Path;

/// The image at `path` as 8-bit RGB, with the path named in any error.
pub fn load_rgb(path: &Path) -> Result<RgbImage> {
    Ok(decode(path)?.to_rgb8())
}

/// An image given as input that cannot serve: not an image, cut short, a directory, not a
/// colour tactile frame, not the sensor's size. Bad input, named by its path.
#[derive(Debug, thiserror::Error)]
#[error("{path}: {problem}")]
pub struct ImageInputError {
    pub path: String,
    pub problem: String,
}

impl ImageInputError {
    pub fn new(path: &Path, problem: impl Into<String>) -> Self {
        Self {
            path: path.display().to_string(),
            problem: problem.into(),
        }
    }
}

/// The image at `path` as decoded, with the path named in any error.
fn decode(path: &Path) -> Result<image::DynamicImage> {
    super::file_input::present(path, "cannot read the image")?;
    tactex_core::image_file::open(path)
        .map_err(|e| ImageInputError::new(path, format!("cannot read the image: {e}")).into())
}

/// A tactile sensor's frame: colour (the shading is read from three channels) and not mostly
/// saturated (a blown-out or blank frame carries no shading to read).
pub fn load_tactile_frame(path: &Path) -> Result<RgbImage> {
    let decoded = decode(path)?;
    if let Some(fault) = tactex_core::image_file::tactile_frame_fault(&decoded) {
        return Err(ImageInputError::new(path, fault.to_string()).into());
    }
    Ok(decoded.to_rgb8())
}
