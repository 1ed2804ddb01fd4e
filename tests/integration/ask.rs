//! End-to-end tests of `tactex ask` and `tactex scene check` on the simulated twin.

use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use tactex_core::catalog::FruitCatalog;
use tactex_core::scene::Scene;
use tactex_sim::world::SimWorld;

fn repo(p: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(p)
}

fn tactex(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_tactex"))
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("runs tactex")
}

fn ask_json(scene: &str, prompt: &str) -> Value {
    let out = tactex(&["ask", "--json", "--reproducible", "--scene", scene, prompt]);
    assert!(
        out.status.success(),
        "tactex ask failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).expect("stdout is one JSON object")
}

fn modulus(o: &Value) -> f64 {
    o["hardness"]["modulus_mpa"]
        .as_f64()
        .unwrap_or(f64::INFINITY)
}

fn selected_labels(a: &Value) -> Vec<String> {
    a["selected"]
        .as_array()
        .unwrap()
        .iter()
        .map(|i| {
            a["objects"][i.as_u64().unwrap() as usize]["label"]
                .as_str()
                .unwrap()
                .to_string()
        })
        .collect()
}

#[test]
fn demo_scene_answers_the_softest_fruit_with_positions_hardness_and_latency() {
    let a = ask_json("scenes/demo.toml", "Which fruit is the softest?");
    // Ground truth of scenes/demo.toml: the ripe tomato (0.45 MPa) is the softest of six.
    assert_eq!(selected_labels(&a), vec!["tomato"]);
    assert_eq!(a["objects"].as_array().unwrap().len(), 6);
    assert!(
        a["answer"]
            .as_str()
            .unwrap()
            .starts_with("The softest fruit is the tomato at the right front")
    );
    let stages: Vec<&str> = a["timing"]
        .as_array()
        .unwrap()
        .iter()
        .map(|t| t["stage"].as_str().unwrap())
        .collect();
    assert_eq!(stages, ["parse", "ground", "press", "hardness", "explain"]);
    assert!(
        a["timing"][2]["sim_s"].as_f64().unwrap() > 1.0,
        "pressing takes robot time"
    );
    for o in a["objects"].as_array().unwrap() {
        assert!(
            o["hardness"]["shore_a"].is_number() && o["hardness"]["shore_00"].is_number(),
            "{o}"
        );
        assert_eq!(o["position_m"].as_array().unwrap().len(), 3);
        // Each estimate carries its 68% and 95% intervals, nested around it, and what they
        // rest on.
        let e = modulus(o);
        let [lo68, hi68, lo95, hi95] = [
            ("p68_mpa", 0),
            ("p68_mpa", 1),
            ("p95_mpa", 0),
            ("p95_mpa", 1),
        ]
        .map(|(k, i)| o["interval"][k][i].as_f64().unwrap());
        assert!(lo95 <= lo68 && lo68 < e && e < hi68 && hi68 <= hi95, "{o}");
        assert!(
            o["interval"]["source"]
                .as_str()
                .unwrap()
                .contains("calibrated on"),
            "{o}"
        );
        assert!(
            o["contact"]["fired_by"]
                .as_array()
                .is_some_and(|f| !f.is_empty()),
            "{o}"
        );
    }
    // The answer names what it ran on.
    assert_eq!(a["fidelity"], "layer");
    assert_eq!(a["sensor"]["name"], "GelSight Mini");
    assert_eq!(a["sensor"]["sha256"].as_str().unwrap().len(), 64);
    assert_eq!(a["estimator"], "indentation");
    assert!(
        a["contact_criterion"]
            .as_str()
            .unwrap()
            .contains("noise floor"),
        "{a}"
    );
}

#[test]
#[cfg_attr(
    not(ci),
    ignore = "needs a Vulkan adapter (lavapipe: mesa-vulkan-drivers, as .ci/run installs)"
)]
fn the_gpu_rendered_camera_finds_the_same_fruit_at_the_same_place() {
    let run = |device| {
        tactex(&[
            "ask",
            "--json",
            "--reproducible",
            "--device",
            device,
            "--scene",
            "scenes/demo.toml",
            "Which fruit is the softest?",
        ])
    };
    let gpu = run("gpu");
    let err = String::from_utf8_lossy(&gpu.stderr).to_string();
    assert!(gpu.status.success(), "{err}");
    let cpu = run("cpu");
    let (gpu, cpu): (Value, Value) = (
        serde_json::from_slice(&gpu.stdout).unwrap(),
        serde_json::from_slice(&cpu.stdout).unwrap(),
    );
    assert_eq!(selected_labels(&gpu), vec!["tomato"]);
    let (g, c) = (
        gpu["objects"].as_array().unwrap(),
        cpu["objects"].as_array().unwrap(),
    );
    assert_eq!(g.len(), c.len());
    for (g, c) in g.iter().zip(c) {
        assert_eq!(g["label"], c["label"]);
        // The renders agree to f32 precision; the noise drawn over them differs where a
        // pixel's fate differs, so centroids agree to a fraction of the 5 mm tolerance.
        for k in 0..3 {
            let d = g["position_m"][k].as_f64().unwrap() - c["position_m"][k].as_f64().unwrap();
            assert!(d.abs() < 3e-3, "{}: {d} m apart", g["label"]);
        }
    }
}

