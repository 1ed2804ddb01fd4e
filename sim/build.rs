//! Under CI (CI=true) sets `cfg(ci)`, which turns on the GPU-path tests: CI installs software
//! Vulkan (lavapipe) so that they really run there. Elsewhere they are `#[ignore]`d with the
//! reason, and `cargo test -- --include-ignored` runs them where an adapter exists.

fn main() {
    println!("cargo:rustc-check-cfg=cfg(ci)");
    println!("cargo:rerun-if-env-changed=CI");
    println!("cargo:rerun-if-changed=build.rs");
    if std::env::var("CI").is_ok_and(|v| v == "true") {
        println!("cargo:rustc-cfg=ci");
    }
}
