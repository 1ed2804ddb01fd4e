//! `tactex read`: what the twin reads from one tactile frame (real or rendered) through a
//! sensor's optics: the gel's indentation map, the imprint's peak depth and the contact's
//! size, as the indentation estimator reads every frame of a press; `--out` draws it.

use crate::app::{load_sensor, load_tactile_frame};
use crate::report::indentation_view::indentation_view;
use crate::report::output::write_png_atomic;
use crate::report::tail::print_json_or_text;
use anyhow::{Context, Result, bail};
use clap::Args;
use serde::{Deserialize, Serialize};
use std::path::PathBuf;
use tactex_core::tactile::frame_reading::{FrameReading, read_frame};
use tactex_core::tactile::sensor_profile::ProfileId;
use tactex_core::tactile::slopes::ColourDrift;

#[derive(Args, Debug)]
pub struct ReadArgs {
    /// The tactile frame.
    pub image: PathBuf,
    /// A no-contact frame of the same sensor; default the profile's background.
    #[arg(long)]
    pub reference: Option<PathBuf>,
    /// Sensor profile whose optics the frame is read through (TOML); default the built-in
    /// GelSight Mini.
    #[arg(long)]
    pub sensor: Option<PathBuf>,
    /// Write the frame beside its indentation map, the contact outlined (PNG).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Print one JSON object on stdout.
    #[arg(long)]
    pub json: bool,
}

impl ReadArgs {
    pub(crate) fn request(&self) -> ReadRequest {
        ReadRequest {
            image: self.image.clone(),
            reference: self.reference.clone(),
            sensor: self.sensor.clone(),
            out: self.out.clone(),
        }
    }
}

/// One frame to read: `tactex read`'s arguments and Python's `tactex.read` keywords.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ReadRequest {
    /// The tactile frame (PNG of the sensor's size).
    pub image: PathBuf,
    /// A no-contact frame of the same sensor; None: the profile's background.
    #[serde(default)]
    pub reference: Option<PathBuf>,
    /// Sensor profile whose optics the frame is read through; None: the built-in Mini.
    #[serde(default)]
    pub sensor: Option<PathBuf>,
    /// Where the frame beside its indentation map will be written (checked here; the
    /// caller writes it with `write_picture`).
    #[serde(default)]
    pub out: Option<PathBuf>,
}

/// Shallower than this no imprint is reported: the reading of a frame against itself, or of
/// noise, integrates to micrometres.
pub const MIN_IMPRINT_MM: f64 = 0.01;

#[derive(Serialize)]
pub struct ReadReport {
    pub image: String,
    /// The no-contact frame's file; null when it is the profile's background.
    pub reference: Option<String>,
    pub sensor: ProfileId,
    /// Whether an imprint was read (a peak of at least `MIN_IMPRINT_MM`); without one the
    /// contact's figures are null.
    pub imprint: bool,
    /// The imprint's depth into the gel (mean of the 20 deepest pixels).
    pub peak_depth_mm: f64,
    /// The contact's semi-axes, wide then narrow (mm), from the edge `contact_edge` names.
    pub contact_axes_mm: Option<[f64; 2]>,
    /// Where the contact's size was taken: "outline" (the round outline where the gel's
    /// slope peaks) or "half_depth" (the region deeper than half the peak, where the frame
    /// shows no round outline: a first touch, an imprint cut by the frame).
    pub contact_edge: Option<&'static str>,
    /// The radius of the circle of the contact's area (the semi-axes' geometric mean).
    pub contact_radius_mm: Option<f64>,
    /// Whether the imprint lies within the frame (else its depth reads short).
    pub within_frame: Option<bool>,
    /// Share of the pixels whose shading could be read.
    pub readable_share: f64,
}