#[test]
fn five_fruits_are_found_placed_and_ordered_by_hardness() {
    let catalog = FruitCatalog::builtin();
    let scene = Scene::load(&repo("tests/scenes/five.toml"), &catalog).unwrap();
    let truth = SimWorld::from_scene(&scene).unwrap();

    let a = ask_json("tests/scenes/five.toml", "Which fruit is the softest?");
    let objects = a["objects"].as_array().unwrap();
    assert_eq!(objects.len(), 5, "every fruit is returned");
    let mut measured = Vec::new();
    for o in objects {
        let label = o["label"].as_str().unwrap();
        let (k, t) = truth
            .objects
            .iter()
            .enumerate()
            .find(|(_, t)| t.label == label)
            .unwrap_or_else(|| panic!("unexpected {label}"));
        let p: Vec<f64> = o["position_m"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap())
            .collect();
        let err = ((p[0] - t.centre.x).powi(2)
            + (p[1] - t.centre.y).powi(2)
            + (p[2] - t.centre.z).powi(2))
        .sqrt();
        assert!(err < 0.02, "{label} is {err:.4} m from its true centre");
        measured.push((
            scene.objects[k].hardness.modulus_mpa().unwrap(),
            modulus(o),
            label.to_string(),
        ));
    }
    measured.sort_by(|a, b| a.0.total_cmp(&b.0));
    let estimates: Vec<f64> = measured.iter().map(|m| m.1).collect();
    assert!(
        estimates.windows(2).all(|w| w[0] < w[1]),
        "estimated order {measured:?}"
    );
    assert_eq!(selected_labels(&a), vec!["kiwi"]);

    let a = ask_json("tests/scenes/five.toml", "Which fruit is the hardest?");
    assert_eq!(selected_labels(&a), vec!["apple"]);
    let a = ask_json(
        "tests/scenes/five.toml",
        "Identify the hardness of the lemon",
    );
    assert_eq!(selected_labels(&a), vec!["lemon"]);
    assert_eq!(
        a["objects"].as_array().unwrap().len(),
        1,
        "only the lemon is touched"
    );
    assert!(a["answer"].as_str().unwrap().contains("lemon"));
}

#[test]
fn one_fruit_scene_and_a_fruit_that_is_not_there() {
    let a = ask_json("tests/scenes/one.toml", "How hard is the mango?");
    assert_eq!(selected_labels(&a), vec!["mango"]);
    let e = modulus(&a["objects"][0]);
    assert!(
        (0.45..0.8).contains(&e),
        "ripe mango is 0.6 MPa, estimated {e}"
    );
    let a = ask_json("tests/scenes/one.toml", "How hard is the kiwi?");
    assert!(a["objects"].as_array().unwrap().is_empty());
    assert!(
        a["answer"]
            .as_str()
            .unwrap()
            .contains("I could not find a kiwi on the table.")
    );
}

#[test]
fn same_scene_and_seed_give_identical_bytes() {
    let run = |seed: &str| {
        tactex(&[
            "ask",
            "--json",
            "--reproducible",
            "--seed",
            seed,
            "--scene",
            "tests/scenes/one.toml",
            "How hard is the mango?",
        ])
        .stdout
    };
    let first = run("7");
    assert!(!first.is_empty());
    assert_eq!(first, run("7"));
    assert_ne!(first, run("8"), "the seed drives the sensor noise");
}

