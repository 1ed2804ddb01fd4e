//! `tactex datagen scenes`: the YOLO segmentation data set passes a format check (data.yaml
//! as Ultralytics reads it, label polygons inside the image with classes from data.yaml, and
//! each polygon covering its fruit's true mask), the seed decides the bytes, an interrupted
//! run resumes, and bad input gets a one-line error.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;

fn tactex(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_tactex"))
        .args(args)
        .output()
        .expect("tactex runs")
}

fn datagen(out: &Path, seed: &str) -> std::process::Output {
    tactex(&[
        "datagen",
        "scenes",
        "--count",
        "5",
        "--out",
        out.to_str().unwrap(),
        "--seed",
        seed,
        "--fruits",
        "2-4",
        "--val-fraction",
        "0.4",
    ])
}

fn ok(out: std::process::Output) {
    assert!(
        out.status.success(),
        "tactex failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
}

fn one_line_error(out: &std::process::Output) -> String {
    assert!(!out.status.success(), "expected a failure");
    let err = String::from_utf8_lossy(&out.stderr).trim().to_string();
    assert_eq!(err.lines().count(), 1, "not one line: {err}");
    assert!(!err.contains("panicked"), "{err}");
    err
}

/// The fields of data.yaml that Ultralytics reads: path, train, val, nc and names.
struct DataYaml {
    path: PathBuf,
    train: String,
    val: String,
    nc: usize,
    names: BTreeMap<usize, String>,
}

fn unquote(s: &str) -> String {
    s.trim().trim_matches('"').to_string()
}

fn read_data_yaml(file: &Path) -> DataYaml {
    let text = std::fs::read_to_string(file).unwrap();
    let mut fields = BTreeMap::new();
    let mut names = BTreeMap::new();
    let mut in_names = false;
    for line in text.lines().filter(|l| !l.trim_start().starts_with('#')) {
        if in_names && line.starts_with("  ") {
            let (k, v) = line.trim().split_once(':').expect("names entry is i: name");
            names.insert(k.parse::<usize>().expect("class index"), unquote(v));
            continue;
        }
        in_names = false;
        let (k, v) = line.split_once(':').expect("key: value");
        if k == "names" {
            in_names = true;
        } else {
            fields.insert(k.to_string(), unquote(v));
        }
    }
    DataYaml {
        path: PathBuf::from(&fields["path"]),
        train: fields["train"].clone(),
        val: fields["val"].clone(),
        nc: fields["nc"].parse().unwrap(),
        names,
    }
}

/// Even-odd point-in-polygon at pixel centres (pixel coordinates).
fn inside(poly: &[(f64, f64)], x: f64, y: f64) -> bool {
    let mut c = false;
    let n = poly.len();
    for i in 0..n {
        let (a, b) = (poly[i], poly[(i + n - 1) % n]);
        if (a.1 > y) != (b.1 > y) && x < (b.0 - a.0) * (y - a.1) / (b.1 - a.1) + a.0 {
            c = !c;
        }
    }
    c
}

fn files(dir: &Path) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    v.sort();
    v
}

#[test]
fn scene_dataset_is_valid_yolo_segmentation_data_with_polygons_on_the_true_masks() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("scenes");
    ok(datagen(&dir, "2"));
    let yaml = read_data_yaml(&dir.join("data.yaml"));
    assert_eq!(yaml.path, dir.canonicalize().unwrap());
    assert_eq!(yaml.nc, yaml.names.len());
    assert_eq!(
        yaml.names.keys().copied().collect::<Vec<_>>(),
        (0..yaml.nc).collect::<Vec<_>>()
    );
    for name in ["banana", "apple", "avocado"] {
        assert!(
            yaml.names.values().any(|n| n == name),
            "{name} has no class"
        );
    }
    let mut scenes = 0;
    let mut polygons = 0;
    for split in [&yaml.train, &yaml.val] {
        let images = yaml.path.join(split);
        for image_path in files(&images) {
            scenes += 1;
            let image = image::open(&image_path).unwrap().to_rgb8();
            let (w, h) = image.dimensions();
            assert_eq!((w, h), (640, 480));
            // Ultralytics finds labels by replacing /images/ with /labels/ and the extension.
            let label_path = PathBuf::from(
                image_path
                    .to_str()
                    .unwrap()
                    .replace("/images/", "/labels/")
                    .replace(".png", ".txt"),
            );
            let stem = image_path.file_stem().unwrap().to_str().unwrap();
            let split_name = images.file_name().unwrap().to_str().unwrap();
            let meta: serde_json::Value = serde_json::from_str(
                &std::fs::read_to_string(dir.join(format!("meta/{split_name}/{stem}.json")))
                    .unwrap(),
            )
            .unwrap();
            let instances = image::open(dir.join(format!("instances/{split_name}/{stem}.png")))
                .unwrap()
                .to_luma16();
            let depth = image::open(dir.join(format!("depth/{split_name}/{stem}.png")))
                .unwrap()
                .to_luma16();
            // Depth in mm: the table 0.7 m below the camera.
            let centre = depth.get_pixel(320, 400)[0];
            assert!((600..=760).contains(&centre), "table depth {centre} mm");
            let labelled: Vec<&serde_json::Value> = meta["objects"]
                .as_array()
                .unwrap()
                .iter()
                .filter(|o| o["labelled"].as_bool().unwrap())
                .collect();
            let text = std::fs::read_to_string(&label_path).unwrap();
            let lines: Vec<&str> = text.lines().collect();
            assert_eq!(lines.len(), labelled.len(), "{}", label_path.display());
            assert!(!lines.is_empty(), "{} has no fruit", label_path.display());
            for (line, object) in lines.iter().zip(labelled) {
                let fields: Vec<&str> = line.split(' ').collect();
                let class: usize = fields[0].parse().expect("integer class");
                assert!(class < yaml.nc, "class {class} not in data.yaml");
                assert_eq!(yaml.names[&class], object["label"].as_str().unwrap());
                let coords: Vec<f64> = fields[1..].iter().map(|v| v.parse().unwrap()).collect();
                assert!(
                    coords.len() >= 6 && coords.len().is_multiple_of(2),
                    "{line}"
                );
                assert!(coords.iter().all(|v| (0.0..=1.0).contains(v)), "{line}");
                let poly: Vec<(f64, f64)> = coords
                    .chunks(2)
                    .map(|p| (p[0] * w as f64, p[1] * h as f64))
                    .collect();
                // The polygon covers the fruit's true mask: IoU over the pixels.
                let id = object["instance_id"].as_u64().unwrap() as u16;
                let (mut both, mut either) = (0u32, 0u32);
                for (x, y, p) in instances.enumerate_pixels() {
                    let in_mask = p[0] == id;
                    let in_poly = inside(&poly, x as f64, y as f64);
                    both += (in_mask && in_poly) as u32;
                    either += (in_mask || in_poly) as u32;
                }
                let iou = both as f64 / either as f64;
                assert!(iou > 0.9, "{}: {} IoU {iou}", stem, yaml.names[&class]);
                polygons += 1;
            }
        }
    }
    assert_eq!(scenes, 5);
    assert!(
        files(&yaml.path.join(&yaml.val)).len() == 2,
        "val share 0.4 of 5"
    );
    assert!(
        polygons >= 10,
        "{polygons} labelled fruits in 5 scenes of 2-4"
    );
    assert!(dir.join("preview.png").is_file());
}

