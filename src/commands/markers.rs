//! `tactex markers`: marker dots on a tactile frame (real or rendered): their centroids, and
//! with a reference frame each reference marker's displacement (tracked to the nearest dot
//! within 0.45 of the grid pitch, estimated from the reference's own spacing).

use crate::app::load_rgb;
use crate::report::output::write_png_atomic;
use crate::report::tail::print_json_or_text;
use anyhow::{Result, bail};
use clap::Args;
use serde::Serialize;
use std::path::PathBuf;
use tactex_core::tactile::markers::{
    detect_markers, grid_pitch_px, mean_moved_displacement, track,
};

#[derive(Args, Debug)]
pub struct MarkersArgs {
    /// The tactile frame.
    pub image: PathBuf,
    /// A no-contact frame of the same sensor: report each of its markers' displacement.
    #[arg(long)]
    pub reference: Option<PathBuf>,
    /// Annotated markers to score the detections against: CSV with a header and columns
    /// Mx,My,dx,dy (FOTS's format: rest position and displacement in whole pixels, truncated,
    /// so the marker is taken at M + d + 1/2); at most 10000 markers, each once.
    #[arg(long)]
    pub annotations: Option<PathBuf>,
    /// With --annotations: write the frame, 3x, with annotated (red) and found (green)
    /// markers and the misses ringed in yellow.
    #[arg(long, requires = "annotations")]
    pub overlay: Option<PathBuf>,
    /// Print one JSON object on stdout.
    #[arg(long)]
    pub json: bool,
}

/// An annotation is found when a detection lies within this distance.
const FOUND_WITHIN_PX: f64 = 1.5;

#[derive(Serialize)]
struct AnnotationScore {
    annotations: String,
    count: usize,
    /// Annotated markers with a detection within 1.5 px.
    found: usize,
    /// The others: where annotated, and how far the nearest detection is.
    misses: Vec<Miss>,
}

#[derive(Serialize)]
struct Miss {
    x_px: f64,
    y_px: f64,
    nearest_px: f64,
}

/// Markers one annotation file lists at most (a GelSight Mini shows about 100).
const MAX_MARKERS: usize = 10_000;

fn read_marker_annotations(path: &std::path::Path) -> Result<Vec<(f64, f64)>> {
    let text = tactex_core::text_file::read_to_string(path)
        .map_err(|e| anyhow::anyhow!("{}: cannot read: {e}", path.display()))?;
    let mut out = Vec::new();
    // Where each marker was first listed (its coordinates' bits -> file line).
    let mut first_line = std::collections::HashMap::new();
    for (i, line) in text.lines().enumerate().skip(1) {
        if line.trim().is_empty() {
            continue;
        }
        let v: Vec<f64> = line
            .split(',')
            .map(|c| c.trim().parse::<f64>())
            .collect::<Result<_, _>>()
            .map_err(|_| {
                anyhow::anyhow!(
                    "{}: line {}: not four numbers Mx,My,dx,dy",
                    path.display(),
                    i + 1
                )
            })?;
        let [mx, my, dx, dy] = v[..] else {
            bail!(
                "{}: line {}: not four numbers Mx,My,dx,dy",
                path.display(),
                i + 1
            );
        };
        let (x, y) = (mx + dx, my + dy);
        let side = f64::from(tactex_core::image_file::MAX_SIDE_PX);
        if !(v.iter().all(|c| c.is_finite())
            && (0.0..side).contains(&x)
            && (0.0..side).contains(&y))
        {
            bail!(
                "{}: line {}: marker at ({}, {}) px is not in an image (0 to {side} px)",
                path.display(),
                i + 1,
                crate::app::flag_range::show(x),
                crate::app::flag_range::show(y)
            );
        }
        if out.len() == MAX_MARKERS {
            bail!(
                "{}: more than {MAX_MARKERS} annotated markers, the most one frame has",
                path.display()
            );
        }
        if let Some(first) = first_line.insert((x.to_bits(), y.to_bits()), i + 1) {
            bail!(
                "{}: line {}: the marker of line {first} again",
                path.display(),
                i + 1
            );
        }
        out.push((x + 0.5, y + 0.5));
    }
    if out.is_empty() {
        bail!("{}: no annotated markers", path.display());
    }
    Ok(out)
}

fn score_annotations(
    path: &std::path::Path,
    annotated: &[(f64, f64)],
    found: &[(f64, f64)],
) -> AnnotationScore {
    let misses: Vec<Miss> = annotated
        .iter()
        .map(|&(x, y)| Miss {
            x_px: x,
            y_px: y,
            nearest_px: found
                .iter()
                .map(|p| (p.0 - x).hypot(p.1 - y))
                .fold(f64::INFINITY, f64::min),
        })
        .filter(|m| m.nearest_px > FOUND_WITHIN_PX)
        .collect();
    AnnotationScore {
        annotations: path.display().to_string(),
        count: annotated.len(),
        found: annotated.len() - misses.len(),
        misses,
    }
}

