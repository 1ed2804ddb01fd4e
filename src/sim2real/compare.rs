//! `tactex compare`: sim-to-real on annotated ball presses (a recorded session's presses:
//! `compare_session`). Each press is rebuilt in the twin
//! (the ball at the annotated centre, pressed until the contact solver's contact radius is the
//! annotated one, since the depth was not recorded), rendered through the calibration, and
//! scored against the real frame: SSIM (grey, 7x7 uniform window, data range 255, as
//! scikit-image) and mean absolute intensity error, over the whole frame and over the contact
//! (a box of four contact radii around it), next to the score of the bare background. The
//! contact circle is estimated on the real frame and on the rendered one and scored against
//! the marked circle.

use crate::app::ball_presses::{self, Split, contact_box, rebuild};
use crate::app::estimator_choice::EstimatorChoice;
use crate::app::flag_range::{FieldError, choice, flag};
use crate::app::press_options::fields::GEL_MODULUS_MPA;
use crate::app::request_json::parsed;
use crate::report::output::{OutputDir, write_json_atomic, write_png_atomic};
use crate::report::side_by_side::side_by_side;
use crate::report::tail::print_json_or_text;
use crate::sim2real::compare_session::{SessionCompare, SessionComparison, compare_session};
use crate::sim2real::contact_circle_score::{CircleScore, CircleSummary, score_circle, summarise};
use crate::sim2real::reading_score::{self, ReadingScore, ReadingSummary, score_reading};
use anyhow::{Result, bail};
use clap::Args;
use image::RgbImage;
use serde::{Deserialize, Serialize};
use std::path::PathBuf;
use tactex_core::tactile::ball_calibration::BallPress;
use tactex_core::tactile::sensor_profile::SensorProfile;
use tactex_core::tactile::ssim::{gray, ssim};
use tactex_sim::contact::{ContactSolver, Fidelity};
use tactex_sim::render::gel::{
    DeviceChoice, GelImageFields, PressFrame, SensorOptics, open_renderer,
};

#[derive(Args, Debug)]
pub struct CompareArgs {
    /// Sensor profile: for ball presses, the calibrated one (`tactex calibrate`) whose
    /// background and table render the rebuilt presses; with --session, the twin's sensor
    /// (default the built-in GelSight Mini).
    #[arg(long, required_unless_present = "session")]
    pub sensor: Option<PathBuf>,
    /// Folder of the real ball-press frames.
    #[arg(long, required_unless_present = "session", conflicts_with = "session")]
    pub images: Option<PathBuf>,
    /// CSV of the annotated contact circles.
    #[arg(long, required_unless_present = "session", conflicts_with = "session")]
    pub annotations: Option<PathBuf>,
    /// Instead of ball presses: a recorded session (`ask --record`), every press rebuilt in
    /// the twin and scored recorded against rebuilt.
    #[arg(long)]
    pub session: Option<PathBuf>,
    /// With --session: the objects as they stood, for a session that carries no scene (one
    /// recorded on real devices).
    #[arg(long, conflicts_with_all = ["images", "annotations"])]
    pub scene: Option<PathBuf>,
    /// With --session: the twin's seed (default: the session's).
    #[arg(long, conflicts_with_all = ["images", "annotations"])]
    pub seed: Option<u64>,
    /// With --session: the twin's gel modulus (MPa, 0.01 to 50) instead of the stock 0.3.
    #[arg(long, conflicts_with_all = ["images", "annotations"], value_parser = GEL_MODULUS_MPA.parser())]
    pub gel_modulus_mpa: Option<f64>,
    /// With --session: the hardness estimator that reads both presses (learned,
    /// indentation, hertz or FILE.onnx).
    #[arg(long, conflicts_with_all = ["images", "annotations"], default_value = crate::app::DEFAULT_ESTIMATOR)]
    pub estimator: crate::app::estimator_choice::EstimatorChoice,
    /// Which presses to score: eval (every third, held out of calibration), calib, or all.
    #[arg(long, default_value = "eval", value_parser = choice::<Split>(&Split::NAMES))]
    pub split: Split,
    /// Contact model that rebuilds each press.
    #[arg(long, default_value = "layer")]
    pub fidelity: Fidelity,
    /// Rendering device: auto, gpu or cpu.
    #[arg(long, default_value = "auto")]
    pub device: DeviceChoice,
    /// Render without the profile's glow (light scattered in the gel), to see what it adds.
    #[arg(long, conflicts_with = "session")]
    pub no_glow: bool,
    /// Write real | rendered | difference images per press here.
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Print one JSON object on stdout.
    #[arg(long)]
    pub json: bool,
}

