//! Recorded sessions end to end: `ask --record` on the twin, then `ask --backend replay`
//! from the recording gives the same answer, hardness and robot time; a replay that asks
//! for other moves, and broken sessions, are one-line errors.

use crate::cli::{one_line_error, tactex};
use serde_json::Value;
use std::path::Path;
use std::process::Output;

fn ok(out: &Output) -> &[u8] {
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    &out.stdout
}

fn record(dir: &Path, prompt: &str) -> Vec<u8> {
    let d = dir.to_str().unwrap();
    ok(&tactex(&[
        "ask",
        "--json",
        "--reproducible",
        "--record",
        d,
        prompt,
    ]))
    .to_vec()
}

fn replay(dir: &Path, prompt: &str) -> Output {
    let d = dir.to_str().unwrap();
    tactex(&[
        "ask",
        "--json",
        "--reproducible",
        "--backend",
        "replay",
        "--session",
        d,
        prompt,
    ])
}

#[test]
fn a_recorded_sim_run_replays_to_the_same_answer_hardness_and_robot_time() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("banana");
    let prompt = "How hard is the banana?";
    let recorded = record(&dir, prompt);
    let replayed = replay(&dir, prompt);
    // Byte for byte: answer, positions, hardness, evidence and robot time per stage.
    assert_eq!(
        String::from_utf8_lossy(ok(&replayed)),
        String::from_utf8_lossy(&recorded)
    );
    let answer: Value = serde_json::from_slice(&recorded).unwrap();
    assert!(
        answer["objects"][0]["hardness"]["modulus_mpa"]
            .as_f64()
            .unwrap()
            > 0.0
    );

    // The recording is whole: its manifest lists frames that exist, with arm poses.
    let manifest: Value =
        serde_json::from_slice(&std::fs::read(dir.join("manifest.json")).unwrap()).unwrap();
    assert_eq!(manifest["format"], "tactex-session/1");
    assert_eq!(manifest["prompt"], prompt);
    assert_eq!(manifest["answer"], answer);
    let rgbd = manifest["camera"]["frames"].as_array().unwrap();
    assert_eq!(rgbd.len(), 10, "the pipeline's depth median of 10 frames");
    let tactile = manifest["tactile"]["frames"].as_array().unwrap();
    assert!(
        tactile.len() >= 9,
        "a reference, the search and 8 press frames"
    );
    for f in tactile {
        assert!(dir.join(f["image"].as_str().unwrap()).is_file());
        assert!(f["arm_pose"]["position"].is_array());
    }
    let depth = image::open(dir.join(rgbd[0]["depth"].as_str().unwrap())).unwrap();
    assert!(matches!(depth, image::DynamicImage::ImageLuma16(_)));
    assert!(!tmp.path().join("banana.partial").exists());
}

#[test]
fn a_replay_asked_another_question_says_it_diverged() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("s");
    record(&dir, "How hard is the banana?");
    let stderr = one_line_error(&replay(&dir, "How hard is the avocado?"));
    assert!(stderr.contains("diverged"), "{stderr}");
    assert!(stderr.contains("replay arm"), "{stderr}");
}

