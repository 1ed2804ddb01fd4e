//! `tactex eval hardness`, `eval ripeness`, `eval grounding`, `eval scenarios`, `eval fruits`
//! and `eval explanations` end to end on small runs: their JSON contracts, plots and raw records, tests
//! that recompute from the raw predictions, and bad input named.

use crate::cli::tactex;
use std::process::Command;

/// `tactex eval ARGS --json --out DIR` into a fresh DIR: the directory and stdout's JSON.
fn eval_json(args: &[&str]) -> (tempfile::TempDir, serde_json::Value) {
    let dir = tempfile::tempdir().unwrap();
    let mut all = vec!["eval"];
    all.extend(args);
    all.extend(["--json", "--out", dir.path().to_str().unwrap()]);
    let o = tactex(&all);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v = serde_json::from_slice(&o.stdout).expect("one JSON object on stdout");
    (dir, v)
}

/// Each bad argument of `eval <command>` fails with a one-line error naming it.
fn bad_arguments_are_named(command: &str, cases: &[(&[&str], &str)]) {
    for (args, needle) in cases {
        let mut all = vec!["eval", command];
        all.extend(args.iter());
        let o = tactex(&all);
        assert!(!o.status.success(), "{all:?}");
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(err.contains(needle), "{err}");
        assert_eq!(err.trim().lines().count(), 1, "one line: {err}");
    }
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
        "--frames",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let report: serde_json::Value = serde_json::from_slice(&o.stdout).expect("JSON on stdout");
    let estimators = report["estimators"].as_array().unwrap();
    let names: Vec<&str> = estimators
        .iter()
        .map(|e| e["name"].as_str().unwrap())
        .collect();
    assert_eq!(names, ["hertz_slopes", "indentation", "onnx_small"]);
    for e in estimators {
        let n = e["n"].as_u64().unwrap();
        assert_eq!(n + e["failures"].as_u64().unwrap(), 4);
        // A press an estimator cannot stand behind (hertz_slopes: the gel took nearly all
        // the travel) is refused, and scores need three presses.
        for field in ["rmse", "r2", "spearman"] {
            match n >= 3 {
                true => assert!(e[field].as_f64().unwrap().is_finite(), "{field}"),
                false => assert!(e[field].is_null(), "{field} of {n} presses"),
            }
        }
    }
    assert_eq!(estimators[1]["n"], 4, "indentation measures every sphere");
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
    let learned = &first["predictions"][2]["evidence"];
    assert_eq!(learned["kind"], "learned");
    assert_eq!(learned["backend"], "tract");
    // Every frame's reading beside the solver's gel: on the stock Mini a sphere's frames
    // within the frame read their peak (over the border's share) and contact radius within
    // a fifth of the solver's, the median within a tenth.
    let frames: Vec<serde_json::Value> = std::fs::read_to_string(out.join("frames.jsonl"))
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert_eq!(frames.len(), 4 * 8);
    let f = |v: &serde_json::Value, k: &str| v[k].as_f64().unwrap();
    let within: Vec<&serde_json::Value> = frames
        .iter()
        .filter(|v| v["within_frame"] == true)
        .collect();
    assert!(within.len() >= 16, "{} of 32 frames within", within.len());
    let median_error = |read: &dyn Fn(&serde_json::Value) -> f64, truth: &str| {
        let mut e: Vec<f64> = within
            .iter()
            .map(|v| (read(v) / f(v, truth) - 1.0).abs())
            .collect();
        e.sort_by(f64::total_cmp);
        assert!(e[e.len() * 9 / 10] < 0.2, "{truth}: {e:?}");
        e[e.len() / 2]
    };
    let peak = median_error(
        &|v| f(v, "read_peak_mm") / f(v, "border_share"),
        "gel_peak_mm",
    );
    let radius = median_error(&|v| f(v, "read_contact_radius_mm"), "contact_radius_mm");
    assert!(
        peak < 0.1 && radius < 0.1,
        "median errors: peak {peak}, radius {radius}"
    );
}

