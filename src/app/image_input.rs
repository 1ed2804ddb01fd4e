//! Colour images given on the command line (frames, backgrounds, camera shots).

use anyhow::Result;
use image::RgbImage;
use std::path::Path;

/// The image at `path` as 8-bit RGB, with the path named in any error.
pub fn load_rgb(path: &Path) -> Result<RgbImage> {
    Ok(decode(path)?.to_rgb8())
}

/// The image at `path` as decoded, with the path named in any error.
fn decode(path: &Path) -> Result<image::DynamicImage> {
    super::file_input::present(path, "cannot read the image")?;
    tactex_core::image_file::open(path)
        .map_err(|e| anyhow::anyhow!("{}: cannot read the image: {e}", path.display()))
}

/// A tactile sensor's frame: colour (the shading is read from three channels) and not mostly
/// saturated (a blown-out or blank frame carries no shading to read).
pub fn load_tactile_frame(path: &Path) -> Result<RgbImage> {
    let decoded = decode(path)?;
    if let Some(fault) = tactex_core::image_file::tactile_frame_fault(&decoded) {
        anyhow::bail!("{}: {fault}", path.display());
    }
    Ok(decoded.to_rgb8())
}
