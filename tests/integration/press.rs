//! `tactex press` and `tactex bench contact` from the command line: the JSON contract, the
//! maps on disk, and clear one-line errors for bad input.

use crate::cli::{json, tactex};
use std::process::Command;

#[test]
fn press_reports_the_documented_fields_and_softer_means_less_force() {
    let mut forces = Vec::new();
    for hardness in ["20 00", "60 00", "30A", "rigid"] {
        let v = json(&tactex(&[
            "press",
            "--shape",
            "sphere",
            "--radius-mm",
            "10",
            "--hardness",
            hardness,
            "--depth-mm",
            "1",
            "--json",
        ]));
        for field in [
            "force_n",
            "contact_radius_mm",
            "contact_area_mm2",
            "max_pressure_mpa",
            "gel_max_indentation_mm",
            "object_max_indentation_mm",
            "gel_modulus_mpa",
            "gel_poisson",
            "object_modulus_mpa",
            "object_poisson",
            "iterations",
            "residual",
            "warnings",
        ] {
            assert!(v.get(field).is_some(), "{field} missing: {v}");
        }
        assert_eq!(v["fidelity"], "layer");
        forces.push(v["force_n"].as_f64().unwrap());
        if hardness == "rigid" {
            assert!(v["object_modulus_mpa"].is_null());
            assert_eq!(v["object_max_indentation_mm"], 0.0);
        }
    }
    assert!(forces.windows(2).all(|w| w[0] < w[1]), "{forces:?}");
}

#[test]
fn press_writes_maps_with_their_scale() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("maps");
    let v = json(&tactex(&[
        "press",
        "--shape",
        "ellipsoid",
        "--size-mm",
        "30,20,25",
        "--modulus-mpa",
        "0.8",
        "--depth-mm",
        "0.75",
        "--fidelity",
        "halfspace",
        "--json",
        "--out",
        out.to_str().unwrap(),
    ]));
    assert!(v["force_n"].as_f64().unwrap() > 0.0);
    let sidecar: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("maps.json")).unwrap()).unwrap();
    for map in sidecar["maps"].as_array().unwrap() {
        let file = out.join(map["file"].as_str().unwrap());
        let image = image::open(&file).unwrap();
        assert_eq!(image.color(), image::ColorType::L16, "{}", file.display());
        assert_eq!(image.width() as u64, map["grid"]["nx"].as_u64().unwrap());
    }
    // The brightest gel pixel is the deepest indentation.
    let normal = image::open(out.join("gel_normal.png"))
        .unwrap()
        .into_luma16();
    let entry = &sidecar["maps"][0];
    let top = *normal.as_raw().iter().max().unwrap() as f64;
    let deepest = entry["offset"].as_f64().unwrap() + top * entry["scale"].as_f64().unwrap();
    let reported = v["gel_max_indentation_mm"].as_f64().unwrap();
    assert!((deepest - reported).abs() < 1e-3, "{deepest} vs {reported}");
    // The rendered GelSight Mini frame: 320 x 240 RGB, the imprint at the pad's centre.
    let tactile = image::open(out.join("tactile.png")).unwrap().into_rgb8();
    assert_eq!(tactile.dimensions(), (320, 240));
}

#[test]
fn the_contact_circle_seen_in_a_rendered_press_is_the_solvers() {
    // The twin's frame (markers, noise) read back by `tactex contact` against the no-contact
    // frame `press --out` writes: the contact radius the solver found, from the image alone.
    for (radius_mm, hardness, depth_mm) in [("5", "40A", "1"), ("3", "70A", "0.5")] {
        let dir = tempfile::tempdir().unwrap();
        let v = json(&tactex(&[
            "press",
            "--shape",
            "sphere",
            "--radius-mm",
            radius_mm,
            "--hardness",
            hardness,
            "--depth-mm",
            depth_mm,
            "--device",
            "cpu",
            "--json",
            "--out",
            dir.path().to_str().unwrap(),
        ]));
        let seen = json(&tactex(&[
            "contact",
            dir.path().join("tactile.png").to_str().unwrap(),
            "--reference",
            dir.path().join("reference.png").to_str().unwrap(),
            "--mm-per-px",
            "0.0634",
            "--json",
        ]));
        assert_eq!(seen["evidence"]["contact"], true, "{seen}");
        let solver = v["contact_radius_mm"].as_f64().unwrap();
        let image = seen["contact_radius_mm"].as_f64().unwrap();
        // Measured 2.493 vs 2.544 mm and 1.315 vs 1.340 mm: 2% short, about a pixel.
        assert!(
            (image / solver - 1.0).abs() < 0.04,
            "{radius_mm} mm {hardness}: {image:.3} mm seen, {solver:.3} mm solved"
        );
        // The pad is centred over the sphere: the imprint is in the frame's middle.
        let c = &seen["circle"]["centre_px"];
        let (x, y) = (c[0].as_f64().unwrap(), c[1].as_f64().unwrap());
        assert!((x - 160.0).hypot(y - 120.0) < 2.5, "{c}");
    }
}

