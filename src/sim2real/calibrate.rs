//! `tactex calibrate`: fits the gradient -> colour table from annotated ball presses, then the
//! glow round a contact from the same presses rebuilt in the twin, measures the camera's
//! noise, and writes a sensor profile (TOML + its background PNG beside it).

use crate::app::ball_presses::{self, Split, contact_box, rebuild};
use crate::app::estimator_choice::{Beside, EstimatorChoice};
use crate::app::flag_range::{FieldError, choice, count};
use crate::app::request_json::parsed;
#[cfg(feature = "plots")]
use crate::eval::fruits::measure_beside;
use crate::report::output::write_profile_atomic;
use crate::report::tail::print_json_or_text;
use anyhow::{Context, Result, bail};
use clap::Args;
use image::RgbImage;
use serde::{Deserialize, Serialize};
use std::path::PathBuf;
use tactex_core::stats::median;
use tactex_core::tactile::ball_calibration::{
    BallPress, SampleRule, camera_noise_sigma, samples_from_ball_press,
};
use tactex_core::tactile::gel_glow::{GelGlow, GlowDesign, GlowPress};
use tactex_core::tactile::sensor_profile::{CalibrationFit, ProfileId, SensorProfile};
use tactex_core::tactile::shading_table::{ShadingTable, frame_position};
use tactex_core::tactile::spec::{GelSpec, TactileSpec};
use tactex_sim::contact::{ContactSolver, Fidelity};
use tactex_sim::render::gel::{CpuRenderer, SensorOptics};

#[derive(Args, Debug)]
#[command(allow_negative_numbers = true)]
pub struct CalibrateArgs {
    /// Directory of the ball-press images.
    #[arg(long)]
    pub images: PathBuf,
    /// CSV: image,center_x_px,center_y_px,contact_radius_px; at most 1000 presses, each image once.
    #[arg(long)]
    pub annotations: PathBuf,
    /// The sensor's no-contact frame.
    #[arg(long)]
    pub background: PathBuf,
    /// The ball's radius (mm, above 0 up to 100).
    #[arg(long, value_parser = BALL_RADIUS_MM.parser())]
    pub ball_radius_mm: f64,
    /// The frames' scale (mm per pixel, 0.001 to 1).
    #[arg(long, value_parser = MM_PER_PX.parser())]
    pub mm_per_px: f64,
    /// The sensor profile to write (TOML; its background goes beside it as
    /// NAME.background.png).
    #[arg(long)]
    pub out: PathBuf,
    /// The profile's name (default: the output file's stem); one line of at most 100
    /// characters.
    #[arg(long, value_parser = profile_name)]
    pub name: Option<String>,
    /// The gel's Young's modulus (MPa, above 0 up to 1000); default the GelSight Mini's.
    #[arg(long, value_parser = GEL_MODULUS_MPA.parser())]
    pub gel_modulus_mpa: Option<f64>,
    /// The gel's thickness (mm, 0.5 to 50); default the GelSight Mini's.
    #[arg(long, value_parser = GEL_THICKNESS_MM.parser())]
    pub gel_thickness_mm: Option<f64>,
    /// The gel's Poisson ratio (0 to 0.5); default the GelSight Mini's.
    #[arg(long, value_parser = GEL_POISSON.parser())]
    pub gel_poisson: Option<f64>,
    /// The camera's frame rate (Hz, above 0 up to 1000); default the GelSight Mini's.
    #[arg(long, value_parser = FRAME_RATE_HZ.parser())]
    pub frame_rate_hz: Option<f64>,
    /// Which presses to fit: calib (all but every third), eval, or all.
    #[arg(long, default_value = "calib", value_parser = choice::<Split>(&Split::NAMES))]
    pub split: Split,
    /// Table nodes over slope magnitude; 2 to 100, and at most 768 nodes with --dir-bins.
    #[arg(long, value_parser = count::<u32>(MAG_BINS.0, MAG_BINS.1), default_value_t = DEFAULT_MAG_BINS)]
    pub mag_bins: u32,
    /// Table nodes over slope direction; 4 to 256, and at most 768 nodes with --mag-bins.
    #[arg(long, value_parser = count::<u32>(DIR_BINS.0, DIR_BINS.1), default_value_t = DEFAULT_DIR_BINS)]
    pub dir_bins: u32,
    /// Largest slope (dw/dr) the table covers (above 0 up to 100).
    #[arg(long, default_value_t = DEFAULT_MAG_MAX, value_parser = MAG_MAX.parser())]
    pub mag_max: f64,
    /// Weight tying neighbouring table nodes together (0 to 1e6).
    #[arg(long, default_value_t = DEFAULT_SMOOTHNESS, value_parser = SMOOTHNESS.parser())]
    pub smoothness: f64,
    /// Attribution of the images, stored in the file.
    #[arg(long, default_value = "")]
    pub source: String,
    /// A real frame of the sensor's marker grid, flat or pressed (FOTS's markers/press.png):
    /// the profile's grid (columns, rows, pitch, dot size and darkness) is read from it. It
    /// may be the background's size or that turned a quarter. Without it the profile has no
    /// markers (ball presses carry none).
    #[arg(long)]
    pub markers: Option<PathBuf>,
    /// Fit no glow (light scattered in the gel round a contact): the table alone.
    #[arg(long)]
    pub no_glow: bool,
    /// Contact model that rebuilds the presses the glow is fitted to.
    #[arg(long, default_value = "layer")]
    pub fidelity: Fidelity,
    /// Placements of each catalog fruit on which the twin, pressing through the new profile,
    /// measures the default estimator's intervals, written beside the profile as
    /// NAME.indentation-layer.intervals.json (what `ask --sensor NAME.toml` then quotes); 0
    /// for none, else 4 to 1000 (16: 176 presses, 2-3 minutes).
    #[arg(long, value_parser = interval_placements_flag, default_value_t = BESIDE_PLACEMENTS)]
    pub interval_placements: usize,
    /// Print one JSON object on stdout: what was fitted.
    #[arg(long)]
    pub json: bool,
}

