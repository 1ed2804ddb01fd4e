//! Files named by users, read with their work bounded: a FIFO or a device (`/dev/zero`)
//! given where a file belongs is refused before it is opened, which would block, or read,
//! which would not end; a regular file is read up to a size no input of tactex comes near.
//! Every scene, profile, calibration, configuration and model file comes through here.

use std::io::{self, Read};
use std::path::Path;

/// The largest text file read (scenes, profiles, calibrations, configurations, sessions).
pub const MAX_TEXT_BYTES: u64 = 64 << 20;
/// The largest binary model file read (an ONNX network).
pub const MAX_MODEL_BYTES: u64 = 1 << 30;

/// Ok when `path` is a regular file (links followed); a FIFO, device or socket is an
/// InvalidInput error. Missing files keep their own error.
pub fn regular(path: &Path) -> io::Result<()> {
    let kind = std::fs::metadata(path)?.file_type();
    if kind.is_file() || kind.is_dir() {
        // A folder's own error ("Is a directory") is clearer from the reader.
        return Ok(());
    }
    Err(io::Error::new(
        io::ErrorKind::InvalidInput,
        "not a regular file (a FIFO, device or socket)",
    ))
}

/// The bytes of the file at `path`, at most `max` of them.
pub fn read_bytes(path: &Path, max: u64) -> io::Result<Vec<u8>> {
    regular(path)?;
    let mut bytes = Vec::new();
    std::fs::File::open(path)?
        .take(max + 1)
        .read_to_end(&mut bytes)?;
    if bytes.len() as u64 > max {
        return Err(io::Error::new(
            io::ErrorKind::InvalidData,
            format!("larger than {} MiB, the most tactex reads", max >> 20),
        ));
    }
    Ok(bytes)
}

/// The text of the file at `path` (UTF-8, at most `MAX_TEXT_BYTES`).
pub fn read_to_string(path: &Path) -> io::Result<String> {
    String::from_utf8(read_bytes(path, MAX_TEXT_BYTES)?)
        .map_err(|_| io::Error::new(io::ErrorKind::InvalidData, "not UTF-8 text"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_device_given_as_a_file_is_refused_without_reading_it() {
        // /dev/zero would be read for ever.
        let e = read_to_string(Path::new("/dev/zero")).unwrap_err();
        assert_eq!(e.kind(), io::ErrorKind::InvalidInput);
        assert!(e.to_string().contains("not a regular file"), "{e}");
    }

    #[test]
    fn a_file_past_the_limit_is_refused_and_one_within_is_read() {
        let dir = std::env::temp_dir().join(format!("tactex-text-file-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("ten.txt");
        std::fs::write(&path, "0123456789").unwrap();
        assert_eq!(read_bytes(&path, 10).unwrap().len(), 10);
        let e = read_bytes(&path, 9).unwrap_err();
        assert_eq!(e.kind(), io::ErrorKind::InvalidData);
        assert_eq!(read_to_string(&path).unwrap(), "0123456789");
        std::fs::remove_dir_all(&dir).ok();
    }

    #[test]
    fn a_missing_file_keeps_its_own_error() {
        let e = read_to_string(Path::new("/no/such/tactex/file.toml")).unwrap_err();
        assert_eq!(e.kind(), io::ErrorKind::NotFound);
    }
}
