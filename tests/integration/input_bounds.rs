//! Work bounded before it starts and nonsense refused at the edge: annotation files with
//! repeated, non-finite or too many rows, and images larger than any sensor gives, are each
//! one line naming the file (and line), before any of them is fitted or decoded.

use crate::cli::{one_line_error, tactex};
use std::path::Path;

const FOTS: &str = "tests/fixtures/fots";

fn write(dir: &Path, name: &str, text: &str) -> String {
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path.to_str().unwrap().to_string()
}

fn calibrate(annotations: &str) -> std::process::Output {
    let out = Path::new(annotations).with_file_name("profile.toml");
    tactex(&[
        "calibrate",
        "--out",
        out.to_str().unwrap(),
        "--images",
        &format!("{FOTS}/ball-presses"),
        "--annotations",
        annotations,
        "--background",
        &format!("{FOTS}/background.png"),
        "--ball-radius-mm",
        "2.35",
        "--mm-per-px",
        "0.0511",
    ])
}

#[test]
fn ball_press_annotations_listing_a_press_twice_or_too_many_are_refused() {
    let tmp = tempfile::tempdir().unwrap();
    let header = "image,center_x_px,center_y_px,contact_radius_px\n";
    let twice = write(
        tmp.path(),
        "twice.csv",
        &format!("{header}0001.png,76,182,38\n0004.png,85,235,42\n0001.png,76,182,38\n"),
    );
    let err = one_line_error(&calibrate(&twice));
    assert!(
        err.contains("twice.csv:4: image 0001.png is annotated already on line 2"),
        "{err}"
    );
    let rows: String = (0..1001)
        .map(|i| format!("{i:04}.png,76,182,38\n"))
        .collect();
    let many = write(tmp.path(), "many.csv", &format!("{header}{rows}"));
    let err = one_line_error(&calibrate(&many));
    assert!(err.contains("more than 1000 annotated presses"), "{err}");
}

#[test]
fn marker_annotations_off_any_image_or_repeated_are_refused() {
    let tmp = tempfile::tempdir().unwrap();
    for (row, says) in [
        ("NaN,3,1,1", "(NaN, 4) px is not in an image"),
        ("1e308,3,1,1", "(1e308, 4) px is not in an image"),
        ("-20,3,1,1", "(-19, 4) px is not in an image"),
        ("10,3,1,1\n10,3,1,1", "line 3: the marker of line 2 again"),
    ] {
        let file = write(tmp.path(), "m.csv", &format!("Mx,My,dx,dy\n{row}\n"));
        let err = one_line_error(&tactex(&[
            "markers",
            &format!("{FOTS}/markers/press.png"),
            "--annotations",
            &file,
        ]));
        assert!(err.contains(says), "{row}: {err}");
    }
}

#[test]
fn an_image_larger_than_any_sensor_gives_is_refused_before_it_is_decoded() {
    let tmp = tempfile::tempdir().unwrap();
    let big = tmp.path().join("big.png");
    // Small on disk, 4097 px wide: decoding is what would cost.
    image::GrayImage::new(4097, 4).save(&big).unwrap();
    let err = one_line_error(&tactex(&[
        "contact",
        "--reference",
        &format!("{FOTS}/background.png"),
        big.to_str().unwrap(),
    ]));
    assert!(
        err.contains("big.png") && err.contains("larger than 4096 x 4096 px"),
        "{err}"
    );
}

#[test]
fn unclear_causes_are_said_plainly_naming_the_flag_file_or_field() {
    let tmp = tempfile::tempdir().unwrap();
    let press = |grid: &str| {
        tactex(&[
            "press",
            "--shape",
            "sphere",
            "--hardness",
            "35A",
            "--depth-mm",
            "1",
            "--marker-grid",
            grid,
        ])
    };
    let err = one_line_error(&press("1000x1000"));
    assert!(
        err.contains("--marker-grid: 1000x1000 is 1000000 markers"),
        "{err}"
    );
    let err = one_line_error(&press("0x5"));
    assert!(err.contains("0x5 is 0 markers"), "{err}");

    let softest = "Which fruit is the softest?";
    let err = one_line_error(&tactex(&["ask", "--detector", "yolo:", softest]));
    assert!(err.contains("--detector: 'yolo:' names no model"), "{err}");
    let empty = write(tmp.path(), "empty.onnx", "");
    let err = one_line_error(&tactex(&[
        "ask",
        "--detector",
        &format!("yolo:{empty}"),
        softest,
    ]));
    assert!(
        err.contains("not an ONNX model: the file is empty"),
        "{err}"
    );

    // A model card with a field of the wrong type names the card and the field.
    let model = tmp.path().join("m.onnx");
    std::fs::copy("models/hardness-small.onnx", &model).unwrap();
    let card = std::fs::read_to_string("models/hardness-small.json").unwrap();
    let mut card: serde_json::Value = serde_json::from_str(&card).unwrap();
    card["height"] = "tall".into();
    std::fs::write(tmp.path().join("m.json"), card.to_string()).unwrap();
    let err = one_line_error(&tactex(&[
        "ask",
        "--estimator",
        model.to_str().unwrap(),
        softest,
    ]));
    assert!(
        err.contains("m.json: not a model card: field `height`"),
        "{err}"
    );

    // An LLM config of the wrong type names the line and key.
    let config = write(
        tmp.path(),
        "llm.toml",
        "base_url = \"http://127.0.0.1:9/v1\"\nmodel = \"m\"\ntimeout_s = \"soon\"\n",
    );
    let err = one_line_error(&tactex(&[
        "ask",
        "--explainer",
        "llm",
        "--llm-config",
        &config,
        softest,
    ]));
    assert!(
        err.contains("llm.toml: line 3 (`timeout_s = \"soon\"`)"),
        "{err}"
    );
}

