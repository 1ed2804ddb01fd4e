//! Sim-to-real on real GelSight frames (FOTS; fixtures in tests/fixtures/fots with their
//! attribution): calibration and comparison of ball presses, the contact criterion, and
//! marker detection against the published annotations.

use image::RgbImage;
use std::path::{Path, PathBuf};

use crate::cli::{json, tactex};
use tactex_core::stats::median;
use tactex_core::tactile::ball_calibration::read_annotations;
use tactex_core::tactile::contact::{ContactRule, contact_evidence};
use tactex_core::tactile::contact_circle::estimate_contact_circle;

fn fixtures() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/fots")
}

/// The FOTS frames' pixel size (its profile's, from the marked ball presses).
const FOTS_MM_PER_PX: Option<f64> = Some(0.05107252298263534);

fn rgb(path: &Path) -> RgbImage {
    image::open(path).unwrap().to_rgb8()
}

/// FOTS scale: 19.58 px/mm.
const MM_PER_PX: &str = "0.051072522982635343";

#[test]
fn calibrated_renderer_matches_held_out_real_presses() {
    let f = fixtures();
    let dir = tempfile::tempdir().unwrap();
    let calib = dir.path().join("fots.toml");
    let presses = f.join("ball-presses");
    let annotations = presses.join("annotations.csv");
    let out = tactex(&[
        "calibrate",
        "--images",
        presses.to_str().unwrap(),
        "--annotations",
        annotations.to_str().unwrap(),
        "--background",
        f.join("background.png").to_str().unwrap(),
        "--ball-radius-mm",
        "2.35",
        "--mm-per-px",
        MM_PER_PX,
        "--interval-placements",
        "0",
        "--out",
        calib.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let compare = |extra: &[&str]| {
        let mut args = vec![
            "compare",
            "--sensor",
            calib.to_str().unwrap(),
            "--images",
            presses.to_str().unwrap(),
            "--annotations",
            annotations.to_str().unwrap(),
            "--device",
            "cpu",
            "--json",
        ];
        args.extend_from_slice(extra);
        json(&tactex(&args))
    };
    let report = compare(&[]);
    assert_eq!(report["glow"], true);
    assert_eq!(report["sensor"]["name"], "fots");
    assert_eq!(report["sensor"]["sha256"].as_str().unwrap().len(), 64);
    let n = report["presses"].as_array().unwrap().len();
    // Fixture annotations hold 9 presses; every third (3) is held out of the calibration.
    assert_eq!(n, 3);
    let (mean, bare) = (&report["mean"], &report["background_only_mean"]);
    let v = |s: &serde_json::Value, k: &str| s[k].as_f64().unwrap();
    eprintln!("rendered {mean}\nbackground only {bare}");
    assert!(v(mean, "ssim") >= 0.90, "{mean}");
    // What rendering adds: the contact region looks more like the real one than the bare
    // background does, by structure and by intensity.
    assert!(
        v(mean, "ssim_contact") > v(bare, "ssim_contact") + 0.01,
        "{mean} vs {bare}"
    );
    assert!(
        v(mean, "mae_contact") < 0.75 * v(bare, "mae_contact"),
        "{mean} vs {bare}"
    );
    // The glow fitted on the calibration presses carries to the held-out ones: the real
    // contacts' wider coloured glow and darker inside are closer than the slopes' shading
    // alone (on the fixtures 0.961 -> 0.976 and 9.9 -> 7.6 grey levels; without the
    // indentation terms the glow reached 0.971).
    let plain = compare(&["--no-glow"]);
    assert_eq!(plain["glow"], false);
    let plain = &plain["mean"];
    eprintln!("without glow {plain}");
    assert!(
        v(mean, "ssim_contact") > v(plain, "ssim_contact") + 0.012,
        "{mean} vs {plain}"
    );
    assert!(
        v(mean, "mae_contact") < 0.9 * v(plain, "mae_contact"),
        "{mean} vs {plain}"
    );
}

#[test]
fn compare_rejects_a_bad_sensor_profile_in_one_line() {
    let f = fixtures();
    let dir = tempfile::tempdir().unwrap();
    let calib = dir.path().join("calib.toml");
    std::fs::write(&calib, "format = \"something else\"\n").unwrap();
    let presses = f.join("ball-presses");
    let out = tactex(&[
        "compare",
        "--sensor",
        calib.to_str().unwrap(),
        "--images",
        presses.to_str().unwrap(),
        "--annotations",
        presses.join("annotations.csv").to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    assert!(err.contains("calib.toml"), "{err}");
}

/// The full shared set where this checkout has it, else the fixtures.
fn ball_press_frames() -> Vec<PathBuf> {
    let shared =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/real/fots-gelsight/ball-presses");
    let dir = if shared.is_dir() {
        shared
    } else {
        fixtures().join("ball-presses")
    };
    let mut frames: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "png"))
        .collect();
    frames.sort();
    frames
}

#[test]
fn contact_criterion_fires_on_every_ball_press_and_not_on_the_background() {
    let rule = ContactRule::default();
    let background = rgb(&fixtures().join("background.png"));
    for frame in ball_press_frames() {
        let e = contact_evidence(&rgb(&frame), &background, &rule, FOTS_MM_PER_PX).unwrap();
        assert!(e.contact, "{}: {e:?}", frame.display());
    }
    let same = contact_evidence(&background, &background, &rule, FOTS_MM_PER_PX).unwrap();
    assert!(!same.contact && same.min_tile_ssim > 0.999);
    // A later no-contact frame: camera noise of 2 grey levels and a colour drift of 15 levels
    // in blue, about what the FOTS frames show between shots.
    let mut state = 12345u64;
    let mut uniform = || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let drifted = RgbImage::from_fn(background.width(), background.height(), |x, y| {
        let p = background.get_pixel(x, y);
        image::Rgb(std::array::from_fn(|c| {
            // Sum of 12 uniforms: near-normal with sigma 1, scaled to 2.
            let noise = 2.0 * ((0..12).map(|_| uniform()).sum::<f64>() - 6.0);
            let drift = if c == 2 { 15.0 } else { 0.0 };
            (p[c] as f64 + noise + drift).round().clamp(0.0, 255.0) as u8
        }))
    });
    let e = contact_evidence(&drifted, &background, &rule, FOTS_MM_PER_PX).unwrap();
    assert!(!e.contact, "{e:?}");
}

#[test]
fn contact_circles_estimated_on_real_ball_presses_match_the_marked_ones() {
    let frames = ball_press_frames();
    let dir = frames[0].parent().unwrap();
    let marked = read_annotations(&dir.join("annotations.csv")).unwrap();
    let background = rgb(&fixtures().join("background.png"));
    let (mut centre_errors, mut radius_errors) = (Vec::new(), Vec::new());
    for press in &marked {
        let frame = rgb(&dir.join(&press.image));
        let c = estimate_contact_circle(&frame, &background)
            .unwrap_or_else(|| panic!("{}: no contact circle", press.image));
        let [x, y] = press.centre_px;
        centre_errors.push((c.centre_px[0] - x).hypot(c.centre_px[1] - y));
        radius_errors.push(c.radius_px - press.contact_radius_px);
    }
    let mean_abs = radius_errors.iter().map(|e| e.abs()).sum::<f64>() / marked.len() as f64;
    let centre = median(&mut centre_errors).unwrap();
    let bias = median(&mut radius_errors).unwrap();
    eprintln!(
        "{} presses: centre error median {centre:.2} px, radius error median {bias:+.2} px, mean |error| {mean_abs:.2} px",
        marked.len()
    );
    // Hand-marked circles at 19.58 px/mm in whole pixels: measured 4.0 px, +0.45 px and
    // 1.9 px on the 30 shared presses (2.7, +0.3 and 1.8 on the held-out third).
    assert!(centre <= 5.0, "centre error median {centre:.2} px");
    assert!(bias.abs() <= 1.5, "radius error median {bias:+.2} px");
    assert!(mean_abs <= 2.5, "radius error mean |.| {mean_abs:.2} px");
    // No contact, no circle: the rays of a frame against itself find no edge.
    assert!(estimate_contact_circle(&background, &background).is_none());
}

#[test]
fn contact_command_finds_the_marked_circle_and_no_contact_on_the_background() {
    let f = fixtures();
    let background = f.join("background.png");
    let out = tactex(&[
        "contact",
        f.join("ball-presses/0014.png").to_str().unwrap(),
        "--reference",
        background.to_str().unwrap(),
        "--mm-per-px",
        MM_PER_PX,
        "--json",
    ]);
    let r = json(&out);
    assert_eq!(r["evidence"]["contact"], true);
    // Marked: centre (125, 191) + 1/2, radius 39 px (1.99 mm).
    let c = &r["circle"];
    let (x, y) = (
        c["centre_px"][0].as_f64().unwrap(),
        c["centre_px"][1].as_f64().unwrap(),
    );
    assert!((x - 125.5).hypot(y - 191.5) < 5.0, "{c}");
    assert!((c["radius_px"].as_f64().unwrap() - 39.0).abs() < 3.0, "{c}");
    let mm = r["contact_radius_mm"].as_f64().unwrap();
    assert!((mm - 39.0 * 0.0510725).abs() < 0.16, "{mm} mm");

    let out = tactex(&[
        "contact",
        background.to_str().unwrap(),
        "--reference",
        background.to_str().unwrap(),
        "--json",
    ]);
    let r = json(&out);
    assert_eq!(r["evidence"]["contact"], false);
    assert!(r.get("circle").is_none(), "{r}");

    // A reference of another size is named in one line.
    let marker_frame = f.join("markers/press.png");
    let out = tactex(&[
        "contact",
        background.to_str().unwrap(),
        "--reference",
        marker_frame.to_str().unwrap(),
    ]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    assert!(err.contains("markers/press.png"), "{err}");
}

#[test]
fn markers_found_on_the_real_marker_frame_match_the_annotations() {
    let f = fixtures().join("markers");
    let out = tactex(&["markers", f.join("press.png").to_str().unwrap(), "--json"]);
    let report = json(&out);
    let found: Vec<(f64, f64)> = report["markers"]
        .as_array()
        .unwrap()
        .iter()
        .map(|m| (m[0].as_f64().unwrap(), m[1].as_f64().unwrap()))
        .collect();
    let text = std::fs::read_to_string(f.join("press.csv")).unwrap();
    let mut within = 0;
    let mut total = 0;
    for line in text.lines().skip(1) {
        let v: Vec<f64> = line.split(',').map(|c| c.trim().parse().unwrap()).collect();
        // Annotated position = Mx + dx, My + dy: FOTS's Lucas-Kanade track written as
        // int(x) - int(Mx), so whole pixels truncated: the marker lies in [M + d, M + d + 1),
        // and its centre is compared with M + d + 1/2 (the median offset of the
        // detections from the raw integers is +0.48, +0.47 px, as truncation predicts).
        let (x, y) = (v[0] + v[2] + 0.5, v[1] + v[3] + 0.5);
        let d = found
            .iter()
            .map(|p| (p.0 - x).hypot(p.1 - y))
            .fold(f64::INFINITY, f64::min);
        total += 1;
        within += (d <= 1.5) as usize;
    }
    eprintln!("{within} of {total} annotated markers found within 1.5 px");
    assert_eq!(total, 99);
    // 94 of 99 today (93 with plain silhouette means, before the circle through the hull
    // restored dots that the ridge's highlights cut); of the five misses three annotations
    // sit 2.6-6.6 px from a whole, unoccluded dot (optical-flow drift), and two dots are
    // half hidden under the highlight.
    assert!(within >= 94, "{within} of {total}");

    // The command scores the same annotations the same way, and draws them.
    let dir = tempfile::tempdir().unwrap();
    let overlay = dir.path().join("overlay.png");
    let out = tactex(&[
        "markers",
        f.join("press.png").to_str().unwrap(),
        "--annotations",
        f.join("press.csv").to_str().unwrap(),
        "--overlay",
        overlay.to_str().unwrap(),
        "--json",
    ]);
    let report = json(&out);
    assert_eq!(report["annotated"]["count"], 99);
    assert_eq!(report["annotated"]["found"], within as u64);
    assert_eq!(image::open(&overlay).unwrap().width(), 3 * 320);
}

#[test]
fn calibrate_rejects_bad_input_in_one_line_and_writes_nothing() {
    let f = fixtures();
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("calib.toml");
    let bad_csv = dir.path().join("bad.csv");
    std::fs::write(
        &bad_csv,
        "image,center_x_px,center_y_px,contact_radius_px\n0001.png,76,182\n",
    )
    .unwrap();
    let good_csv = dir.path().join("presses/annotations.csv");
    let out_dir = dir.path().join("d");
    std::fs::create_dir(&out_dir).unwrap();
    let background_of_dir = dir.path().join("d.background.png");
    // A copy of the presses: one case asks to write over one of them.
    let images = dir.path().join("presses");
    std::fs::create_dir(&images).unwrap();
    for entry in std::fs::read_dir(f.join("ball-presses")).unwrap() {
        let entry = entry.unwrap().path();
        std::fs::copy(&entry, images.join(entry.file_name().unwrap())).unwrap();
    }
    let background = f.join("background.png");
    for (annotations, radius, extra, expect) in [
        (&good_csv, "-1", vec![], "--ball-radius-mm"),
        (&bad_csv, "2.35", vec![], "bad.csv:2"),
        // Table sizes whose fit would run for minutes (it grows with the cube of the nodes).
        (
            &good_csv,
            "2.35",
            vec!["--mag-bins", "100"],
            "--mag-bins 100 x --dir-bins 24",
        ),
        (&good_csv, "2.35", vec!["--dir-bins", "300"], "--dir-bins"),
        (&good_csv, "2.35", vec![], "is a directory"),
        (&good_csv, "2.35", vec![], "over the input"),
    ] {
        let over_input = images.join("0001.png");
        let target = match expect {
            "is a directory" => &out_dir,
            "over the input" => &over_input,
            _ => &out,
        };
        let mut argv = vec![
            "calibrate",
            "--images",
            images.to_str().unwrap(),
            "--annotations",
            annotations.to_str().unwrap(),
            "--background",
            background.to_str().unwrap(),
            "--ball-radius-mm",
            radius,
            "--mm-per-px",
            MM_PER_PX,
            "--out",
            target.to_str().unwrap(),
        ];
        argv.extend(extra);
        let run = tactex(&argv);
        assert!(!run.status.success());
        let err = String::from_utf8_lossy(&run.stderr);
        assert_eq!(err.trim().lines().count(), 1, "{err}");
        assert!(err.contains(expect), "{err}");
        assert!(!out.exists());
        assert!(!background_of_dir.exists(), "{err}");
    }
    // The folder and the CSV swapped: the flag is named, not only the OS's error.
    for (images, annotations, expect) in [
        (&images, &images, "--annotations"),
        (&good_csv, &good_csv, "--images"),
    ] {
        let run = tactex(&[
            "calibrate",
            "--images",
            images.to_str().unwrap(),
            "--annotations",
            annotations.to_str().unwrap(),
            "--background",
            background.to_str().unwrap(),
            "--ball-radius-mm",
            "2.35",
            "--mm-per-px",
            MM_PER_PX,
            "--out",
            out.to_str().unwrap(),
        ]);
        assert!(!run.status.success());
        let err = String::from_utf8_lossy(&run.stderr);
        assert_eq!(err.trim().lines().count(), 1, "{err}");
        assert!(err.starts_with(&format!("error: {expect} ")), "{err}");
        assert!(!out.exists());
    }
}

/// The real presses read through the fixture profile's table and glow, as the indentation
/// estimator reads frames: the glow undone, the contact is the ball's and not a bowl of
/// scattered light. Before the glow was read backwards the radius read +72% over the marked
/// one (30 FOTS presses through fots-9) and the depth +23% over the layer model's. The
/// half-depth region still read the radius +14% (a blurred real imprint is wider at half
/// its depth); the contact's edge where the slope peaks reads it within 3% on these nine
/// (issue 46 asks within 10%).
#[test]
fn real_presses_read_through_the_glow_give_the_balls_depth() {
    let f = fixtures();
    let presses = f.join("ball-presses");
    let report = json(&tactex(&[
        "compare",
        "--sensor",
        f.join("profile/fots-9.toml").to_str().unwrap(),
        "--images",
        presses.to_str().unwrap(),
        "--annotations",
        presses.join("annotations.csv").to_str().unwrap(),
        "--split",
        "all",
        "--device",
        "cpu",
        "--json",
    ]));
    let (real, rendered) = (&report["reading_real"], &report["reading_rendered"]);
    eprintln!("real {real}\nrendered {rendered}");
    let v = |s: &serde_json::Value, k: &str| s[k].as_f64().unwrap();
    assert_eq!(v(real, "presses"), 9.0);
    assert!(v(real, "depth_error_median_abs") < 0.25, "{real}");
    assert!(v(real, "radius_error_median").abs() < 0.1, "{real}");
    // The twin's own renders through the profile read as the stock Mini's do.
    assert!(v(rendered, "depth_error_median_abs") < 0.2, "{rendered}");
    assert!(v(rendered, "radius_error_median_abs") < 0.12, "{rendered}");
}

/// The stock Mini's reading against the geometry it rendered: a rigid 2.35 mm ball pressed
/// 0.6 mm in makes a 0.6 mm deep imprint. Before the marker dots' slopes were filled (they
/// read as flat gel) it read 0.548 mm, 9% short.
#[test]
fn the_stock_mini_reads_a_steel_balls_depth_within_five_percent() {
    let flags = [
        "--shape",
        "sphere",
        "--radius-mm",
        "2.35",
        "--hardness",
        "rigid",
        "--depth-mm",
        "0.6",
    ];
    let report = press_and_read(&flags, None);
    let depth = report["peak_depth_mm"].as_f64().unwrap();
    assert!((depth - 0.6).abs() < 0.05 * 0.6, "{report}");
    // A round contact inside the frame: its size is the outline's.
    assert_eq!(report["contact_edge"], "outline", "{report}");
}

/// `press` with these flags (through `sensor` when given), and the `read` report of its frame
/// against its no-contact frame, read through the same sensor.
fn press_and_read(press_flags: &[&str], sensor: Option<&Path>) -> serde_json::Value {
    let dir = tempfile::tempdir().unwrap();
    let press = dir.path().join("press");
    let sensor_flags: Vec<&str> = match sensor {
        Some(p) => vec!["--sensor", p.to_str().unwrap()],
        None => vec![],
    };
    let mut argv = vec!["press"];
    argv.extend(press_flags);
    argv.extend(&sensor_flags);
    argv.extend(["--out", press.to_str().unwrap()]);
    let made = tactex(&argv);
    assert!(
        made.status.success(),
        "{}",
        String::from_utf8_lossy(&made.stderr)
    );
    let (frame, reference) = (press.join("tactile.png"), press.join("reference.png"));
    let mut argv = vec![
        "read",
        frame.to_str().unwrap(),
        "--reference",
        reference.to_str().unwrap(),
        "--json",
    ];
    argv.extend(&sensor_flags);
    json(&tactex(&argv))
}

/// A rigid sphere pressed through the fixture profile, and the `read` report of its frame.
fn press_and_read_through_fots_9(radius_mm: &str, depth_mm: &str) -> serde_json::Value {
    let flags = [
        "--shape",
        "sphere",
        "--radius-mm",
        radius_mm,
        "--hardness",
        "rigid",
        "--depth-mm",
        depth_mm,
    ];
    press_and_read(&flags, Some(&fixtures().join("profile/fots-9.toml")))
}

/// The camera's noise alone, read backwards through a profile's table and glow, was read as
/// a broad imprint (fots-9: 0.05 mm deep, 6.7 mm wide; the R1.5 profile: 0.1 mm), a floor
/// under every shallow press; the reading smooths the change by 0.06 mm first.
#[test]
fn a_frame_of_camera_noise_alone_reads_no_imprint_through_a_profile() {
    let report = press_and_read_through_fots_9("20", "0.001");
    assert!(report["peak_depth_mm"].as_f64().unwrap() < 0.02, "{report}");
}

#[test]
fn read_draws_the_indentation_map_and_refuses_a_frame_of_another_size() {
    let f = fixtures();
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("read.png");
    let profile = f.join("profile/fots-9.toml");
    let frame = f.join("ball-presses/0014.png");
    let report = json(&tactex(&[
        "read",
        frame.to_str().unwrap(),
        "--sensor",
        profile.to_str().unwrap(),
        "--out",
        png.to_str().unwrap(),
        "--json",
    ]));
    // Marked: 39 px = 1.99 mm; the ball is 2.35 mm.
    let radius = report["contact_radius_mm"].as_f64().unwrap();
    let depth = report["peak_depth_mm"].as_f64().unwrap();
    assert!((1.5..3.2).contains(&radius), "{report}");
    assert!(depth > 0.5 && depth < 2.35, "{report}");
    assert_eq!(report["imprint"], true);
    let drawn = rgb(&png);
    assert_eq!(drawn.dimensions(), (2 * 240, 320));
    // The no-contact frame read against itself: no imprint, and no contact made of noise.
    let flat = json(&tactex(&[
        "read",
        f.join("profile/fots-9.background.png").to_str().unwrap(),
        "--sensor",
        profile.to_str().unwrap(),
        "--json",
    ]));
    assert_eq!(flat["imprint"], false, "{flat}");
    assert!(flat["contact_radius_mm"].is_null(), "{flat}");
    // The picture may not replace the frame it was read from.
    let copy = dir.path().join("copy.png");
    std::fs::copy(&frame, &copy).unwrap();
    let out = tactex(&[
        "read",
        copy.to_str().unwrap(),
        "--sensor",
        profile.to_str().unwrap(),
        "--out",
        copy.to_str().unwrap(),
    ]);
    assert!(!out.status.success());
    assert_eq!(rgb(&copy), rgb(&frame));
    // A frame of the stock Mini's size through the FOTS profile: one line, nothing written.
    let small = dir.path().join("small.png");
    RgbImage::from_fn(320, 240, |x, y| {
        image::Rgb([(x / 2) as u8, (y / 2) as u8, 90])
    })
    .save(&small)
    .unwrap();
    let out_png = dir.path().join("no.png");
    let out = tactex(&[
        "read",
        small.to_str().unwrap(),
        "--sensor",
        profile.to_str().unwrap(),
        "--out",
        out_png.to_str().unwrap(),
    ]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("small.png") && err.contains("240 x 320"),
        "{err}"
    );
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    assert!(!out_png.exists());
}

/// Frames `read` cannot read are refused in one line naming the file or flag, and nothing is
/// written: a greyscale or blank frame (the shading is read from three channels), a blown-out
/// reference, and a picture asked for under another format's name.
#[test]
fn read_refuses_a_greyscale_or_blank_frame_a_blown_out_reference_and_a_jpg_name() {
    let f = fixtures();
    let dir = tempfile::tempdir().unwrap();
    // A copy of the profile: one case asks to draw over its background.
    for name in ["fots-9.toml", "fots-9.background.png"] {
        std::fs::copy(f.join("profile").join(name), dir.path().join(name)).unwrap();
    }
    let profile = dir.path().join("fots-9.toml");
    let background = dir.path().join("fots-9.background.png");
    let frame = f.join("profile/fots-9.background.png");
    let grey = dir.path().join("grey.png");
    image::imageops::grayscale(&rgb(&frame))
        .save(&grey)
        .unwrap();
    let white = dir.path().join("white.png");
    let (w, h) = rgb(&frame).dimensions();
    RgbImage::from_pixel(w, h, image::Rgb([255, 255, 255]))
        .save(&white)
        .unwrap();
    // A blank frame read against the gel's reference once read as a 2-6 mm imprint.
    let blank = dir.path().join("blank.png");
    RgbImage::from_pixel(w, h, image::Rgb([140, 120, 100]))
        .save(&blank)
        .unwrap();
    let out_png = dir.path().join("view.png");
    let out_jpg = dir.path().join("view.jpg");
    let frame = frame.to_str().unwrap();
    for (argv, expect, out) in [
        (
            vec![grey.to_str().unwrap()],
            "grey.png: a greyscale image",
            &out_png,
        ),
        (
            vec![frame, "--reference", white.to_str().unwrap()],
            "--reference",
            &out_png,
        ),
        (
            vec![blank.to_str().unwrap()],
            "blank.png: featureless",
            &out_png,
        ),
        (vec![frame], "--out", &out_jpg),
        // The profile's background is the default reference: not to be drawn over.
        (vec![frame], "is an input", &background),
    ] {
        let mut full = vec!["read"];
        full.extend(argv);
        full.extend([
            "--sensor",
            profile.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ]);
        let run = tactex(&full);
        assert!(!run.status.success());
        let err = String::from_utf8_lossy(&run.stderr);
        assert_eq!(err.trim().lines().count(), 1, "{err}");
        assert!(err.contains(expect), "{err}");
        if out == &background {
            assert_eq!(
                rgb(&background),
                rgb(&f.join("profile/fots-9.background.png"))
            );
        } else {
            assert!(!out.exists(), "{err}");
        }
    }
}

/// Each of compare's flags carries its own help: the split's text once sat under --estimator.
#[test]
fn compare_help_puts_the_splits_text_under_split() {
    let out = tactex(&["compare", "--help"]);
    let help = String::from_utf8_lossy(&out.stdout);
    let estimator = help.find("--estimator").unwrap();
    let split = help.find("--split").unwrap();
    let text = help.find("Which presses to score").unwrap();
    assert!(estimator < split && split < text, "{help}");
}

/// A long ellipsoid (a banana's body, 180 x 36 mm) lying along the frame's rows makes a strip
/// that runs off both sides; pressed 3.8 mm off its ridge the strip nears one long edge and
/// presses it in. Zeroed on the border's median that edge pulled the imprint to 0.38 mm
/// against 0.57 on the ridge; zeroed on the lowest side of an unlevel border, 0.55 and 0.60.
#[test]
fn a_strip_running_off_the_frame_reads_as_deep_off_its_ridge_as_on_it() {
    let read_at = |at: &str| {
        let at = format!("--at-mm={at}");
        let flags = [
            "--shape",
            "ellipsoid",
            "--size-mm",
            "180,36,36",
            "--modulus-mpa",
            "0.8",
            "--depth-mm",
            "1.5",
            &at,
        ];
        press_and_read(&flags, None)
    };
    let (ridge, off) = (read_at("0,0"), read_at("0,-3.8"));
    // A contact crossing the frame has no round outline: its size is the half-depth
    // region's.
    assert_eq!(ridge["contact_edge"], "half_depth", "{ridge}");
    let depth = |r: &serde_json::Value| r["peak_depth_mm"].as_f64().unwrap();
    let (ridge, off) = (depth(&ridge), depth(&off));
    assert!(
        (off / ridge - 1.0).abs() < 0.15,
        "{off} mm off the ridge, {ridge} mm on it"
    );
}