/// What `calibrate` fitted and wrote: the profile, and how well its table fits the presses.
#[derive(Serialize, Debug)]
pub struct Calibration {
    /// The profile file written (its background beside it).
    pub profile: PathBuf,
    pub sensor: ProfileId,
    pub presses: usize,
    /// Pixels the table was fitted to.
    pub samples: usize,
    pub mag_bins: u32,
    pub dir_bins: u32,
    /// The table's rms residual over those pixels, R, G, B (grey levels).
    pub rms_grey: [f64; 3],
    /// The camera's noise (1 sigma, grey levels), from the presses' flat gel.
    pub noise_sigma_grey: f64,
    /// The grid read from the marker frame, if one was given.
    pub markers: Option<MarkerReading>,
    /// Whether a glow was fitted.
    pub glow: bool,
    /// The default estimator's interval calibration measured through the new profile and
    /// written beside it (`--interval-placements`), if one was asked for and made.
    pub intervals: Option<BesideIntervals>,
    /// Why the intervals asked for were not measured.
    pub intervals_not_measured: Option<String>,
}

/// An interval calibration written beside the profile.
#[derive(Serialize, Debug)]
pub struct BesideIntervals {
    pub file: PathBuf,
    /// Held-out presses of the twin, read through the profile, it rests on.
    pub presses: usize,
    pub bins: usize,
}

/// `--interval-placements`: 0, or a count in the range the help states.
fn interval_placements_flag(text: &str) -> Result<usize, String> {
    let v: u64 = text.trim().parse().map_err(|_| {
        format!(
            "expected 0, or a whole number from {INTERVAL_PLACEMENTS_MIN} to {INTERVAL_PLACEMENTS_MAX}"
        )
    })?;
    interval_placements_within(v)?;
    Ok(v as usize)
}

/// 0 (none), or enough placements to make the presses a calibration needs, and not more
/// than the most.
fn interval_placements_within(v: u64) -> Result<(), String> {
    if v == 0 || (INTERVAL_PLACEMENTS_MIN..=INTERVAL_PLACEMENTS_MAX).contains(&v) {
        return Ok(());
    }
    let why = if v < INTERVAL_PLACEMENTS_MIN {
        format!(
            " (fewer make under the {} presses an interval calibration needs)",
            tactex_core::hardness::interval_calibration::MIN_PER_BIN
        )
    } else {
        String::new()
    };
    Err(format!(
        "{v}: 0 for none, or {INTERVAL_PLACEMENTS_MIN} to {INTERVAL_PLACEMENTS_MAX}{why}"
    ))
}