#[test]
#[cfg_attr(
    not(ci),
    ignore = "needs libonnxruntime.so from PyPI's wheel in TACTEX_TEST_ORT_DYLIB, as .ci/run installs"
)]
fn the_trained_model_answers_alike_on_tract_and_onnx_runtime() {
    let library = match std::env::var("TACTEX_TEST_ORT_DYLIB") {
        Ok(p) if !p.is_empty() => p,
        _ => panic!("TACTEX_TEST_ORT_DYLIB must name libonnxruntime.so (see .ci/run)"),
    };
    let args = [
        "eval", "hardness", "--count", "3", "--shapes", "sphere", "--json",
    ];
    let runs: Vec<Vec<serde_json::Value>> = [None, Some(library.as_str())]
        .iter()
        .map(|lib| {
            let mut cmd = Command::new(env!("CARGO_BIN_EXE_tactex"));
            cmd.args(args).env_remove("ORT_DYLIB_PATH");
            let dir = tempfile::tempdir().unwrap();
            cmd.args(["--out", dir.path().to_str().unwrap()]);
            if let Some(lib) = lib {
                cmd.env("ORT_DYLIB_PATH", lib);
            }
            let o = cmd.output().unwrap();
            assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
            let lines = std::fs::read_to_string(dir.path().join("predictions.jsonl")).unwrap();
            lines
                .lines()
                .map(|l| serde_json::from_str::<serde_json::Value>(l).unwrap())
                .collect()
        })
        .collect();
    let (tract, ort) = (&runs[0], &runs[1]);
    assert_eq!(tract.len(), 3);
    for (a, b) in tract.iter().zip(ort) {
        let (pa, pb) = (&a["predictions"][2], &b["predictions"][2]);
        assert_eq!(pa["evidence"]["backend"], "tract");
        assert!(
            pb["evidence"]["backend"]
                .as_str()
                .unwrap()
                .starts_with("onnxruntime 1."),
            "{pb}"
        );
        let (sa, sb) = (
            pa["shore_a"].as_f64().unwrap(),
            pb["shore_a"].as_f64().unwrap(),
        );
        assert!(
            (sa - sb).abs() < 0.05,
            "Shore A {sa} (tract) vs {sb} (onnxruntime)"
        );
    }
}

#[test]
fn stages_are_told_apart_and_each_test_recomputes_from_the_predictions() {
    // Through a profile file (the built-in one renamed): the report names the sensor.
    let profiles = tempfile::tempdir().unwrap();
    let profile = crate::cli::renamed_stock_profile(profiles.path(), "lab mini");
    let (dir, r) = eval_json(&[
        "ripeness",
        "--fruits",
        "lime",
        "--presses",
        "4",
        "--sensor",
        profile.to_str().unwrap(),
    ]);
    assert_eq!(r["estimator"], "indentation");
    assert_eq!(r["sensor"]["name"], "lab mini");
    assert_eq!(r["sensor"]["sha256"].as_str().unwrap().len(), 64);
    let lime = &r["fruits"][0];
    assert_eq!(lime["fruit"], "lime");
    let stages = lime["stages"].as_array().unwrap();
    assert_eq!(stages.len(), 2);
    let values = |k: usize| -> Vec<f64> {
        stages[k]["predictions"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap())
            .collect()
    };
    let (unripe, ripe) = (values(0), values(1));
    assert_eq!(unripe.len() + ripe.len(), 8);
    for s in stages {
        let (q25, med, q75) = (
            s["q25"].as_f64().unwrap(),
            s["median"].as_f64().unwrap(),
            s["q75"].as_f64().unwrap(),
        );
        assert!(q25 <= med && med <= q75);
    }
    // U of the harder stage: pairs where it reads harder, ties counting a half.
    let u: f64 = unripe
        .iter()
        .flat_map(|a| ripe.iter().map(move |b| (a, b)))
        .map(|(a, b)| match a.total_cmp(b) {
            std::cmp::Ordering::Greater => 1.0,
            std::cmp::Ordering::Equal => 0.5,
            std::cmp::Ordering::Less => 0.0,
        })
        .sum();
    let test = &lime["tests"][0];
    assert_eq!(test["harder"], "unripe");
    assert_eq!(test["softer"], "ripe");
    assert_eq!(test["u"].as_f64().unwrap(), u);
    // Unripe lime (4 MPa) reads harder than ripe (1.5 MPa) in every press: the exact
    // one-sided p of complete separation of 4 and 4 is 1 / C(8, 4).
    assert_eq!(u, 16.0);
    assert!((test["p"].as_f64().unwrap() - 1.0 / 70.0).abs() < 1e-12);
    assert!(dir.path().join("ripeness.png").is_file());
    assert!(dir.path().join("ripeness.json").is_file());
}

