//! Records the commit the binary was built from, for the provenance line of generated
//! reports (src/report/provenance.rs); outside a git checkout it says "unknown". Under CI
//! (CI=true) it sets `cfg(ci)`, which turns on the tests that need what `.ci/run`
//! installs (elsewhere they are `#[ignore]`d with the reason, and `--include-ignored` runs them).

use std::process::Command;

fn main() {
    let commit = Command::new("git")
        .args(["rev-parse", "--short=12", "HEAD"])
        .output()
        .ok()
        .filter(|o| o.status.success())
        .and_then(|o| String::from_utf8(o.stdout).ok())
        .map(|s| s.trim().to_string())
        .filter(|s| !s.is_empty())
        .unwrap_or_else(|| "unknown".into());
    println!("cargo:rustc-env=TACTEX_BUILD_COMMIT={commit}");
    // A new commit or checkout moves HEAD or the branch it names.
    for path in [".git/HEAD", ".git/refs/heads", ".git/packed-refs"] {
        if std::path::Path::new(path).exists() {
            println!("cargo:rerun-if-changed={path}");
        }
    }
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rustc-check-cfg=cfg(ci)");
    println!("cargo:rerun-if-env-changed=CI");
    if std::env::var("CI").is_ok_and(|v| v == "true") {
        println!("cargo:rustc-cfg=ci");
    }
}