/// Placements of each kind `calibrate` measures a new profile's intervals on, by default:
/// 176 presses, three bins (docs/sim-to-real.md).
pub const BESIDE_PLACEMENTS: usize = 16;

/// The fewest placements of each catalog fruit that make the presses an interval
/// calibration needs (11 kinds: 44 presses against 40), and the most.
pub const INTERVAL_PLACEMENTS_MIN: u64 = 4;
pub const INTERVAL_PLACEMENTS_MAX: u64 = 1000;

#[derive(Serialize, Debug)]
pub struct MarkerReading {
    pub frame: PathBuf,
    pub cols: u32,
    pub rows: u32,
    pub pitch_mm: f64,
    pub radius_mm: f64,
    pub darkness: f64,
}

/// The glow's blurs (pixels): colour changes spread over 3-27 px, a wider brightening that
/// follows the change's magnitude, and unblurred indentation terms for the contact's inside
/// (chosen on the FOTS presses, docs/sensor_profile.md).
const GLOW_DESIGN: GlowDesign = GlowDesign {
    colour: &[0.0, 3.0, 9.0, 27.0],
    magnitude: &[9.0, 27.0, 81.0],
    indentation: &[0.0],
    indented_colour: &[0.0],
};

/// The glow that maps the twin's renders of the presses onto the real frames: each press
/// rebuilt and shaded without glow, its change from the flat gel's shading fitted to the
/// real frame's, over the box of four contact radii.
fn fit_glow(
    profile: &SensorProfile,
    presses: &[(BallPress, RgbImage)],
    ball_radius_mm: f64,
    fidelity: Fidelity,
) -> Result<GelGlow> {
    let optics = SensorOptics {
        noise_sigma: 0.0,
        glow: None,
        ..SensorOptics::for_profile(profile)
    };
    let (w, h) = (optics.width, optics.height);
    let mut solver = ContactSolver::new();
    let mut changes = Vec::new();
    for (press, real) in presses {
        let (_, _, fields, _) = rebuild(
            &mut solver,
            press,
            ball_radius_mm,
            &profile.spec.gel,
            &optics,
            fidelity,
        )?;
        let (flat, change) = CpuRenderer.shading_change(&optics, &fields);
        let target: Vec<[f32; 3]> = real
            .pixels()
            .zip(&flat)
            .map(|(p, f)| std::array::from_fn(|c| f32::from(p[c]) - f[c]))
            .collect();
        changes.push((change, fields.normal_mm, target, contact_box(press, w, h)));
    }
    let fitted: Vec<GlowPress> = changes
        .iter()
        .map(|(change, indentation_mm, target, window)| GlowPress {
            change,
            indentation_mm,
            target,
            window: *window,
        })
        .collect();
    GelGlow::fit(&fitted, w as usize, h as usize, &GLOW_DESIGN).context("fitting the glow")
}

/// The marker grid of a real marker frame, in the profile's orientation (a frame turned a
/// quarter has its columns and rows swapped), and its dots' darkness.
fn read_markers(
    path: &std::path::Path,
    (w, h): (u32, u32),
    mm_per_px: f64,
) -> Result<(tactex_core::tactile::spec::MarkerGrid, f64)> {
    let frame = crate::app::load_rgb(path)?;
    let turned = match frame.dimensions() {
        d if d == (w, h) => false,
        d if d == (h, w) => true,
        (fw, fh) => bail!(
            "--markers {}: {fw} x {fh} px; the background is {w} x {h} (or turned, {h} x {w})",
            path.display()
        ),
    };
    let layout = tactex_core::tactile::marker_grid::read_marker_grid(&frame)
        .map_err(|e| anyhow::anyhow!("--markers {}: {e}", path.display()))?;
    let (cols, rows) = if turned {
        (layout.rows, layout.cols)
    } else {
        (layout.cols, layout.rows)
    };
    Ok((
        tactex_core::tactile::spec::MarkerGrid {
            cols,
            rows,
            pitch_mm: layout.pitch_px * mm_per_px,
            radius_mm: layout.radius_px * mm_per_px,
        },
        layout.darkness,
    ))
}

