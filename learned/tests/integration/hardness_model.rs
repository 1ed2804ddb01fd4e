//! The learned-model estimator against a probe model whose output is a known function of the
//! frames (learned/tests/fixtures/hardness-probe.onnx, written by models/train/make_probe_model.py):
//! frame picking, pixel layout, the flip batch and the uncertainty are all checked exactly.

use image::{Rgb, RgbImage};
use std::path::{Path, PathBuf};
use tactex_core::frames::TactileFrame;
use tactex_core::hardness::estimate::{EstimateError, Evidence, HardnessEstimator, PressSequence};
use tactex_core::tactile::spec::TactileSpec;
use tactex_learned::hardness_model::OnnxEstimator;
use tactex_learned::runtime::{OnnxBackend, backend};

fn probe_path() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/hardness-probe.onnx")
}

const COEFFS: [f64; 4] = [-1.0, 0.02, 0.001, 0.005];

/// Frame k: a gradient that differs per channel and per frame, so a wrong pick, channel order
/// or axis order changes the probe's output.
fn frame(k: u32, w: u32, h: u32) -> TactileFrame {
    let image = RgbImage::from_fn(w, h, |x, y| {
        Rgb([
            ((x * 3 + 7 * k) % 256) as u8,
            ((y * 2 + 3 * k * k) % 256) as u8,
            ((x + y + 40 * k) % 256) as u8,
        ])
    });
    TactileFrame {
        image,
        timestamp_s: f64::from(k) * 0.04,
    }
}

fn press(n: u32, w: u32, h: u32) -> PressSequence {
    PressSequence {
        reference: frame(99, w, h),
        frames: (0..n).map(|k| frame(k, w, h)).collect(),
        travel_mm: (0..n).map(|k| 0.25 * f64::from(k)).collect(),
    }
}

fn mean(img: &RgbImage, channels: &[usize]) -> f64 {
    let mut sum = 0.0;
    for p in img.pixels() {
        for &c in channels {
            sum += f64::from(p[c]);
        }
    }
    sum / (img.pixels().len() * channels.len()) as f64
}

#[test]
fn probe_model_output_is_the_known_function_of_the_picked_frames() {
    assert_eq!(
        backend().unwrap(),
        OnnxBackend::Tract,
        "tests run without ORT_DYLIB_PATH"
    );
    let est = OnnxEstimator::load(&probe_path()).unwrap();
    assert_eq!(est.name(), "onnx_probe");
    let seq = press(8, 320, 240);
    let all = [0, 1, 2];
    let (f0, f1, f7) = (
        &seq.frames[0].image,
        &seq.frames[1].image,
        &seq.frames[7].image,
    );
    let expected_ln = COEFFS[0]
        + COEFFS[1] * (mean(f7, &all) - mean(f0, &all))
        + COEFFS[2] * mean(f1, &all)
        + COEFFS[3] * mean(f7, &[0]);
    let got = est.estimate(&seq, &TactileSpec::gelsight_mini()).unwrap();
    let modulus = got.hardness.modulus_mpa().unwrap();
    assert!(
        (modulus.ln() - expected_ln).abs() < 1e-5,
        "ln E {} vs {expected_ln}",
        modulus.ln()
    );
    let Evidence::Learned(ev) = &got.evidence else {
        panic!("learned evidence expected");
    };
    assert_eq!(ev.frames_used, vec![0, 1, 7]);
    assert_eq!(ev.backend, "tract");
    // Every probe term is an image mean, so the four flips agree and the interval is the
    // card's held-out RMSE (0.25 in ln E) either side.
    assert!(ev.flip_spread_ln < 1e-6, "spread {}", ev.flip_spread_ln);
    let [lo, hi] = got.interval.p68_mpa;
    assert!((lo.unwrap().ln() - (expected_ln - 0.25)).abs() < 1e-5);
    assert!((hi.unwrap().ln() - (expected_ln + 0.25)).abs() < 1e-5);
}

#[test]
fn a_sequence_the_model_cannot_read_is_refused() {
    let est = OnnxEstimator::load(&probe_path()).unwrap();
    let spec = TactileSpec::gelsight_mini();
    let short = est.estimate(&press(5, 320, 240), &spec).unwrap_err();
    assert!(
        matches!(&short, EstimateError::BadSequence(m) if m.contains("frame 8")),
        "{short}"
    );
    let small = est.estimate(&press(8, 160, 120), &spec).unwrap_err();
    assert!(
        matches!(&small, EstimateError::BadSequence(m) if m.contains("160x120") && m.contains("320x240")),
        "{small}"
    );
}

fn copy_probe(dir: &Path, card_edit: impl Fn(&mut serde_json::Value)) -> PathBuf {
    let model = dir.join("m.onnx");
    std::fs::copy(probe_path(), &model).unwrap();
    let mut card: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(probe_path().with_extension("json")).unwrap(),
    )
    .unwrap();
    card_edit(&mut card);
    std::fs::write(dir.join("m.json"), card.to_string()).unwrap();
    model
}

#[test]
fn bad_model_files_get_errors_that_name_the_file_and_field() {
    let dir = tempfile::tempdir().unwrap();
    let err = |path: &Path| {
        OnnxEstimator::load(path)
            .err()
            .expect("must fail")
            .to_string()
    };

    let no_card = dir.path().join("lonely.onnx");
    std::fs::copy(probe_path(), &no_card).unwrap();
    let e = err(&no_card);
    assert!(e.contains("lonely.json") && e.contains("model card"), "{e}");

    let model = copy_probe(dir.path(), |c| c["input"] = "pixels".into());
    let e = err(&model);
    assert!(
        e.contains("m.onnx") && e.contains("no input 'pixels'"),
        "{e}"
    );

    let model = copy_probe(dir.path(), |c| c["frame_picks"] = serde_json::json!([1, 7]));
    let e = err(&model);
    assert!(e.contains("m.json") && e.contains("frame_picks"), "{e}");

    let model = copy_probe(dir.path(), |c| c["ln_modulus_rmse"] = (-1.0).into());
    assert!(err(&model).contains("ln_modulus_rmse"));

    let model = copy_probe(dir.path(), |_| {});
    std::fs::write(&model, b"not a protobuf").unwrap();
    let e = err(&model);
    assert!(e.contains("m.onnx") && e.contains("not a model"), "{e}");
}
