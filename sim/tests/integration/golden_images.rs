//! Golden images: one press rendered at every fidelity level through the built-in GelSight
//! Mini and through a profile calibrated from real presses (tests/fixtures/fots/profile,
//! made by the `calibrate` command in sim/tests/golden/README.md), compared with the
//! committed frames in sim/tests/golden/, beside the renderer they pin. The CPU path must
//! give them byte for byte; the GPU path (CI's lavapipe) within the tolerance its agreement
//! with the CPU path is held to elsewhere.
//!
//! A frame that differs is written beside the run's target directory as `NAME.actual.png`
//! with `NAME.diff.png` (the absolute difference, 8x), and the failure names both. When a
//! change is meant to alter the frames, `TACTEX_BLESS_GOLDEN=1 cargo test -p tactex-sim
//! --test integration golden_images::` writes them anew; the commit then says why they
//! changed.

use glam::DVec2;
use image::RgbImage;
use std::path::{Path, PathBuf};
use tactex_core::hertz::Elastic;
use tactex_core::tactile::sensor_profile::SensorProfile;
use tactex_sim::contact::{ContactProblem, ContactSolver, Fidelity, ObjectSurface};
use tactex_sim::render::gel::{
    CpuRenderer, DeviceChoice, GelImageFields, GelRenderer, PressFrame, SensorOptics, image_fields,
    open_renderer, pad_rect,
};

const SEED: u32 = 7;

/// tactex-sim's own directory (the goldens) and the repository's (the fixture profile).
fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn repository() -> PathBuf {
    root().join("..")
}

/// The sensors the goldens cover: the built-in Mini and a calibrated profile.
fn profiles() -> Vec<(&'static str, SensorProfile)> {
    let fots = repository().join("tests/fixtures/fots/profile/fots-9.toml");
    vec![
        ("mini", SensorProfile::gelsight_mini()),
        (
            "fots-9",
            SensorProfile::load(&fots).expect("the fixture profile loads"),
        ),
    ]
}

/// A 4 mm sphere of 0.5 MPa (a ripe tomato's stiffness), off the pad's centre, 0.8 mm past
/// first touch: deep enough that every level's imprint, bulge and marker motion show.
fn pressed_fields(profile: &SensorProfile, fidelity: Fidelity) -> GelImageFields {
    let optics = SensorOptics::for_profile(profile);
    let surface = ObjectSurface::Sphere {
        radius_mm: 4.0,
        centre_mm: DVec2::new(1.2, -0.8),
    };
    let problem = ContactProblem {
        surface: &surface,
        object: Elastic {
            modulus_mpa: Some(0.5),
            poisson: 0.45,
        },
        gel: profile.spec.gel,
        pad: pad_rect(&optics),
        approach_mm: 0.8,
        cell_mm: None,
    };
    let mut solver = ContactSolver::new();
    let solution = solver.solve(&problem, fidelity).expect("the press solves");
    image_fields(&mut solver, &solution, &profile.spec.gel, &optics)
}

/// Every golden case: its name, the optics and the fields of its press.
fn cases() -> Vec<(String, SensorOptics, GelImageFields)> {
    let mut out = Vec::new();
    for (name, profile) in profiles() {
        for fidelity in Fidelity::ALL {
            out.push((
                format!("{name}-{}", fidelity.name()),
                SensorOptics::for_profile(&profile),
                pressed_fields(&profile, fidelity),
            ));
        }
    }
    out
}

fn golden_path(name: &str) -> PathBuf {
    root().join("tests/golden").join(format!("{name}.png"))
}

/// Where a failing comparison leaves the actual frame and the difference.
fn failure_dir() -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("golden");
    std::fs::create_dir_all(&dir).expect("target dir");
    dir
}

fn load_golden(name: &str) -> RgbImage {
    let path = golden_path(name);
    image::open(&path)
        .unwrap_or_else(|e| {
            panic!(
                "{}: {e} (TACTEX_BLESS_GOLDEN=1 writes the goldens)",
                path.display()
            )
        })
        .to_rgb8()
}