/// `--name`, checked before the fit as the profile will check it.
fn profile_name(s: &str) -> Result<String, String> {
    tactex_core::printable::check_name(s)?;
    Ok(s.to_string())
}

impl CalibrateArgs {
    pub(crate) fn request(&self) -> CalibrateRequest {
        CalibrateRequest {
            images: self.images.clone(),
            annotations: self.annotations.clone(),
            background: self.background.clone(),
            ball_radius_mm: self.ball_radius_mm,
            mm_per_px: self.mm_per_px,
            out: self.out.clone(),
            name: self.name.clone(),
            gel_modulus_mpa: self.gel_modulus_mpa,
            gel_thickness_mm: self.gel_thickness_mm,
            gel_poisson: self.gel_poisson,
            frame_rate_hz: self.frame_rate_hz,
            split: self.split,
            mag_bins: self.mag_bins,
            dir_bins: self.dir_bins,
            mag_max: self.mag_max,
            smoothness: self.smoothness,
            source: self.source.clone(),
            markers: self.markers.clone(),
            glow: !self.no_glow,
            fidelity: self.fidelity,
            interval_placements: self.interval_placements,
        }
    }
}

/// The numbers a calibration takes and their ranges (`tactex calibrate --help` states them).
pub mod fields {
    use crate::app::flag_range::Field;
    use tactex_core::tactile::sensor_profile::{MIN_GEL_THICKNESS_MM, MIN_MM_PER_PX};
    pub const BALL_RADIUS_MM: Field = Field::above("ball_radius_mm", 0.0, 100.0);
    pub const MM_PER_PX: Field = Field::within("mm_per_px", MIN_MM_PER_PX, 1.0);
    pub const GEL_MODULUS_MPA: Field = Field::above("gel_modulus_mpa", 0.0, 1000.0);
    pub const GEL_THICKNESS_MM: Field =
        Field::within("gel_thickness_mm", MIN_GEL_THICKNESS_MM, 50.0);
    pub const GEL_POISSON: Field = Field::within("gel_poisson", 0.0, 0.5);
    pub const FRAME_RATE_HZ: Field = Field::above("frame_rate_hz", 0.0, 1000.0);
    pub const MAG_MAX: Field = Field::above("mag_max", 0.0, 100.0);
    pub const SMOOTHNESS: Field = Field::within("smoothness", 0.0, 1e6);
    /// Table nodes over slope magnitude and direction: whole numbers in these ranges.
    pub const MAG_BINS: (u64, u64) = (2, 100);
    pub const DIR_BINS: (u64, u64) = (4, 256);
    pub const DEFAULT_MAG_BINS: u32 = 12;
    pub const DEFAULT_DIR_BINS: u32 = 24;
    pub const DEFAULT_MAG_MAX: f64 = 2.5;
    pub const DEFAULT_SMOOTHNESS: f64 = 20.0;
}
use fields::*;

