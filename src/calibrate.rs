//! `tactex calibrate`: fits the gradient -> colour table from annotated ball presses and
//! writes a self-contained calibration file.

use crate::ball_presses::{self, Split};
use crate::output::write_bytes_atomic;
use crate::press::positive;
use anyhow::{Context, Result, bail};
use clap::Args;
use std::path::PathBuf;
use tactex_core::ball_calibration::{SampleRule, samples_from_ball_press};
use tactex_core::shading_table::ShadingTable;
use tactex_core::tactile_spec::TactileSpec;
use tactex_sim::gel_render::{CALIBRATION_FORMAT, FitReport, GelCalibration};

#[derive(Args, Debug)]
#[command(allow_negative_numbers = true)]
pub struct CalibrateArgs {
    /// Directory of the ball-press images.
    #[arg(long)]
    pub images: PathBuf,
    /// CSV: image,center_x_px,center_y_px,contact_radius_px.
    #[arg(long)]
    pub annotations: PathBuf,
    /// The sensor's no-contact frame.
    #[arg(long)]
    pub background: PathBuf,
    #[arg(long)]
    pub ball_radius_mm: f64,
    #[arg(long)]
    pub mm_per_px: f64,
    #[arg(long)]
    pub out: PathBuf,
    /// Which presses to fit: calib (all but every third), eval, or all.
    #[arg(long, value_enum, default_value_t = Split::Calib)]
    pub split: Split,
    /// Table nodes over slope magnitude.
    #[arg(long, default_value_t = 12)]
    pub mag_bins: u32,
    /// Table nodes over slope direction.
    #[arg(long, default_value_t = 24)]
    pub dir_bins: u32,
    /// Largest slope (dw/dr) the table covers.
    #[arg(long, default_value_t = 2.5)]
    pub mag_max: f32,
    /// Weight tying neighbouring table nodes together.
    #[arg(long, default_value_t = 20.0)]
    pub smoothness: f64,
    /// Attribution of the images, stored in the file.
    #[arg(long, default_value = "")]
    pub source: String,
}

pub fn run(args: &CalibrateArgs) -> Result<()> {
    let radius = positive("ball-radius-mm", args.ball_radius_mm)?;
    let scale = positive("mm-per-px", args.mm_per_px)?;
    let background = ball_presses::load_rgb(&args.background)?;
    let presses = ball_presses::load(
        &args.images,
        &args.annotations,
        args.split,
        background.dimensions(),
    )?;
    let rule = SampleRule::default();
    let mut samples = Vec::new();
    for (press, img) in &presses {
        if press.contact_radius_px * scale >= radius {
            bail!(
                "{}: {} has a contact radius of {:.2} mm, not smaller than the ball's {radius} mm",
                args.annotations.display(),
                press.image,
                press.contact_radius_px * scale
            );
        }
        samples.extend(samples_from_ball_press(
            img,
            &background,
            press,
            radius,
            scale,
            &rule,
        ));
    }
    let table = ShadingTable::fit(
        &samples,
        args.mag_bins,
        args.dir_bins,
        args.mag_max,
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
    let calib = GelCalibration {
        format: CALIBRATION_FORMAT.into(),
        width: background.width(),
        height: background.height(),
        mm_per_px: scale,
        gel: TactileSpec::gelsight_mini().gel,
        table,
        background_png: GelCalibration::encode_background(&background),
        fit: FitReport {
            images: presses.iter().map(|(p, _)| p.image.clone()).collect(),
            samples: samples.len(),
            rms_grey: rms,
            ball_radius_mm: radius,
        },
        source: args.source.clone(),
    };
    let json = serde_json::to_vec_pretty(&calib)?;
    write_bytes_atomic(&args.out, &json)?;
    println!(
        "{}: fitted {} x {} bins to {} pixels of {} presses; rms residual R {:.2} G {:.2} B {:.2} grey levels",
        args.out.display(),
        args.mag_bins,
        args.dir_bins,
        samples.len(),
        presses.len(),
        rms[0],
        rms[1],
        rms[2]
    );
    Ok(())
}
