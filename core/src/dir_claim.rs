//! One writer per directory: a directory whose creation is the lock and whose pid file says
//! which process holds it. Sessions, output directories and data sets claim through this,
//! so a second tactex writing to the same place is refused instead of mixing files.

use std::path::{Path, PathBuf};

/// The file in a claimed directory naming the process that holds it.
pub const PID_FILE: &str = "tactex.pid";

/// The lock a data set's writer claims inside it (a tactile shard adds its shard).
pub const DATASET_LOCK: &str = ".tactex-writing";

#[derive(Debug, thiserror::Error)]
#[error("{path}: {reason}")]
pub struct ClaimError {
    pub path: PathBuf,
    pub reason: String,
}

fn error(path: &Path, reason: impl std::fmt::Display) -> ClaimError {
    ClaimError {
        path: path.to_path_buf(),
        reason: reason.to_string(),
    }
}

/// Whether process `pid` runs (where /proc says; elsewhere assumed to).
fn process_runs(pid: u32) -> bool {
    if cfg!(target_os = "linux") {
        Path::new(&format!("/proc/{pid}")).exists()
    } else {
        true
    }
}

fn is_new(dir: &Path) -> bool {
    std::fs::metadata(dir)
        .and_then(|m| m.modified())
        .ok()
        .and_then(|t| t.elapsed().ok())
        .is_some_and(|age| age.as_secs() < 10)
}

/// Creates `dir` for this process alone; `doing` says what the holder does there ("recording
/// a session"), for the refusal. A directory left by a process that no longer runs is
/// removed first, with whatever it held.
pub fn claim_dir(dir: &Path, doing: &str) -> Result<(), ClaimError> {
    for _ in 0..2 {
        match std::fs::create_dir(dir) {
            Ok(()) => {
                let pid_file = dir.join(PID_FILE);
                return std::fs::write(&pid_file, std::process::id().to_string())
                    .map_err(|e| error(&pid_file, e));
            }
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => {
                let owner = std::fs::read_to_string(dir.join(PID_FILE))
                    .ok()
                    .and_then(|t| t.trim().parse::<u32>().ok());
                match owner {
                    Some(pid) if pid == std::process::id() || process_runs(pid) => {
                        return Err(error(
                            dir,
                            format!("another tactex (pid {pid}) is {doing} here"),
                        ));
                    }
                    // No pid file yet: its owner is between creating it and writing the file.
                    None if is_new(dir) => {
                        return Err(error(dir, format!("another tactex is {doing} here")));
                    }
                    _ => std::fs::remove_dir_all(dir)
                        .map_err(|e| error(dir, format!("cannot remove a stale claim: {e}")))?,
                }
            }
            Err(e) => return Err(error(dir, format!("cannot create: {e}"))),
        }
    }
    Err(error(dir, format!("another tactex keeps {doing} here")))
}

/// Gives a claimed directory up, leaving what was written there (the pid file aside).
pub fn release_dir(dir: &Path) {
    let _ = std::fs::remove_file(dir.join(PID_FILE));
}

/// A claimed directory used only as a lock: removed, with its pid file, when dropped.
#[derive(Debug)]
pub struct LockDir(PathBuf);

impl LockDir {
    pub fn claim(dir: &Path, doing: &str) -> Result<LockDir, ClaimError> {
        claim_dir(dir, doing)?;
        Ok(LockDir(dir.to_path_buf()))
    }
}

impl Drop for LockDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_directory_is_claimed_once_and_a_stale_claim_taken_over() {
        let tmp = tempfile::tempdir().unwrap();
        let dir = tmp.path().join("s.partial");
        claim_dir(&dir, "recording a session").unwrap();
        let second = claim_dir(&dir, "recording a session")
            .unwrap_err()
            .to_string();
        assert!(second.contains("is recording a session here"), "{second}");
        // A pid no process has (above Linux's pid_max): left by a crash, taken over.
        std::fs::write(dir.join(PID_FILE), "4294967295").unwrap();
        std::fs::write(dir.join("leftover.png"), b"x").unwrap();
        if cfg!(target_os = "linux") {
            claim_dir(&dir, "recording a session").unwrap();
            assert!(!dir.join("leftover.png").exists());
        }
    }
}
