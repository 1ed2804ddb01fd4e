//! Colour images given on the command line (frames, backgrounds, camera shots).

use anyhow::Result;
use image::RgbImage;
use std::path::Path;

/// The image at `path` as 8-bit RGB, with the path named in any error.
pub fn load_rgb(path: &Path) -> Result<RgbImage> {
    super::file_input::present(path, "cannot read the image")?;
    Ok(tactex_core::image_file::open(path)
        .map_err(|e| anyhow::anyhow!("{}: cannot read the image: {e}", path.display()))?
        .to_rgb8())
}
