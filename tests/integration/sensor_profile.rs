//! Sensor profiles end to end: `calibrate` writes one from real ball presses (FOTS fixtures,
//! with their attribution in tests/fixtures/fots), `sensor show|check` read it, `press
//! --sensor` renders with it, and bad profiles fail in one line naming the field.

use std::path::{Path, PathBuf};

use crate::cli::{json, one_line_error, tactex};
use tactex_core::tactile::markers::grid_pitch_px;
use tactex_core::tactile::ssim::ssim_rgb;

fn fixtures() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/fots")
}

/// `calibrate` on the fixtures' ball presses into `dir/fots.toml`.
fn calibrated(dir: &Path) -> PathBuf {
    calibrated_with(dir, &[])
}

/// The same with `extra` flags; no intervals measured unless `extra` asks for them.
fn calibrated_with(dir: &Path, extra: &[&str]) -> PathBuf {
    let f = fixtures();
    let presses = f.join("ball-presses");
    let profile = dir.join("fots.toml");
    let (annotations, background) = (presses.join("annotations.csv"), f.join("background.png"));
    let mut args = vec![
        "calibrate",
        "--images",
        presses.to_str().unwrap(),
        "--annotations",
        annotations.to_str().unwrap(),
        "--background",
        background.to_str().unwrap(),
        "--ball-radius-mm",
        "2.35",
        "--mm-per-px",
        "0.051072522982635343",
        "--out",
        profile.to_str().unwrap(),
        "--source",
        "FOTS (Zhao et al., RA-L 2024), MIT",
    ];
    args.extend_from_slice(extra);
    if !extra.contains(&"--interval-placements") {
        args.extend(["--interval-placements", "0"]);
    }
    let out = tactex(&args);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    profile
}

