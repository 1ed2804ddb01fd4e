//! `tactex detect`: a YOLOv8-seg model on one colour image (a camera frame, real or from
//! `datagen scenes`): boxes, scores, mask areas, and an overlay PNG. For bringing up a
//! detector before it drives the robot.

use crate::app::load_rgb;
use crate::report::output::write_png_atomic;
use crate::report::tail::print_json_or_text;
use anyhow::Result;
use clap::Args;
use image::Rgb;
use serde::Serialize;
use std::path::PathBuf;
use tactex_learned::yolo_seg::YoloSegDetector;

#[derive(Args, Debug)]
pub struct DetectArgs {
    /// The colour image.
    pub image: PathBuf,
    /// The YOLOv8-seg ONNX export.
    #[arg(long)]
    pub model: PathBuf,
    /// Minimum class score, 0 to under 1 (Ultralytics' default 0.25).
    #[arg(long, default_value_t = 0.25)]
    pub confidence: f64,
    /// NMS IoU threshold, 0 to 1 (Ultralytics' default 0.7).
    #[arg(long, default_value_t = 0.7, value_parser = crate::app::flag_range::within(0.0, 1.0))]
    pub iou: f64,
    /// Print one JSON object on stdout.
    #[arg(long)]
    pub json: bool,
    /// Write the image with boxes and masks drawn here (PNG).
    #[arg(long)]
    pub overlay: Option<PathBuf>,
}

#[derive(Serialize)]
struct Found {
    label: String,
    class: usize,
    score: f64,
    /// x0, y0, x1, y1 in pixels (inclusive).
    bbox: [u32; 4],
    mask_px: usize,
}

#[derive(Serialize)]
struct DetectReport {
    image: String,
    model: String,
    backend: String,
    detections: Vec<Found>,
}

pub(crate) fn run(args: &DetectArgs) -> Result<()> {
    anyhow::ensure!(
        (0.0..1.0).contains(&args.confidence),
        "--confidence: {} is not in [0, 1)",
        args.confidence
    );
    let image = load_rgb(&args.image)?;
    let mut detector = YoloSegDetector::load(&args.model)?;
    detector.settings.confidence = args.confidence;
    detector.settings.iou = args.iou;
    let found = detector.detect_image(&image)?;
    if let Some(path) = &args.overlay {
        let mut canvas = image.clone();
        for (d, class) in &found {
            let colour = crate::report::palette::class_colour(*class);
            for (x, y, m) in d.mask.enumerate_pixels() {
                if m[0] > 0 {
                    let p = canvas.get_pixel_mut(x, y);
                    *p = Rgb(std::array::from_fn(|c| {
                        ((u16::from(p[c]) + u16::from(colour[c])) / 2) as u8
                    }));
                }
            }
            let [x0, y0, x1, y1] = d.bbox;
            let rect =
                imageproc::rect::Rect::at(x0 as i32, y0 as i32).of_size(x1 - x0 + 1, y1 - y0 + 1);
            imageproc::drawing::draw_hollow_rect_mut(&mut canvas, rect, colour);
        }
        write_png_atomic(path, &canvas)?;
    }
    let report = DetectReport {
        image: args.image.display().to_string(),
        model: args.model.display().to_string(),
        backend: detector.backend().to_string(),
        detections: found
            .iter()
            .map(|(d, class)| Found {
                label: d.label.clone(),
                class: *class,
                score: d.score,
                bbox: d.bbox,
                mask_px: d.mask.pixels().filter(|p| p[0] > 0).count(),
            })
            .collect(),
    };
    print_json_or_text(&report, args.json, || {
        println!(
            "{}: {} detections ({}, {})",
            report.image,
            report.detections.len(),
            report.model,
            report.backend
        );
        for d in &report.detections {
            println!(
                "  {:<12} {:.3}  box [{}, {}, {}, {}]  mask {} px",
                d.label, d.score, d.bbox[0], d.bbox[1], d.bbox[2], d.bbox[3], d.mask_px
            );
        }
        Ok(())
    })?;
    Ok(())
}