#[derive(Serialize, Debug, Clone, Copy, Default)]
pub struct Scores {
    pub ssim: f64,
    pub mae: f64,
    pub ssim_contact: f64,
    pub mae_contact: f64,
}

#[derive(Serialize, Debug)]
pub struct PressComparison {
    pub image: String,
    pub contact_radius_px: f64,
    /// Travel past first touch that gives the annotated contact radius.
    pub depth_mm: f64,
    pub force_n: f64,
    pub rendered: Scores,
    /// The bare no-contact frame scored the same way: what rendering the press adds.
    pub background_only: Scores,
    /// The contact circle estimated on the real frame (against the calibration's no-contact
    /// frame) and on the rendered one (against the rendered no-contact frame).
    pub circle_real: Option<CircleScore>,
    pub circle_rendered: Option<CircleScore>,
    /// The frame read through the profile (indentation map, as the estimators read it): its
    /// peak depth against the rebuilt press's and its contact radius against the marked one.
    pub reading_real: Option<ReadingScore>,
    pub reading_rendered: Option<ReadingScore>,
    pub warnings: Vec<String>,
}

#[derive(Serialize, Debug)]
pub struct CompareReport {
    /// The calibrated profile the presses were rendered through.
    pub sensor: tactex_core::tactile::sensor_profile::ProfileId,
    pub split: String,
    pub fidelity: String,
    /// Whether the presses were rendered with the profile's glow.
    pub glow: bool,
    pub device: String,
    pub presses: Vec<PressComparison>,
    pub mean: Scores,
    pub background_only_mean: Scores,
    pub circle_real: CircleSummary,
    pub circle_rendered: CircleSummary,
    pub reading_real: ReadingSummary,
    pub reading_rendered: ReadingSummary,
}

/// Mean absolute difference over all channels (grey levels).
fn mae(a: &RgbImage, b: &RgbImage, window: [u32; 4]) -> f64 {
    let [x0, y0, x1, y1] = window;
    let mut sum = 0.0;
    for y in y0..y1 {
        for x in x0..x1 {
            let (p, q) = (a.get_pixel(x, y), b.get_pixel(x, y));
            sum += (0..3).map(|c| p[c].abs_diff(q[c]) as f64).sum::<f64>();
        }
    }
    sum / (3 * (x1 - x0) * (y1 - y0)) as f64
}

fn ssim_in(a: &RgbImage, b: &RgbImage, window: [u32; 4]) -> f64 {
    let [x0, y0, x1, y1] = window;
    let w = a.width() as usize;
    let crop = |g: &[f64]| -> Vec<f64> {
        (y0..y1)
            .flat_map(|y| (x0..x1).map(move |x| (x, y)))
            .map(|(x, y)| g[y as usize * w + x as usize])
            .collect()
    };
    let (ga, gb) = (crop(&gray(a)), crop(&gray(b)));
    ssim(&ga, &gb, (x1 - x0) as usize, (y1 - y0) as usize, 255.0).unwrap_or(f64::NAN)
}

fn scores(real: &RgbImage, rendered: &RgbImage, press: &BallPress) -> Scores {
    let (w, h) = real.dimensions();
    let full = [0, 0, w, h];
    let contact = contact_box(press, w, h);
    Scores {
        ssim: ssim_in(real, rendered, full),
        mae: mae(real, rendered, full),
        ssim_contact: ssim_in(real, rendered, contact),
        mae_contact: mae(real, rendered, contact),
    }
}

fn mean(all: impl Iterator<Item = Scores>) -> Scores {
    let v: Vec<Scores> = all.collect();
    let n = v.len().max(1) as f64;
    Scores {
        ssim: v.iter().map(|s| s.ssim).sum::<f64>() / n,
        mae: v.iter().map(|s| s.mae).sum::<f64>() / n,
        ssim_contact: v.iter().map(|s| s.ssim_contact).sum::<f64>() / n,
        mae_contact: v.iter().map(|s| s.mae_contact).sum::<f64>() / n,
    }
}

/// What `compare` found: ball presses or a recorded session, each rebuilt and scored.
#[derive(Serialize, Debug)]
#[serde(untagged)]
pub enum Comparison {
    BallPresses(CompareReport),
    Session(SessionComparison),
}

impl CompareArgs {
    pub(crate) fn request(&self) -> CompareRequest {
        CompareRequest {
            sensor: self.sensor.clone(),
            images: self.images.clone(),
            annotations: self.annotations.clone(),
            session: self.session.clone(),
            scene: self.scene.clone(),
            seed: self.seed,
            gel_modulus_mpa: self.gel_modulus_mpa,
            estimator: self.estimator.clone(),
            split: self.split,
            fidelity: self.fidelity,
            device: self.device,
            glow: !self.no_glow,
            out: self.out.clone(),
        }
    }
}