/// Per channel, the mean and largest absolute difference.
fn differences(a: &RgbImage, b: &RgbImage) -> ([f64; 3], u8) {
    let mut sum = [0f64; 3];
    let mut max = 0u8;
    for (p, q) in a.pixels().zip(b.pixels()) {
        for c in 0..3 {
            let d = p[c].abs_diff(q[c]);
            sum[c] += f64::from(d);
            max = max.max(d);
        }
    }
    let n = f64::from(a.width() * a.height());
    (sum.map(|s| s / n), max)
}

/// Writes `actual` and its 8x difference from `golden` for a failure message.
fn write_failure(name: &str, actual: &RgbImage, golden: &RgbImage) -> String {
    let dir = failure_dir();
    let actual_path = dir.join(format!("{name}.actual.png"));
    let diff_path = dir.join(format!("{name}.diff.png"));
    actual.save(&actual_path).expect("write the actual frame");
    if actual.dimensions() == golden.dimensions() {
        let diff = RgbImage::from_fn(actual.width(), actual.height(), |x, y| {
            let (p, q) = (actual.get_pixel(x, y), golden.get_pixel(x, y));
            image::Rgb(std::array::from_fn(|c| {
                p[c].abs_diff(q[c]).saturating_mul(8)
            }))
        });
        diff.save(&diff_path).expect("write the difference");
    }
    format!(
        "actual {} and difference {}",
        actual_path.display(),
        diff_path.display()
    )
}

#[test]
fn cpu_renders_of_every_fidelity_and_profile_match_their_golden_images_exactly() {
    let bless = std::env::var("TACTEX_BLESS_GOLDEN").is_ok_and(|v| v == "1");
    let mut failures = Vec::new();
    for (name, optics, fields) in cases() {
        let frame = CpuRenderer.render_one(
            &optics,
            &PressFrame {
                fields: &fields,
                seed: SEED,
            },
        );
        if bless {
            frame.save(golden_path(&name)).expect("write the golden");
            continue;
        }
        let golden = load_golden(&name);
        if frame.dimensions() != golden.dimensions() {
            failures.push(format!(
                "{name}: {:?} px against the golden's {:?}; {}",
                frame.dimensions(),
                golden.dimensions(),
                write_failure(&name, &frame, &golden)
            ));
        } else if frame.as_raw() != golden.as_raw() {
            let (mean, max) = differences(&frame, &golden);
            failures.push(format!(
                "{name}: mean |difference| {mean:.4?}, max {max}; {}",
                write_failure(&name, &frame, &golden)
            ));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn the_goldens_differ_by_fidelity_and_by_sensor() {
    // A golden set that collapsed to one picture would pin nothing.
    let names: Vec<String> = cases().into_iter().map(|(n, _, _)| n).collect();
    for (i, a) in names.iter().enumerate() {
        for b in &names[i + 1..] {
            let (ga, gb) = (load_golden(a), load_golden(b));
            if ga.dimensions() == gb.dimensions() {
                let (mean, _) = differences(&ga, &gb);
                assert!(
                    mean.iter().sum::<f64>() > 0.05,
                    "{a} and {b} are nearly the same frame: mean difference {mean:?}"
                );
            }
        }
    }
}

#[test]
#[cfg_attr(
    not(ci),
    ignore = "needs a Vulkan adapter (lavapipe: mesa-vulkan-drivers, as .ci/run installs)"
)]
fn gpu_renders_match_the_golden_images_within_the_gpu_tolerance() {
    let mut gpu: Box<dyn GelRenderer + Send> = open_renderer(DeviceChoice::Gpu)
        .unwrap_or_else(|e| panic!("GPU renderer: {e}"))
        .renderer;
    let mut failures = Vec::new();
    for (name, optics, fields) in cases() {
        let frame = gpu
            .render_batch(
                &optics,
                &[PressFrame {
                    fields: &fields,
                    seed: SEED,
                }],
            )
            .expect("the GPU renders")
            .remove(0);
        let golden = load_golden(&name);
        let (mean, max) = differences(&frame, &golden);
        eprintln!("{name} on {}: mean {mean:.4?}, max {max}", gpu.name());
        // The tolerance of the GPU path against the CPU path (sim/tests/integration/gel_render.rs).
        if mean.iter().any(|m| *m > 1.0) || max > 4 {
            failures.push(format!(
                "{name}: mean |difference| {mean:.4?}, max {max}; {}",
                write_failure(&format!("{name}.gpu"), &frame, &golden)
            ));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
