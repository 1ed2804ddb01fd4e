//! Outputs are whole or absent: a command that fails leaves its output directory as it
//! found it (so the corrected run is accepted), and a directory another tactex writes into
//! is refused with one line, not shared.

use crate::cli::tactex;
use std::path::Path;
use std::process::Output;

/// The error line of a failed run; device notes ("note: ...") may come before it.
fn error_line(out: &Output) -> String {
    assert_eq!(
        out.status.code(),
        Some(1),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let stderr = String::from_utf8_lossy(&out.stderr).to_string();
    let lines: Vec<&str> = stderr
        .lines()
        .filter(|l| !l.starts_with("note: "))
        .collect();
    assert_eq!(lines.len(), 1, "{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    lines[0].to_string()
}

fn entries(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .map(|d| {
            d.map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
                .collect()
        })
        .unwrap_or_default();
    names.sort();
    names
}

const PRESS: [&str; 8] = [
    "press",
    "--shape",
    "sphere",
    "--hardness",
    "35A",
    "--depth-mm",
    "1",
    "--out",
];

#[test]
fn press_whose_output_file_is_a_directory_writes_nothing_and_the_retry_writes_all() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("o");
    std::fs::create_dir_all(out.join("tactile.png")).unwrap();
    let mut args = PRESS.to_vec();
    args.push(out.to_str().unwrap());
    let err = error_line(&tactex(&args));
    assert!(err.contains("tactile.png: is a directory"), "{err}");
    assert_eq!(entries(&out), ["tactile.png"], "nothing else written");
    assert_eq!(entries(tmp.path()), ["o"], "no staging directory left");

    std::fs::remove_dir(out.join("tactile.png")).unwrap();
    let ran = tactex(&args);
    assert!(
        ran.status.success(),
        "{}",
        String::from_utf8_lossy(&ran.stderr)
    );
    assert_eq!(
        entries(&out),
        [
            "gel_lateral_x.png",
            "gel_lateral_y.png",
            "gel_normal.png",
            "maps.json",
            "pressure.png",
            "reference.png",
            "tactile.png"
        ]
    );
    assert_eq!(entries(tmp.path()), ["o"]);
}

#[test]
fn press_into_the_directory_of_its_sensor_profile_does_not_write_over_the_profiles_files() {
    // A profile kept in the output directory whose background is named as an output
    // (reference.png): the press would have replaced it with its own rendered frame.
    let tmp = tempfile::tempdir().unwrap();
    let fixture = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/fots/profile");
    let text = std::fs::read_to_string(fixture.join("fots-9.toml"))
        .unwrap()
        .replace("fots-9.background.png", "reference.png");
    std::fs::write(tmp.path().join("p.toml"), text).unwrap();
    let background = tmp.path().join("reference.png");
    std::fs::copy(fixture.join("fots-9.background.png"), &background).unwrap();
    let before = std::fs::read(&background).unwrap();
    let profile = tmp.path().join("p.toml");
    let mut args = PRESS[..PRESS.len() - 1].to_vec();
    let out = tmp.path().to_str().unwrap();
    args.extend(["--sensor", profile.to_str().unwrap(), "--out", out]);
    let err = error_line(&tactex(&args));
    assert!(
        err.contains("reference.png: is one of this command's inputs"),
        "{err}"
    );
    assert_eq!(
        std::fs::read(&background).unwrap(),
        before,
        "the background is intact"
    );
    assert_eq!(
        entries(tmp.path()),
        ["p.toml", "reference.png"],
        "nothing written"
    );
}

#[test]
fn an_output_directory_another_tactex_writes_is_refused() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("o");
    // This test process stands for the other tactex: it runs, so its claim holds.
    let staging = tmp.path().join("o.partial");
    std::fs::create_dir(&staging).unwrap();
    std::fs::write(staging.join("tactex.pid"), std::process::id().to_string()).unwrap();
    let mut args = PRESS.to_vec();
    args.push(out.to_str().unwrap());
    let err = error_line(&tactex(&args));
    assert!(err.contains("is writing outputs here"), "{err}");
    assert!(!out.exists());
    assert!(
        staging.join("tactex.pid").exists(),
        "the other's claim kept"
    );
}

