//! `tactex eval hardness` end to end on a few presses: the JSON contract, the plot and the
//! per-press records, and its bad-input errors.

use std::process::Command;

fn tactex(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_tactex"))
        .args(args)
        .env("XDG_RUNTIME_DIR", std::env::temp_dir())
        .output()
        .expect("tactex runs")
}

#[test]
fn scores_each_estimator_and_draws_predicted_against_true() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("eval");
    let o = tactex(&[
        "eval",
        "hardness",
        "--count",
        "4",
        "--shapes",
        "sphere",
        "--json",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let report: serde_json::Value = serde_json::from_slice(&o.stdout).expect("JSON on stdout");
    let estimators = report["estimators"].as_array().unwrap();
    let names: Vec<&str> = estimators
        .iter()
        .map(|e| e["name"].as_str().unwrap())
        .collect();
    assert_eq!(names, ["hertz_slopes", "indentation"]);
    for e in estimators {
        assert_eq!(
            e["n"].as_u64().unwrap() + e["failures"].as_u64().unwrap(),
            4
        );
        for field in ["rmse", "r2", "spearman"] {
            assert!(e[field].as_f64().unwrap().is_finite(), "{field}");
        }
    }
    let png = image::open(out.join("hardness.png")).expect("a PNG plot");
    assert!(png.width() > 400 && png.height() > 400);
    let lines = std::fs::read_to_string(out.join("predictions.jsonl")).unwrap();
    assert_eq!(lines.lines().count(), 4);
    let first: serde_json::Value = serde_json::from_str(lines.lines().next().unwrap()).unwrap();
    assert!(first["true_shore_a"].as_f64().unwrap() >= 5.0);
    assert!(
        first["predictions"][1]["evidence"]["gel_layer_factor"]
            .as_f64()
            .unwrap()
            < 1.0
    );
}

#[test]
fn bad_arguments_are_named() {
    for (args, needle) in [
        (vec!["--count", "2"], "--count"),
        (vec!["--shapes", "cube"], "--shapes"),
        (vec!["--fidelity", "exact"], "--fidelity"),
    ] {
        let mut all = vec!["eval", "hardness"];
        all.extend(args);
        let o = tactex(&all);
        assert!(!o.status.success());
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(err.contains(needle), "{err}");
        assert_eq!(err.trim().lines().count(), 1, "one line: {err}");
    }
}