#[test]
fn scene_check_loads_obj_and_gltf_meshes() {
    let out = tactex(&["scene", "check", "scenes/meshes.toml"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8_lossy(&out.stdout);
    assert_eq!(text.matches("pear").count(), 2, "{text}");
    for scene in ["scenes/demo.toml", "scenes/bananas.toml"] {
        assert!(
            tactex(&["scene", "check", scene]).status.success(),
            "{scene}"
        );
    }
}

/// Runs a failing command and returns its one-line error.
fn fails(args: &[&str]) -> String {
    let out = tactex(args);
    let err = String::from_utf8_lossy(&out.stderr).to_string();
    assert_eq!(
        out.status.code(),
        Some(1),
        "expected exit 1 for {args:?}, stderr: {err}"
    );
    assert!(
        out.stdout.is_empty(),
        "no half-written output on stdout: {}",
        String::from_utf8_lossy(&out.stdout)
    );
    assert!(!err.contains("panicked"), "{err}");
    assert_eq!(err.trim_end().lines().count(), 1, "one line: {err}");
    err
}

fn bad_scene(body: &str) -> (tempfile::TempDir, String) {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bad.toml");
    std::fs::write(&path, body).unwrap();
    (dir, path.display().to_string())
}

#[test]
fn bad_input_gets_a_one_line_error_naming_file_and_field() {
    let softest = "Which fruit is the softest?";
    let e = fails(&["ask", "--scene", "no/such/scene.toml", softest]);
    assert!(
        e.contains("no/such/scene.toml: file: cannot read scene"),
        "{e}"
    );

    let cases = [
        ("name = \"x\"\n[[objects]\n", "toml: line 2 (`[[objects]`)"),
        (
            "name = \"x\"\n[[objects]]\nkind = \"durian\"\nposition_m = [0, 0]\n",
            "objects[0].kind: unknown kind 'durian'",
        ),
        (
            "name = \"x\"\n[[objects]]\nkind = \"banana\"\nripeness = \"rotten\"\nposition_m = [0, 0]\n",
            "objects[0].ripeness: unknown ripeness stage 'rotten'",
        ),
        (
            "name = \"x\"\n[[objects]]\nkind = \"lime\"\nposition_m = [nan, 0.0]\n",
            "objects[0].position_m: must be finite",
        ),
        (
            "name = \"x\"\n[[objects]]\nkind = \"lime\"\nposition_m = [0.0, 1.5]\n",
            "objects[0].position_m: [0, 1.5] is off the table",
        ),
        (
            "name = \"x\"\n[[objects]]\nkind = \"lime\"\nposition_m = [1e308, 0.0]\n",
            "objects[0].position_m: [1e308, 0] is off the table",
        ),
        // Nonsense a scene must not carry into the world: sizes no object on a table has,
        // objects placed in one another, a camera that cannot see the table or stands in a
        // fruit. `scene check` and `ask` refuse them alike.
        (
            "name = \"x\"\n[[objects]]\nkind = \"sphere\"\nradius_m = 1e308\nhardness = \"40A\"\nposition_m = [0, 0]\n",
            "objects[0].radius_m: 1e308 m is not a size an object on a table has",
        ),
        (
            "name = \"x\"\n[[objects]]\nkind = \"sphere\"\nradius_m = 1e-12\nhardness = \"40A\"\nposition_m = [0, 0]\n",
            "objects[0].radius_m: 1e-12 m is not a size an object on a table has",
        ),
        (
            "name = \"x\"\n[table]\nsize_m = [1e9, 0.4]\n",
            "table.size_m: [1e9, 0.4] m: each side must be 0.05 to 10 m",
        ),
        (
            "name = \"x\"\n[[objects]]\nkind = \"apple\"\nposition_m = [0, 0]\n[[objects]]\nkind = \"apple\"\nposition_m = [0, 0]\n[[objects]]\nkind = \"apple\"\nposition_m = [0, 0]\n",
            "objects[0] (apple) and objects[1] (apple) are placed in one another",
        ),
        (
            "name = \"x\"\n[camera]\nposition_m = [0.0, 0.0, 0.7]\nlook_at_m = [0.0, 0.0, 2.0]\n[[objects]]\nkind = \"lime\"\nposition_m = [0, 0]\n",
            "camera: a camera at [0.0, 0.0, 0.7] looking at [0.0, 0.0, 2.0] does not look down at the table",
        ),
        (
            "name = \"x\"\n[camera]\nposition_m = [0.0, 0.0, 0.02]\nlook_at_m = [0.0, 0.1, 0.0]\n[[objects]]\nkind = \"apple\"\nposition_m = [0, 0]\n",
            "camera: at [0.0, 0.0, 0.02] it stands inside objects[0] (apple)",
        ),
        // So far away that the direction to the table is lost to rounding.
        (
            "name = \"x\"\n[camera]\nposition_m = [1e308, 0.0, 0.7]\nlook_at_m = [0.0, 0.0, 0.0]\n",
            "camera.position_m: [1e308, 0, 0.7] must be within 10 m of the world's origin on each axis",
        ),
    ];
    for (body, expected) in cases {
        let (_dir, path) = bad_scene(body);
        let e = fails(&["ask", "--scene", &path, softest]);
        assert!(e.contains(&format!("{path}: {expected}")), "{e}");
        let out = tactex(&["scene", "check", &path]);
        assert!(out.stdout.is_empty(), "refused, not also printed valid");
        let e = fails(&["scene", "check", &path]);
        assert!(e.contains(expected), "{e}");
    }

    // A mesh a million times too large: the scale is refused before the mesh is built.
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("tri.obj"),
        "v 0 0 0\nv 0.05 0 0\nv 0 0.05 0\nv 0 0 0.05\nf 1 2 3\nf 1 2 4\nf 1 3 4\nf 2 3 4\n",
    )
    .unwrap();
    let path = dir.path().join("scene.toml");
    std::fs::write(&path, "name = \"x\"\n[[objects]]\nkind = \"mesh\"\nmesh = \"tri.obj\"\nscale = 1e6\nhardness = \"40A\"\nposition_m = [0, 0]\n").unwrap();
    let e = fails(&["scene", "check", path.to_str().unwrap()]);
    assert!(
        e.contains("objects[0].scale: 1e6 is not a mesh unit in metres"),
        "{e}"
    );
    // A valid unit that makes the 5 cm mesh 50 um across: no object on a table is that small.
    std::fs::write(&path, "name = \"x\"\n[[objects]]\nkind = \"mesh\"\nmesh = \"tri.obj\"\nscale = 0.001\nhardness = \"40A\"\nposition_m = [0, 0]\n").unwrap();
    let e = fails(&["scene", "check", path.to_str().unwrap()]);
    assert!(
        e.contains("objects[0]: the mesh is") && e.contains("m across at scale 0.001"),
        "{e}"
    );

    // A mesh file that exists but is not a mesh.
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("junk.obj"), "v 1 2\nf 9 9 9\n").unwrap();
    let path = dir.path().join("scene.toml");
    std::fs::write(&path, "name = \"x\"\n[[objects]]\nkind = \"mesh\"\nmesh = \"junk.obj\"\nhardness = \"40A\"\nposition_m = [0, 0]\n").unwrap();
    let e = fails(&["ask", "--scene", path.to_str().unwrap(), softest]);
    assert!(
        e.contains("objects[0].mesh") && e.contains("junk.obj"),
        "{e}"
    );

    let e = fails(&["ask", "  "]);
    assert!(e.contains("prompt: empty"), "{e}");
    // A bad flag value is a bad value like any other: one line naming the flag and choices.
    let e = fails(&["ask", "--estimator", "magic", softest]);
    assert!(
        e.contains("--estimator") && e.contains("unknown estimator \"magic\""),
        "{e}"
    );
    let e = fails(&["ask", "--intervals", "no/such/intervals.json", softest]);
    assert!(
        e.contains("--intervals no/such/intervals.json: cannot read"),
        "{e}"
    );
    let e = fails(&["ask", "--intervals", "models/hardness-small.json", softest]);
    assert!(
        e.contains("--intervals models/hardness-small.json: "),
        "{e}"
    );
    // The shipped intervals were measured through the built-in Mini: through another sensor
    // they would claim a coverage nobody measured.
    let e = fails(&[
        "ask",
        "--sensor",
        "tests/fixtures/fots/profile/fots-9.toml",
        "--intervals",
        "models/intervals/indentation-layer.json",
        softest,
    ]);
    assert!(
        e.contains("--intervals models/intervals/indentation-layer.json: measured through the sensor GelSight Mini")
            && e.contains("eval fruits --sensor"),
        "{e}"
    );
    let e = fails(&["ask", "How hard is the pineapple?"]);
    assert!(
        e.contains("prompt: 'pineapple' is not in the fruit catalog"),
        "{e}"
    );
    let e = fails(&["ask", "What is the weather like?"]);
    assert!(e.contains("prompt: names no known fruit"), "{e}");
    // Every bench refuses zero repetitions rather than quietly running one.
    for bench in ["ask", "scene", "render", "contact"] {
        let e = fails(&["bench", bench, "--reps", "0"]);
        assert!(
            e.contains("--reps") && e.contains("0 is outside [1, 1000]"),
            "{bench}: {e}"
        );
    }
    let e = fails(&["bench", "render", "--batch", "0"]);
    assert!(
        e.contains("--batch") && e.contains("0 is outside [1, 4096]"),
        "{e}"
    );
    let e = fails(&["bench", "ask", "--prompt", "What is the weather like?"]);
    assert!(e.contains("--prompt: prompt: names no known fruit"), "{e}");
}

