//! `tactex contact`: has a tactile frame (real or rendered) touched something, and where? The
//! paper's contact criterion against a no-contact frame, and the contact circle and region.

use crate::app::flag_range::above;
use crate::app::load_tactile_frame;
use crate::report::tail::print_json_or_text;
use anyhow::{Context, Result, bail};
use clap::Args;
use serde::Serialize;
use std::path::PathBuf;
use tactex_core::tactile::contact::{ContactEvidence, ContactRule, bin_for, contact_evidence};
use tactex_core::tactile::contact_circle::{ContactCircle, estimate_contact_circle};

#[derive(Args, Debug)]
pub struct ContactArgs {
    /// The tactile frame.
    pub image: PathBuf,
    /// A no-contact frame of the same sensor.
    #[arg(long)]
    pub reference: PathBuf,
    /// Millimetres per pixel (above 0 up to 1), to give the circle in mm too (GelSight Mini
    /// at 320x240: 0.0634); frames of pixels finer than 0.05 mm are then binned to it for the
    /// criterion, whose thresholds were measured at that size.
    #[arg(long, value_parser = above(0.0, 1.0))]
    pub mm_per_px: Option<f64>,
    /// Print one JSON object on stdout.
    #[arg(long)]
    pub json: bool,
}

#[derive(Serialize)]
struct ContactReport {
    image: String,
    reference: String,
    evidence: ContactEvidence,
    /// Only when the criterion says contact: a frame without contact has no circle.
    #[serde(skip_serializing_if = "Option::is_none")]
    circle: Option<ContactCircle>,
    #[serde(skip_serializing_if = "Option::is_none")]
    contact_radius_mm: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    contact_area_mm2: Option<f64>,
}

pub(crate) fn run(args: &ContactArgs) -> Result<()> {
    let mm_per_px = args.mm_per_px;
    let image = load_tactile_frame(&args.image)?;
    let reference = load_tactile_frame(&args.reference).context("--reference")?;
    if reference.dimensions() != image.dimensions() {
        bail!(
            "{}: {} x {} px, the image is {} x {}",
            args.reference.display(),
            reference.width(),
            reference.height(),
            image.width(),
            image.height()
        );
    }
    let rule = ContactRule::default();
    let Some(evidence) = contact_evidence(&image, &reference, &rule, mm_per_px) else {
        let bin = bin_for(rule.pixel_mm, mm_per_px);
        if bin > 1 {
            bail!(
                "--mm-per-px {:?}: the frame binned {bin} x {bin} to the criterion's {} mm pixels is smaller than one {} px tile",
                mm_per_px.unwrap_or_default(),
                rule.pixel_mm,
                rule.tile_px,
            );
        }
        bail!(
            "{}: too small for the contact test's {} px tiles",
            args.image.display(),
            rule.tile_px,
        );
    };
    let circle = evidence
        .contact
        .then(|| estimate_contact_circle(&image, &reference))
        .flatten();
    let scale = |c: &ContactCircle| mm_per_px.map(|s| (c.radius_px * s, c.region_area_px2 * s * s));
    let mm = circle.as_ref().and_then(scale);
    let report = ContactReport {
        image: args.image.display().to_string(),
        reference: args.reference.display().to_string(),
        evidence,
        contact_radius_mm: mm.map(|m| m.0),
        contact_area_mm2: mm.map(|m| m.1),
        circle,
    };
    print_json_or_text(&report, args.json, || {
        let e = &report.evidence;
        println!(
            "{}: {} (worst 32 px tile SSIM {:.4}, contact at <= {:.4}; frame SSIM {:.3}{})",
            report.image,
            if e.contact { "contact" } else { "no contact" },
            e.min_tile_ssim,
            e.tile_threshold,
            e.ssim,
            e.marker_px.map_or(String::new(), |m| format!(
                "; markers moved {m:.2} px on average"
            ))
        );
        match &report.circle {
            Some(c) => {
                let mm = report.contact_radius_mm.map_or(String::new(), |r| {
                    format!(
                        " = {r:.3} mm, region {:.3} mm^2",
                        report.contact_area_mm2.unwrap_or(0.0)
                    )
                });
                println!(
                    "  contact circle: centre ({:.1}, {:.1}) px, radius {:.1} px{mm}; outline of {} edge points, {:.2} px from round (rms)",
                    c.centre_px[0],
                    c.centre_px[1],
                    c.radius_px,
                    c.edge_px.len(),
                    c.rms_residual_px
                );
            }
            None if e.contact => println!("  no contact circle found"),
            None => {}
        }
        Ok(())
    })
}