#[test]
fn bad_hardness_arguments_are_named() {
    bad_arguments_are_named(
        "hardness",
        &[
            (&["--count", "2"], "--count"),
            (&["--shapes", "cube"], "--shapes"),
            (&["--fidelity", "exact"], "--fidelity"),
            (&["--frames"], "--out"),
            (&["--model", "no-such-model.onnx"], "no-such-model.json"),
        ],
    );
}

#[test]
fn bad_grounding_arguments_are_named() {
    bad_arguments_are_named(
        "grounding",
        &[
            (&["--tolerance-mm", "NaN"], "--tolerance-mm"),
            (&["--tolerance-mm", "-5"], "--tolerance-mm"),
            (&["--tolerance-mm", "1e300"], "--tolerance-mm"),
            (&["--depth-frames", "0"], "--depth-frames"),
            (&["--depth-frames", "100000"], "--depth-frames"),
            (&["--per-kind", "0"], "--per-kind"),
            (&["--per-kind", "1000000"], "--per-kind"),
        ],
    );
}

#[test]
fn bad_ripeness_arguments_are_named() {
    bad_arguments_are_named(
        "ripeness",
        &[
            (&["--fruits", "durian"], "--fruits"),
            (&["--presses", "1"], "--presses"),
            (&["--spot-spread", "-1"], "--spot-spread"),
        ],
    );
    // clap's own refusal of an unknown value names the option too, over several lines.
    let o = tactex(&["eval", "ripeness", "--estimator", "guess"]);
    assert!(!o.status.success());
    assert!(String::from_utf8_lossy(&o.stderr).contains("--estimator"));
}

#[test]
fn grounding_on_the_noisy_twin_finds_each_fruit_and_its_centroid() {
    let (dir, v) = eval_json(&["grounding", "--per-kind", "1", "--depth-frames", "5"]);
    let detectors = v["detectors"].as_array().unwrap();
    assert_eq!(detectors.len(), 3);
    let classical = &detectors[0];
    assert_eq!(classical["name"], "classical");
    assert_eq!(classical["instances"], 10);
    // Every fruit of the ten kinds is found and hovered over, with a mask close to the truth
    // and a centroid within the paper's 5 mm tolerance.
    assert_eq!(classical["success_rate"], 1.0);
    assert!(
        classical["iou_median"].as_f64().unwrap() >= 0.93,
        "{classical}"
    );
    assert!(
        classical["centroid_error_mm_mean"].as_f64().unwrap() <= 3.0,
        "{classical}"
    );
    for d in detectors {
        for key in ["confidence_mean", "iou_mean", "centroid_error_mm_raw_mean"] {
            assert!(d[key].is_number(), "{key} in {d}");
        }
    }
    // The YOLO error profile's masks are shifted and ragged: lower IoU than the classical.
    assert!(
        detectors[2]["iou_median"].as_f64().unwrap() < classical["iou_median"].as_f64().unwrap()
    );
    let tests = v["tests"].as_array().unwrap();
    assert!(tests.iter().any(|t| {
        t["name"]
            .as_str()
            .unwrap()
            .starts_with("Welch t: centroid error classical vs error-gsam")
    }));
    for t in tests {
        let p = t["p"].as_f64().unwrap();
        assert!((0.0..=1.0).contains(&p), "{t}");
    }
    for f in ["results.json", "table.md", "centroid_error.png", "iou.png"] {
        assert!(dir.path().join(f).is_file(), "{f} missing");
    }
    bad_arguments_are_named(
        "grounding",
        &[(
            &["--detector", "sam9"],
            "--detector: unknown detector 'sam9'",
        )],
    );
}