#[test]
fn parse_prints_the_query_contract_as_json() {
    let out = tactex(&["parse", "--json", "Which lemon is ripest?"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let q: Value = serde_json::from_slice(&out.stdout).expect("one JSON object");
    assert_eq!(q["intent"], "extreme");
    assert_eq!(q["property"], "ripeness");
    assert_eq!(q["extreme"], "most");
    assert_eq!(q["targets"], serde_json::json!(["lemon"]));
    assert_eq!(q["all"], false);
    assert_eq!(q["exclude"], serde_json::json!([]));
    assert!(q["filters"].is_object());
    let e = fails(&["parse", "How hard is the pineapple?"]);
    assert!(e.contains("'pineapple' is not in the fruit catalog"), "{e}");
}

#[test]
fn a_value_question_selects_exactly_the_fruit_past_it_hardest_first() {
    // scenes/demo.toml's truth: mango 3.0, apple 3.25 and avocado 5.0 MPa are over 2 MPa;
    // tomato 0.45, banana 0.8 and lime 1.5 under it.
    let a = ask_json("scenes/demo.toml", "Which fruits are harder than 2 MPa?");
    let mut got = selected_labels(&a);
    let moduli: Vec<f64> = a["selected"]
        .as_array()
        .unwrap()
        .iter()
        .map(|i| modulus(&a["objects"][i.as_u64().unwrap() as usize]))
        .collect();
    assert!(moduli.windows(2).all(|w| w[0] >= w[1]), "{moduli:?}");
    got.sort();
    assert_eq!(got, ["apple", "avocado", "mango"], "{}", a["answer"]);
    let answer = a["answer"].as_str().unwrap();
    assert!(
        answer.starts_with("Three fruit are harder than 2 MPa ("),
        "{answer}"
    );
    assert!(answer.contains("Not harder: lime"), "{answer}");
    assert_eq!(a["query"]["intent"], "threshold");

    // A value no fruit passes: said, with the nearest; the question is still answered.
    let a = ask_json("scenes/demo.toml", "Is anything softer than 0.1 MPa?");
    assert_eq!(selected_labels(&a), Vec::<String>::new());
    let answer = a["answer"].as_str().unwrap();
    assert!(
        answer.starts_with("No fruit I measured is softer than 0.1 MPa"),
        "{answer}"
    );
    assert!(answer.contains("The softest is the tomato"), "{answer}");

    // A superlative beside the value picks one of the fruit past it: of tomato 0.45,
    // banana 0.8 and lime 1.5 MPa, the hardest is the lime.
    let a = ask_json(
        "scenes/demo.toml",
        "Which is the hardest fruit softer than 2 MPa?",
    );
    assert_eq!(selected_labels(&a), ["lime"], "{}", a["answer"]);
    let answer = a["answer"].as_str().unwrap();
    assert!(
        answer.starts_with(
            "Of the three fruit softer than 2 MPa (44 Shore A), the hardest is the lime"
        ),
        "{answer}"
    );

    let e = fails(&["parse", "Which fruits are harder than 2?"]);
    assert!(e.contains("hardness value '2': has no unit"), "{e}");
}

#[test]
fn a_question_against_another_fruit_presses_it_and_selects_the_fruit_past_its_reading() {
    // scenes/demo.toml's truth: the lime is 1.5 MPa; mango 3.0, apple 3.25, avocado 5.0.
    let a = ask_json("scenes/demo.toml", "Which fruits are harder than the lime?");
    let mut got = selected_labels(&a);
    got.sort();
    assert_eq!(got, ["apple", "avocado", "mango"], "{}", a["answer"]);
    let answer = a["answer"].as_str().unwrap();
    assert!(
        answer.starts_with("Three fruit are harder than the lime at "),
        "{answer}"
    );
    assert_eq!(a["query"]["relation"]["reference"], "lime");

    // A group against a fruit outside it: only the group and the reference are pressed.
    let a = ask_json(
        "scenes/demo.toml",
        "Which citrus fruit is softer than the apple?",
    );
    assert_eq!(selected_labels(&a), ["lime"], "{}", a["answer"]);
    let mut pressed: Vec<&str> = a["objects"]
        .as_array()
        .unwrap()
        .iter()
        .map(|o| o["label"].as_str().unwrap())
        .collect();
    pressed.sort();
    assert_eq!(pressed, ["apple", "lime"]);

    // A place chooses the fruit asked about, not the reference (the mango is at the left).
    let a = ask_json(
        "scenes/demo.toml",
        "Which fruit on the right is softer than the mango?",
    );
    assert_eq!(selected_labels(&a), ["tomato"], "{}", a["answer"]);
    // Two bounds are refused, as two values are.
    let e = fails(&[
        "parse",
        "Is anything softer than the mango but harder than the banana?",
    ]);
    assert!(e.contains("ask about one at a time"), "{e}");

    // A reference not on the table is said, and nothing is selected.
    let a = ask_json("scenes/demo.toml", "Which fruit is softer than the peach?");
    assert_eq!(selected_labels(&a), Vec::<String>::new());
    let answer = a["answer"].as_str().unwrap();
    assert!(answer.contains("I found no peach"), "{answer}");
    // Several references: past every one of them, each said with its reading, the one that
    // bounds last; both pressed and marked as what the others are held against.
    let a = ask_json(
        "scenes/demo.toml",
        "Which fruit is softer than the apple and the mango?",
    );
    let mut got = selected_labels(&a);
    got.sort();
    assert_eq!(got, ["banana", "lime", "tomato"], "{}", a["answer"]);
    let mut references: Vec<&str> = a["objects"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|o| o["reference"] == true)
        .map(|o| o["label"].as_str().unwrap())
        .collect();
    references.sort();
    assert_eq!(references, ["apple", "mango"]);
    let answer = a["answer"].as_str().unwrap();
    assert!(
        answer.starts_with("Three fruit are softer than both the "),
        "{answer}"
    );
    let a = ask_json(
        "scenes/demo.toml",
        "Which fruit is softer than the apple and the peach?",
    );
    assert!(selected_labels(&a).is_empty());
    let answer = a["answer"].as_str().unwrap();
    assert!(answer.contains("I found no peach"), "{answer}");
    let e = fails(&["parse", "Is anything softer than the apple or the mango?"]);
    assert!(e.contains("'or' leaves open which fruit"), "{e}");
}

#[test]
fn the_reference_at_a_place_is_the_one_there_and_only_it_is_pressed() {
    // Two bananas, an unripe one on the left and an overripe one on the right, and three
    // fruit between them in firmness and place.
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("two-bananas.toml");
    std::fs::write(
        &scene,
        r#"name = "two bananas"
[[objects]]
kind = "banana"
position_m = [-0.17, -0.02]
ripeness = "unripe"
[[objects]]
kind = "banana"
position_m = [0.17, -0.02]
ripeness = "overripe"
[[objects]]
kind = "tomato"
position_m = [0.0, -0.11]
[[objects]]
kind = "lime"
position_m = [0.0, 0.1]
"#,
    )
    .unwrap();
    let scene = scene.to_str().unwrap();
    let bananas_pressed = |a: &Value| -> Vec<f64> {
        a["objects"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|o| o["label"] == "banana")
            .map(|o| o["position_m"][0].as_f64().unwrap())
            .collect()
    };
    // The reference is the one banana at its place (marked so in --json); the other banana
    // is a fruit like any other, asked about and pressed.
    let reference_x = |a: &Value| -> Vec<f64> {
        a["objects"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|o| o["reference"] == true)
            .map(|o| o["position_m"][0].as_f64().unwrap())
            .collect()
    };
    let left = ask_json(scene, "Which fruit is softer than the banana on the left?");
    let right = ask_json(scene, "Which fruit is softer than the right banana?");
    let (l, r) = (reference_x(&left), reference_x(&right));
    assert!(l.len() == 1 && l[0] < 0.0, "{l:?}");
    assert!(r.len() == 1 && r[0] > 0.0, "{r:?}");
    assert_eq!(bananas_pressed(&left).len(), 2);
    // The unripe banana is the firmer: more fruit are softer than it, the overripe banana
    // among them; nothing on the table is softer than the overripe one.
    let softer_than_left = selected_labels(&left);
    assert!(
        softer_than_left.contains(&"banana".to_string())
            && softer_than_left.len() > selected_labels(&right).len(),
        "{} / {}",
        left["answer"],
        right["answer"]
    );
    let answer = left["answer"].as_str().unwrap();
    assert!(answer.contains("the banana at the left"), "{answer}");
    // Instances of the reference's own kind: the banana asked about is the other one.
    let which = ask_json(scene, "Which banana is softer than the banana on the left?");
    assert_eq!(selected_labels(&which), ["banana"], "{}", which["answer"]);
    let selected = &which["objects"][which["selected"][0].as_u64().unwrap() as usize];
    assert!(selected["position_m"][0].as_f64().unwrap() > 0.0);
    assert_eq!(bananas_pressed(&which).len(), 2);
    let none = ask_json(scene, "Which banana is harder than the banana on the left?");
    assert!(selected_labels(&none).is_empty(), "{}", none["answer"]);
    // Two of one kind told apart by place in a yes/no question, and "the other one".
    let x_of_selected = |a: &Value| -> Vec<f64> {
        a["selected"]
            .as_array()
            .unwrap()
            .iter()
            .map(|i| {
                a["objects"][i.as_u64().unwrap() as usize]["position_m"][0]
                    .as_f64()
                    .unwrap()
            })
            .collect()
    };
    let yes = ask_json(
        scene,
        "Is the banana on the right softer than the banana on the left?",
    );
    let x = x_of_selected(&yes);
    assert!(x.len() == 1 && x[0] > 0.0, "{}", yes["answer"]);
    let other = ask_json(scene, "Is the left banana harder than the other one?");
    let x = x_of_selected(&other);
    assert!(x.len() == 1 && x[0] < 0.0, "{}", other["answer"]);
    // Their ripeness, as the issue asked it: the overripe right banana is the riper, and
    // the answer says so in ripeness, with each one's stage.
    let riper = ask_json(
        scene,
        "Is the banana on the right riper than the one on the left?",
    );
    let x = x_of_selected(&riper);
    assert!(x.len() == 1 && x[0] > 0.0, "{}", riper["answer"]);
    let answer = riper["answer"].as_str().unwrap();
    assert!(
        answer.contains("riper than the banana at the left") && answer.contains("overripe"),
        "{answer}"
    );
    let not = ask_json(
        scene,
        "Is the banana on the left riper than the one on the right?",
    );
    assert!(x_of_selected(&not).is_empty(), "{}", not["answer"]);
    assert!(
        not["answer"]
            .as_str()
            .unwrap()
            .contains("is not riper than"),
        "{}",
        not["answer"]
    );
    // A bare place after the comparison is the one there; a place on one side of a question
    // about two kinds keeps the other kind (it filtered the lime away).
    let bare = ask_json(scene, "Is the left banana harder than the right?");
    let x = x_of_selected(&bare);
    assert!(x.len() == 1 && x[0] < 0.0, "{}", bare["answer"]);
    let lime = ask_json(scene, "Is the left banana softer than the lime?");
    let answer = lime["answer"].as_str().unwrap();
    assert!(answer.contains("is not softer than the lime"), "{answer}");
}

#[test]
fn one_of_a_kind_has_no_other_to_hold_against() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("one-banana.toml");
    std::fs::write(
        &scene,
        "name = \"one banana\"\n[[objects]]\nkind = \"banana\"\nposition_m = [-0.13, 0.0]\n\
         [[objects]]\nkind = \"lime\"\nposition_m = [0.13, 0.0]\n",
    )
    .unwrap();
    let a = ask_json(
        scene.to_str().unwrap(),
        "Is the banana on the left riper than the one on the right?",
    );
    let answer = a["answer"].as_str().unwrap();
    assert!(answer.contains("I found one banana only"), "{answer}");
}

#[test]
fn a_size_word_picks_the_instance_that_shows_the_camera_the_most_or_least() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("two-limes.toml");
    std::fs::write(
        &scene,
        r#"name = "two limes"
[[objects]]
kind = "lime"
position_m = [-0.12, 0.0]
size_m = [0.045, 0.045, 0.04]
[[objects]]
kind = "lime"
position_m = [0.12, 0.02]
size_m = [0.058, 0.058, 0.052]
[[objects]]
kind = "apple"
position_m = [0.0, 0.1]
"#,
    )
    .unwrap();
    let scene = scene.to_str().unwrap();
    let pressed_x = |a: &Value| -> Vec<f64> {
        a["objects"]
            .as_array()
            .unwrap()
            .iter()
            .map(|o| o["position_m"][0].as_f64().unwrap())
            .collect()
    };
    // Only the one picked is pressed: the larger lime stands on the right.
    let bigger = ask_json(scene, "How hard is the bigger lime?");
    assert_eq!(selected_labels(&bigger), ["lime"]);
    let x = pressed_x(&bigger);
    assert!(x.len() == 1 && x[0] > 0.0, "{x:?}");
    let smaller = ask_json(scene, "How hard is the smaller of the two limes?");
    let x = pressed_x(&smaller);
    assert!(x.len() == 1 && x[0] < 0.0, "{x:?}");
    let answer = smaller["answer"].as_str().unwrap();
    assert!(!answer.contains("You mentioned"), "{answer}");
    let e = fails(&["parse", "Which fruit is bigger than the apple?"]);
    assert!(e.contains("size against another fruit"), "{e}");
}

