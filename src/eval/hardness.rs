//! `tactex eval hardness`: each hardness estimator on held-out synthetic presses of shapes no
//! model was trained on (catalog fruit meshes and random blobs by default), scored in Shore A
//! by RMSE, R2 and Spearman's rho (core's stats, checked against scipy), with the paper's
//! Fig. 5 (predicted against true hardness) as a PNG.

use crate::app::estimator_choice::{ESTIMATORS, check_reads, unreadable};
use crate::report::output::{OutputDir, write_bytes_atomic, write_json_atomic};
use crate::report::plot::{self, ScatterSeries};
use crate::report::tail::print_json_or_text;
use anyhow::{Context, Result};
use clap::Args;
use indicatif::{ProgressBar, ProgressStyle};
use rayon::prelude::*;
use serde::Serialize;
use std::path::PathBuf;
use tactex_core::catalog::FruitCatalog;
use tactex_core::hardness::estimate::{Evidence, HardnessEstimator};
use tactex_core::hardness::scale::shore_a_to_modulus_mpa;
use tactex_core::stats::{r_squared, rmse, spearman};
use tactex_sim::contact::ContactSolver;
use tactex_sim::datagen::tactile_sample::ShapeFamily;
use tactex_sim::render::gel::CpuRenderer;

#[derive(Args, Debug)]
pub struct HardnessEvalArgs {
    /// Held-out presses; 3 to 100000.
    #[arg(long, value_parser = crate::app::flag_range::count::<u64>(3, 100_000), default_value_t = 60)]
    count: u64,
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Shape families of the held-out objects (comma-separated).
    #[arg(long, value_delimiter = ',', default_value = "fruit,blob")]
    shapes: Vec<String>,
    /// Fidelity level of the presses.
    #[arg(long, default_value = "layer")]
    fidelity: String,
    /// Sensor profile the presses are rendered with and read through (TOML); default the
    /// built-in GelSight Mini.
    #[arg(long)]
    sensor: Option<PathBuf>,
    /// Print the scores as JSON.
    #[arg(long)]
    json: bool,
    /// Write hardness.png (predicted against true), predictions.jsonl and scores.json here.
    #[arg(long)]
    out: Option<PathBuf>,
    /// Also write frames.jsonl to --out: every frame's gel peak and contact radius from the
    /// solver beside what the reader makes of the frame (where a profile's reading fails).
    #[arg(long, requires = "out")]
    frames: bool,
    /// Also score this trained model (NAME.onnx with its card NAME.json beside it); repeatable.
    #[arg(long)]
    model: Vec<PathBuf>,
    /// Leave out the built-in trained model (models/hardness-small.onnx).
    #[arg(long)]
    no_builtin_model: bool,
}

/// Held-out hardness range: Shore A 5 to 90, where the Shore A scale resolves the objects
/// (the paper's Fig. 5 spans Shore A).
const SHORE_A_RANGE: [f64; 2] = [5.0, 90.0];

#[derive(Serialize)]
struct EstimatorScore {
    name: String,
    n: usize,
    rmse: Option<f64>,
    r2: Option<f64>,
    spearman: Option<f64>,
    failures: usize,
    /// Why the estimator is not scored (fewer than 3 presses read: e.g. a model trained on
    /// another frame size than the sensor's), with its first error.
    unscored: Option<String>,
}

#[derive(Serialize)]
struct HardnessEval {
    unit: &'static str,
    count: u64,
    seed: u64,
    shapes: Vec<String>,
    fidelity: String,
    /// The sensor the presses were rendered with and read through.
    sensor: tactex_core::tactile::sensor_profile::ProfileId,
    estimators: Vec<EstimatorScore>,
}

#[derive(Serialize)]
struct Prediction {
    estimator: String,
    shore_a: Option<f64>,
    interval: Option<tactex_core::hardness::estimate::ModulusInterval>,
    evidence: Option<Evidence>,
    error: Option<String>,
}

/// One frame of a held-out press: the solver's gel beside the reader's (`tactex read`'s
/// figures, the peak also as the indentation estimator takes it, over the border's share).
#[derive(Serialize)]
struct FrameRecord {
    index: u64,
    frame: usize,
    travel_mm: f64,
    gel_peak_mm: f64,
    contact_radius_mm: f64,
    read_peak_mm: f64,
    border_share: f64,
    read_contact_radius_mm: f64,
    contact_edge: &'static str,
    within_frame: bool,
}