#[test]
fn bad_press_input_is_one_clear_line_and_a_failure() {
    let dir = tempfile::tempdir().unwrap();
    let empty = dir.path().join("empty.obj");
    std::fs::write(&empty, "# nothing\n").unwrap();
    let out = dir.path().join("o");
    let out_dir = out.to_str().unwrap();
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (
            vec![
                "--shape",
                "sphere",
                "--radius-mm",
                "-2",
                "--hardness",
                "30A",
                "--depth-mm",
                "1",
            ],
            "radius-mm",
        ),
        (
            vec!["--shape", "sphere", "--hardness", "30A", "--depth-mm", "-1"],
            "depth-mm",
        ),
        (
            vec![
                "--shape",
                "sphere",
                "--hardness",
                "30A",
                "--depth-mm",
                "1",
                "--marker-grid",
                "11by9",
            ],
            "marker-grid",
        ),
        (
            vec![
                "--shape",
                "sphere",
                "--hardness",
                "30A",
                "--depth-mm",
                "NaN",
            ],
            "depth-mm",
        ),
        (
            vec![
                "--shape",
                "sphere",
                "--hardness",
                "30A",
                "--depth-mm",
                "1",
                "--fidelity",
                "fem",
            ],
            "fidelity",
        ),
        (
            vec![
                "--shape",
                "sphere",
                "--hardness",
                "soft-ish",
                "--depth-mm",
                "1",
            ],
            "hardness",
        ),
        (
            vec![
                "--shape",
                "mesh",
                "--mesh",
                empty.to_str().unwrap(),
                "--hardness",
                "30A",
                "--depth-mm",
                "1",
            ],
            "empty.obj",
        ),
        (
            vec!["--shape", "sphere", "--modulus-mpa", "0", "--depth-mm", "1"],
            "modulus-mpa",
        ),
        (
            vec!["--shape", "sphere", "--depth-mm", "1", "--tolerance", "0"],
            "tolerance",
        ),
        (
            vec![
                "--shape",
                "sphere",
                "--hardness",
                "30A",
                "--depth-mm",
                "1",
                "--marker-pitch-mm",
                "1e-6",
                "--out",
                out_dir,
            ],
            "--marker-pitch-mm: 0.000001 mm is not over the markers' diameter",
        ),
        // A size the shape does not read would press another object than the one described.
        (
            vec![
                "--shape",
                "sphere",
                "--size-mm",
                "3,3,3",
                "--hardness",
                "30A",
                "--depth-mm",
                "1",
            ],
            "--size-mm: not read for --shape sphere",
        ),
        (
            vec![
                "--shape",
                "box",
                "--size-mm",
                "3,3,3",
                "--radius-mm",
                "2",
                "--hardness",
                "30A",
                "--depth-mm",
                "1",
            ],
            "--radius-mm: not read for --shape box",
        ),
        (
            vec![
                "--shape",
                "ellipsoid",
                "--mesh-scale",
                "1e-9",
                "--hardness",
                "30A",
                "--depth-mm",
                "1",
            ],
            "--mesh-scale",
        ),
        (
            vec![
                "--shape",
                "mesh",
                "--mesh",
                empty.to_str().unwrap(),
                "--radius-mm",
                "4",
                "--hardness",
                "30A",
                "--depth-mm",
                "1",
            ],
            "--radius-mm: not read for --shape mesh",
        ),
    ];
    for (args, named) in cases {
        let mut all = vec!["press"];
        all.extend(args.iter().copied());
        let out = tactex(&all);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{all:?} succeeded");
        assert!(
            err.starts_with("error: ") && err.trim_end().lines().count() == 1,
            "{all:?}: {err}"
        );
        assert!(err.contains(named), "{all:?}: {err}");
        assert!(!err.contains("panicked"));
    }
}

