//! GelSight Mini frame processing against the vendor SDK's own output: a 3280x2464 MJPG
//! fixture frame, and the 320x240 frame OpenCV makes of it with the SDK's
//! `resize_crop_mini` (generated with OpenCV 5.0 in Python; decoders differ by a grey
//! level here and there, so the comparison allows that).

use std::path::Path;
use tactex_hw::gelsight_mini::{FrameError, HEIGHT, WIDTH, crop_to_gel, frame_from_mjpg};

fn fixture(name: &str) -> Vec<u8> {
    std::fs::read(
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("tests/fixtures")
            .join(name),
    )
    .expect("fixture")
}

#[test]
fn a_native_frame_is_cropped_and_resized_as_the_vendor_sdk_does() {
    let ours = frame_from_mjpg(&fixture("gelsight_mini_3280x2464.jpg")).unwrap();
    assert_eq!(ours.dimensions(), (WIDTH, HEIGHT));
    let vendor = tactex_core::image::load_from_memory(&fixture(
        "gelsight_mini_3280x2464_vendor_320x240.png",
    ))
    .unwrap()
    .to_rgb8();
    let diffs: Vec<i32> = ours
        .as_raw()
        .iter()
        .zip(vendor.as_raw())
        .map(|(a, b)| (i32::from(*a) - i32::from(*b)).abs())
        .collect();
    let mean = diffs.iter().sum::<i32>() as f64 / diffs.len() as f64;
    let max = *diffs.iter().max().unwrap();
    eprintln!("mean |diff| {mean:.3}, max {max}");
    assert!(mean <= 0.1 && max <= 4, "mean {mean:.3}, max {max}");
}

#[test]
fn garbage_and_tiny_frames_are_errors_not_panics() {
    let e = frame_from_mjpg(b"not a jpeg").unwrap_err();
    assert!(matches!(e, FrameError::Decode(_)), "{e}");
    let tiny = tactex_core::image::RgbImage::new(10, 8);
    assert!(matches!(
        crop_to_gel(&tiny),
        Err(FrameError::TooSmall { .. })
    ));
}