#[test]
fn colour_and_position_filters_choose_the_fruit() {
    let scene = "scenes/demo.toml";
    let a = ask_json(scene, "How hard is the yellow one?");
    assert_eq!(selected_labels(&a), ["banana"]);
    let a = ask_json(scene, "Which fruit on the right is the softest?");
    assert_eq!(selected_labels(&a), ["tomato"]);
    let labels: Vec<&str> = a["objects"]
        .as_array()
        .unwrap()
        .iter()
        .map(|o| o["label"].as_str().unwrap())
        .collect();
    assert_eq!(
        labels,
        ["tomato", "avocado"],
        "only the right-hand fruit are pressed"
    );
    let a = ask_json(scene, "How firm is the fruit at the front left?");
    assert_eq!(selected_labels(&a), ["banana"]);
}

/// A chat-completions endpoint on 127.0.0.1 that answers every request with `reply(data)`,
/// where `data` is the JSON the explainer put in the user message.
fn fake_llm(reply: fn(&Value) -> String) -> String {
    use std::io::{BufRead, BufReader, Read, Write};
    let listener = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
    let url = format!("http://{}/v1", listener.local_addr().unwrap());
    std::thread::spawn(move || {
        for mut stream in listener.incoming().flatten() {
            let mut reader = BufReader::new(stream.try_clone().unwrap());
            let mut length = 0;
            loop {
                let mut line = String::new();
                if reader.read_line(&mut line).unwrap_or(0) == 0 || line == "\r\n" {
                    break;
                }
                if let Some(v) = line.to_lowercase().strip_prefix("content-length:") {
                    length = v.trim().parse().unwrap_or(0);
                }
            }
            let mut body = vec![0; length];
            reader.read_exact(&mut body).ok();
            let request: Value = serde_json::from_slice(&body).unwrap_or_default();
            let user = request["messages"][1]["content"].as_str().unwrap_or("");
            let data: Value = user
                .strip_prefix("Data: ")
                .and_then(|s| s.lines().next())
                .and_then(|s| serde_json::from_str(s).ok())
                .unwrap_or_default();
            let payload = serde_json::json!({"choices": [{"message": {"content": reply(&data)}}]})
                .to_string();
            let _ = write!(
                stream,
                "HTTP/1.1 200 OK\r\ncontent-type: application/json\r\ncontent-length: {}\r\nconnection: close\r\n\r\n{payload}",
                payload.len()
            );
        }
    });
    url
}