#[test]
fn contact_bench_writes_its_table_and_plot() {
    let dir = tempfile::tempdir().unwrap();
    let v = json(&tactex(&[
        "bench",
        "contact",
        "--cells",
        "auto,0.4",
        "--reference-cell-mm",
        "0.2",
        "--reps",
        "1",
        "--tolerances",
        "1e-3",
        "--json",
        "--out",
        dir.path().to_str().unwrap(),
    ]));
    let rows = v.as_array().unwrap();
    // Four levels and two pad-wide rows at each of two cells, one cold-start row, one
    // looser tolerance and two plain (unpreconditioned) conjugate gradients.
    assert_eq!(rows.len(), 4 * 2 + 2 + 1 + 1 + 2);
    for name in [
        "contact_bench.csv",
        "contact_bench.md",
        "contact_pareto.png",
    ] {
        assert!(dir.path().join(name).is_file(), "{name}");
    }
    // The layer level refines towards its own reference; rigid is far from it.
    let err = |fidelity: &str| {
        rows.iter()
            .find(|r| r["fidelity"] == fidelity && r["cell"] == "auto" && r["start"] == "warm")
            .unwrap()["force_err_vs_reference_pct"]
            .as_f64()
            .unwrap()
    };
    assert!(err("layer") < 2.0 && err("rigid") > 5.0);
    // Stopping the conjugate gradient sooner takes fewer steps and leaves the gel further
    // from the converged solution, though still far within the grid's own error.
    let layer = |tolerance: f64, cg: &str| {
        rows.iter()
            .find(|r| {
                r["fidelity"] == "layer"
                    && r["cell"] == "auto"
                    && r["domain"] == "contact"
                    && r["start"] == "warm"
                    && r["cg"] == cg
                    && r["tolerance"] == tolerance
            })
            .unwrap()
    };
    let f = |r: &serde_json::Value, key: &str| r[key].as_f64().unwrap();
    let (default, loose) = (layer(1e-6, "pre"), layer(1e-3, "pre"));
    assert!(f(loose, "iterations_per_frame") < f(default, "iterations_per_frame"));
    assert!(f(loose, "rms_gel_um_vs_converged") > f(default, "rms_gel_um_vs_converged"));
    assert!(f(loose, "rms_gel_um_vs_converged") < f(default, "rms_gel_um_vs_reference"));
    // The preconditioner takes fewer steps to the same answer.
    let plain = layer(1e-6, "plain");
    assert!(f(default, "iterations_per_frame") < f(plain, "iterations_per_frame"));
    assert!(f(plain, "rms_gel_um_vs_converged") < f(default, "rms_gel_um_vs_reference"));
}

#[test]
fn asking_for_a_gpu_where_there_is_none_names_what_is_missing_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let out_dir = dir.path().join("maps");
    // An ICD list naming no driver: the Vulkan loader then finds no adapter at all.
    let out = Command::new(env!("CARGO_BIN_EXE_tactex"))
        .args([
            "press",
            "--shape",
            "sphere",
            "--hardness",
            "30A",
            "--depth-mm",
            "1",
            "--device",
            "gpu",
            "--out",
            out_dir.to_str().unwrap(),
        ])
        .env("VK_ICD_FILENAMES", dir.path().join("no-driver.json"))
        .env("VK_DRIVER_FILES", dir.path().join("no-driver.json"))
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    assert!(
        err.contains("--device gpu") && err.contains("Vulkan"),
        "{err}"
    );
    assert!(
        !out_dir.exists(),
        "nothing is written when the device is missing"
    );
}
