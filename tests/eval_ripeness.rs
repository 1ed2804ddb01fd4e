//! `tactex eval ripeness` end to end on a small run: the JSON contract, tests that can be
//! recomputed from the raw predictions, and bad input named.

use std::process::Command;

fn tactex(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_tactex"))
        .args(args)
        .env("XDG_RUNTIME_DIR", std::env::temp_dir())
        .output()
        .expect("tactex runs")
}

#[test]
fn stages_are_told_apart_and_each_test_recomputes_from_the_predictions() {
    let dir = tempfile::tempdir().unwrap();
    let o = tactex(&[
        "eval",
        "ripeness",
        "--fruits",
        "lime",
        "--presses",
        "4",
        "--json",
        "--out",
        dir.path().to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let r: serde_json::Value = serde_json::from_slice(&o.stdout).expect("JSON on stdout");
    assert_eq!(r["estimator"], "indentation");
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
fn bad_arguments_are_named() {
    for (args, needle) in [
        (vec!["--fruits", "durian"], "--fruits"),
        (vec!["--presses", "1"], "--presses"),
        (vec!["--spot-spread", "-1"], "--spot-spread"),
        (vec!["--estimator", "guess"], "--estimator"),
    ] {
        let mut all = vec!["eval", "ripeness"];
        all.extend(args);
        let o = tactex(&all);
        assert!(!o.status.success());
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(err.contains(needle), "{err}");
    }
}
