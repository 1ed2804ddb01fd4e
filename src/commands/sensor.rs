//! `tactex sensor show|check`: what a sensor profile says, and whether the twin can render
//! with it (its no-contact frame against its background, at its camera noise).

use crate::report::tail::print_json_or_text;
use anyhow::Result;
use clap::{Args, Subcommand};
use serde::Serialize;
use std::path::PathBuf;
use tactex_core::tactile::gel_glow::{ColourGlow, ScalarGlow};
use tactex_core::tactile::sensor_profile::{ProfileId, SensorProfile};
use tactex_core::tactile::ssim::{gray, ssim};
use tactex_sim::render::gel::{CpuRenderer, GelImageFields, PressFrame, SensorOptics};

#[derive(Subcommand)]
pub enum SensorCommand {
    /// Print a profile (default: the built-in GelSight Mini).
    Show(ShowArgs),
    /// Validate a profile and render its no-contact frame against its background.
    Check(CheckArgs),
}

#[derive(Args)]
pub struct ShowArgs {
    /// The profile (TOML); the built-in GelSight Mini if unset.
    pub file: Option<PathBuf>,
    /// Print the profile's TOML (a starting point for one's own: its background is the
    /// twin's synthetic one).
    #[arg(long, conflicts_with = "json")]
    pub toml: bool,
    /// Print one JSON object on stdout.
    #[arg(long)]
    pub json: bool,
}

#[derive(Args)]
pub struct CheckArgs {
    /// The profile (TOML).
    pub file: PathBuf,
    /// Seed of the rendered frame's camera noise.
    #[arg(long, default_value_t = 0)]
    pub seed: u32,
    /// Print one JSON object on stdout.
    #[arg(long)]
    pub json: bool,
}

pub(crate) fn run(command: &SensorCommand) -> Result<()> {
    match command {
        SensorCommand::Show(args) => show(args),
        SensorCommand::Check(args) => check(args),
    }
}

#[derive(Serialize)]
struct Summary {
    sensor: ProfileId,
    source: String,
    width_px: u32,
    height_px: u32,
    mm_per_px: f64,
    pad_mm: [f64; 2],
    frame_rate_hz: f64,
    noise_sigma_grey: f64,
    vignette: f64,
    exposure: f64,
    gel_modulus_mpa: f64,
    gel_poisson: f64,
    gel_thickness_mm: f64,
    background: String,
    shading: String,
    glow: Option<String>,
    markers: String,
    fit: Option<String>,
}

fn summary(p: &SensorProfile) -> Summary {
    let s = &p.spec;
    let m = &s.markers;
    Summary {
        sensor: p.id(),
        source: p.source.clone(),
        width_px: s.width_px,
        height_px: s.height_px,
        mm_per_px: s.mm_per_px,
        pad_mm: s.pad_size_mm(),
        frame_rate_hz: s.frame_rate_hz,
        noise_sigma_grey: p.noise_sigma_grey,
        vignette: p.vignette,
        exposure: p.exposure,
        gel_modulus_mpa: s.gel.modulus_mpa,
        gel_poisson: s.gel.poisson,
        gel_thickness_mm: s.gel.thickness_mm,
        background: match &p.background {
            Some(_) => "a real no-contact frame".into(),
            None => "synthetic".into(),
        },
        shading: match &p.spec.table {
            Some(t) => format!(
                "calibrated table, {} x {} bins up to slope {}",
                t.mag_bins, t.dir_bins, t.mag_max
            ),
            None => "three analytic lights".into(),
        },
        glow: p.spec.glow.as_ref().map(|g| {
            let sigmas = |s: Vec<f32>| s.iter().map(|s| s.to_string()).collect::<Vec<_>>().join(", ");
            let colour = |t: &[ColourGlow]| sigmas(t.iter().map(|t| t.sigma_px).collect());
            let scalar = |t: &[ScalarGlow]| sigmas(t.iter().map(|t| t.sigma_px).collect());
            [
                ("colour", colour(&g.colour)),
                ("magnitude", scalar(&g.magnitude)),
                ("indentation", scalar(&g.indentation)),
                ("indented colour", colour(&g.indented_colour)),
            ]
            .iter()
            .filter(|(_, s)| !s.is_empty())
            .map(|(source, s)| format!("{source} blurred at {s} px"))
            .collect::<Vec<_>>()
            .join("; ")
        }),
        markers: if m.cols * m.rows == 0 {
            "none".into()
        } else {
            format!(
                "{} x {} at {} mm pitch, {} mm radius, darkness {}",
                m.cols, m.rows, m.pitch_mm, m.radius_mm, p.marker_darkness
            )
        },
        fit: p.fit.as_ref().map(|f| {
            format!(
                "{} ball presses (R {} mm), {} pixels, rms residual R {:.2} G {:.2} B {:.2} grey levels",
                f.images.len(),
                f.ball_radius_mm,
                f.samples,
                f.rms_grey[0],
                f.rms_grey[1],
                f.rms_grey[2]
            )
        }),
    }
}

