//! Running the `tactex` binary from end-to-end tests, and the one-line error every bad input
//! must end in. Each test binary uses what it needs of it.
#![allow(dead_code)]

use std::process::{Command, Output};

/// `tactex ARGS` run from the repository root (with a runtime dir, so that the Vulkan
/// loader keeps stderr clean where a command looks for a GPU).
pub(crate) fn tactex(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_tactex"))
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .env("XDG_RUNTIME_DIR", std::env::temp_dir())
        .output()
        .expect("runs tactex")
}

/// The JSON a successful run printed (its stderr shown if it failed).
pub(crate) fn json(out: &Output) -> serde_json::Value {
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).expect("stdout is JSON")
}

/// The failure's stderr, after checking it is one line, the exit code is 1 and nothing was
/// printed on stdout.
pub(crate) fn one_line_error(out: &Output) -> String {
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

/// The built-in GelSight Mini profile under another name, written to `dir/NAME.toml`: the
/// same sensor, which outputs must name as given.
pub(crate) fn renamed_stock_profile(dir: &std::path::Path, name: &str) -> std::path::PathBuf {
    let stock = tactex(&["sensor", "show", "--toml"]);
    assert!(stock.status.success());
    let text = String::from_utf8(stock.stdout).unwrap().replacen(
        "name = \"GelSight Mini\"",
        &format!("name = \"{name}\""),
        1,
    );
    let path = dir.join(format!("{name}.toml"));
    std::fs::write(&path, text).unwrap();
    path
}