#[test]
fn broken_or_missing_sessions_and_misused_flags_are_one_line_errors() {
    let tmp = tempfile::tempdir().unwrap();
    let p = "How hard is the banana?";
    let missing = tmp.path().join("none");
    let stderr = one_line_error(&replay(&missing, p));
    assert!(stderr.contains("no such session directory"), "{stderr}");

    let empty = tmp.path().join("empty");
    std::fs::create_dir(&empty).unwrap();
    let stderr = one_line_error(&replay(&empty, p));
    assert!(stderr.contains("manifest.json"), "{stderr}");

    let dir = tmp.path().join("s");
    record(&dir, p);
    // Recording over an existing directory is refused; nothing is overwritten.
    let out = tactex(&["ask", "--record", dir.to_str().unwrap(), p]);
    assert!(one_line_error(&out).contains("already exists"));

    let manifest = dir.join("manifest.json");
    let text = std::fs::read_to_string(&manifest).unwrap();
    std::fs::write(
        &manifest,
        text.replace("tactex-session/1", "tactex-session/9"),
    )
    .unwrap();
    let stderr = one_line_error(&replay(&dir, p));
    assert!(stderr.contains("manifest.json: format"), "{stderr}");
    // A camera no lens has is named as such, not found out later as a diverged replay.
    let mut m: Value = serde_json::from_str(&text).unwrap();
    m["camera"]["intrinsics"]["fx"] = (-600.0).into();
    std::fs::write(&manifest, serde_json::to_vec(&m).unwrap()).unwrap();
    let stderr = one_line_error(&replay(&dir, p));
    assert!(
        stderr.contains("manifest.json: camera.intrinsics") && stderr.contains("fx -600"),
        "{stderr}"
    );
    // A recorded sensor no device has, and a fidelity the twin does not know, are named
    // before anything is replayed (a scale of 0 sized the glow's blur in gigabytes).
    let mut m: Value = serde_json::from_str(&text).unwrap();
    m["tactile"]["spec"]["mm_per_px"] = 0.0.into();
    std::fs::write(&manifest, serde_json::to_vec(&m).unwrap()).unwrap();
    let stderr = one_line_error(&replay(&dir, p));
    assert!(
        stderr.contains("manifest.json: tactile.spec.mm_per_px: 0, expected"),
        "{stderr}"
    );
    let mut m: Value = serde_json::from_str(&text).unwrap();
    m["twin"]["fidelity"] = "warp".into();
    std::fs::write(&manifest, serde_json::to_vec(&m).unwrap()).unwrap();
    let stderr = one_line_error(&replay(&dir, p));
    assert!(
        stderr.contains("manifest.json: twin.fidelity: unknown fidelity \"warp\""),
        "{stderr}"
    );
    // A session's own scene text with a mistake is the session's error, not the demo's.
    let mut m: Value = serde_json::from_str(&text).unwrap();
    let toml = m["twin"]["scene_toml"]
        .as_str()
        .unwrap()
        .replacen("position_m", "positionx_m", 1);
    m["twin"]["scene_toml"] = toml.into();
    std::fs::write(&manifest, serde_json::to_vec(&m).unwrap()).unwrap();
    let stderr = one_line_error(&compare_session(&dir, &[]));
    assert!(
        stderr.contains("manifest.json: twin.scene_toml (the scene recorded from")
            && stderr.contains("positionx_m"),
        "{stderr}"
    );
    std::fs::write(&manifest, &text).unwrap();
    std::fs::remove_file(dir.join("tactile/0003.png")).unwrap();
    let stderr = one_line_error(&replay(&dir, p));
    assert!(stderr.contains("tactile/0003.png"), "{stderr}");
    assert!(stderr.contains("missing"), "{stderr}");
    // A frame that is not an image, or not the sensor's size, is named before the replay
    // starts (found halfway, it showed as the arm diverging from the recording).
    std::fs::write(dir.join("tactile/0003.png"), "not a png").unwrap();
    let stderr = one_line_error(&replay(&dir, p));
    assert!(
        stderr.contains("tactile/0003.png: not a readable frame") && !stderr.contains("diverged"),
        "{stderr}"
    );
    image::RgbImage::new(8, 6)
        .save(dir.join("tactile/0003.png"))
        .unwrap();
    let stderr = one_line_error(&replay(&dir, p));
    assert!(
        stderr.contains("tactile/0003.png: 8x6 px, the sensor gives"),
        "{stderr}"
    );
    // A file given where the session folder belongs says so.
    let stderr = one_line_error(&replay(&manifest, p));
    assert!(stderr.contains("not a folder"), "{stderr}");

    let out = tactex(&["ask", "--backend", "replay", p]);
    assert!(one_line_error(&out).contains("--session"));
    let out = tactex(&["ask", "--session", dir.to_str().unwrap(), p]);
    assert!(one_line_error(&out).contains("--backend replay"));
    // A scene beside a replay would be ignored: it is refused instead.
    let d = dir.to_str().unwrap();
    let out = tactex(&[
        "ask",
        "--backend",
        "replay",
        "--session",
        d,
        "--scene",
        "x.toml",
        p,
    ]);
    assert!(one_line_error(&out).contains("--scene: only with --backend sim"));
    // The frames were rendered at the session's fidelity: another one is refused, not
    // reported as the session's while its intervals are another's.
    let out = tactex(&[
        "ask",
        "--backend",
        "replay",
        "--session",
        d,
        "--fidelity",
        "rigid",
        p,
    ]);
    let stderr = one_line_error(&out);
    assert!(
        stderr.contains("--fidelity rigid: a replay reads the frames its session recorded"),
        "{stderr}"
    );
}

fn compare_session(dir: &Path, extra: &[&str]) -> Output {
    let mut args = vec!["compare", "--json", "--session", dir.to_str().unwrap()];
    args.extend_from_slice(extra);
    tactex(&args)
}

fn press_frames(report: &Value) -> Vec<&Value> {
    report["presses"]
        .as_array()
        .unwrap()
        .iter()
        .flat_map(|p| p["frames"].as_array().unwrap()[1..].iter())
        .collect()
}

