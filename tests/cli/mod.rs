//! Running the `tactex` binary from end-to-end tests, and the one-line error every bad input
//! must end in. Each test binary uses what it needs of it.
#![allow(dead_code)]

use std::process::{Command, Output};

/// `tactex ARGS` run from the repository root.
pub fn tactex(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_tactex"))
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("runs tactex")
}

/// The failure's stderr, after checking it is one line, the exit code is 1 and nothing was
/// printed on stdout.
pub fn one_line_error(out: &Output) -> String {
    assert_eq!(
        out.status.code(),
        Some(1),
        "{}",
        String::from_utf8_lossy(&out.stdout)
    );
    let stderr = String::from_utf8_lossy(&out.stderr).to_string();
    assert_eq!(stderr.trim().lines().count(), 1, "{stderr}");
    assert!(out.stdout.is_empty());
    stderr
}