#[test]
fn scenarios_score_every_tier_end_to_end_with_plots() {
    let (dir, v) = eval_json(&["scenarios", "--runs", "1", "--detector", "classical"]);
    let detectors = v["detectors"].as_array().unwrap();
    assert_eq!(detectors.len(), 1);
    assert_eq!(detectors[0]["name"], "classical");
    let tiers = detectors[0]["tiers"].as_array().unwrap();
    assert_eq!(tiers.len(), 4);
    let runs: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.path().join("runs.json")).unwrap()).unwrap();
    let runs = runs.as_array().unwrap();
    assert_eq!(runs.len(), 4);
    for (t, tier) in tiers.iter().enumerate() {
        assert_eq!(tier["tier"], t as u64 + 1);
        assert_eq!(tier["runs"], 1);
        // The rates recompute from the raw records.
        let run = &runs[t];
        let ol = run["object_successes"].as_f64().unwrap() / run["asked"].as_f64().unwrap();
        assert!(
            (tier["ol_sr"].as_f64().unwrap() - ol).abs() < 1e-12,
            "{tier}"
        );
        let sl = if run["scenario_success"].as_bool().unwrap() {
            1.0
        } else {
            0.0
        };
        assert_eq!(tier["sl_sr"].as_f64().unwrap(), sl, "{tier}");
        // The classical detector on the noisy twin gets the paper's simple tiers right.
        if t < 3 {
            assert_eq!(sl, 1.0, "tier {}: {run}", t + 1);
        }
        let stages: Vec<&str> = tier["latency"]
            .as_array()
            .unwrap()
            .iter()
            .map(|l| l["stage"].as_str().unwrap())
            .collect();
        assert_eq!(stages, ["parse", "ground", "press", "hardness", "explain"]);
        let press = &tier["latency"][2];
        assert!(
            press["sim_s"].as_f64().unwrap() > 1.0,
            "pressing takes robot time"
        );
    }
    for png in [
        "object_success.png",
        "scenario_success.png",
        "latency_wall.png",
        "latency_robot.png",
    ] {
        let bytes = std::fs::read(dir.path().join(png)).unwrap();
        assert!(bytes.starts_with(b"\x89PNG"), "{png}");
    }
    bad_arguments_are_named(
        "scenarios",
        &[
            (&["--runs", "0"], "--runs"),
            (&["--tiers", "5"], "--tiers"),
            (&["--detector", "sonar"], "sonar"),
        ],
    );
}

#[test]
fn explanations_of_the_template_are_accurate_and_complete_on_every_prompt_kind() {
    let (dir, v) = eval_json(&["explanations", "--prompts", "100"]);
    assert_eq!(v["explainer"], "template");
    assert_eq!(v["prompts"], 100);
    assert_eq!(v["accuracy"], 1.0, "{v}");
    assert_eq!(v["completeness"], 1.0, "{v}");
    assert_eq!(v["categories"].as_array().unwrap().len(), 6);
    let cases: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.path().join("cases.json")).unwrap()).unwrap();
    let cases = cases.as_array().unwrap();
    assert_eq!(cases.len(), 100);
    // Some prompts ask for a fruit that is not there, and the answers say so.
    let absent = cases
        .iter()
        .filter(|c| c["answer"].as_str().unwrap().contains("could not find"))
        .count();
    assert!(absent >= 5, "{absent}");
    let png = std::fs::read(dir.path().join("scores.png")).unwrap();
    assert_eq!(&png[1..4], b"PNG");
    bad_arguments_are_named(
        "explanations",
        &[(&["--prompts", "0"], "0 is outside [1, 100000]")],
    );
}