/// One held-out press and what each estimator made of it.
#[derive(Serialize)]
struct PressRecord {
    index: u64,
    attempt: u32,
    family: ShapeFamily,
    true_shore_a: f64,
    true_modulus_mpa: f64,
    predictions: Vec<Prediction>,
    #[serde(skip)]
    frames: Vec<FrameRecord>,
}

pub(crate) fn run(args: &HardnessEvalArgs) -> Result<()> {
    let mut space = crate::app::sample_space::sample_space(&args.fidelity, &args.shapes)?;
    if args.sensor.is_some() {
        space = space.around(crate::app::load_sensor(args.sensor.as_deref())?);
    }
    let sensor_id = space.sensor.id();
    space.modulus_mpa = SHORE_A_RANGE.map(|s| shore_a_to_modulus_mpa(s).expect("below 100"));
    let catalog = FruitCatalog::builtin();
    let mut estimators: Vec<Box<dyn HardnessEstimator + Sync>> = Vec::new();
    for named in ESTIMATORS {
        if named.trained && args.no_builtin_model {
            continue;
        }
        let estimator = (named.open)()?;
        // Through a profile of another frame size a built-in model reads nothing: it is left
        // out with why, and the others are scored.
        match unreadable(estimator.as_ref(), &space.sensor) {
            None => estimators.push(estimator),
            Some(why) => eprintln!(
                "note: the built-in {} estimator is left out: {why} (--model scores one trained on this sensor)",
                named.name
            ),
        }
    }
    for path in &args.model {
        let model = tactex_learned::builtin::from_file("--model", path)?;
        check_reads(
            &model,
            &format!("--model {}", path.display()),
            &space.sensor,
        )?;
        estimators.push(Box::new(model));
    }
    // Claimed before the presses: an --out that cannot be written fails first.
    let out = args
        .out
        .as_deref()
        .map(|dir| OutputDir::create("--out", dir))
        .transpose()?;
    let bar = ProgressBar::new(args.count).with_style(
        ProgressStyle::with_template("eval hardness [{bar:30}] {pos}/{len} presses, eta {eta}")
            .expect("a valid template"),
    );
    let records: Vec<PressRecord> = (0..args.count)
        .into_par_iter()
        .map_init(ContactSolver::new, |solver, index| -> Result<_> {
            let (draw, press) = space
                .press(solver, &catalog, args.seed, index)
                .with_context(|| format!("press {index}"))?;
            let sequence = press.sequence(press.render(&mut CpuRenderer, &draw.optics())?);
            let spec = draw.spec();
            let predictions = estimators
                .iter()
                .map(|e| {
                    let name = e.name().to_string();
                    match e.estimate(&sequence, &spec) {
                        Ok(h) => Prediction {
                            estimator: name,
                            shore_a: Some(h.hardness.shore_a()),
                            interval: Some(h.interval.clone()),
                            evidence: Some(h.evidence),
                            error: None,
                        },
                        Err(err) => Prediction {
                            estimator: name,
                            shore_a: None,
                            interval: None,
                            evidence: None,
                            error: Some(err.to_string()),
                        },
                    }
                })
                .collect();
            let frames = match args.frames {
                true => frame_records(index, &press.frames, &sequence, &spec),
                false => Vec::new(),
            };
            bar.inc(1);
            Ok(PressRecord {
                index,
                attempt: draw.attempt,
                family: draw.family,
                true_shore_a: draw.shore_a,
                true_modulus_mpa: draw.modulus_mpa,
                predictions,
                frames,
            })
        })
        .collect::<Result<_>>()?;
    bar.finish_and_clear();

    let mut scores = Vec::new();
    let mut series = Vec::new();
    for (k, e) in estimators.iter().enumerate() {
        let pairs: Vec<(f64, f64)> = records
            .iter()
            .filter_map(|r| r.predictions[k].shore_a.map(|p| (r.true_shore_a, p)))
            .collect();
        let (truth, pred): (Vec<f64>, Vec<f64>) = pairs.iter().copied().unzip();
        let name = e.name().to_string();
        if pairs.len() < 3 {
            let first_error = records
                .iter()
                .find_map(|r| r.predictions[k].error.as_deref())
                .unwrap_or("none");
            scores.push(EstimatorScore {
                name,
                n: pairs.len(),
                rmse: None,
                r2: None,
                spearman: None,
                failures: records.len() - pairs.len(),
                unscored: Some(format!(
                    "only {} of {} presses estimated (first error: {first_error})",
                    pairs.len(),
                    records.len()
                )),
            });
            continue;
        }
        let score = EstimatorScore {
            name: name.clone(),
            n: pairs.len(),
            rmse: Some(rmse(&truth, &pred)?),
            r2: Some(r_squared(&truth, &pred)?),
            spearman: Some(spearman(&truth, &pred)?.statistic),
            failures: records.len() - pairs.len(),
            unscored: None,
        };
        series.push(ScatterSeries {
            name: format!(
                "{name}: RMSE {:.1}, R2 {:.2}, Spearman {:.2}",
                score.rmse.unwrap_or(f64::NAN),
                score.r2.unwrap_or(f64::NAN),
                score.spearman.unwrap_or(f64::NAN)
            ),
            points: pairs,
        });
        scores.push(score);
    }
    let report = HardnessEval {
        unit: "Shore A",
        count: args.count,
        seed: args.seed,
        shapes: args.shapes.clone(),
        fidelity: args.fidelity.clone(),
        sensor: sensor_id,
        estimators: scores,
    };
    if let Some(out) = out {
        let dir = out.path();
        let mut lines = String::new();
        for r in &records {
            lines += &serde_json::to_string(r)?;
            lines.push('\n');
        }
        write_bytes_atomic(&dir.join("predictions.jsonl"), lines.as_bytes())?;
        if args.frames {
            let mut lines = String::new();
            for f in records.iter().flat_map(|r| &r.frames) {
                lines += &serde_json::to_string(f)?;
                lines.push('\n');
            }
            write_bytes_atomic(&dir.join("frames.jsonl"), lines.as_bytes())?;
        }
        write_json_atomic(&dir.join("scores.json"), &report)?;
        plot::predicted_vs_true(
            &dir.join("hardness.png"),
            &format!(
                "Hardness on held-out shapes ({}), {} presses",
                args.shapes.join(", "),
                args.count
            ),
            "true hardness (Shore A)",
            "predicted hardness (Shore A)",
            [0.0, 100.0],
            &series,
        )?;
        out.finish()?;
    }
    print_json_or_text(&report, args.json, || {
        println!(
            "{} held-out presses ({}; {}), Shore A {}-{}",
            args.count,
            args.shapes.join(", "),
            args.fidelity,
            SHORE_A_RANGE[0],
            SHORE_A_RANGE[1]
        );
        println!("estimator     n   RMSE (Shore A)    R2   Spearman  failures");
        for s in &report.estimators {
            match (s.rmse, s.r2, s.spearman) {
                (Some(rmse), Some(r2), Some(rho)) => println!(
                    "{:<12} {:>3}  {:>14.2}  {:>5.2}  {:>8.3}  {:>8}",
                    s.name, s.n, rmse, r2, rho, s.failures
                ),
                _ => println!(
                    "{:<12} {:>3}  not scored: {}",
                    s.name,
                    s.n,
                    s.unscored.as_deref().unwrap_or("")
                ),
            }
        }
        if let Some(dir) = &args.out {
            println!("wrote {}", dir.join("hardness.png").display());
        }
        Ok(())
    })?;
    Ok(())
}

