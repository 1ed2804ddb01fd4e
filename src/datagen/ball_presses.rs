//! `tactex datagen ball-presses`: a sensor's calibration set made in the twin, laid out as
//! `tactex calibrate` reads a real one (FOTS's layout): `background.png`, the presses as
//! `NNNN.png`, `annotations.csv` (`image,center_x_px,center_y_px,contact_radius_px`) and,
//! when the sensor has marker dots, `markers.png` (the flat gel with its dots), plus
//! `presses.json` with each press's truth (travel, force, the sensor). A calibration of
//! these presses can be checked against the sensor that made them, which a real set cannot.
//!
//! Press i is drawn from (seed, i) alone: a rigid ball at a uniform place in the frame (its
//! contact circle inside it), pressed until the solver's contact radius is a uniform share
//! of the ball's radius, rendered with the sensor's camera noise and without marker dots (a
//! calibration gel carries none; neither do FOTS's ball presses).

use crate::app::ball_presses::rebuild;
use crate::report::output::{OutputDir, write_bytes_atomic, write_json_atomic, write_png_atomic};
use anyhow::{Result, bail};
use clap::Args;
use indicatif::{ProgressBar, ProgressStyle};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::Serialize;
use std::fmt::Write as _;
use std::path::PathBuf;
use tactex_core::tactile::ball_calibration::BallPress;
use tactex_sim::contact::{ContactSolver, Fidelity};
use tactex_sim::render::gel::{
    DeviceChoice, GelImageFields, PressFrame, SensorOptics, open_renderer,
};

#[derive(Args, Debug)]
pub struct BallPressDatagenArgs {
    /// Presses; 1 to 1000 (the most `calibrate` reads).
    #[arg(long, value_parser = crate::app::flag_range::count::<usize>(1, 1000))]
    pub count: usize,
    /// Output directory.
    #[arg(long)]
    pub out: PathBuf,
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Sensor profile that renders the presses (TOML); default the built-in GelSight Mini.
    #[arg(long)]
    pub sensor: Option<PathBuf>,
    /// The ball's radius (mm, above 0 up to 100).
    #[arg(long, default_value_t = 2.35, value_parser = crate::app::flag_range::above(0.0, 100.0))]
    pub ball_radius_mm: f64,
    /// Contact radii are drawn uniformly between these shares of the ball's radius, MIN,MAX
    /// (above 0, below 0.95).
    #[arg(long, default_value = "0.35,0.85", value_parser = share_range)]
    pub contact_share: ShareRange,
    /// Contact model of the presses: rigid, hertz, halfspace or layer.
    #[arg(long, default_value = "layer")]
    pub fidelity: Fidelity,
    /// Device that renders: cpu (the default, so that the data never depends on the
    /// machine), gpu or auto.
    #[arg(long, default_value = "cpu")]
    pub device: DeviceChoice,
}

/// The smallest contact radius drawn (pixels).
const MIN_CONTACT_RADIUS_PX: f64 = 3.0;

#[derive(Clone, Copy, Debug)]
pub struct ShareRange(f64, f64);

fn share_range(text: &str) -> Result<ShareRange, String> {
    let parts: Vec<f64> = text
        .split(',')
        .map(|s| {
            s.trim()
                .parse::<f64>()
                .map_err(|_| format!("'{s}' is not a number"))
        })
        .collect::<Result<_, _>>()?;
    match parts[..] {
        [lo, hi] if lo > 0.0 && lo <= hi && hi < 0.95 => Ok(ShareRange(lo, hi)),
        _ => Err(format!(
            "'{text}': expected MIN,MAX with 0 < MIN <= MAX < 0.95"
        )),
    }
}

#[derive(Serialize)]
struct PressTruth {
    image: String,
    centre_px: [f64; 2],
    contact_radius_px: f64,
    travel_mm: f64,
    force_n: f64,
}

#[derive(Serialize)]
struct Manifest {
    format: &'static str,
    seed: u64,
    sensor: tactex_core::tactile::sensor_profile::ProfileId,
    ball_radius_mm: f64,
    mm_per_px: f64,
    fidelity: String,
    presses: Vec<PressTruth>,
}

/// The annotated press `index` draws: its place keeps the contact circle (and a pixel) inside
/// the frame.
fn draw_press(args: &BallPressDatagenArgs, index: usize, optics: &SensorOptics) -> BallPress {
    let mut rng =
        ChaCha8Rng::seed_from_u64(args.seed ^ (index as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15));
    let ShareRange(lo, hi) = args.contact_share;
    let radius_px = rng.random_range(lo..=hi) * args.ball_radius_mm / optics.mm_per_px;
    let margin = radius_px + 1.0;
    let (w, h) = (optics.width as f64, optics.height as f64);
    BallPress {
        image: format!("{index:04}.png"),
        centre_px: [
            rng.random_range(margin..=(w - margin)),
            rng.random_range(margin..=(h - margin)),
        ],
        contact_radius_px: radius_px,
    }
}