#[test]
fn same_seed_same_bytes_and_an_interrupted_run_resumes() {
    let tmp = tempfile::tempdir().unwrap();
    let (a, b) = (tmp.path().join("a"), tmp.path().join("b"));
    ok(datagen(&a, "4"));
    ok(datagen(&b, "4"));
    let label = "labels/train/scene_000000.txt";
    let image = "images/train/scene_000000.png";
    for file in [label, image, "depth/train/scene_000000.png"] {
        assert_eq!(
            std::fs::read(a.join(file)).unwrap(),
            std::fs::read(b.join(file)).unwrap(),
            "{file}"
        );
    }
    // An interrupted scene (no label file yet) is redone; the rest is kept.
    let before = std::fs::read(a.join(label)).unwrap();
    std::fs::remove_file(a.join(label)).unwrap();
    std::fs::write(a.join(image), b"half").unwrap();
    let out = datagen(&a, "4");
    ok(out);
    assert_eq!(std::fs::read(a.join(label)).unwrap(), before);
    assert_eq!(
        std::fs::read(a.join(image)).unwrap(),
        std::fs::read(b.join(image)).unwrap()
    );
    // Other settings into the same directory are refused.
    let err = one_line_error(&datagen(&a, "5"));
    assert!(
        err.contains("dataset.json") && err.contains("other settings") && err.contains("seed"),
        "{err}"
    );
}

#[test]
#[cfg_attr(
    not(ci),
    ignore = "needs a Vulkan adapter (lavapipe: mesa-vulkan-drivers, as .ci/run installs)"
)]
fn gpu_rendered_sets_say_so_and_are_not_mixed_with_cpu_renders() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("gpu");
    let args = |device: &'static str| {
        let dir = dir.to_str().unwrap().to_string();
        move |extra: &[&str]| {
            let mut all = vec!["datagen", "scenes", "--count", "2", "--seed", "9"];
            all.extend_from_slice(&["--out", &dir, "--device", device]);
            all.extend_from_slice(extra);
            tactex(&all)
        }
    };
    let out = args("gpu")(&[]);
    let err = String::from_utf8_lossy(&out.stderr).to_string();
    assert!(out.status.success(), "{err}");
    let info: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("dataset.json")).unwrap()).unwrap();
    assert_eq!(info["renderer"], "gpu");
    assert_eq!(
        files(&dir.join("labels/train")).len() + files(&dir.join("labels/val")).len(),
        2
    );
    let err = one_line_error(&args("cpu")(&[]));
    assert!(err.contains("renderer"), "{err}");
}

#[test]
fn bad_scene_datagen_settings_are_one_line_errors() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("x");
    let out = out.to_str().unwrap();
    let cases: [(&[&str], &str); 4] = [
        (&["--count", "0"], "--count"),
        (&["--count", "1", "--fruits", "0-3"], "--fruits"),
        (&["--count", "1", "--kinds", "apple,pineapple"], "pineapple"),
        (&["--count", "1", "--val-fraction", "1.5"], "--val-fraction"),
    ];
    for (args, names) in cases {
        let mut all = vec!["datagen", "scenes", "--out", out];
        all.extend_from_slice(args);
        let err = one_line_error(&tactex(&all));
        assert!(err.contains(names), "{args:?}: {err}");
    }
}