/// A calibration from annotated ball presses: `tactex calibrate`'s flags and Python's
/// `tactex.calibrate` keywords map onto it (`--no-glow` is `glow: false`).
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CalibrateRequest {
    /// Directory of the ball-press images.
    pub images: PathBuf,
    /// CSV: image,center_x_px,center_y_px,contact_radius_px.
    pub annotations: PathBuf,
    /// The sensor's no-contact frame.
    pub background: PathBuf,
    pub ball_radius_mm: f64,
    pub mm_per_px: f64,
    /// The sensor profile to write (TOML; its background beside it).
    pub out: PathBuf,
    /// The profile's name; None: the output file's stem.
    #[serde(default)]
    pub name: Option<String>,
    /// The gel's modulus, thickness, Poisson ratio and the camera's frame rate; None: the
    /// GelSight Mini's.
    #[serde(default)]
    pub gel_modulus_mpa: Option<f64>,
    #[serde(default)]
    pub gel_thickness_mm: Option<f64>,
    #[serde(default)]
    pub gel_poisson: Option<f64>,
    #[serde(default)]
    pub frame_rate_hz: Option<f64>,
    #[serde(default = "calib", deserialize_with = "parsed")]
    pub split: Split,
    #[serde(default = "mag_bins")]
    pub mag_bins: u32,
    #[serde(default = "dir_bins")]
    pub dir_bins: u32,
    #[serde(default = "mag_max")]
    pub mag_max: f64,
    #[serde(default = "smoothness")]
    pub smoothness: f64,
    /// Attribution of the images, stored in the file.
    #[serde(default)]
    pub source: String,
    /// A real frame of the sensor's marker grid.
    #[serde(default)]
    pub markers: Option<PathBuf>,
    /// Fit the glow round a contact (else the table alone).
    #[serde(default = "yes")]
    pub glow: bool,
    /// Contact model that rebuilds the presses the glow is fitted to.
    #[serde(default, deserialize_with = "parsed")]
    pub fidelity: Fidelity,
    /// Placements of each catalog fruit the profile's intervals are measured on; 0: none.
    #[serde(default = "interval_placements")]
    pub interval_placements: usize,
}

fn interval_placements() -> usize {
    BESIDE_PLACEMENTS
}

fn calib() -> Split {
    Split::Calib
}
fn mag_bins() -> u32 {
    DEFAULT_MAG_BINS
}
fn dir_bins() -> u32 {
    DEFAULT_DIR_BINS
}
fn mag_max() -> f64 {
    DEFAULT_MAG_MAX
}
fn smoothness() -> f64 {
    DEFAULT_SMOOTHNESS
}
fn yes() -> bool {
    true
}

impl CalibrateRequest {
    /// Every number within the range `calibrate --help` states, however the request was
    /// built.
    pub fn check(&self) -> Result<(), FieldError> {
        BALL_RADIUS_MM.check(self.ball_radius_mm)?;
        MM_PER_PX.check(self.mm_per_px)?;
        let optional = [
            (GEL_MODULUS_MPA, self.gel_modulus_mpa),
            (GEL_THICKNESS_MM, self.gel_thickness_mm),
            (GEL_POISSON, self.gel_poisson),
            (FRAME_RATE_HZ, self.frame_rate_hz),
        ];
        for (field, v) in optional {
            if let Some(v) = v {
                field.check(v)?;
            }
        }
        MAG_MAX.check(self.mag_max)?;
        SMOOTHNESS.check(self.smoothness)?;
        for (name, (lo, hi), v) in [
            ("mag_bins", MAG_BINS, self.mag_bins),
            ("dir_bins", DIR_BINS, self.dir_bins),
        ] {
            if !(lo..=hi).contains(&u64::from(v)) {
                return Err(FieldError::new(
                    name,
                    format!("{v} is outside [{lo}, {hi}]"),
                ));
            }
        }
        if let Some(name) = &self.name {
            profile_name(name).map_err(|e| FieldError::new("name", e))?;
        }
        interval_placements_within(self.interval_placements as u64)
            .map_err(|e| FieldError::new("interval_placements", e))?;
        Ok(())
    }
}

/// Fits the profile the flags describe and writes it to `--out`.
/// The most table nodes (--mag-bins x --dir-bins) a fit may have: its normal equations are
/// dense, so its time grows with the cube of the nodes (12 x 48 took 10 s, 12 x 64 23 s).
pub const MAX_TABLE_NODES: u32 = 768;

pub fn calibrate(args: &CalibrateRequest) -> Result<Calibration> {
    let mut fit = fit_profile(args)?;
    fit.measure_intervals(args.interval_placements);
    Ok(fit)
}

impl Calibration {
    /// Measures the default estimator's intervals through the profile just written and keeps
    /// them beside it. The profile stands on its own: intervals that cannot be made are
    /// reported with why, and the profile is kept (answers through it are then marked
    /// uncalibrated).
    pub fn measure_intervals(&mut self, placements: usize) {
        if placements == 0 {
            self.intervals_not_measured = Some(self.none_asked_for());
            return;
        }
        match measure_beside(&self.profile, placements) {
            Ok((file, c)) => {
                self.intervals = Some(BesideIntervals {
                    file,
                    presses: c.presses,
                    bins: c.bins.len(),
                });
                self.intervals_not_measured = None;
            }
            Err(e) => {
                self.intervals_not_measured = Some(format!(
                    "{e:#} (more placements press more; a gel with marker dots reads far better with its --markers frame)"
                ))
            }
        }
    }