/// What `compare` scores: annotated real ball presses rebuilt through a calibrated profile,
/// or a recorded session rebuilt in the twin. `tactex compare`'s flags and Python's
/// `tactex.compare` keywords map onto it (`--no-glow` is `glow: false`).
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CompareRequest {
    /// For ball presses, the calibrated profile; with `session`, the twin's sensor.
    #[serde(default)]
    pub sensor: Option<PathBuf>,
    /// Folder of the real ball-press frames.
    #[serde(default)]
    pub images: Option<PathBuf>,
    /// CSV of the annotated contact circles.
    #[serde(default)]
    pub annotations: Option<PathBuf>,
    /// A recorded session (`ask --record`) instead of ball presses.
    #[serde(default)]
    pub session: Option<PathBuf>,
    /// With `session`: the objects as they stood, for a session that carries no scene.
    #[serde(default)]
    pub scene: Option<PathBuf>,
    /// With `session`: the twin's seed (default: the session's).
    #[serde(default)]
    pub seed: Option<u64>,
    /// With `session`: the twin's gel modulus (MPa).
    #[serde(default)]
    pub gel_modulus_mpa: Option<f64>,
    /// With `session`: the estimator that reads both presses.
    #[serde(default = "default_estimator", deserialize_with = "parsed")]
    pub estimator: EstimatorChoice,
    /// Which presses to score.
    #[serde(default = "held_out", deserialize_with = "parsed")]
    pub split: Split,
    #[serde(default, deserialize_with = "parsed")]
    pub fidelity: Fidelity,
    #[serde(default, deserialize_with = "parsed")]
    pub device: DeviceChoice,
    /// Render with the profile's glow (ball presses).
    #[serde(default = "yes")]
    pub glow: bool,
    /// Write real | rendered | difference images per press here.
    #[serde(default)]
    pub out: Option<PathBuf>,
}

fn default_estimator() -> EstimatorChoice {
    crate::app::DEFAULT_ESTIMATOR
        .parse()
        .expect("the default estimator is registered")
}

fn held_out() -> Split {
    Split::Eval
}

fn yes() -> bool {
    true
}

impl CompareRequest {
    /// The rules the CLI's parser keeps between the flags, for a request built in code.
    pub fn check(&self) -> Result<(), FieldError> {
        if let Some(e) = self.gel_modulus_mpa {
            GEL_MODULUS_MPA.check(e)?;
        }
        if self.session.is_some() {
            let ball_only = [
                ("images", self.images.is_some()),
                ("annotations", self.annotations.is_some()),
                ("glow", !self.glow),
            ];
            if let Some((field, _)) = ball_only.iter().find(|(_, given)| *given) {
                return Err(FieldError::new(
                    field,
                    format!("for ball presses; not with {}", flag("session")),
                ));
            }
        } else {
            let session_only = [
                ("scene", self.scene.is_some()),
                ("seed", self.seed.is_some()),
                ("gel_modulus_mpa", self.gel_modulus_mpa.is_some()),
            ];
            if let Some((field, _)) = session_only.iter().find(|(_, given)| *given) {
                return Err(FieldError::new(
                    field,
                    format!("read only with {}", flag("session")),
                ));
            }
            let needed = [
                ("sensor", self.sensor.is_none()),
                ("images", self.images.is_none()),
                ("annotations", self.annotations.is_none()),
            ];
            if let Some((field, _)) = needed.iter().find(|(_, missing)| *missing) {
                return Err(FieldError::new(
                    field,
                    format!(
                        "needed: ball presses take {}, {} and {}, or give {} DIR",
                        flag("sensor"),
                        flag("images"),
                        flag("annotations"),
                        flag("session")
                    ),
                ));
            }
        }
        Ok(())
    }

    fn session_compare(&self) -> Option<SessionCompare<'_>> {
        let session = self.session.as_deref()?;
        Some(SessionCompare {
            session,
            scene: self.scene.as_deref(),
            seed: self.seed,
            gel_modulus_mpa: self.gel_modulus_mpa,
            sensor: self.sensor.as_deref(),
            fidelity: self.fidelity,
            estimator: &self.estimator,
            out: self.out.as_deref(),
            json: false,
        })
    }
}

/// Runs the comparison the flags name, writing `--out` when given.
pub fn compare(args: &CompareRequest) -> Result<Comparison> {
    args.check()?;
    match args.session_compare() {
        Some(session) => Ok(Comparison::Session(compare_session(&session)?)),
        None => Ok(Comparison::BallPresses(compare_ball_presses(args)?)),
    }
}

