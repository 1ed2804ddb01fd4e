//! `tactex detect` and `--detector yolo:FILE` from the command line, against the YOLOv8-seg
//! probe model (learned/tests/fixtures, written by models/train/make_yolo_probe.py): its apple
//! and lime boxes sit on a red and a green disk drawn here.

use image::{Rgb, RgbImage};
use std::path::PathBuf;
use std::process::Command;

fn tactex(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_tactex"))
        .args(args)
        .output()
        .expect("tactex runs")
}

fn probe(name: &str) -> String {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("learned/tests/fixtures")
        .join(name)
        .display()
        .to_string()
}

fn disks() -> RgbImage {
    RgbImage::from_fn(640, 480, |x, y| {
        let d = |cx: f64, cy: f64| {
            ((x as f64 + 0.5 - cx).powi(2) + (y as f64 + 0.5 - cy).powi(2)).sqrt()
        };
        if d(400.0, 200.0) <= 40.0 {
            Rgb([220, 40, 40])
        } else if d(200.0, 300.0) <= 30.0 {
            Rgb([40, 200, 40])
        } else {
            Rgb([128, 128, 128])
        }
    })
}

#[test]
fn detect_reports_the_probe_fruit_and_draws_an_overlay() {
    let tmp = tempfile::tempdir().unwrap();
    let image = tmp.path().join("disks.png");
    disks().save(&image).unwrap();
    let overlay = tmp.path().join("overlay.png");
    let model = probe("yolo-seg-probe.onnx");
    let out = tactex(&[
        "detect",
        image.to_str().unwrap(),
        "--model",
        &model,
        "--json",
        "--overlay",
        overlay.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let d = report["detections"].as_array().unwrap();
    assert_eq!(d.len(), 2);
    assert_eq!(d[0]["label"], "apple");
    assert_eq!(d[1]["label"], "lime");
    // Mask areas: the probe's prototypes are 4x4 means thresholded where a cell is about 30%
    // fruit, which moves the outline out by about a pixel: pi (r + 1)^2 = 5281 and 3019 px.
    let area = |i: usize| d[i]["mask_px"].as_f64().unwrap();
    assert!((area(0) / 5281.0 - 1.0).abs() < 0.03, "apple {}", area(0));
    assert!((area(1) / 3019.0 - 1.0).abs() < 0.03, "lime {}", area(1));
    assert_eq!(report["backend"], "tract");
    let drawn = image::open(&overlay).unwrap().to_rgb8();
    assert_ne!(
        drawn.get_pixel(400, 200),
        disks().get_pixel(400, 200),
        "mask tinted"
    );
    // A higher threshold keeps the apple only.
    let out = tactex(&[
        "detect",
        image.to_str().unwrap(),
        "--model",
        &model,
        "--confidence",
        "0.85",
    ]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("1 detections") && text.contains("apple"),
        "{text}"
    );
}

#[test]
fn unusable_models_are_one_line_errors_naming_the_file() {
    let tmp = tempfile::tempdir().unwrap();
    let image = tmp.path().join("disks.png");
    disks().save(&image).unwrap();
    let det = probe("yolo-det-probe.onnx");
    let cases = [
        vec![
            "detect",
            image.to_str().unwrap(),
            "--model",
            "/no/such/model.onnx",
        ],
        vec!["detect", image.to_str().unwrap(), "--model", &det],
        vec![
            "ask",
            "--detector",
            "yolo:/no/such/model.onnx",
            "which fruit is the softest",
        ],
        vec!["ask", "--detector", "magic", "which fruit is the softest"],
    ];
    let names = [
        "/no/such/model.onnx",
        "yolo-det-probe.onnx",
        "/no/such/model.onnx",
        "magic",
    ];
    for (args, name) in cases.iter().zip(names) {
        let out = tactex(args);
        assert!(!out.status.success(), "{args:?} succeeded");
        let err = String::from_utf8_lossy(&out.stderr).trim().to_string();
        assert_eq!(err.lines().count(), 1, "{err}");
        assert!(err.contains(name), "{args:?}: {err}");
        assert!(!err.contains("panicked"), "{err}");
    }
}
