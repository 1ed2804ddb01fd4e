//! Every numeric flag of every subcommand, given NaN, an infinity, 1e300 or -1e300: refused
//! with exit 1 and one stderr line that names the flag, never a panic, a hang or a run. The
//! table lists the flags that parse as numbers (found by giving each flag of `--help` a word
//! in place of its value); each subcommand runs with what it needs besides.

use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// The arguments a subcommand needs besides the flag under test.
fn base(sub: &str, flag: &str, out: &str) -> Vec<String> {
    let args: Vec<&str> = match sub {
        "ask" => vec!["lime"],
        "press" => vec!["--shape", "sphere", "--hardness", "35A", "--depth-mm", "1"],
        "calibrate" => vec![
            "--images",
            "tests/fixtures/fots/ball-presses",
            "--annotations",
            "tests/fixtures/fots/ball-presses/annotations.csv",
            "--background",
            "tests/fixtures/fots/background.png",
            "--ball-radius-mm",
            "2.35",
            "--mm-per-px",
            "0.0511",
        ],
        "compare" => vec!["--session", "no-such-session"],
        "contact" => vec![
            "--reference",
            "tests/fixtures/fots/background.png",
            "tests/fixtures/fots/ball-presses/0001.png",
        ],
        "detect" => vec![
            "--model",
            "learned/tests/fixtures/yolo-seg-probe.onnx",
            "tests/fixtures/fots/ball-presses/0001.png",
        ],
        "sensor check" => vec!["no-such-profile.toml"],
        _ => vec![],
    };
    let mut v: Vec<String> = args.into_iter().map(String::from).collect();
    if matches!(sub, "calibrate" | "datagen scenes" | "datagen ball-presses") {
        v.extend(["--out".to_string(), out.to_string()]);
    }
    if matches!(sub, "datagen scenes" | "datagen ball-presses") && flag != "--count" {
        v.extend(["--count".to_string(), "1".to_string()]);
    }
    v
}

const NUMERIC_FLAGS: &[(&str, &str)] = &[
    ("ask", "--seed"),
    ("ask", "--gel-modulus-mpa"),
    ("serve", "--port"),
    ("serve", "--seed"),
    ("serve", "--max-queries"),
    ("serve", "--max-prompt-chars"),
    ("twin", "--seed"),
    ("twin", "--port"),
    ("twin", "--report-port"),
    ("twin", "--normal-report-port"),
    ("twin", "--real-report-port"),
    ("twin", "--http-port"),
    ("twin", "--base-m"),
    ("twin", "--time-scale"),
    ("press", "--radius-mm"),
    ("press", "--size-mm"),
    ("press", "--yaw-deg"),
    ("press", "--mesh-scale"),
    ("press", "--object-poisson"),
    ("press", "--grid-mm"),
    ("press", "--tolerance"),
    ("press", "--gel-thickness-mm"),
    ("press", "--gel-modulus-mpa"),
    ("press", "--marker-pitch-mm"),
    ("press", "--seed"),
    ("calibrate", "--gel-modulus-mpa"),
    ("calibrate", "--gel-thickness-mm"),
    ("calibrate", "--gel-poisson"),
    ("calibrate", "--frame-rate-hz"),
    ("calibrate", "--mag-bins"),
    ("calibrate", "--dir-bins"),
    ("calibrate", "--mag-max"),
    ("calibrate", "--smoothness"),
    ("calibrate", "--interval-placements"),
    ("sensor check", "--seed"),
    ("compare", "--seed"),
    ("contact", "--mm-per-px"),
    ("detect", "--confidence"),
    ("detect", "--iou"),
    ("eval grounding", "--per-kind"),
    ("eval grounding", "--seed"),
    ("eval grounding", "--depth-frames"),
    ("eval grounding", "--tolerance-mm"),
    ("eval hardness", "--count"),
    ("eval hardness", "--seed"),
    ("eval ripeness", "--seed"),
    ("eval ripeness", "--presses"),
    ("eval ripeness", "--spot-spread"),
    ("eval scenarios", "--runs"),
    ("eval scenarios", "--seed"),
    ("eval scenarios", "--tiers"),
    ("eval fruits", "--placements"),
    ("eval fruits", "--crowded"),
    ("eval fruits", "--seed"),
    ("eval explanations", "--prompts"),
    ("eval explanations", "--seed"),
    ("datagen tactile", "--count"),
    ("datagen tactile", "--seed"),
    ("datagen scenes", "--count"),
    ("datagen scenes", "--seed"),
    ("datagen scenes", "--val-fraction"),
    ("datagen ball-presses", "--count"),
    ("datagen ball-presses", "--seed"),
    ("datagen ball-presses", "--ball-radius-mm"),
    ("datagen ball-presses", "--contact-share"),
    ("bench contact", "--reps"),
    ("bench contact", "--reference-cell-mm"),
    ("bench contact", "--tolerances"),
    ("bench render", "--reps"),
    ("bench render", "--batch"),
    ("bench datagen", "--count"),
    ("bench scene", "--reps"),
    ("bench ask", "--reps"),
    ("bench ask", "--seed"),
];

#[test]
fn every_numeric_flag_refuses_nan_infinities_and_huge_values_in_one_line() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("out");
    let cases: Vec<(&str, &str, &str)> = NUMERIC_FLAGS
        .iter()
        .flat_map(|&(sub, flag)| {
            ["NaN", "inf", "1e300", "-1e300"]
                .into_iter()
                .map(move |v| (sub, flag, v))
        })
        .collect();
    let check = |&(sub, flag, value): &(&str, &str, &str)| -> Option<String> {
        let mut args: Vec<String> = sub.split(' ').map(String::from).collect();
        args.extend(base(sub, flag, out.to_str().unwrap()));
        args.push(format!("{flag}={value}"));
        let mut child = Command::new(env!("CARGO_BIN_EXE_tactex"))
            .args(&args)
            .current_dir(env!("CARGO_MANIFEST_DIR"))
            .env("XDG_RUNTIME_DIR", std::env::temp_dir())
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .expect("runs tactex");
        let start = Instant::now();
        while child.try_wait().unwrap().is_none() {
            if start.elapsed() > Duration::from_secs(30) {
                let _ = child.kill();
                return Some(format!("{sub} {flag}={value}: still running after 30 s"));
            }
            std::thread::sleep(Duration::from_millis(20));
        }
        let done = child.wait_with_output().unwrap();
        let stderr = String::from_utf8_lossy(&done.stderr).trim().to_string();
        let why = if done.status.code() != Some(1) {
            format!("exit {:?}", done.status.code())
        } else if stderr.lines().count() != 1 {
            "not one line".into()
        } else if !stderr.contains(flag) {
            "does not name the flag".into()
        } else {
            return None;
        };
        Some(format!("{sub} {flag}={value}: {why}: {stderr}"))
    };
    // Two at a time: the runs are processes, and CI has two cores.
    let half = cases.len() / 2;
    let (a, b) = cases.split_at(half);
    let wrong: Vec<String> = std::thread::scope(|s| {
        let first = s.spawn(|| a.iter().filter_map(check).collect::<Vec<_>>());
        let mut w: Vec<String> = b.iter().filter_map(check).collect();
        w.extend(first.join().unwrap());
        w
    });
    assert!(
        wrong.is_empty(),
        "{} of {} runs:\n{}",
        wrong.len(),
        cases.len(),
        wrong.join("\n")
    );
}