    /// Why no intervals were measured when none were asked for, naming a file beside the
    /// profile that was measured through another one.
    fn none_asked_for(&self) -> String {
        match self.stale_beside() {
            Some(path) => format!(
                "none asked for (interval placements 0); {} beside it was measured through another profile and is not used",
                path.display()
            ),
            None => "none asked for (interval placements 0)".into(),
        }
    }

    /// An interval file beside the profile, under the default estimator's name, measured
    /// through another profile.
    fn stale_beside(&self) -> Option<PathBuf> {
        let estimator: EstimatorChoice = crate::app::DEFAULT_ESTIMATOR
            .parse()
            .expect("the default estimator is named");
        let name = estimator.flag_value();
        match estimator.look_beside(
            &self.profile,
            Fidelity::default().name(),
            &name,
            &self.sensor,
        ) {
            Beside::Stale(path, _) => Some(path),
            _ => None,
        }
    }
}

/// A library built without eval (the `plots` feature) cannot press the catalog.
#[cfg(not(feature = "plots"))]
fn measure_beside(
    _profile: &std::path::Path,
    _placements: usize,
) -> Result<(
    PathBuf,
    tactex_core::hardness::interval_calibration::IntervalCalibration,
)> {
    bail!(
        "this build of the library has no fruit evaluation (its `plots` feature); `tactex calibrate` measures them"
    )
}