#[test]
fn calibrate_measures_the_new_profiles_intervals_beside_it_and_ask_quotes_them() {
    let dir = tempfile::tempdir().unwrap();
    let markers = fixtures().join("markers/press.png");
    let profile = calibrated_with(
        dir.path(),
        &[
            "--markers",
            markers.to_str().unwrap(),
            "--interval-placements",
            "4",
        ],
    );
    // The twin pressed each catalog fruit at 4 places through the profile: 44 presses, and a
    // calibration needs 40 measured.
    let beside = dir.path().join("fots.indentation-layer.intervals.json");
    let written: serde_json::Value =
        serde_json::from_slice(&std::fs::read(&beside).unwrap()).unwrap();
    assert_eq!(written["sensor"]["name"], "fots", "{written}");
    assert!(written["presses"].as_u64().unwrap() >= 40, "{written}");
    let shown = json(&tactex(&[
        "sensor",
        "show",
        profile.to_str().unwrap(),
        "--json",
    ]));
    assert_eq!(
        written["sensor"], shown["sensor"],
        "measured through this very profile"
    );

    let o = tactex(&[
        "ask",
        "--sensor",
        profile.to_str().unwrap(),
        "--json",
        "How hard is the lime?",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("intervals measured through this sensor"),
        "{err}"
    );
    let answer: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let lime = &answer["objects"][0];
    assert_eq!(lime["interval"]["calibrated"], true, "{answer}");

    // Fewer placements than make the presses a calibration needs are refused up front.
    let f = fixtures();
    let presses = f.join("ball-presses");
    let other = dir.path().join("other.toml");
    let run = tactex(&[
        "calibrate",
        "--images",
        presses.to_str().unwrap(),
        "--annotations",
        presses.join("annotations.csv").to_str().unwrap(),
        "--background",
        f.join("background.png").to_str().unwrap(),
        "--ball-radius-mm",
        "2.35",
        "--mm-per-px",
        "0.0511",
        "--interval-placements",
        "2",
        "--out",
        other.to_str().unwrap(),
    ]);
    assert!(!run.status.success());
    let err = String::from_utf8_lossy(&run.stderr);
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    assert!(err.contains("--interval-placements"), "{err}");
    assert!(!other.exists());
}

/// `press --json` of the FOTS ball (radius 2.35 mm, rigid) 0.4 mm deep through `profile` on
/// the CPU path, its maps and frames in `out`.
fn rigid_ball_press(profile: &Path, out: &Path) -> serde_json::Value {
    json(&tactex(&[
        "press",
        "--shape",
        "sphere",
        "--radius-mm",
        "2.35",
        "--hardness",
        "rigid",
        "--depth-mm",
        "0.4",
        "--sensor",
        profile.to_str().unwrap(),
        "--device",
        "cpu",
        "--out",
        out.to_str().unwrap(),
        "--json",
    ]))
}

#[test]
fn a_calibrated_profile_renders_its_background_when_nothing_touches() {
    let dir = tempfile::tempdir().unwrap();
    let profile = calibrated(dir.path());
    let background = dir.path().join("fots.background.png");
    assert!(background.is_file());
    let shown = json(&tactex(&[
        "sensor",
        "show",
        profile.to_str().unwrap(),
        "--json",
    ]));
    assert_eq!(shown["sensor"]["name"], "fots");
    assert_eq!(shown["width_px"], 240);
    assert_eq!(shown["height_px"], 320);
    assert!(shown["shading"].as_str().unwrap().contains("table"));
    // A real camera: a grey level of noise or so.
    let noise = shown["noise_sigma_grey"].as_f64().unwrap();
    assert!((0.2..3.0).contains(&noise), "{noise}");

    let out = dir.path().join("press");
    let report = rigid_ball_press(&profile, &out);
    assert_eq!(report["sensor"], shown["sensor"]);
    let open = |p: &Path| image::open(p).unwrap().to_rgb8();
    let (reference, tactile, bg) = (
        open(&out.join("reference.png")),
        open(&out.join("tactile.png")),
        open(&background),
    );
    assert_eq!(reference.dimensions(), (240, 320));
    let at_rest = ssim_rgb(&reference, &bg).unwrap();
    assert!(
        at_rest >= 0.95,
        "no-contact frame vs background: SSIM {at_rest}"
    );
    // The press shows where the ball is: tens of grey levels, against a few of noise.
    let changed = tactile
        .pixels()
        .zip(reference.pixels())
        .map(|(a, b)| (0..3).map(|c| a[c].abs_diff(b[c])).max().unwrap())
        .max()
        .unwrap();
    assert!(changed > 30, "largest change {changed} grey levels");
}

#[test]
fn the_built_in_profile_prints_as_a_profile_that_loads_to_the_same_hash() {
    let dir = tempfile::tempdir().unwrap();
    let toml = tactex(&["sensor", "show", "--toml"]);
    assert!(toml.status.success());
    let path = dir.path().join("mini.toml");
    std::fs::write(&path, &toml.stdout).unwrap();
    let builtin = json(&tactex(&["sensor", "show", "--json"]));
    let loaded = json(&tactex(&[
        "sensor",
        "show",
        path.to_str().unwrap(),
        "--json",
    ]));
    assert_eq!(builtin["sensor"], loaded["sensor"]);
    let checked = json(&tactex(&[
        "sensor",
        "check",
        path.to_str().unwrap(),
        "--json",
    ]));
    assert!(
        checked["no_contact_ssim"].as_f64().unwrap() > 0.5,
        "{checked}"
    );
}

#[test]
fn bad_profiles_fail_in_one_line_naming_the_field() {
    let dir = tempfile::tempdir().unwrap();
    let stock = String::from_utf8(tactex(&["sensor", "show", "--toml"]).stdout).unwrap();
    for (from, to, field) in [
        ("mm_per_px = 0.0634", "mm_per_px = 0.0", "camera.mm_per_px"),
        ("modulus_mpa = 0.3", "modulus_mpa = -2.0", "gel.modulus_mpa"),
        (
            "noise_sigma_grey = 0.5",
            "noise_sigma_grey = inf",
            "camera.noise_sigma_grey",
        ),
        ("width_px = 320", "width_px = 0", "camera.width_px"),
        (
            "background = \"synthetic\"",
            "background = \"gone.png\"",
            "optics.background",
        ),
        (
            "shading = \"lights\"",
            "shading = \"table\"",
            "optics.table",
        ),
        ("cols = 9", "cols = \"nine\"", "line"),
        ("cols = 9", "cols = 0", "markers"),
    ] {
        assert!(stock.contains(from), "{from}");
        let path = dir.path().join("bad.toml");
        std::fs::write(&path, stock.replacen(from, to, 1)).unwrap();
        for args in [
            vec!["sensor", "check", path.to_str().unwrap()],
            vec![
                "press",
                "--shape",
                "sphere",
                "--hardness",
                "rigid",
                "--depth-mm",
                "0.2",
                "--sensor",
                path.to_str().unwrap(),
            ],
        ] {
            let err = one_line_error(&tactex(&args));
            assert!(
                err.contains("bad.toml") && err.contains(field),
                "{to}: {err}"
            );
            // A flag is named only where one gave the file: `sensor check FILE` has none.
            assert_eq!(err.contains("--sensor"), args[0] == "press", "{err}");
        }
    }
    let missing = dir.path().join("missing.toml");
    let err = one_line_error(&tactex(&["sensor", "check", missing.to_str().unwrap()]));
    assert!(
        err.contains("missing.toml") && !err.contains("--sensor"),
        "{err}"
    );
}

#[test]
fn datagen_draws_around_a_profile_and_keeps_one_profile_per_data_set() {
    let dir = tempfile::tempdir().unwrap();
    let profile = calibrated(dir.path());
    let bg = image::open(dir.path().join("fots.background.png"))
        .unwrap()
        .to_rgb8();
    let data = dir.path().join("data");
    let run = |extra: &[&str]| {
        let mut args = vec![
            "datagen",
            "tactile",
            "--count",
            "3",
            "--shapes",
            "sphere,box",
            "--out",
            data.to_str().unwrap(),
        ];
        args.extend_from_slice(extra);
        tactex(&args)
    };
    let out = run(&["--sensor", profile.to_str().unwrap()]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let shown = json(&tactex(&[
        "sensor",
        "show",
        profile.to_str().unwrap(),
        "--json",
    ]));
    let info: serde_json::Value =
        serde_json::from_slice(&std::fs::read(data.join("dataset.json")).unwrap()).unwrap();
    assert_eq!(info["sensor"], shown["sensor"]);
    assert_eq!(
        (info["width"].as_u64(), info["height"].as_u64()),
        (Some(240), Some(320))
    );
    for k in 0..3 {
        let reference = image::open(data.join(format!("samples/{k:07}/reference.png")))
            .unwrap()
            .to_rgb8();
        // The profile's background under a few percent of exposure jitter and its noise.
        let s = ssim_rgb(&reference, &bg).unwrap();
        eprintln!("sample {k}: no-contact frame vs the profile's background SSIM {s:.4}");
        assert!(s >= 0.9, "sample {k}: SSIM {s}");
    }
    // Resuming the data set with another sensor is refused, naming the field.
    let err = one_line_error(&run(&[]));
    assert!(
        err.contains("dataset.json") && err.contains("sensor"),
        "{err}"
    );
}

#[test]
fn calibrate_reads_the_marker_grid_from_a_real_marker_frame_and_press_draws_it() {
    let dir = tempfile::tempdir().unwrap();
    let f = fixtures();
    let frame = f.join("markers/press.png");
    let profile = calibrated_with(
        dir.path(),
        &["--markers", frame.to_str().unwrap(), "--no-glow"],
    );
    let mm_per_px = 0.05107252298263534;
    // FOTS's authors annotated the frame's 11 x 9 grid (landscape; the presses are portrait).
    let annotated: Vec<(f64, f64)> = std::fs::read_to_string(f.join("markers/press.csv"))
        .unwrap()
        .lines()
        .skip(1)
        .map(|l| {
            let v: Vec<f64> = l.split(',').map(|c| c.trim().parse().unwrap()).collect();
            (v[0] + v[2] + 0.5, v[1] + v[3] + 0.5)
        })
        .collect();
    assert_eq!(annotated.len(), 99);
    let pitch_px = grid_pitch_px(&annotated).unwrap();
    let text = std::fs::read_to_string(&profile).unwrap();
    let toml: toml::Value = toml::from_str(&text).unwrap();
    let m = &toml["markers"];
    assert_eq!(
        (m["cols"].as_integer(), m["rows"].as_integer()),
        (Some(9), Some(11))
    );
    let pitch_mm = m["pitch_mm"].as_float().unwrap();
    assert!(
        (pitch_mm / (pitch_px * mm_per_px) - 1.0).abs() < 0.02,
        "pitch {pitch_mm} mm against the annotations' {} mm",
        pitch_px * mm_per_px
    );
    // Dots of about a fifth of the pitch across, blocking most of the light.
    let radius_mm = m["radius_mm"].as_float().unwrap();
    assert!(
        (0.15..0.3).contains(&(radius_mm / pitch_mm)),
        "{radius_mm} mm"
    );
    let darkness = m["darkness"].as_float().unwrap();
    assert!((0.5..=1.0).contains(&darkness), "{darkness}");

    // The twin draws that grid: its no-contact frame shows 99 dots at the real pitch.
    let pressed = dir.path().join("press");
    rigid_ball_press(&profile, &pressed);
    let found = json(&tactex(&[
        "markers",
        pressed.join("reference.png").to_str().unwrap(),
        "--json",
    ]));
    assert_eq!(found["count"].as_u64(), Some(99), "{found}");
    let drawn: Vec<(f64, f64)> = found["markers"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| (p[0].as_f64().unwrap(), p[1].as_f64().unwrap()))
        .collect();
    let drawn_pitch = grid_pitch_px(&drawn).unwrap();
    assert!(
        (drawn_pitch / pitch_px - 1.0).abs() < 0.03,
        "{drawn_pitch} px vs {pitch_px} px"
    );
}

#[test]
fn the_learned_model_says_so_when_it_reads_another_sensor_than_it_was_trained_on() {
    let dir = tempfile::tempdir().unwrap();
    let profile = crate::cli::renamed_stock_profile(dir.path(), "lab mini");
    let ask = |extra: &[&str]| {
        let mut args = vec![
            "ask",
            "How hard is the lime?",
            "--json",
            "--estimator",
            "learned",
        ];
        args.extend_from_slice(extra);
        json(&tactex(&args))
    };
    let on_stock = ask(&[]);
    let evidence = &on_stock["objects"][0]["evidence"];
    assert_eq!(evidence["trained_on_sensor"], "GelSight Mini", "{evidence}");
    assert!(evidence.get("other_sensor").is_none(), "{evidence}");
    let on_lab = ask(&["--sensor", profile.to_str().unwrap()]);
    let note = on_lab["objects"][0]["evidence"]["other_sensor"]
        .as_str()
        .expect("a note on the other sensor");
    assert!(
        note.contains("'lab mini'") && note.contains("trained on sensor 'GelSight Mini'"),
        "{note}"
    );
}

/// `calibrate` checked against a sensor whose truth is known: the twin's GelSight Mini makes
/// a ball-press set (`datagen ball-presses`), and the profile calibrated from it gives the
/// Mini back: its marker grid from the set's marker frame, and its held-out presses rendered
/// through the fitted table as the Mini's analytic lights rendered them, to a few grey levels
/// (camera noise 0.5).
#[test]
fn calibrating_the_twins_own_mini_gives_the_mini_back() {
    let dir = tempfile::tempdir().unwrap();
    let set = dir.path().join("set");
    let out = tactex(&[
        "datagen",
        "ball-presses",
        "--count",
        "9",
        "--seed",
        "3",
        "--out",
        set.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let truth: serde_json::Value =
        serde_json::from_slice(&std::fs::read(set.join("presses.json")).unwrap()).unwrap();
    assert_eq!(truth["presses"].as_array().unwrap().len(), 9);
    assert_eq!(truth["sensor"]["name"], "GelSight Mini");

    // In a folder that does not exist yet: `calibrate --out` makes it.
    let profile = dir.path().join("profiles/mini.toml");
    let file = |name: &str| set.join(name).to_str().unwrap().to_string();
    let out = tactex(&[
        "calibrate",
        "--images",
        set.to_str().unwrap(),
        "--annotations",
        &file("annotations.csv"),
        "--background",
        &file("background.png"),
        "--markers",
        &file("markers.png"),
        "--ball-radius-mm",
        "2.35",
        "--mm-per-px",
        "0.0634",
        "--no-glow",
        "--interval-placements",
        "0",
        "--out",
        profile.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let fitted = tactex_core::tactile::sensor_profile::SensorProfile::load(&profile).unwrap();
    let stock = tactex_core::tactile::sensor_profile::SensorProfile::gelsight_mini();
    let (m, s) = (fitted.spec.markers, stock.spec.markers);
    assert_eq!((m.cols, m.rows), (s.cols, s.rows));
    assert!(
        (m.pitch_mm / s.pitch_mm - 1.0).abs() < 0.01,
        "pitch {}",
        m.pitch_mm
    );
    assert!(
        (m.radius_mm / s.radius_mm - 1.0).abs() < 0.1,
        "dot radius {}",
        m.radius_mm
    );

    let out = tactex(&[
        "compare",
        "--sensor",
        profile.to_str().unwrap(),
        "--images",
        set.to_str().unwrap(),
        "--annotations",
        &file("annotations.csv"),
        "--json",
    ]);
    let report = json(&out);
    let (ssim, mae) = (
        report["mean"]["ssim_contact"].as_f64().unwrap(),
        report["mean"]["mae_contact"].as_f64().unwrap(),
    );
    let bare = report["background_only_mean"]["mae_contact"]
        .as_f64()
        .unwrap();
    assert!(
        ssim >= 0.97 && mae <= 3.0,
        "held-out contact SSIM {ssim}, MAE {mae}"
    );
    assert!(
        bare > 3.0 * mae,
        "the bare background scores {bare}, the presses {mae}"
    );
}

/// A model reads one frame size: through a profile of another (the FOTS profile's 240 x 320
/// against the built-in model's 320 x 240) every fruit came back not measured after all the
/// presses were made. It is refused when chosen, naming the flag and both sizes.
#[test]
fn a_model_for_another_frame_size_is_refused_before_any_press() {
    let profile = fixtures().join("profile/fots-9.toml");
    let err = one_line_error(&tactex(&[
        "ask",
        "How hard is the lime?",
        "--estimator",
        "learned",
        "--sensor",
        profile.to_str().unwrap(),
    ]));
    assert!(
        err.contains("--estimator learned")
            && err.contains("reads 320 x 240 frames")
            && err.contains("makes 240 x 320"),
        "{err}"
    );
}