pub(crate) fn run(args: &BallPressDatagenArgs) -> Result<()> {
    let profile = crate::app::load_sensor(args.sensor.as_deref())?;
    let with_markers = SensorOptics::for_profile(&profile);
    let optics = SensorOptics {
        markers: Vec::new(),
        ..with_markers.clone()
    };
    // `calibrate` reads slopes from the pixels inside a contact: a few pixels at least.
    let smallest_px = args.contact_share.0 * args.ball_radius_mm / optics.mm_per_px;
    if smallest_px < MIN_CONTACT_RADIUS_PX {
        bail!(
            "--ball-radius-mm {}: its smallest contact is {smallest_px:.2} px in radius at {} mm/px; at least {MIN_CONTACT_RADIUS_PX} px is needed",
            args.ball_radius_mm,
            optics.mm_per_px
        );
    }
    let reach_px = args.contact_share.1 * args.ball_radius_mm / optics.mm_per_px + 1.0;
    if 2.0 * reach_px >= optics.width.min(optics.height) as f64 {
        bail!(
            "--ball-radius-mm {}: a contact of {:.0} px across does not fit the {} x {} frame",
            args.ball_radius_mm,
            2.0 * reach_px,
            optics.width,
            optics.height
        );
    }
    let choice = open_renderer(args.device)?;
    if let Some(note) = &choice.note {
        eprintln!("note: {note}");
    }
    let mut renderer = choice.renderer;
    let out = OutputDir::create("--out", &args.out)?;
    let mut solver = ContactSolver::new();
    let bar = ProgressBar::new(args.count as u64).with_style(
        ProgressStyle::with_template("{bar:40} {pos}/{len} presses, {eta} left")
            .expect("constant template"),
    );
    let gel = profile.spec.gel;
    let mut truths = Vec::with_capacity(args.count);
    let mut csv = String::from("image,center_x_px,center_y_px,contact_radius_px\n");
    for index in 0..args.count {
        let press = draw_press(args, index, &optics);
        let (travel_mm, force_n, fields, warnings) = rebuild(
            &mut solver,
            &press,
            args.ball_radius_mm,
            &gel,
            &optics,
            args.fidelity,
        )?;
        if let Some(w) = warnings.first() {
            bail!("press {index}: {w}; draw smaller contacts (--contact-share)");
        }
        // Seeds 1.. for the presses, 0 for the background: every frame its own noise.
        let frame = PressFrame {
            fields: &fields,
            seed: index as u32 + 1,
        };
        let image = renderer.render_batch(&optics, &[frame])?.remove(0);
        write_png_atomic(&out.path().join(&press.image), &image)?;
        writeln!(
            csv,
            "{},{:.3},{:.3},{:.3}",
            press.image, press.centre_px[0], press.centre_px[1], press.contact_radius_px
        )
        .expect("writing to a String");
        truths.push(PressTruth {
            image: press.image,
            centre_px: press.centre_px,
            contact_radius_px: press.contact_radius_px,
            travel_mm,
            force_n,
        });
        bar.inc(1);
    }
    bar.finish_and_clear();
    let flat = GelImageFields::flat(optics.width, optics.height);
    let background = renderer
        .render_batch(
            &optics,
            &[PressFrame {
                fields: &flat,
                seed: 0,
            }],
        )?
        .remove(0);
    write_png_atomic(&out.path().join("background.png"), &background)?;
    // The sensor's dots on the flat gel, for `calibrate --markers` (a real set brings one).
    if !with_markers.markers.is_empty() {
        let dots = renderer
            .render_batch(
                &with_markers,
                &[PressFrame {
                    fields: &flat,
                    seed: 0,
                }],
            )?
            .remove(0);
        write_png_atomic(&out.path().join("markers.png"), &dots)?;
    }
    write_bytes_atomic(&out.path().join("annotations.csv"), csv.as_bytes())?;
    write_json_atomic(
        &out.path().join("presses.json"),
        &Manifest {
            format: "tactex-ball-presses/1",
            seed: args.seed,
            sensor: profile.id(),
            ball_radius_mm: args.ball_radius_mm,
            mm_per_px: optics.mm_per_px,
            fidelity: args.fidelity.to_string(),
            presses: truths,
        },
    )?;
    out.finish()?;
    println!(
        "{} ball presses of {} ({} x {} px, {} mm/px) in {}",
        args.count,
        profile.id(),
        optics.width,
        optics.height,
        optics.mm_per_px,
        args.out.display()
    );
    Ok(())
}