/// Fits the profile the request describes and writes it (its background beside it).
fn fit_profile(args: &CalibrateRequest) -> Result<Calibration> {
    args.check()?;
    let (radius, scale) = (args.ball_radius_mm, args.mm_per_px);
    let nodes = args.mag_bins * args.dir_bins;
    if nodes > MAX_TABLE_NODES {
        bail!(
            "--mag-bins {} x --dir-bins {} is {nodes} table nodes; at most {MAX_TABLE_NODES} (the fit's time grows with the cube of the nodes)",
            args.mag_bins,
            args.dir_bins
        );
    }
    if args.out.is_dir() {
        bail!(
            "--out {}: is a directory, not a profile file",
            args.out.display()
        );
    }
    let background = crate::app::load_tactile_frame(&args.background).context("--background")?;
    // Before the fit: a marker frame that cannot be read fails first.
    let markers = match &args.markers {
        Some(path) => Some((path, read_markers(path, background.dimensions(), scale)?)),
        None => None,
    };
    let presses = ball_presses::load(
        &args.images,
        &args.annotations,
        args.split,
        background.dimensions(),
    )?;
    // The profile and its background may not be written over the inputs they are made from.
    let written = [
        args.out.clone(),
        tactex_core::tactile::sensor_profile::SensorProfile::background_path(&args.out),
    ];
    let inputs: Vec<std::path::PathBuf> = [args.background.clone(), args.annotations.clone()]
        .into_iter()
        .chain(args.markers.clone())
        .chain(presses.iter().map(|(p, _)| args.images.join(&p.image)))
        .collect();
    for w in &written {
        if let Some(input) = inputs
            .iter()
            .find(|i| crate::report::output::same_file(i, w))
        {
            bail!(
                "--out {}: would write {} over the input {}; name another file",
                args.out.display(),
                w.display(),
                input.display()
            );
        }
    }
    ball_presses::check_within_ball(&presses, &args.annotations, scale, radius)?;
    let rule = SampleRule::default();
    let mut samples = Vec::new();
    let mut noise = Vec::new();
    for (press, img) in &presses {
        samples.extend(samples_from_ball_press(
            img,
            &background,
            press,
            radius,
            scale,
            &rule,
        ));
        noise.extend(camera_noise_sigma(img, &background, press, &rule));
    }
    let table = ShadingTable::fit(
        &samples,
        args.mag_bins,
        args.dir_bins,
        args.mag_max as f32,
        args.smoothness,
    )
    .context("fitting the shading table")?;
    let mut sq = [0.0f64; 3];
    for s in &samples {
        let got = table.change(s.gx, s.gy, s.u, s.v);
        for c in 0..3 {
            sq[c] += ((got[c] - s.change[c]) as f64).powi(2);
        }
    }
    let rms = sq.map(|v| (v / samples.len() as f64).sqrt());
    // The presses' flat gel drifts from the recorded background (the same smooth change in
    // every press: the table's zero-slope value); the profile's background is the flat gel
    // as the presses saw it, so that its no-contact frame is its background.
    let (w, h) = background.dimensions();
    let flat_gel = image::RgbImage::from_fn(w, h, |x, y| {
        let (u, v) = frame_position(x, y, w, h);
        let drift = table.flat_change(u, v);
        let b = background.get_pixel(x, y);
        image::Rgb(std::array::from_fn(|c| {
            (f32::from(b[c]) + drift[c]).round().clamp(0.0, 255.0) as u8
        }))
    });
    let table = table.split_flat();
    let stock = SensorProfile::gelsight_mini();
    let gel = GelSpec {
        modulus_mpa: args.gel_modulus_mpa.unwrap_or(stock.spec.gel.modulus_mpa),
        poisson: args.gel_poisson.unwrap_or(stock.spec.gel.poisson),
        thickness_mm: args.gel_thickness_mm.unwrap_or(stock.spec.gel.thickness_mm),
    };
    let frame_rate_hz = args.frame_rate_hz.unwrap_or(stock.spec.frame_rate_hz);
    let name = match &args.name {
        Some(n) => n.clone(),
        None => args
            .out
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| "calibrated sensor".into()),
    };
    let noise_sigma_grey = median(&mut noise).unwrap_or(0.0);
    let (grid, marker_darkness, markers) = match markers {
        Some((path, (grid, darkness))) => {
            let reading = MarkerReading {
                frame: path.clone(),
                cols: grid.cols,
                rows: grid.rows,
                pitch_mm: grid.pitch_mm,
                radius_mm: grid.radius_mm,
                darkness,
            };
            (grid, darkness, Some(reading))
        }
        // The ball presses carry no markers: a profile without a marker grid.
        None => (
            tactex_core::tactile::spec::MarkerGrid {
                cols: 0,
                rows: 0,
                ..stock.spec.markers
            },
            stock.marker_darkness,
            None,
        ),
    };
    let mut profile = SensorProfile {
        source: args.source.clone(),
        spec: TactileSpec {
            model: name,
            width_px: w,
            height_px: h,
            mm_per_px: scale,
            gel,
            markers: grid,
            frame_rate_hz,
            table: Some(table),
            glow: None,
            ..stock.spec.clone()
        },
        background: Some(flat_gel),
        noise_sigma_grey,
        // The real background carries the sensor's vignetting.
        vignette: 0.0,
        // The presses' own exposure: the background was taken at it.
        exposure: 1.0,
        marker_darkness,
        fit: Some(CalibrationFit {
            images: presses.iter().map(|(p, _)| p.image.clone()).collect(),
            samples: samples.len(),
            rms_grey: rms,
            ball_radius_mm: radius,
        }),
    };
    if args.glow {
        profile.spec.glow = Some(fit_glow(&profile, &presses, radius, args.fidelity)?);
    }
    profile
        .validate()
        .map_err(|(field, message)| anyhow::anyhow!("the fitted profile: {field}: {message}"))?;
    write_profile_atomic(&args.out, &profile).context("--out")?;
    Ok(Calibration {
        profile: args.out.clone(),
        sensor: profile.id(),
        presses: presses.len(),
        samples: samples.len(),
        mag_bins: args.mag_bins,
        dir_bins: args.dir_bins,
        rms_grey: rms,
        noise_sigma_grey,
        markers,
        glow: profile.spec.glow.is_some(),
        intervals: None,
        intervals_not_measured: None,
    })
}