fn draw_overlay(
    image: &image::RgbImage,
    found: &[(f64, f64)],
    annotated: &[(f64, f64)],
    misses: &[Miss],
) -> image::RgbImage {
    use imageproc::drawing::{draw_cross_mut, draw_hollow_circle_mut};
    const S: u32 = 3;
    let mut canvas = image::imageops::resize(
        image,
        image.width() * S,
        image.height() * S,
        image::imageops::FilterType::Nearest,
    );
    // Detections (and the annotations as scored) put pixel x's centre at x: on the canvas
    // it is at S x + S/2.
    let at = |x: f64, y: f64| {
        let s = S as f64;
        ((s * x + s / 2.0) as i32, (s * y + s / 2.0) as i32)
    };
    for &(x, y) in annotated {
        draw_hollow_circle_mut(&mut canvas, at(x, y), 4, image::Rgb([255, 0, 0]));
    }
    for &(x, y) in found {
        let (cx, cy) = at(x, y);
        draw_cross_mut(&mut canvas, image::Rgb([0, 255, 0]), cx, cy);
    }
    for m in misses {
        draw_hollow_circle_mut(
            &mut canvas,
            at(m.x_px, m.y_px),
            14,
            image::Rgb([255, 255, 0]),
        );
    }
    canvas
}

#[derive(Serialize)]
struct Displacement {
    x_px: f64,
    y_px: f64,
    /// None when the marker was not found near its reference position.
    dx_px: Option<f64>,
    dy_px: Option<f64>,
}

#[derive(Serialize)]
struct MarkersReport {
    image: String,
    count: usize,
    markers: Vec<[f64; 2]>,
    #[serde(skip_serializing_if = "Option::is_none")]
    reference: Option<String>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pitch_px: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    displacements: Option<Vec<Displacement>>,
    #[serde(skip_serializing_if = "Option::is_none")]
    mean_moved_px: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    annotated: Option<AnnotationScore>,
}

pub(crate) fn run(args: &MarkersArgs) -> Result<()> {
    let image = load_rgb(&args.image)?;
    let found = detect_markers(&image);
    let mut report = MarkersReport {
        image: args.image.display().to_string(),
        count: found.len(),
        markers: found.iter().map(|p| [p.0, p.1]).collect(),
        reference: None,
        pitch_px: None,
        displacements: None,
        mean_moved_px: None,
        annotated: None,
    };
    if let Some(path) = &args.annotations {
        let annotated = read_marker_annotations(path)?;
        let score = score_annotations(path, &annotated, &found);
        if let Some(out) = &args.overlay {
            write_png_atomic(
                out,
                &draw_overlay(&image, &found, &annotated, &score.misses),
            )?;
        }
        report.annotated = Some(score);
    }
    if let Some(path) = &args.reference {
        let reference = load_rgb(path)?;
        if reference.dimensions() != image.dimensions() {
            bail!(
                "{}: {} x {} px, the image is {} x {}",
                path.display(),
                reference.width(),
                reference.height(),
                image.width(),
                image.height()
            );
        }
        let rest = detect_markers(&reference);
        let Some(pitch) = grid_pitch_px(&rest) else {
            bail!("{}: fewer than two markers found", path.display());
        };
        let moved = track(&rest, &found, 0.45 * pitch);
        report.mean_moved_px = Some(mean_moved_displacement(&moved));
        report.displacements = Some(
            rest.iter()
                .zip(&moved)
                .map(|(r, d)| Displacement {
                    x_px: r.0,
                    y_px: r.1,
                    dx_px: d.map(|d| d.0),
                    dy_px: d.map(|d| d.1),
                })
                .collect(),
        );
        report.pitch_px = Some(pitch);
        report.reference = Some(path.display().to_string());
    }
    print_json_or_text(&report, args.json, || {
        if let Some(a) = &report.annotated {
            println!(
                "{}: {} of {} annotated markers found within {FOUND_WITHIN_PX} px",
                a.annotations, a.found, a.count
            );
            for m in &a.misses {
                println!(
                    "  missed ({:.1}, {:.1}): nearest detection {:.2} px away",
                    m.x_px, m.y_px, m.nearest_px
                );
            }
        }
        match &report.displacements {
            None => {
                println!("{}: {} markers (x, y px)", report.image, report.count);
                for m in &report.markers {
                    println!("  {:8.2} {:8.2}", m[0], m[1]);
                }
            }
            Some(d) => {
                let lost = d.iter().filter(|d| d.dx_px.is_none()).count();
                println!(
                    "{}: {} markers; {} in the reference (pitch {:.1} px), {lost} lost; mean displacement of those that moved {:.2} px",
                    report.image,
                    report.count,
                    d.len(),
                    report.pitch_px.unwrap_or(0.0),
                    report.mean_moved_px.unwrap_or(0.0)
                );
                println!("  {:>8} {:>8} {:>7} {:>7}", "x", "y", "dx", "dy");
                for m in d {
                    let f = |v: Option<f64>| v.map_or("lost".into(), |v| format!("{v:+.2}"));
                    println!(
                        "  {:8.2} {:8.2} {:>7} {:>7}",
                        m.x_px,
                        m.y_px,
                        f(m.dx_px),
                        f(m.dy_px)
                    );
                }
            }
        }
        Ok(())
    })
}