pub(crate) fn run(args: &CompareArgs) -> Result<()> {
    let request = args.request();
    request.check()?;
    if let Some(session) = request.session_compare() {
        let session = SessionCompare {
            json: args.json,
            ..session
        };
        return crate::sim2real::compare_session::run(&session);
    }
    let report = compare_ball_presses(&request)?;
    print_json_or_text(&report, args.json, || {
        print_report(&report);
        Ok(())
    })
}

fn compare_ball_presses(args: &CompareRequest) -> Result<CompareReport> {
    let (Some(profile_path), Some(images), Some(annotations)) =
        (&args.sensor, &args.images, &args.annotations)
    else {
        bail!("compare: needs --sensor, --images and --annotations, or --session DIR");
    };
    let profile = crate::app::load_sensor(Some(profile_path))?;
    let (Some(real_background), Some(fit)) = (&profile.background, &profile.fit) else {
        bail!(
            "--sensor {}: not a calibrated profile (no background frame or no ball-press fit); `tactex calibrate` writes one",
            profile_path.display()
        );
    };
    // The rebuilt presses are compared with single real frames: no added camera noise; and
    // ball presses are taken on a gel without marker dots, as `calibrate` reads them, even
    // when the profile has the sensor's grid from a marker frame.
    let mut optics = SensorOptics {
        noise_sigma: 0.0,
        markers: Vec::new(),
        ..SensorOptics::for_profile(&profile)
    };
    if !args.glow {
        optics.glow = None;
    }
    let spec = &profile.spec;
    let presses = ball_presses::load(
        images,
        annotations,
        args.split,
        (spec.width_px, spec.height_px),
    )?;
    ball_presses::check_within_ball(&presses, annotations, spec.mm_per_px, fit.ball_radius_mm)?;
    // Claimed before any work: an --out that cannot be written fails first, and the side by
    // sides, named as the real frames are, may not land on them (--out the images' folder).
    let out_dir = match args.out.as_deref() {
        Some(dir) => {
            let mut claimed = OutputDir::create("--out", dir)?;
            claimed.keep(presses.iter().map(|(p, _)| images.join(&p.image)));
            claimed.keep([annotations.clone()]);
            claimed.keep(SensorProfile::files(profile_path));
            Some(claimed)
        }
        None => None,
    };
    let choice = open_renderer(args.device)?;
    if let Some(note) = &choice.note {
        eprintln!("note: {note}");
    }
    let mut renderer = choice.renderer;
    let mut solver = ContactSolver::new();
    let mut rebuilt = Vec::new();
    for (press, _) in &presses {
        rebuilt.push(rebuild(
            &mut solver,
            press,
            fit.ball_radius_mm,
            &spec.gel,
            &optics,
            args.fidelity,
        )?);
    }
    let flat = GelImageFields::flat(optics.width, optics.height);
    let mut frames: Vec<PressFrame> = rebuilt
        .iter()
        .map(|(_, _, fields, _)| PressFrame { fields, seed: 0 })
        .collect();
    frames.push(PressFrame {
        fields: &flat,
        seed: 0,
    });
    let mut images = renderer.render_batch(&optics, &frames)?;
    let background = images.pop().expect("the flat frame was rendered last");
    let mut out = Vec::new();
    for (((press, real), (depth, force, _, warnings)), rendered) in
        presses.iter().zip(&rebuilt).zip(&images)
    {
        if let Some(dir) = &out_dir {
            write_png_atomic(
                &dir.path().join(&press.image),
                &side_by_side(real, rendered),
            )?;
        }
        out.push(PressComparison {
            image: press.image.clone(),
            contact_radius_px: press.contact_radius_px,
            depth_mm: *depth,
            force_n: *force,
            rendered: scores(real, rendered, press),
            background_only: scores(real, &background, press),
            circle_real: score_circle(real, real_background, press),
            circle_rendered: score_circle(rendered, &background, press),
            reading_real: score_reading(real, real_background, spec, press, *depth),
            reading_rendered: score_reading(rendered, &background, spec, press, *depth),
            warnings: warnings.clone(),
        });
    }
    let report = CompareReport {
        sensor: profile.id(),
        split: args.split.name().into(),
        fidelity: args.fidelity.name().into(),
        glow: optics.glow.is_some(),
        device: renderer.name(),
        mean: mean(out.iter().map(|p| p.rendered)),
        background_only_mean: mean(out.iter().map(|p| p.background_only)),
        circle_real: summarise(out.iter().map(|p| &p.circle_real)),
        circle_rendered: summarise(out.iter().map(|p| &p.circle_rendered)),
        reading_real: reading_score::summarise(out.iter().filter_map(|p| p.reading_real.as_ref())),
        reading_rendered: reading_score::summarise(
            out.iter().filter_map(|p| p.reading_rendered.as_ref()),
        ),
        presses: out,
    };
    if let Some(dir) = out_dir {
        write_json_atomic(&dir.path().join("compare.json"), &report)?;
        dir.finish()?;
    }
    Ok(report)
}

