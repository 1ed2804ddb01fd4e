//! Recorded sessions end to end: `ask --record` on the twin, then `ask --backend replay`
//! from the recording gives the same answer, hardness and robot time; a replay that asks
//! for other moves, and broken sessions, are one-line errors.

use serde_json::Value;
use std::path::Path;
use std::process::{Command, Output};

fn tactex(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_tactex"))
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("runs tactex")
}

fn ok(out: &Output) -> &[u8] {
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    &out.stdout
}

fn one_line_error(out: &Output) -> String {
    assert_eq!(
        out.status.code(),
        Some(1),
        "{}",
        String::from_utf8_lossy(&out.stdout)
    );
    let stderr = String::from_utf8_lossy(&out.stderr).to_string();
    assert_eq!(stderr.trim().lines().count(), 1, "{stderr}");
    assert!(out.stdout.is_empty());
    stderr
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
    std::fs::write(&manifest, &text).unwrap();
    std::fs::remove_file(dir.join("tactile/0003.png")).unwrap();
    let stderr = one_line_error(&replay(&dir, p));
    assert!(stderr.contains("tactile/0003.png"), "{stderr}");
    assert!(stderr.contains("missing"), "{stderr}");

    let out = tactex(&["ask", "--backend", "replay", p]);
    assert!(one_line_error(&out).contains("--session"));
    let out = tactex(&["ask", "--session", dir.to_str().unwrap(), p]);
    assert!(one_line_error(&out).contains("--backend replay"));
}
