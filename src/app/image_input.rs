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
    if !decoded.color().has_color() {
        anyhow::bail!(
            "{}: a greyscale image; a tactile frame is colour (its shading is read from three channels)",
            path.display()
        );
    }
    let frame = decoded.to_rgb8();
    let saturated = frame.pixels().filter(|p| p.0.contains(&255)).count();
    if 2 * saturated > frame.pixels().len() {
        anyhow::bail!(
            "{}: {:.0}% of its pixels are saturated (255); a tactile frame this blown out carries no shading",
            path.display(),
            100.0 * saturated as f64 / frame.pixels().len() as f64
        );
    }
    Ok(frame)
}
