//! Outputs are written whole or not at all: a file into a temporary file beside the target,
//! then renamed over it; a directory of outputs into `DIR.partial`, moved in when complete.

use anyhow::{Context, Result, bail};
use std::io::Write;
use std::path::{Path, PathBuf};

fn atomic(path: &Path, write: impl FnOnce(&mut std::fs::File) -> Result<()>) -> Result<()> {
    let dir = path
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    // `--out profiles/mine.toml` makes its folder, as `--out DIR` does.
    std::fs::create_dir_all(dir).with_context(|| format!("{}: cannot create", dir.display()))?;
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
    check_png_path(path)?;
    write_bytes_atomic(path, &png_bytes(image)?)
}

/// Whether two paths name one existing file (a path that does not exist is no input).
pub fn same_file(a: &Path, b: &Path) -> bool {
    match (std::fs::canonicalize(a), std::fs::canonicalize(b)) {
        (Ok(a), Ok(b)) => a == b,
        _ => false,
    }
}

/// A PNG goes only to a file named .png: `--out view.jpg` would hold PNG bytes under a name
/// that says otherwise.
pub fn check_png_path(path: &Path) -> Result<()> {
    let png = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("png"));
    if !png {
        bail!("{}: writes a PNG image; name the file .png", path.display());
    }
    Ok(())
}

/// A sensor profile: its background PNG beside it first, then the TOML, so that a profile
/// file on disk always has its background.
pub fn write_profile_atomic(
    path: &Path,
    profile: &tactex_core::tactile::sensor_profile::SensorProfile,
) -> Result<()> {
    use tactex_core::tactile::sensor_profile::SensorProfile;
    let bg = SensorProfile::background_path(path);
    let bg_name = bg
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    // A profile path that cannot take the file must fail before its background is written.
    if path.is_dir() {
        bail!("{}: is a directory, not a profile file", path.display());
    }
    if let Some(img) = &profile.background {
        write_png_atomic(&bg, img)?;
    }
    let written = write_bytes_atomic(path, profile.to_toml(&bg_name).as_bytes());
    if written.is_err() && profile.background.is_some() {
        // Not half a profile: a background without its TOML is no profile at all.
        let _ = std::fs::remove_file(&bg);
    }
    written
}

/// A directory of outputs written whole or not at all: files go into `DIR.partial`, claimed
/// by this process, and move into `DIR` only when the command has written all of them. A
/// failed run leaves `DIR` as it was, so the retry starts clean; two runs into one directory
/// do not mix their files.
pub struct OutputDir {
    flag: &'static str,
    target: PathBuf,
    staging: PathBuf,
    finished: bool,
    /// The command's input files, which no output may replace.
    inputs: Vec<PathBuf>,
}

impl OutputDir {
    /// `flag` names the option that gave `target`, for messages.
    pub fn create(flag: &'static str, target: &Path) -> Result<OutputDir> {
        if target.exists() && !target.is_dir() {
            bail!("{flag} {}: exists and is not a directory", target.display());
        }
        // "." or "dir/..": the staging directory needs a name beside the target.
        let target = if target.file_name().is_none() {
            target
                .canonicalize()
                .with_context(|| format!("{flag} {}: cannot resolve", target.display()))?
        } else {
            target.to_path_buf()
        };
        if let Some(parent) = target.parent().filter(|p| !p.as_os_str().is_empty()) {
            std::fs::create_dir_all(parent)
                .with_context(|| format!("{flag} {}: cannot create", parent.display()))?;
        }
        let mut name = target.file_name().expect("resolved above").to_os_string();
        name.push(".partial");
        let staging = target.with_file_name(name);
        tactex_core::dir_claim::claim_dir(&staging, "writing outputs")
            .map_err(|e| anyhow::anyhow!("{flag} {}: {e}", target.display()))?;
        Ok(OutputDir {
            flag,
            target,
            staging,
            finished: false,
            inputs: Vec::new(),
        })
    }