fn print_report(report: &CompareReport) {
    println!(
        "{:<10} {:>6} {:>9} {:>8} | {:>6} {:>6} {:>8} {:>8} | background only: {:>6} {:>6} {:>8} {:>8}",
        "image",
        "a (px)",
        "depth mm",
        "force N",
        "SSIM",
        "MAE",
        "SSIM(c)",
        "MAE(c)",
        "SSIM",
        "MAE",
        "SSIM(c)",
        "MAE(c)"
    );
    let line = |name: &str, a: String, d: String, f: String, r: &Scores, b: &Scores| {
        println!(
            "{name:<10} {a:>6} {d:>9} {f:>8} | {:>6.3} {:>6.2} {:>8.3} {:>8.2} |                   {:>6.3} {:>6.2} {:>8.3} {:>8.2}",
            r.ssim,
            r.mae,
            r.ssim_contact,
            r.mae_contact,
            b.ssim,
            b.mae,
            b.ssim_contact,
            b.mae_contact
        )
    };
    for p in &report.presses {
        line(
            &p.image,
            format!("{:.0}", p.contact_radius_px),
            format!("{:.3}", p.depth_mm),
            format!("{:.2}", p.force_n),
            &p.rendered,
            &p.background_only,
        );
        for w in &p.warnings {
            println!("    warning: {w}");
        }
    }
    line(
        "mean",
        String::new(),
        String::new(),
        String::new(),
        &report.mean,
        &report.background_only_mean,
    );
    println!(
        "{} presses ({} split), {} contact, {}, rendered on {}; (c): the box of 4 contact radii around the press",
        report.presses.len(),
        report.split,
        report.fidelity,
        if report.glow {
            "with the profile's glow"
        } else {
            "no glow"
        },
        report.device
    );
    for (frames, c) in [
        ("real", &report.circle_real),
        ("rendered", &report.circle_rendered),
    ] {
        println!(
            "contact circle on the {frames} frames vs the marked one: found {}/{}, centre error median {:.1} px, radius error median {:+.1} px, mean |error| {:.1} px",
            c.found,
            c.presses,
            c.centre_error_median_px,
            c.radius_error_median_px,
            c.radius_error_mean_abs_px
        );
    }
    for (frames, r) in [
        ("real", &report.reading_real),
        ("rendered", &report.reading_rendered),
    ] {
        println!(
            "read on the {frames} frames ({} presses): peak depth vs the model's {:+.1}% median ({:.1}% median |error|), contact radius vs the marked one {:+.1}% ({:.1}%)",
            r.presses,
            100.0 * r.depth_error_median,
            100.0 * r.depth_error_median_abs,
            100.0 * r.radius_error_median,
            100.0 * r.radius_error_median_abs
        );
    }
}

#[cfg(test)]
mod request_tests {
    use super::*;
    use crate::app::request_json::from_json;

    #[test]
    fn a_request_from_code_keeps_the_rules_the_flags_keep_between_them() {
        let ball = r#"{"sensor": "p.toml", "images": "i", "annotations": "a.csv"}"#;
        let request: CompareRequest = from_json(ball).unwrap();
        assert!(request.check().is_ok());
        assert_eq!((request.split, request.glow), (Split::Eval, true));
        let field = |json: &str| {
            let request: CompareRequest = from_json(json).unwrap();
            request.check().unwrap_err().field
        };
        assert_eq!(
            field(r#"{"images": "i", "annotations": "a.csv"}"#),
            "sensor"
        );
        assert_eq!(field(r#"{"session": "s", "images": "i"}"#), "images");
        assert_eq!(field(r#"{"session": "s", "glow": false}"#), "glow");
        assert_eq!(
            field(r#"{"sensor": "p", "images": "i", "annotations": "a", "seed": 3}"#),
            "seed"
        );
        assert_eq!(
            field(r#"{"session": "s", "gel_modulus_mpa": 1e9}"#),
            "gel_modulus_mpa"
        );
        let e = from_json::<CompareRequest>(r#"{"session": "s", "split": "dev"}"#).unwrap_err();
        assert_eq!(e.field, "split");
    }
}