#[test]
fn an_eval_whose_model_is_bad_leaves_no_output_directory() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("o");
    let bad = tmp.path().join("bad.onnx");
    std::fs::write(&bad, b"not a model").unwrap();
    let err = error_line(&tactex(&[
        "eval",
        "hardness",
        "--model",
        bad.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]));
    assert!(err.contains("--model"), "{err}");
    assert_eq!(entries(tmp.path()), ["bad.onnx"]);
}

#[test]
fn a_scene_data_set_that_cannot_be_drawn_leaves_nothing_and_the_corrected_run_is_accepted() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("d");
    let out_s = out.to_str().unwrap();
    let scenes = |extra: &[&str]| {
        let mut args = vec!["datagen", "scenes", "--count", "1", "--out", out_s];
        args.extend_from_slice(extra);
        tactex(&args)
    };
    let err = error_line(&scenes(&["--fruits", "1-500"]));
    assert!(err.contains("--fruits") && err.contains("12"), "{err}");
    assert!(!out.exists());
    // Twelve bananas never fit the demo table: refused at the first scene, nothing kept,
    // in a new directory and in one the user made.
    for made in [false, true] {
        if made {
            std::fs::create_dir(&out).unwrap();
        }
        let err = error_line(&scenes(&["--fruits", "12-12", "--kinds", "banana"]));
        assert!(err.contains("do not fit on the table"), "{err}");
        assert_eq!(out.exists(), made);
        assert!(entries(&out).is_empty(), "{:?}", entries(&out));
    }
    let ran = scenes(&["--fruits", "1-2"]);
    assert!(
        ran.status.success(),
        "{}",
        String::from_utf8_lossy(&ran.stderr)
    );
    assert!(out.join("dataset.json").is_file());
    assert!(!out.join(".tactex-writing").exists());
}

#[test]
fn a_scene_data_set_another_tactex_writes_is_refused() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("d");
    let lock = out.join(".tactex-writing");
    std::fs::create_dir_all(&lock).unwrap();
    std::fs::write(lock.join("tactex.pid"), std::process::id().to_string()).unwrap();
    let err = error_line(&tactex(&[
        "datagen",
        "scenes",
        "--count",
        "1",
        "--out",
        out.to_str().unwrap(),
    ]));
    assert!(err.contains("is writing this data set here"), "{err}");
    assert!(lock.join("tactex.pid").exists());
}

#[test]
fn compare_into_the_folder_of_its_real_frames_does_not_write_over_them() {
    // The side by sides are named as the real frames: --out the frames' folder replaced
    // them with 720 x 320 comparisons, and the next run failed on their size.
    let tmp = tempfile::tempdir().unwrap();
    let fixtures = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/fots");
    let presses = tmp.path().join("presses");
    std::fs::create_dir(&presses).unwrap();
    for entry in std::fs::read_dir(fixtures.join("ball-presses")).unwrap() {
        let entry = entry.unwrap().path();
        std::fs::copy(&entry, presses.join(entry.file_name().unwrap())).unwrap();
    }
    let before = entries(&presses);
    let frame = std::fs::read(presses.join("0001.png")).unwrap();
    let profile = fixtures.join("profile/fots-9.toml");
    let err = error_line(&tactex(&[
        "compare",
        "--sensor",
        profile.to_str().unwrap(),
        "--images",
        presses.to_str().unwrap(),
        "--annotations",
        presses.join("annotations.csv").to_str().unwrap(),
        "--split",
        "all",
        "--device",
        "cpu",
        "--out",
        presses.to_str().unwrap(),
    ]));
    assert!(err.contains("is one of this command's inputs"), "{err}");
    assert_eq!(entries(&presses), before, "nothing written");
    assert_eq!(std::fs::read(presses.join("0001.png")).unwrap(), frame);
}