    /// Files the command reads (a sensor profile and its background, a mesh), which
    /// `finish` refuses to replace: a profile kept in the output directory under an output's
    /// name would be overwritten by it.
    pub fn keep(&mut self, inputs: impl IntoIterator<Item = PathBuf>) {
        self.inputs.extend(inputs);
    }

    /// Where the command writes its files until `finish`.
    pub fn path(&self) -> &Path {
        &self.staging
    }

    /// Moves every file into the target directory, after checking that none lands where a
    /// directory is (or a directory where a file is), so that a refusal moves nothing.
    pub fn finish(mut self) -> Result<()> {
        tactex_core::dir_claim::release_dir(&self.staging);
        if !self.target.exists() {
            std::fs::rename(&self.staging, &self.target).with_context(|| {
                format!("{} {}: cannot create", self.flag, self.target.display())
            })?;
        } else {
            if let Some(dest) = first_input_replaced(&self.staging, &self.target, &self.inputs)? {
                bail!(
                    "{}: is one of this command's inputs, and {} {} would write over it; nothing was written",
                    dest.display(),
                    self.flag,
                    self.target.display()
                );
            }
            if let Some((dest, is_dir)) = first_conflict(&self.staging, &self.target)? {
                let (there, ours) = if is_dir {
                    ("a directory", "a file")
                } else {
                    ("a file", "a directory")
                };
                bail!(
                    "{}: is {there}, where {} {} writes {ours}; nothing was written",
                    dest.display(),
                    self.flag,
                    self.target.display()
                );
            }
            move_into(&self.staging, &self.target)?;
        }
        self.finished = true;
        Ok(())
    }
}

impl Drop for OutputDir {
    fn drop(&mut self) {
        if !self.finished {
            let _ = std::fs::remove_dir_all(&self.staging);
        }
    }
}

/// The first place in `to` where an entry of `from` cannot go, and whether what stands
/// there is a directory.
fn first_conflict(from: &Path, to: &Path) -> Result<Option<(PathBuf, bool)>> {
    for entry in
        std::fs::read_dir(from).with_context(|| format!("{}: cannot read", from.display()))?
    {
        let entry = entry?;
        let dest = to.join(entry.file_name());
        let Ok(there) = std::fs::symlink_metadata(&dest) else {
            continue;
        };
        if entry.file_type()?.is_dir() {
            if !there.is_dir() {
                return Ok(Some((dest, false)));
            }
            if let Some(found) = first_conflict(&entry.path(), &dest)? {
                return Ok(Some(found));
            }
        } else if there.is_dir() {
            return Ok(Some((dest, true)));
        }
    }
    Ok(None)
}

/// The first file of `from` whose place in `to` is one of `inputs`.
fn first_input_replaced(from: &Path, to: &Path, inputs: &[PathBuf]) -> Result<Option<PathBuf>> {
    if inputs.is_empty() {
        return Ok(None);
    }
    for entry in
        std::fs::read_dir(from).with_context(|| format!("{}: cannot read", from.display()))?
    {
        let entry = entry?;
        let dest = to.join(entry.file_name());
        if entry.file_type()?.is_dir() {
            if let Some(found) = first_input_replaced(&entry.path(), &dest, inputs)? {
                return Ok(Some(found));
            }
        } else if inputs.iter().any(|i| same_file(i, &dest)) {
            return Ok(Some(dest));
        }
    }
    Ok(None)
}

fn move_into(from: &Path, to: &Path) -> Result<()> {
    for entry in
        std::fs::read_dir(from).with_context(|| format!("{}: cannot read", from.display()))?
    {
        let entry = entry?;
        let dest = to.join(entry.file_name());
        if entry.file_type()?.is_dir() && dest.is_dir() {
            move_into(&entry.path(), &dest)?;
        } else {
            std::fs::rename(entry.path(), &dest)
                .with_context(|| format!("{}: cannot write", dest.display()))?;
        }
    }
    std::fs::remove_dir(from).with_context(|| format!("{}: cannot remove", from.display()))
}