fn show(args: &ShowArgs) -> Result<()> {
    let profile = match &args.file {
        Some(file) => crate::app::sensor::load_profile(file)?,
        None => tactex_core::tactile::sensor_profile::SensorProfile::gelsight_mini(),
    };
    if args.toml {
        let name = args
            .file
            .as_deref()
            .map(SensorProfile::background_path)
            .and_then(|p| p.file_name().map(|n| n.to_string_lossy().into_owned()))
            .unwrap_or_default();
        print!("{}", profile.to_toml(&name));
        return Ok(());
    }
    let s = summary(&profile);
    print_json_or_text(&s, args.json, || {
        println!("{}", s.sensor);
        println!("  sha256      {}", s.sensor.sha256);
        if !s.source.is_empty() {
            println!("  source      {}", s.source);
        }
        println!(
            "  camera      {} x {} px at {} mm/px ({:.1} x {:.1} mm), {} Hz, noise {:.2} grey levels, vignette {}, exposure {}",
            s.width_px,
            s.height_px,
            s.mm_per_px,
            s.pad_mm[0],
            s.pad_mm[1],
            s.frame_rate_hz,
            s.noise_sigma_grey,
            s.vignette,
            s.exposure
        );
        println!(
            "  gel         E {} MPa, nu {}, {} mm thick",
            s.gel_modulus_mpa, s.gel_poisson, s.gel_thickness_mm
        );
        println!("  background  {}", s.background);
        println!("  shading     {}", s.shading);
        if let Some(glow) = &s.glow {
            println!("  glow        {glow}");
        }
        println!("  markers     {}", s.markers);
        if let Some(fit) = &s.fit {
            println!("  fit         {fit}");
        }
        Ok(())
    })
}

#[derive(Serialize)]
struct CheckReport {
    sensor: ProfileId,
    noise_sigma_grey: f64,
    /// The rendered no-contact frame against the profile's background as the renderer lays
    /// it down (vignetting applied): what its markers and camera noise change (grey SSIM, 7x7
    /// window).
    no_contact_ssim: f64,
}

fn check(args: &CheckArgs) -> Result<()> {
    let profile = crate::app::sensor::load_profile(&args.file)?;
    let optics = SensorOptics::for_profile(&profile);
    let (w, h) = (optics.width, optics.height);
    let flat = GelImageFields::flat(w, h);
    let frame = CpuRenderer.render_one(
        &optics,
        &PressFrame {
            fields: &flat,
            seed: args.seed,
        },
    );
    // The background as the renderer lays it down (vignetting applied), without markers or
    // noise.
    let bare = SensorOptics {
        markers: Vec::new(),
        noise_sigma: 0.0,
        ..optics.clone()
    };
    let background = gray(&CpuRenderer.render_one(
        &bare,
        &PressFrame {
            fields: &flat,
            seed: 0,
        },
    ));
    let score =
        ssim(&gray(&frame), &background, w as usize, h as usize, 255.0).ok_or_else(|| {
            anyhow::anyhow!("{}: the frame is too small to score", args.file.display())
        })?;
    let report = CheckReport {
        sensor: profile.id(),
        noise_sigma_grey: profile.noise_sigma_grey,
        no_contact_ssim: score,
    };
    print_json_or_text(&report, args.json, || {
        println!(
            "{}: valid; its no-contact frame against its background: SSIM {:.4} (its markers and {:.2} grey levels of noise)",
            report.sensor, report.no_contact_ssim, report.noise_sigma_grey
        );
        Ok(())
    })?;
    Ok(())
}
