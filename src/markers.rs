//! `tactex markers`: marker dots on a tactile frame (real or rendered): their centroids, and
//! with a reference frame each reference marker's displacement (tracked to the nearest dot
//! within 0.45 of the grid pitch, estimated from the reference's own spacing).

use crate::ball_presses::load_rgb;
use anyhow::{Result, bail};
use clap::Args;
use serde::Serialize;
use std::path::PathBuf;
use tactex_core::perception::markers::{
    detect_markers, grid_pitch_px, mean_moved_displacement, track,
};

#[derive(Args, Debug)]
pub struct MarkersArgs {
    /// The tactile frame.
    pub image: PathBuf,
    /// A no-contact frame of the same sensor: report each of its markers' displacement.
    #[arg(long)]
    pub reference: Option<PathBuf>,
    /// Print one JSON object on stdout.
    #[arg(long)]
    pub json: bool,
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
}

pub fn run(args: &MarkersArgs) -> Result<()> {
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
    };
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
    if args.json {
        println!("{}", serde_json::to_string_pretty(&report)?);
        return Ok(());
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
}
