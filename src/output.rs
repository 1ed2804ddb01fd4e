//! Output files are written whole or not at all: into a temporary file beside the target,
//! then renamed over it.

use anyhow::{Context, Result};
use std::io::Write;
use std::path::Path;

fn atomic(path: &Path, write: impl FnOnce(&mut std::fs::File) -> Result<()>) -> Result<()> {
    let dir = path
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let mut tmp = tempfile::NamedTempFile::new_in(dir)
        .with_context(|| format!("{}: cannot write there", dir.display()))?;
    write(tmp.as_file_mut()).with_context(|| format!("{}: write failed", path.display()))?;
    tmp.as_file_mut().flush()?;
    // Readable like any other output file, not the temporary file's 0600.
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        tmp.as_file()
            .set_permissions(std::fs::Permissions::from_mode(0o644))?;
    }
    tmp.persist(path)
        .with_context(|| format!("{}: cannot write", path.display()))?;
    Ok(())
}

pub fn write_bytes_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    atomic(path, |f| Ok(f.write_all(bytes)?))
}

pub fn write_json_atomic(path: &Path, value: &impl serde::Serialize) -> Result<()> {
    let mut text = serde_json::to_string_pretty(value)?;
    text.push('\n');
    write_bytes_atomic(path, text.as_bytes())
}

/// A 16-bit greyscale PNG.
pub fn write_png16_atomic(path: &Path, width: u32, height: u32, data: Vec<u16>) -> Result<()> {
    let image = image::ImageBuffer::<image::Luma<u16>, Vec<u16>>::from_raw(width, height, data)
        .context("map size does not match its grid")?;
    let mut bytes = std::io::Cursor::new(Vec::new());
    image
        .write_to(&mut bytes, image::ImageFormat::Png)
        .context("encoding PNG")?;
    write_bytes_atomic(path, bytes.get_ref())
}

/// An 8-bit RGB PNG, encoded in memory.
pub fn png_bytes(image: &image::RgbImage) -> Result<Vec<u8>> {
    let mut bytes = std::io::Cursor::new(Vec::new());
    image
        .write_to(&mut bytes, image::ImageFormat::Png)
        .context("encoding PNG")?;
    Ok(bytes.into_inner())
}

/// An 8-bit RGB PNG.
pub fn write_png_atomic(path: &Path, image: &image::RgbImage) -> Result<()> {
    write_bytes_atomic(path, &png_bytes(image)?)
}

/// A sensor profile: its background PNG beside it first, then the TOML, so that a profile
/// file on disk always has its background.
pub fn write_profile_atomic(
    path: &Path,
    profile: &tactex_core::sensor_profile::SensorProfile,
) -> Result<()> {
    use tactex_core::sensor_profile::SensorProfile;
    let bg = SensorProfile::background_path(path);
    let bg_name = bg
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    if let Some(img) = &profile.background {
        write_png_atomic(&bg, img)?;
    }
    write_bytes_atomic(path, profile.to_toml(&bg_name).as_bytes())
}