#[test]
fn compare_session_rebuilds_a_sim_recording_exactly() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("banana");
    record(&dir, "How hard is the banana?");
    let report: Value = serde_json::from_slice(ok(&compare_session(&dir, &[]))).unwrap();
    let presses = report["presses"].as_array().unwrap();
    assert_eq!(presses.len(), 1, "{report:#}");
    assert_eq!(presses[0]["object"], "banana");
    let frames = press_frames(&report);
    assert_eq!(frames.len(), 8, "the pipeline's 8 press frames");
    // Same scene, pose, seed and frame order: the twin gives back the very frames.
    for f in &frames {
        assert_eq!(f["ssim"].as_f64().unwrap(), 1.0, "{f}");
        assert_eq!(f["marker_error_px"].as_f64().unwrap(), 0.0, "{f}");
    }
    assert!(
        frames.last().unwrap()["recorded_marker_px"]
            .as_f64()
            .unwrap()
            > 1.0
    );
    assert_eq!(report["all_frames_mean_ssim"].as_f64().unwrap(), 1.0);
    assert_eq!(report["max_shore_a_difference"].as_f64().unwrap(), 0.0);
    assert_eq!(
        presses[0]["hardness"]["modulus_ratio"].as_f64().unwrap(),
        1.0
    );

    // A session without its scene (as a real one) needs --scene, and says so.
    let manifest = dir.join("manifest.json");
    let mut m: Value = serde_json::from_slice(&std::fs::read(&manifest).unwrap()).unwrap();
    m.as_object_mut().unwrap().remove("twin");
    m["backend"] = "hw".into();
    std::fs::write(&manifest, serde_json::to_vec_pretty(&m).unwrap()).unwrap();
    let stderr = one_line_error(&compare_session(&dir, &[]));
    assert!(stderr.contains("manifest.json: twin"), "{stderr}");
    assert!(stderr.contains("--scene"), "{stderr}");
    let report: Value =
        serde_json::from_slice(ok(&compare_session(&dir, &["--scene", "scenes/demo.toml"])))
            .unwrap();
    assert_eq!(report["mean_ssim"].as_f64().unwrap(), 1.0);

    let stderr = one_line_error(&compare_session(&tmp.path().join("none"), &[]));
    assert!(stderr.contains("no such session directory"), "{stderr}");
}

#[test]
fn compare_session_sees_a_recording_made_with_a_softer_gel() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("soft-gel");
    let prompt = "How hard is the banana?";
    ok(&tactex(&[
        "ask",
        "--reproducible",
        "--gel-modulus-mpa",
        "0.15",
        "--record",
        dir.to_str().unwrap(),
        prompt,
    ]));
    let report: Value = serde_json::from_slice(ok(&compare_session(&dir, &[]))).unwrap();
    assert_eq!(report["recorded_gel_modulus_mpa"].as_f64().unwrap(), 0.15);
    assert_eq!(report["twin_gel_modulus_mpa"].as_f64().unwrap(), 0.3);
    let frames = press_frames(&report);
    assert!(!frames.is_empty(), "{report:#}");
    // The softer gel takes more of the travel: a deeper imprint than the twin's.
    let min_ssim = report["min_ssim"].as_f64().unwrap();
    assert!(min_ssim < 0.99, "{min_ssim}");
    let marker_error = report["mean_marker_error_px"].as_f64().unwrap();
    assert!(marker_error > 0.2, "{marker_error}");
    // Read with the twin's 0.3 MPa gel, the recorded press puts the object's compliance
    // share on a gel twice as stiff as the one that took it: Hertz's split
    // (1/E*_gel) / (1/E*_gel + 1/E*_object), equal in both, gives the object twice the
    // modulus (0.3 / 0.15).
    let h = &report["presses"][0]["hardness"];
    let ratio = h["modulus_ratio"].as_f64().unwrap();
    assert!((ratio - 2.0).abs() < 0.1, "{h}");
    assert!(h["shore_a_difference"].as_f64().unwrap() > 0.0, "{h}");

    // The same twin with the recording's gel rebuilds it exactly.
    let report: Value =
        serde_json::from_slice(ok(&compare_session(&dir, &["--gel-modulus-mpa", "0.15"]))).unwrap();
    assert_eq!(report["mean_ssim"].as_f64().unwrap(), 1.0);
}

#[test]
fn two_recordings_into_one_directory_one_wins_and_the_session_is_whole() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("s");
    let spawn = || {
        std::process::Command::new(env!("CARGO_BIN_EXE_tactex"))
            .args(["ask", "--json", "--record", dir.to_str().unwrap()])
            .arg("Which fruit is the softest?")
            .current_dir(env!("CARGO_MANIFEST_DIR"))
            .env("XDG_RUNTIME_DIR", std::env::temp_dir())
            .stdout(std::process::Stdio::piped())
            .stderr(std::process::Stdio::piped())
            .spawn()
            .expect("runs tactex")
    };
    let (a, b) = (spawn(), spawn());
    let outs = [a.wait_with_output().unwrap(), b.wait_with_output().unwrap()];
    let won: Vec<&Output> = outs.iter().filter(|o| o.status.success()).collect();
    assert_eq!(won.len(), 1, "exactly one recording wins");
    let lost = outs.iter().find(|o| !o.status.success()).unwrap();
    let stderr = one_line_error(lost);
    assert!(
        stderr.contains("recording a session here") || stderr.contains("already exists"),
        "{stderr}"
    );
    // Whole: every frame listed exists, and no frame exists that is not listed.
    let manifest: Value =
        serde_json::from_slice(&std::fs::read(dir.join("manifest.json")).unwrap()).unwrap();
    let listed = manifest["tactile"]["frames"].as_array().unwrap();
    for f in listed {
        assert!(dir.join(f["image"].as_str().unwrap()).is_file());
    }
    let on_disk = std::fs::read_dir(dir.join("tactile")).unwrap().count();
    assert_eq!(on_disk, listed.len());
    assert!(!dir.join("tactex.pid").exists());
    assert!(!tmp.path().join("s.partial").exists());
}