/// `tactex ask --json --explainer llm` on the one-fruit scene against the endpoint at `url`.
fn ask_llm(url: &str, prompt: &str) -> Value {
    let out = Command::new(env!("CARGO_BIN_EXE_tactex"))
        .args(["ask", "--json", "--reproducible", "--explainer", "llm"])
        .args(["--scene", "tests/scenes/one.toml", prompt])
        .env("TACTEX_LLM_BASE_URL", url)
        .env("TACTEX_LLM_MODEL", "fake")
        .env_remove("TACTEX_LLM_API_KEY")
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("runs tactex");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).expect("stdout is one JSON object")
}

#[test]
fn the_llm_explainer_is_used_when_grounded_and_replaced_when_it_invents() {
    // A model that says what the data says, in its own words.
    let url = fake_llm(|data| {
        let o = &data["objects"][0];
        format!(
            "I pressed the {} at the {}: {} ({}), so it is {}.",
            o["label"].as_str().unwrap_or("?"),
            o["location"].as_str().unwrap_or("?"),
            o["hardness"]["shore"].as_str().unwrap_or("?"),
            o["hardness"]["modulus"].as_str().unwrap_or("?"),
            o["ripeness"].as_str().unwrap_or("?"),
        )
    });
    let a = ask_llm(&url, "How hard is the mango?");
    assert_eq!(a["explainer"], "llm:fake");
    assert_eq!(a["explain_notice"], Value::Null);
    let text = a["answer"].as_str().unwrap();
    assert!(text.starts_with("I pressed the mango at the"), "{text}");

    // A model that makes up a number: the template answers and the notice says why.
    let url = fake_llm(|_| "The mango is 9.99 MPa and ripe.".into());
    let a = ask_llm(&url, "How hard is the mango?");
    assert_eq!(a["explainer"], "template");
    let notice = a["explain_notice"].as_str().unwrap();
    assert!(
        notice.contains("9.99 mpa is not a measured value"),
        "{notice}"
    );
    assert!(
        a["answer"]
            .as_str()
            .unwrap()
            .starts_with("The mango at the")
    );
}

