//! Files named by the user, checked to be there before a loader reads them, so that a
//! missing one keeps its I/O error in the chain (`error_kind` tells it from a bad one by
//! type) while its message reads as the loader's would.

use anyhow::Result;
use std::path::Path;

/// Ok when `path` can be looked up and is a file or folder (not a FIFO or device, which
/// would block or never end); else its I/O error under "PATH: READING" (READING may
/// be empty), as in "scene.toml: file: cannot read scene: No such file or directory".
pub fn present(path: &Path, reading: &str) -> Result<()> {
    match tactex_core::text_file::regular(path) {
        Ok(()) => Ok(()),
        Err(e) if reading.is_empty() => {
            Err(anyhow::Error::new(e).context(path.display().to_string()))
        }
        Err(e) => Err(anyhow::Error::new(e).context(format!("{}: {reading}", path.display()))),
    }
}