pub(crate) fn run(args: &CalibrateArgs) -> Result<()> {
    let request = args.request();
    let mut fit = fit_profile(&request)?;
    if !args.json {
        print_fit(&fit);
    }
    if request.interval_placements > 0 {
        eprintln!(
            "measuring the default estimator's intervals through {}: each catalog fruit pressed at {} places (--interval-placements 0 skips this)",
            fit.profile.display(),
            request.interval_placements
        );
    }
    fit.measure_intervals(request.interval_placements);
    match (&fit.intervals, &fit.intervals_not_measured) {
        (Some(i), _) if !args.json => println!(
            "{}: intervals measured on {} twin presses through the profile ({} {})",
            i.file.display(),
            i.presses,
            i.bins,
            if i.bins == 1 { "bin" } else { "bins" }
        ),
        (None, Some(why)) if request.interval_placements > 0 => eprintln!(
            "warning: the profile is written, but its intervals could not be made ({why}); answers through it are marked uncalibrated"
        ),
        (None, Some(why)) if fit.stale_beside().is_some() => eprintln!("note: {why}"),
        _ => {}
    }
    print_json_or_text(&fit, args.json, || Ok(()))
}

/// What was fitted, in lines.
fn print_fit(fit: &Calibration) {
    if let Some(m) = &fit.markers {
        println!(
            "{}: markers {} x {}, pitch {:.3} mm, dot radius {:.3} mm, darkness {:.2}",
            m.frame.display(),
            m.cols,
            m.rows,
            m.pitch_mm,
            m.radius_mm,
            m.darkness
        );
    }
    println!(
        "{}: fitted {} x {} bins to {} pixels of {} presses; rms residual R {:.2} G {:.2} B {:.2} grey levels",
        fit.profile.display(),
        fit.mag_bins,
        fit.dir_bins,
        fit.samples,
        fit.presses,
        fit.rms_grey[0],
        fit.rms_grey[1],
        fit.rms_grey[2]
    );
    println!(
        "camera noise {:.2} grey levels (1 sigma); profile {}",
        fit.noise_sigma_grey, fit.sensor
    );
}

#[cfg(test)]
mod request_tests {
    use super::*;
    use crate::app::request_json::from_json;

    #[test]
    fn a_calibration_from_code_is_held_to_the_ranges_the_flags_state() {
        let base =
            r#""images": "i", "annotations": "a.csv", "background": "b.png", "out": "o.toml""#;
        let parse = |extra: &str| {
            from_json::<CalibrateRequest>(&format!(
                "{{{base}, \"ball_radius_mm\": 2, \"mm_per_px\": 0.05{extra}}}"
            ))
            .unwrap()
        };
        let request = parse("");
        assert!(request.check().is_ok());
        assert_eq!((request.mag_bins, request.dir_bins), (12, 24));
        assert!(request.glow && request.split == Split::Calib);
        for (extra, field) in [
            (r#", "mag_bins": 1"#, "mag_bins"),
            (r#", "dir_bins": 1000"#, "dir_bins"),
            (r#", "gel_poisson": 0.7"#, "gel_poisson"),
            (r#", "smoothness": -1"#, "smoothness"),
            (r#", "name": "a\nb""#, "name"),
            (r#", "interval_placements": 2"#, "interval_placements"),
            (r#", "interval_placements": 1001"#, "interval_placements"),
        ] {
            assert_eq!(parse(extra).check().unwrap_err().field, field, "{extra}");
        }
        let e =
            from_json::<CalibrateRequest>(&format!("{{{base}, \"mm_per_px\": 0.05}}")).unwrap_err();
        assert_eq!(e.field, "ball_radius_mm", "{e}");
        assert_eq!(request.interval_placements, BESIDE_PLACEMENTS);
        assert!(parse(r#", "interval_placements": 0"#).check().is_ok());
    }

    #[test]
    fn the_fewest_interval_placements_make_the_presses_a_calibration_needs() {
        use tactex_core::hardness::interval_calibration::MIN_PER_BIN;
        let kinds = tactex_core::catalog::FruitCatalog::builtin().names().len();
        let presses = |placements: u64| placements as usize * kinds;
        assert!(presses(INTERVAL_PLACEMENTS_MIN) >= MIN_PER_BIN);
        assert!(presses(INTERVAL_PLACEMENTS_MIN - 1) < MIN_PER_BIN);
    }
}