#[test]
fn the_llm_explainer_without_an_endpoint_is_a_one_line_error() {
    let out = Command::new(env!("CARGO_BIN_EXE_tactex"))
        .args(["ask", "--explainer", "llm", "How hard is the mango?"])
        .env_remove("TACTEX_LLM_BASE_URL")
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    assert!(err.contains("TACTEX_LLM_BASE_URL"), "{err}");
}

/// `tactex ARGS` with the LLM variables pointing at `url`: (exit code, stdout, stderr).
fn with_llm(url: &str, args: &[&str]) -> (Option<i32>, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_tactex"))
        .args(args)
        .env("TACTEX_LLM_BASE_URL", url)
        .env("TACTEX_LLM_MODEL", "fake")
        .env("TACTEX_LLM_TIMEOUT_S", "2")
        .env_remove("TACTEX_LLM_API_KEY")
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("runs tactex");
    (
        out.status.code(),
        String::from_utf8_lossy(&out.stdout).into(),
        String::from_utf8_lossy(&out.stderr).into(),
    )
}

#[test]
fn the_llm_parser_reads_what_the_rules_cannot_and_falls_back_when_it_fails() {
    // The rules find nothing to ask about here; the model reads "the softest of every fruit".
    let prompt = "Which would squash first if I sat on it?";
    let (code, _, err) = with_llm("http://127.0.0.1:9/v1", &["parse", prompt]);
    assert_eq!(code, Some(1), "{err}");
    let url = fake_llm(|_| {
        r#"{"intent": "extreme", "property": "softness", "extreme": "most", "all": true}"#.into()
    });
    let (code, out, err) = with_llm(&url, &["parse", "--json", "--parser", "llm", prompt]);
    assert_eq!(code, Some(0), "{err}");
    let q: Value = serde_json::from_str(&out).unwrap();
    assert_eq!(
        (q["intent"].as_str(), q["all"].as_bool()),
        (Some("extreme"), Some(true))
    );
    assert_eq!(q["parser"], "llm:fake");
    // The whole question on the twin, read by the model.
    let (code, out, err) = with_llm(
        &url,
        &[
            "ask",
            "--json",
            "--reproducible",
            "--parser",
            "llm",
            "--scene",
            "tests/scenes/one.toml",
            prompt,
        ],
    );
    assert_eq!(code, Some(0), "{err}");
    let a: Value = serde_json::from_str(&out).unwrap();
    assert_eq!(a["parser"], "llm:fake");
    assert_eq!(a["parse_notice"], Value::Null);
    assert_eq!(a["selected"].as_array().map(Vec::len), Some(1));

    // A model that writes prose, one that names a fruit the catalog lacks, and no server at
    // all: the rules read the question, and a note says why.
    let prose = fake_llm(|_| "The banana, surely.".into());
    let outside = fake_llm(|_| {
        r#"{"intent": "identify", "property": "hardness", "targets": ["durian"]}"#.into()
    });
    for (url, cause) in [
        (prose.as_str(), "no JSON object in the reply"),
        (outside.as_str(), "'durian' is not in the fruit catalog"),
        ("http://127.0.0.1:9/v1", "127.0.0.1:9"),
    ] {
        let (code, out, err) = with_llm(
            url,
            &["parse", "--parser", "llm", "How hard is the banana?"],
        );
        assert_eq!(code, Some(0), "{err}");
        assert!(out.contains("parser:   rules"), "{out}");
        assert!(out.contains("objects:  banana"), "{out}");
        assert!(err.starts_with("note: ") && err.contains(cause), "{err}");
        assert!(err.trim_end().ends_with("read by the rules"), "{err}");
    }
    // Falling back to rules that refuse too: the rules' one-line error, after the note; in
    // `ask`, one line with both reasons.
    let (code, _, err) = with_llm(&prose, &["parse", "--parser", "llm", prompt]);
    assert_eq!(code, Some(1), "{err}");
    assert!(err.contains("names no known fruit"), "{err}");
    let (code, _, err) = with_llm(
        &prose,
        &[
            "ask",
            "--parser",
            "llm",
            "--scene",
            "tests/scenes/one.toml",
            prompt,
        ],
    );
    assert_eq!(code, Some(1), "{err}");
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    assert!(
        err.contains("names no known fruit")
            && err.contains("the model's reading was not a query (no JSON object"),
        "{err}"
    );
    // --llm-config with no one to read it is refused.
    let (code, _, err) = with_llm(&prose, &["parse", "--llm-config", "llm.toml", prompt]);
    assert_eq!(code, Some(1), "{err}");
    assert!(
        err.contains("--llm-config llm.toml: read only by --parser llm"),
        "{err}"
    );
}