/// A ball-press set whose contacts would be under a few pixels (nothing to calibrate from,
/// and a solver grid sized for a speck) or wider than the frame is refused before any press,
/// naming the flag, and leaves no output directory.
#[test]
fn ball_presses_too_small_or_too_large_for_the_frame_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    for radius in ["0.01", "100"] {
        let out_dir = dir.path().join(format!("set-{radius}"));
        let out = tactex(&[
            "datagen",
            "ball-presses",
            "--count",
            "2",
            "--ball-radius-mm",
            radius,
            "--out",
            out_dir.to_str().unwrap(),
        ]);
        let err = one_line_error(&out);
        assert!(err.contains("--ball-radius-mm"), "{err}");
        assert!(!out_dir.exists());
    }
}

#[test]
fn an_object_far_smaller_than_a_pixel_is_pressed_with_its_fields_pooled_not_out_of_memory() {
    // A 0.01 mm sphere's solver cells are 0.5 um: rendered over the pad at that cell they
    // asked for 7.8 GB; a shallow press of a large sphere (8 mm, 1 um in) was refused as "too
    // small to press". Both are pressed, the pooling said in a warning.
    let dir = tempfile::tempdir().unwrap();
    for (radius, depth) in [("0.01", "0.6"), ("8", "0.001")] {
        let out_dir = dir.path().join(format!("r{radius}"));
        let out = tactex(&[
            "press",
            "--shape",
            "sphere",
            "--radius-mm",
            radius,
            "--hardness",
            "40A",
            "--depth-mm",
            depth,
            "--out",
            out_dir.to_str().unwrap(),
            "--json",
        ]);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        assert!(report["force_n"].as_f64().unwrap() > 0.0, "{report}");
        let warned = report["warnings"].as_array().unwrap().iter().any(|w| {
            w.as_str()
                .unwrap()
                .contains("finer than the frame can show")
        });
        assert!(warned, "{report}");
        assert!(out_dir.join("tactile.png").exists());
    }
}

#[test]
fn a_fifo_or_device_given_as_an_input_file_is_refused_not_waited_on() {
    // A FIFO blocks its reader until a writer comes, and /dev/zero never ends: each was a
    // hang (or all the memory) where a file was expected.
    let tmp = tempfile::tempdir().unwrap();
    let fifo = tmp.path().join("scene.toml");
    let made = std::process::Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .unwrap();
    assert!(made.success());
    let fifo = fifo.to_str().unwrap();
    let ask = |flag: &str, path: &str| {
        one_line_error(&tactex(&["ask", "Which fruit is the softest?", flag, path]))
    };
    for (flag, path) in [
        ("--scene", fifo),
        ("--scene", "/dev/zero"),
        ("--sensor", "/dev/zero"),
        ("--camera-calibration", fifo),
    ] {
        let err = ask(flag, path);
        assert!(
            err.contains(path) && err.contains("not a regular file"),
            "{flag} {path}: {err}"
        );
    }
    let err = one_line_error(&tactex(&["read", "/dev/zero"]));
    assert!(err.contains("not a regular file"), "{err}");
    // A mesh given straight to `press`: refused as a FIFO, not opened (which would block).
    let mesh = tmp.path().join("fruit.obj");
    assert!(
        std::process::Command::new("mkfifo")
            .arg(&mesh)
            .status()
            .unwrap()
            .success()
    );
    let mesh = mesh.to_str().unwrap();
    let err = one_line_error(&tactex(&[
        "press",
        "--shape",
        "mesh",
        "--mesh",
        mesh,
        "--hardness",
        "30A",
        "--depth-mm",
        "1",
    ]));
    assert!(
        err.contains(mesh) && err.contains("not a regular file"),
        "{err}"
    );
}