/// Reads the frame as the estimators do.
pub fn read(args: &ReadRequest) -> Result<(ReadReport, FrameReading, image::RgbImage)> {
    if let Some(out) = &args.out {
        crate::report::output::check_png_path(out).context("--out")?;
    }
    let profile = load_sensor(args.sensor.as_deref())?;
    let image = load_tactile_frame(&args.image)?;
    let (reference, reference_name) = match (&args.reference, &profile.background) {
        (Some(path), _) => (
            load_tactile_frame(path).context("--reference")?,
            Some(path.display().to_string()),
        ),
        (None, Some(bg)) => (bg.clone(), None),
        (None, None) => bail!(
            "--reference: needed, the sensor profile {} has no background frame",
            profile.id()
        ),
    };
    let spec = &profile.spec;
    let size = (spec.width_px, spec.height_px);
    if image.dimensions() != size {
        return Err(crate::app::image_input::ImageInputError::new(
            &args.image,
            format!(
                "{} x {} px, the sensor {} has {} x {}",
                image.width(),
                image.height(),
                profile.id(),
                size.0,
                size.1
            ),
        )
        .into());
    }
    if reference.dimensions() != size {
        bail!(
            "--reference {}: {} x {} px, the sensor {} has {} x {}",
            reference_name
                .as_deref()
                .unwrap_or("(the profile's background)"),
            reference.width(),
            reference.height(),
            profile.id(),
            size.0,
            size.1
        );
    }
    if let Some(out) = &args.out {
        use crate::report::output::same_file;
        // The profile's own files too: its background is the default reference.
        let sensor_files = args
            .sensor
            .iter()
            .flat_map(|s| tactex_core::tactile::sensor_profile::SensorProfile::files(s));
        let inputs: Vec<PathBuf> = [args.image.clone()]
            .into_iter()
            .chain(args.reference.clone())
            .chain(sensor_files)
            .collect();
        if inputs.iter().any(|p| same_file(p, out)) {
            bail!(
                "--out {}: is an input (a frame or the sensor profile's file); name another file",
                out.display()
            );
        }
    }
    let reading =
        read_frame(&image, &reference, spec, ColourDrift::Measured).expect("sizes were checked");
    let readable = reading.valid.iter().filter(|v| **v).count();
    let imprint = reading.peak_mm >= MIN_IMPRINT_MM;
    let report = ReadReport {
        image: args.image.display().to_string(),
        reference: reference_name,
        sensor: profile.id(),
        imprint,
        peak_depth_mm: reading.peak_mm.max(0.0),
        contact_axes_mm: imprint.then_some(reading.contact_axes_mm),
        contact_edge: imprint.then(|| reading.contact_edge()),
        contact_radius_mm: imprint.then(|| reading.contact_radius_mm()),
        within_frame: imprint.then_some(reading.within_frame),
        readable_share: readable as f64 / reading.valid.len() as f64,
    };
    Ok((report, reading, image))
}

/// The frame beside its indentation map, written to `out` (`--out`).
pub fn write_picture(
    out: &std::path::Path,
    image: &image::RgbImage,
    reading: &FrameReading,
) -> Result<()> {
    write_png_atomic(out, &indentation_view(image, reading)).context("--out")
}

pub(crate) fn run(args: &ReadArgs) -> Result<()> {
    let (report, reading, image) = read(&args.request())?;
    if let Some(out) = &args.out {
        write_picture(out, &image, &reading)?;
    }
    print_json_or_text(&report, args.json, || {
        let (Some(axes), Some(radius), Some(within)) = (
            report.contact_axes_mm,
            report.contact_radius_mm,
            report.within_frame,
        ) else {
            println!(
                "{}: no imprint read (none {MIN_IMPRINT_MM} mm deep or more; {:.0}% of the pixels readable); read through {}",
                report.image,
                100.0 * report.readable_share,
                report.sensor
            );
            return Ok(());
        };
        let edge = match report.contact_edge {
            Some("outline") => "the outline where the slope peaks",
            _ => "the half-depth region",
        };
        println!(
            "{}: peak depth {:.3} mm, contact radius {:.3} mm (semi-axes {:.3} x {:.3} mm, from {edge}){}; read through {}",
            report.image,
            report.peak_depth_mm,
            radius,
            axes[0],
            axes[1],
            if within {
                ""
            } else {
                ", the imprint reaches the frame's edge (its depth reads short)"
            },
            report.sensor
        );
        Ok(())
    })
}