#[test]
fn fruits_scores_each_kind_and_writes_tables_that_ask_answers_again() {
    let (dir, v) = eval_json(&[
        "fruits",
        "--placements",
        "2",
        "--crowded",
        "0",
        "--kinds",
        "strawberry,lime",
    ]);
    let kinds = v["kinds"].as_array().unwrap();
    assert_eq!(kinds.len(), 2, "{v}");
    for k in kinds {
        assert_eq!(k["fruits"], 2, "{k}");
        assert_eq!(k["located_and_measured"], 1.0, "{k}");
        // Catalog fruit read by the calibrated default estimator: within 0.5 in ln E.
        assert!(k["worst_abs_ln_error"].as_f64().unwrap() < 0.5, "{k}");
    }
    assert!(
        v["intervals"]
            .as_str()
            .unwrap()
            .contains("indentation-layer.json"),
        "{v}"
    );
    let rows: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.path().join("fruits.json")).unwrap()).unwrap();
    let first = &rows[0];
    for png in ["ln_error.png", "coverage.png", "estimate_vs_true.png"] {
        assert!(dir.path().join(png).is_file(), "{png}");
    }
    // The written table is a scene file `ask` answers with the same estimate.
    let scene = dir.path().join("scenes/table-0.toml");
    let seed = first["seed"].as_u64().unwrap().to_string();
    let o = tactex(&[
        "ask",
        "--json",
        "--reproducible",
        "--scene",
        scene.to_str().unwrap(),
        "--seed",
        &seed,
        "Describe the hardness of all the fruits.",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let a: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let e = a["objects"][0]["hardness"]["modulus_mpa"].as_f64().unwrap();
    assert!(
        (e - first["estimate_mpa"].as_f64().unwrap()).abs() < 1e-9,
        "{a}"
    );

    // Through a calibrated profile: tables are pressed in parallel while each press is read
    // on a thread of its own (this once deadlocked), and the shipped intervals, measured
    // through the built-in Mini, are not applied.
    let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_tactex"))
        .args([
            "eval",
            "fruits",
            "--placements",
            "1",
            "--crowded",
            "0",
            "--kinds",
            "strawberry,lime",
            "--sensor",
            "tests/fixtures/fots/profile/fots-9.toml",
            "--json",
        ])
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    let start = std::time::Instant::now();
    while child.try_wait().unwrap().is_none() {
        if start.elapsed() > std::time::Duration::from_secs(600) {
            child.kill().unwrap();
            panic!("eval fruits through a profile did not finish in 10 minutes");
        }
        std::thread::sleep(std::time::Duration::from_millis(200));
    }
    let o = child.wait_with_output().unwrap();
    assert!(o.status.success());
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert!(
        v["intervals"]
            .as_str()
            .unwrap()
            .contains("none is shipped for it through fots-9")
            && v["intervals"]
                .as_str()
                .unwrap()
                .contains("measured through the built-in GelSight Mini"),
        "{v}"
    );

    bad_arguments_are_named(
        "fruits",
        &[
            (&["--kinds", "durian"], "--kinds: no fruit \"durian\""),
            (
                &[
                    "--placements",
                    "1",
                    "--crowded",
                    "0",
                    "--kinds",
                    "lime",
                    "--calibrate",
                    "c.json",
                ],
                "at least 40",
            ),
            (
                &["--placements", "0", "--crowded", "0"],
                "--placements, --crowded",
            ),
        ],
    );
}
