//! `tactex datagen tactile`: same seed and shard give the same bytes, an interrupted run
//! resumes to the same bytes, shards partition the data set, and bad input gets a one-line
//! error. Small and fast settings (hertz level, primitives) keep the debug build quick.

use std::collections::BTreeMap;
use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::Command;

fn tactex(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_tactex"))
        .args(args)
        .output()
        .expect("tactex runs")
}

fn datagen(out: &Path, extra: &[&str]) -> std::process::Output {
    datagen_with(out, "sphere,ellipsoid,box", "11", extra)
}

fn datagen_with(out: &Path, shapes: &str, seed: &str, extra: &[&str]) -> std::process::Output {
    let mut args = vec![
        "datagen",
        "tactile",
        "--out",
        out.to_str().unwrap(),
        "--fidelity",
        "hertz",
        "--shapes",
        shapes,
        "--seed",
        seed,
    ];
    args.extend_from_slice(extra);
    tactex(&args)
}

fn ok(out: std::process::Output) {
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// Every file under `dir` with its bytes, by relative path.
fn tree(dir: &Path) -> BTreeMap<PathBuf, Vec<u8>> {
    fn walk(root: &Path, dir: &Path, out: &mut BTreeMap<PathBuf, Vec<u8>>) {
        for entry in std::fs::read_dir(dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                walk(root, &path, out);
            } else {
                out.insert(
                    path.strip_prefix(root).unwrap().to_path_buf(),
                    std::fs::read(&path).unwrap(),
                );
            }
        }
    }
    let mut out = BTreeMap::new();
    walk(dir, dir, &mut out);
    out
}

fn manifest_lines(dir: &Path, name: &str) -> Vec<serde_json::Value> {
    std::fs::read_to_string(dir.join(name))
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect()
}

#[test]
fn same_seed_same_bytes_and_an_interrupted_run_resumes_to_them() {
    let tmp = tempfile::tempdir().unwrap();
    let (a, b) = (tmp.path().join("a"), tmp.path().join("b"));
    ok(datagen(&a, &["--count", "4"]));
    ok(datagen(&b, &["--count", "4"]));
    let full = tree(&a);
    assert_eq!(full, tree(&b), "two runs with one seed differ");
    assert_eq!(
        full.len(),
        2 + 4 * 9,
        "{:?}",
        full.keys().collect::<Vec<_>>()
    );

    // Interrupt b: keep one whole manifest line and half of the next, lose a frame file.
    let manifest = b.join("shard-0-of-1.jsonl");
    let text = std::fs::read_to_string(&manifest).unwrap();
    let first = text.find('\n').unwrap() + 1;
    std::fs::write(&manifest, &text[..first + 40]).unwrap();
    std::fs::remove_file(b.join("samples/0000002/frame_5.png")).unwrap();
    ok(datagen(&b, &["--count", "4"]));
    assert_eq!(
        full,
        tree(&b),
        "the resumed run differs from the uninterrupted one"
    );

    // Labels: the paper's protocol and the documented fields.
    for line in manifest_lines(&a, "shard-0-of-1.jsonl") {
        let travel: Vec<f64> = serde_json::from_value(line["press"]["travel_mm"].clone()).unwrap();
        assert_eq!(travel.len(), 8);
        for (j, t) in travel.iter().enumerate() {
            assert!((t - 0.25 * j as f64).abs() < 1e-12);
        }
        for field in [
            "modulus_mpa",
            "shore_a",
            "shore_00",
            "offset_mm",
            "yaw_deg",
            "noise_seed",
        ] {
            assert!(!line[field].is_null(), "{field} missing: {line}");
        }
        assert_eq!(line["fidelity"], "hertz");
        assert_eq!(line["contact"]["contact"], true);
    }
}

#[test]
fn shards_partition_the_data_set() {
    let tmp = tempfile::tempdir().unwrap();
    let whole = tmp.path().join("whole");
    let split = tmp.path().join("split");
    ok(datagen(&whole, &["--count", "3"]));
    ok(datagen(&split, &["--count", "3", "--shard", "0/2"]));
    ok(datagen(&split, &["--count", "3", "--shard", "1/2"]));
    let mut lines: Vec<serde_json::Value> = manifest_lines(&split, "shard-0-of-2.jsonl");
    assert_eq!(lines.len(), 2);
    lines.extend(manifest_lines(&split, "shard-1-of-2.jsonl"));
    lines.sort_by_key(|l| l["index"].as_u64());
    assert_eq!(lines, manifest_lines(&whole, "shard-0-of-1.jsonl"));
    let (w, s) = (tree(&whole), tree(&split));
    for (path, bytes) in &w {
        if path.starts_with("samples") {
            assert_eq!(Some(bytes), s.get(path), "{}", path.display());
        }
    }
}

#[test]
fn npz_samples_hold_the_frames_the_gel_and_the_travel() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("npz");
    ok(datagen(&dir, &["--count", "1", "--format", "npz"]));
    let file = std::fs::File::open(dir.join("samples/0000000.npz")).unwrap();
    let mut archive = zip::ZipArchive::new(file).unwrap();
    let mut header = |name: &str| {
        let mut entry = archive.by_name(name).unwrap();
        let mut bytes = Vec::new();
        entry.read_to_end(&mut bytes).unwrap();
        assert_eq!(&bytes[..8], b"\x93NUMPY\x01\x00");
        let len = u16::from_le_bytes([bytes[8], bytes[9]]) as usize;
        assert_eq!((10 + len) % 64, 0);
        (
            String::from_utf8(bytes[10..10 + len].to_vec()).unwrap(),
            bytes.len() - 10 - len,
        )
    };
    let (frames, n) = header("frames.npy");
    assert!(
        frames.contains("'descr': '|u1'") && frames.contains("(9, 240, 320, 3)"),
        "{frames}"
    );
    assert_eq!(n, 9 * 240 * 320 * 3);
    let (gel, n) = header("gel_normal_mm.npy");
    assert!(
        gel.contains("'<f4'") && gel.contains("(8, 240, 320)"),
        "{gel}"
    );
    assert_eq!(n, 8 * 240 * 320 * 4);
    let (travel, n) = header("travel_mm.npy");
    assert!(travel.contains("(8,)"), "{travel}");
    assert_eq!(n, 64);
}

#[test]
fn bad_input_gets_one_clear_line_and_writes_nothing() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("d");
    for (args, expect) in [
        (vec!["--count", "2", "--shard", "2/2"], "--shard"),
        (vec!["--count", "2", "--shard", "a"], "--shard"),
        (vec!["--count", "0"], "--count"),
    ] {
        let out = datagen(&dir, &args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success());
        assert!(
            err.contains(expect) && err.trim().lines().count() == 1,
            "{err}"
        );
        assert!(!dir.exists(), "{args:?} wrote {}", dir.display());
    }
    let out = datagen_with(&dir, "cube", "11", &["--count", "1"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && err.contains("--shapes") && err.contains("cube"),
        "{err}"
    );

    // The output path is a file.
    let file = tmp.path().join("file");
    std::fs::write(&file, "x").unwrap();
    let out = datagen(&file, &["--count", "1"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && err.contains("not a directory"),
        "{err}"
    );

    // A second run into one directory with other settings.
    ok(datagen(&dir, &["--count", "1"]));
    let out = datagen_with(&dir, "sphere,ellipsoid,box", "12", &["--count", "1"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && err.contains("dataset.json") && err.contains("seed"),
        "{err}"
    );
}