#[test]
fn a_prompt_with_terminal_escape_codes_is_shown_escaped_not_acted_on() {
    let err = fails(&["ask", "hello \u{1b}[2J\u{1b}]0;pwned\u{7} there"]);
    assert!(err.contains("\\u{1b}[2J"), "{err}");
    assert!(!err.trim_end().chars().any(char::is_control), "{err:?}");
}

#[test]
fn a_mesh_that_cannot_be_simulated_is_refused_for_what_is_wrong_with_it() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path();
    std::fs::create_dir(p.join("meshdir")).unwrap();
    std::os::unix::fs::symlink("/dev/zero", p.join("zero.obj")).unwrap();
    std::fs::write(
        p.join("tri.obj"),
        "v 0 0 0\nv 0.05 0 0\nv 0 0.05 0\nf 1 2 3\n",
    )
    .unwrap();
    // A glTF whose buffer lives in a .bin that is not there.
    std::fs::write(
        p.join("m.gltf"),
        r#"{"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}],
"meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],"buffers":[{"byteLength":36,"uri":"m.bin"}],
"bufferViews":[{"buffer":0,"byteLength":36}],"accessors":[{"bufferView":0,"componentType":5126,
"count":3,"type":"VEC3","max":[1,1,0],"min":[0,0,0]}]}"#,
    )
    .unwrap();
    for (mesh, says) in [
        ("meshdir", "is a directory, not a mesh file"),
        ("zero.obj", "not a regular file (a FIFO, device or socket)"),
        ("tri.obj", "1 triangles on 3 vertices"),
        ("m.gltf", "buffer 0 file"),
    ] {
        let scene = p.join("s.toml");
        std::fs::write(
            &scene,
            format!(
                "name = \"x\"\n[[objects]]\nkind = \"mesh\"\nmesh = \"{mesh}\"\nhardness = \"40A\"\nposition_m = [0, 0]\n"
            ),
        )
        .unwrap();
        let e = fails(&["scene", "check", scene.to_str().unwrap()]);
        assert!(
            e.contains("objects[0].mesh") && e.contains(says),
            "{mesh}: {e}"
        );
        if mesh == "m.gltf" {
            assert!(e.contains("m.bin' not found"), "{e}");
        }
    }
    // More objects than a table holds: refused for the count, before any is placed.
    let many: String = (0..65)
        .map(|i| {
            format!(
                "[[objects]]\nkind = \"lime\"\nposition_m = [{}, 0]\n",
                i as f64 * 1e-3
            )
        })
        .collect();
    let (_d, path) = bad_scene(&format!("name = \"x\"\n{many}"));
    let e = fails(&["scene", "check", &path]);
    assert!(
        e.contains("objects: 65 objects; a scene has at most 64"),
        "{e}"
    );
}

/// A banana lying along the pad's axis (yaw 0, the default when a scene gives none) was
/// pressed off its ridge and its imprint ran off the frame's side, which lowered the
/// integration's zero: it read 0.36 MPa for 0.8 with a 95% interval excluding the truth,
/// while every other yaw read 0.72-0.87. Swept here every 30 degrees (every 5 in the
/// closing figures: worst |ln| 0.11, the 95% interval holding the truth at all 37).
#[test]
fn a_banana_reads_right_at_every_yaw_including_along_the_pads_axis() {
    let dir = tempfile::tempdir().unwrap();
    let mut held = 0;
    let yaws = [0, 30, 60, 90, 120, 150, 180];
    for yaw in yaws {
        let scene = dir.path().join(format!("banana{yaw}.toml"));
        std::fs::write(
            &scene,
            format!(
                "name = \"banana\"\n\n[[objects]]\nkind = \"banana\"\nposition_m = [0.0, -0.05]\nyaw_deg = {yaw}\nmodulus_mpa = 0.8\n"
            ),
        )
        .unwrap();
        let answer = ask_json(scene.to_str().unwrap(), "How hard is the banana?");
        let banana = &answer["objects"][0];
        let e = modulus(banana);
        assert!((e / 0.8).ln().abs() <= 0.3, "yaw {yaw}: {e} MPa\n{banana}");
        let p95 = &banana["interval"]["p95_mpa"];
        let (lo, hi) = (
            p95[0].as_f64().unwrap_or(0.0),
            p95[1].as_f64().unwrap_or(f64::INFINITY),
        );
        held += usize::from(lo <= 0.8 && 0.8 <= hi);
    }
    assert!(
        held >= yaws.len() - 1,
        "the 95% interval held the truth at {held} of {}",
        yaws.len()
    );
}