/// Each frame of a press read as the indentation estimator reads it, beside the solver's.
fn frame_records(
    index: u64,
    solved: &[tactex_sim::datagen::press_protocol::PressedFrame],
    sequence: &tactex_core::hardness::estimate::PressSequence,
    spec: &tactex_core::tactile::spec::TactileSpec,
) -> Vec<FrameRecord> {
    use tactex_core::hardness::border_level::read_share_of_indentation;
    use tactex_core::tactile::frame_reading::read_frame;
    use tactex_core::tactile::slopes::ColourDrift;
    // Read as the estimators read a press: its first frame's drift given to the rest.
    let mut drift = ColourDrift::Measured;
    solved
        .iter()
        .zip(&sequence.frames)
        .enumerate()
        .filter_map(|(frame, (truth, image))| {
            let reading = read_frame(&image.image, &sequence.reference.image, spec, drift)?;
            drift = drift.for_next_frame(reading.drift);
            Some(FrameRecord {
                index,
                frame,
                travel_mm: truth.travel_mm,
                gel_peak_mm: truth.gel_max_indentation_mm,
                contact_radius_mm: truth.contact_radius_mm,
                read_peak_mm: reading.peak_mm,
                border_share: read_share_of_indentation(&reading, &spec.gel),
                read_contact_radius_mm: reading.contact_radius_mm(),
                contact_edge: reading.contact_edge(),
                within_frame: reading.within_frame,
            })
        })
        .collect()
}
