//! The YOLOv8-seg detector against probe models of Ultralytics' real signature whose outputs
//! are known (learned/tests/fixtures/yolo-*.onnx, written by models/train/make_yolo_probe.py):
//! a red and a green disk are drawn, the probe's boxes sit on them and its prototypes light up
//! on red and on green, so letterbox, decoding, NMS and the masks are checked against the
//! drawing. Bad model files get one clear error each.

use glam::DVec3;
use image::{Rgb, RgbImage};
use std::path::{Path, PathBuf};
use tactex_core::catalog::FruitCatalog;
use tactex_core::frames::DepthImage;
use tactex_core::geometry::{CameraIntrinsics, Pose};
use tactex_core::ground::detect::{Detector, RgbdView};
use tactex_core::query;
use tactex_learned::runtime::OnnxError;
use tactex_learned::yolo_seg::YoloSegDetector;

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures")
        .join(name)
}

const RED: (f64, f64, f64) = (400.0, 200.0, 40.0);
const GREEN: (f64, f64, f64) = (200.0, 300.0, 30.0);

fn in_disk((cx, cy, r): (f64, f64, f64), x: u32, y: u32) -> bool {
    (x as f64 + 0.5 - cx).powi(2) + (y as f64 + 0.5 - cy).powi(2) <= r * r
}

fn scene_image() -> RgbImage {
    RgbImage::from_fn(640, 480, |x, y| {
        if in_disk(RED, x, y) {
            Rgb([220, 40, 40])
        } else if in_disk(GREEN, x, y) {
            Rgb([40, 200, 40])
        } else {
            Rgb([128, 128, 128])
        }
    })
}

fn iou_with_disk(mask: &image::GrayImage, disk: (f64, f64, f64)) -> f64 {
    let (mut both, mut either) = (0u32, 0u32);
    for (x, y, p) in mask.enumerate_pixels() {
        let (a, b) = (p[0] > 0, in_disk(disk, x, y));
        both += (a && b) as u32;
        either += (a || b) as u32;
    }
    both as f64 / either as f64
}

#[test]
fn probe_detections_sit_on_the_drawn_fruit_with_their_masks() {
    let detector = YoloSegDetector::load(&fixture("yolo-seg-probe.onnx")).unwrap();
    assert_eq!(detector.class_names(), ["apple", "lime", "banana"]);
    assert_eq!(detector.input_size(), (640, 640));
    let found = detector.detect_image(&scene_image()).unwrap();
    // The shifted duplicate apple is suppressed; the banana at 0.1 is below 0.25.
    let labels: Vec<(&str, f64)> = found
        .iter()
        .map(|(d, _)| (d.label.as_str(), (d.score * 100.0).round() / 100.0))
        .collect();
    assert_eq!(labels, vec![("apple", 0.9), ("lime", 0.8)]);
    let (apple, lime) = (&found[0].0, &found[1].0);
    // Boxes: input (400, 280) +- 42 is image (400, 200) +- 42 after the 80 px letterbox.
    assert_eq!(apple.bbox, [358, 158, 442, 242]);
    assert_eq!(lime.bbox, [168, 268, 232, 332]);
    // Masks from 4x coarser prototypes, upsampled: the disk within a pixel or so.
    let (a, l) = (
        iou_with_disk(&apple.mask, RED),
        iou_with_disk(&lime.mask, GREEN),
    );
    assert!(a > 0.93, "apple mask IoU {a}");
    assert!(l > 0.9, "lime mask IoU {l}");
}

#[test]
fn prompt_conditioning_keeps_only_the_asked_kind_and_sizes_come_from_depth() {
    let detector = YoloSegDetector::load(&fixture("yolo-seg-probe.onnx")).unwrap();
    let image = scene_image();
    let k = CameraIntrinsics {
        width: 640,
        height: 480,
        fx: 600.0,
        fy: 600.0,
        cx: 320.0,
        cy: 240.0,
    };
    // Looking straight down from 0.7 m; the fruit tops at 0.65 m, the table at 0.7 m.
    let pose = Pose {
        position: DVec3::new(0.0, 0.0, 0.7),
        rotation: glam::DQuat::from_rotation_x(std::f64::consts::PI),
    };
    let depth = DepthImage::from_fn(640, 480, |x, y| {
        image::Luma([if in_disk(RED, x, y) || in_disk(GREEN, x, y) {
            0.65
        } else {
            0.7
        }])
    });
    let view = RgbdView {
        color: &image,
        depth: &depth,
        intrinsics: &k,
        pose: &pose,
    };
    let catalog = FruitCatalog::builtin();
    let q = query::parse("I want to know the hardness of the lime", &catalog).unwrap();
    let found = detector.detect_for(&view, &q).unwrap();
    assert_eq!(found.len(), 1);
    assert_eq!(found[0].label, "lime");
    // The green disk is 60 px across at 0.65 m: 65 mm.
    let length = found[0].size_m[0];
    assert!((length - 0.065).abs() < 0.006, "lime footprint {length} m");
    assert_eq!(detector.name(), "yolo:yolo-seg-probe");
}

fn load_error(path: &Path) -> String {
    match YoloSegDetector::load(path) {
        Ok(_) => panic!("{} loaded", path.display()),
        Err(e @ OnnxError::Model { .. }) => {
            let e = e.to_string();
            assert_eq!(e.lines().count(), 1, "{e}");
            e
        }
        Err(e) => panic!("unexpected error {e}"),
    }
}

#[test]
fn missing_malformed_and_wrong_signature_models_are_clear_errors() {
    let tmp = tempfile::tempdir().unwrap();
    let missing = tmp.path().join("nope.onnx");
    let e = load_error(&missing);
    assert!(e.contains("nope.onnx") && e.contains("cannot read"), "{e}");
    let garbage = tmp.path().join("garbage.onnx");
    std::fs::write(&garbage, "this is not a model").unwrap();
    let e = load_error(&garbage);
    assert!(e.contains("garbage.onnx"), "{e}");
    let e = load_error(&fixture("yolo-seg-probe-unnamed.onnx"));
    assert!(e.contains("no class names"), "{e}");
    let e = load_error(&fixture("yolo-det-probe.onnx"));
    assert!(
        e.contains("has 1 outputs") && e.contains("YOLOv8-seg"),
        "{e}"
    );
    let e = load_error(&fixture("yolo-seg-probe-two-names.onnx"));
    assert!(e.contains("39 channels") && e.contains("2 classes"), "{e}");
    // The hardness model is an ONNX file of another signature altogether.
    let e = load_error(&fixture("hardness-probe.onnx"));
    assert!(e.contains("hardness-probe.onnx"), "{e}");
}
