//! `tactex eval fruits`: the whole pipeline (camera with noise, classical detector, presses on
//! the elastic twin, the chosen estimator, its intervals) per catalog fruit kind.
//!
//! Each kind is put on the table alone at random places and yaws, in turn at each ripeness
//! stage's modulus and at a modulus drawn between its stages; then crowded tables of 10-12
//! fruits of any kinds, drawn with overlapping footprints so that the physics settles many
//! of them against each other. Every scene is asked "Describe the hardness of all the
//! fruits." A fruit is located when a report of its kind touches it (its touch point lies on
//! it in the clean render), and placed when that report's centre lies within 1 cm of the
//! fruit's outline centre; measured when the report has a modulus. The figures per kind:
//! located and measured, median and worst |ln(E_est / E_true)|, and how often the 68% and
//! 95% intervals hold the truth. `--calibrate FILE` writes the residuals as an interval
//! calibration instead (run it on another seed than the evaluation's).

use crate::app::detector_choice::DetectorChoice;
use crate::app::estimator_choice::{Beside, EstimatorChoice};
use crate::app::{Twin, TwinAnswer};
use crate::eval::report_matching::match_reports;
use crate::report::output::{OutputDir, write_bytes_atomic, write_json_atomic};
use crate::report::plot::{self, BarSeries, ScatterSeries};
use crate::report::provenance::write_markdown_report;
use crate::report::tail::print_json_or_text;
use anyhow::{Context, Result, bail, ensure};
use clap::Args;
use indicatif::{ProgressBar, ProgressStyle};
use rand::seq::IndexedRandom;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;
use serde::Serialize;
use std::path::PathBuf;
use tactex_core::catalog::{FruitCatalog, FruitSpec};
use tactex_core::hardness::estimate::Evidence;
use tactex_core::hardness::interval_calibration::{
    HeldOutPress, IntervalCalibration, is_elongated,
};
use tactex_core::hardness::scale::Hardness;
use tactex_core::pipeline::{Language, PipelineConfig};
use tactex_core::scene::Scene;
use tactex_core::tactile::sensor_profile::{ProfileId, SensorProfile};
use tactex_sim::contact::Fidelity;
use tactex_sim::datagen::scene_random::{RandomSceneError, Variation, random_scene};
use tactex_sim::render::device::DeviceChoice;

/// The question every scene is asked.
pub const PROMPT: &str = "Describe the hardness of all the fruits.";
/// A report's centre this close to the fruit's outline centre places it.
pub const PLACED_WITHIN_M: f64 = 0.01;
/// Crowded tables: the share of fruits put against an earlier one (the physics settles them
/// touching).
const CROWDED_TOUCHING_SHARE: f64 = 0.6;
/// A single-stage kind's "between" moduli span its stage's modulus times 1/1.5 to 1.5.
const SINGLE_STAGE_SPAN: f64 = 1.5;

#[derive(Args)]
pub struct FruitEvalArgs {
    /// Placements of each kind alone on the table (its stages in turn, every other one at a
    /// modulus between them); 0 to 1000.
    #[arg(long, value_parser = crate::app::flag_range::count::<usize>(0, 1000), default_value_t = 8)]
    pub placements: usize,
    /// Crowded tables of 10-12 fruits, some touching.
    #[arg(long, default_value_t = 6)]
    pub crowded: usize,
    /// Only these kinds alone (comma-separated); every catalog kind if unset.
    #[arg(long, value_delimiter = ',')]
    pub kinds: Vec<String>,
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Contact physics of the sim GelSight: rigid, hertz, halfspace or layer.
    #[arg(long, default_value = "layer")]
    pub fidelity: Fidelity,
    /// Sensor profile the sim GelSight renders with (TOML); default the built-in GelSight
    /// Mini.
    #[arg(long)]
    pub sensor: Option<PathBuf>,
    /// Hardness estimator: learned, indentation, hertz or FILE.onnx.
    #[arg(long, default_value = crate::app::DEFAULT_ESTIMATOR)]
    pub estimator: EstimatorChoice,
    /// Interval calibration to score (default: the one shipped for the estimator).
    #[arg(long)]
    pub intervals: Option<PathBuf>,
    /// Write the presses' residuals as an interval calibration (JSON) here.
    #[arg(long)]
    pub calibrate: Option<PathBuf>,
    /// Device that renders the camera: cpu (the default, so that the figures never depend on
    /// the machine), gpu or auto.
    #[arg(long, default_value = "cpu")]
    pub device: DeviceChoice,
    /// Write results.json, fruits.json, table.md and PNG plots here, and each table as a
    /// scene file (scenes/table-N.toml: `tactex ask --scene FILE --seed S` answers it again,
    /// S being the row's `seed`).
    #[arg(long)]
    pub out: Option<PathBuf>,
    #[arg(long)]
    pub json: bool,
}

/// One table the pipeline is asked about.
struct Table {
    crowded: bool,
    index: usize,
    seed: u64,
    scene: Scene,
    kinds: Vec<String>,
    /// The stage each fruit's modulus is (its name), or "between".
    stages: Vec<String>,
}

/// How the pipeline did on one fruit.
#[derive(Clone, Debug, Serialize)]
pub struct FruitRow {
    pub crowded: bool,
    pub table: usize,
    /// The seed of the table's sim devices (`ask --seed`).
    pub seed: u64,
    pub kind: String,
    pub stage: String,
    pub true_modulus_mpa: f64,
    pub touching: bool,
    pub located: bool,
    /// Distance from the report's centre to the fruit's outline centre (mm).
    pub position_error_mm: Option<f64>,
    pub placed: bool,
    pub estimate_mpa: Option<f64>,
    /// Wide over narrow semi-axis of the first contact, as the estimator's evidence says.
    pub first_contact_aspect: Option<f64>,
    /// The estimator's own standard error in ln E (half its own 68% interval in ln), before
    /// any interval calibration.
    pub own_ln_se: Option<f64>,
    /// ln(E_est / E_true).
    pub ln_error: Option<f64>,
    pub in_68: Option<bool>,
    pub in_95: Option<bool>,
    pub not_measured: Option<String>,
    /// For a fruit not located: the report nearest its outline centre ("tomato 14 mm away").
    pub nearest_report: Option<String>,
}

#[derive(Clone, Debug, Serialize)]
pub struct KindResult {
    pub kind: String,
    /// Fruits of the kind (alone and crowded).
    pub fruits: usize,
    pub located_and_measured: f64,
    pub median_abs_ln_error: Option<f64>,
    pub worst_abs_ln_error: Option<f64>,
    pub coverage_68: Option<f64>,
    pub coverage_95: Option<f64>,
}

#[derive(Clone, Debug, Serialize)]
pub struct CrowdedResult {
    pub tables: usize,
    /// Reports that matched no fruit (a fruit split in two, a fruit of the wrong kind).
    pub false_reports: usize,
    pub fruits: usize,
    pub touching: usize,
    /// Located with the report's centre within 1 cm, of all crowded fruits and of those
    /// touching a neighbour.
    pub placed: f64,
    pub placed_touching: f64,
}

#[derive(Clone, Debug, Serialize)]
pub struct FruitReport {
    pub protocol: String,
    pub estimator: String,
    pub fidelity: String,
    /// The sim GelSight's profile.
    pub sensor: tactex_core::tactile::sensor_profile::ProfileId,
    pub intervals: String,
    pub seed: u64,
    pub kinds: Vec<KindResult>,
    pub all: KindResult,
    /// Reports on the tables of one fruit that matched no fruit.
    pub false_reports_alone: usize,
    pub crowded: CrowdedResult,
}

/// A modulus for placement `i` of a kind: its stages in turn on even placements, a draw
/// log-uniform between its softest and hardest stage (or around its one stage) on odd ones.
fn modulus_for(fruit: &FruitSpec, i: usize, rng: &mut ChaCha8Rng) -> (f64, String) {
    if i.is_multiple_of(2) {
        let s = &fruit.stages[(i / 2) % fruit.stages.len()];
        return (s.modulus_mpa, s.name.clone());
    }
    let [lo, hi] = between_range(fruit);
    let e = (lo.ln() + rng.random::<f64>() * (hi / lo).ln()).exp();
    (e, "between".into())
}

/// The moduli "between stages" are drawn from: the kind's softest to hardest stage, or
/// within `SINGLE_STAGE_SPAN` of its one stage.
fn between_range(fruit: &FruitSpec) -> [f64; 2] {
    let moduli = fruit.stages.iter().map(|s| s.modulus_mpa);
    let (lo, hi) = moduli.fold((f64::MAX, 0.0f64), |(l, h), e| (l.min(e), h.max(e)));
    if hi / lo < 1.01 {
        [lo / SINGLE_STAGE_SPAN, hi * SINGLE_STAGE_SPAN]
    } else {
        [lo, hi]
    }
}

/// Sets each fruit's modulus (and the ripeness it implies).
fn set_moduli(scene: &mut Scene, catalog: &FruitCatalog, moduli: &[f64]) {
    for (o, &e) in scene.objects.iter_mut().zip(moduli) {
        o.hardness = Hardness::ModulusMpa(e);
        if let Some(f) = catalog.get(&o.label) {
            o.ripeness = Some(f.stage_for_modulus(Some(e)).name.clone());
        }
    }
}

fn tables(args: &FruitEvalArgs, catalog: &FruitCatalog) -> Result<Vec<Table>> {
    let kinds: Vec<String> = if args.kinds.is_empty() {
        catalog.names().iter().map(|s| s.to_string()).collect()
    } else {
        args.kinds.clone()
    };
    let mut out = Vec::new();
    for (k, kind) in kinds.iter().enumerate() {
        let fruit = catalog.get(kind).with_context(|| {
            format!(
                "--kinds: no fruit {kind:?} in the catalog (known: {})",
                catalog.names().join(", ")
            )
        })?;
        for i in 0..args.placements {
            let seed = args
                .seed
                .wrapping_mul(1_000_003)
                .wrapping_add((k * 1000 + i) as u64);
            let mut rng = ChaCha8Rng::seed_from_u64(seed);
            let (e, stage) = modulus_for(fruit, i, &mut rng);
            let mut scene = random_scene(&[kind.as_str()], catalog, seed, &Variation::default())
                .with_context(|| format!("{kind} placement {i}"))?;
            set_moduli(&mut scene, catalog, &[e]);
            out.push(Table {
                crowded: false,
                index: out.len(),
                seed,
                scene,
                kinds: vec![kind.clone()],
                stages: vec![stage],
            });
        }
    }
    let all: Vec<&FruitSpec> = catalog.fruits.iter().collect();
    let crowded = Variation {
        gap_m: 0.005,
        margin_m: 0.02,
        touching_share: CROWDED_TOUCHING_SHARE,
        ..Variation::default()
    };
    for j in 0..args.crowded {
        let n = 10 + j % 3;
        let mut found = None;
        // A draw of twelve large fruits may not fit the table: draw again.
        for attempt in 0..32u64 {
            let seed = args
                .seed
                .wrapping_mul(7_000_003)
                .wrapping_add(j as u64 * 1009 + (attempt << 40));
            let mut rng = ChaCha8Rng::seed_from_u64(seed);
            let fruits: Vec<&FruitSpec> = (0..n)
                .map(|_| *all.choose(&mut rng).expect("a catalog has fruit"))
                .collect();
            let names: Vec<&str> = fruits.iter().map(|f| f.name.as_str()).collect();
            match random_scene(&names, catalog, seed, &crowded) {
                Ok(mut scene) => {
                    let picks: Vec<(f64, String)> = fruits
                        .iter()
                        .map(|f| {
                            let i = rng.random_range(0..2 * f.stages.len());
                            modulus_for(f, i, &mut rng)
                        })
                        .collect();
                    let moduli: Vec<f64> = picks.iter().map(|p| p.0).collect();
                    set_moduli(&mut scene, catalog, &moduli);
                    found = Some(Table {
                        crowded: true,
                        index: out.len(),
                        seed,
                        scene,
                        kinds: names.iter().map(|s| s.to_string()).collect(),
                        stages: picks.into_iter().map(|p| p.1).collect(),
                    });
                    break;
                }
                Err(RandomSceneError::NoRoom { .. }) => continue,
                Err(e) => return Err(e.into()),
            }
        }
        out.push(
            found.with_context(|| {
                format!("crowded table {j}: no draw of {n} fruits fits the table")
            })?,
        );
    }
    Ok(out)
}

/// Objects closer than this count as touching (the meshes' vertex spacing is about 2.6 mm).
const TOUCH_GAP_M: f64 = 0.003;

/// Each fruit's row, and how many reports matched no fruit.
fn score(table: &Table, twin: &TwinAnswer) -> (Vec<FruitRow>, usize) {
    let answer = &twin.answer;
    let of_object = match_reports(answer, &table.kinds, twin);
    let false_reports = (0..answer.objects.len())
        .filter(|r| !of_object.contains(&Some(*r)))
        .count();
    // What a report's position estimates: the outline's centre seen from above.
    let (top_centres, touching): (Vec<[f64; 3]>, Vec<bool>) = {
        let world = twin.world.lock().expect("world lock");
        let centres = world.objects.iter();
        (
            centres
                .map(|o| o.mesh.top_view_centre().to_array())
                .collect(),
            world.touching(TOUCH_GAP_M),
        )
    };
    let rows = (0..table.kinds.len())
        .map(|o| {
            let truth = table.scene.objects[o]
                .hardness
                .modulus_mpa()
                .expect("the eval sets a modulus");
            let report = of_object[o].map(|r| &answer.objects[r]);
            let position_error_mm = report.map(|r| {
                let c = top_centres[o];
                (r.position_m[0] - c[0]).hypot(r.position_m[1] - c[1]) * 1e3
            });
            let estimate_mpa = report
                .and_then(|r| r.hardness)
                .map(|h| h.modulus_mpa.unwrap_or(f64::INFINITY));
            let interval = report.and_then(|r| r.interval.as_ref());
            let measured = estimate_mpa.is_some();
            FruitRow {
                crowded: table.crowded,
                table: table.index,
                seed: table.seed,
                kind: table.kinds[o].clone(),
                stage: table.stages[o].clone(),
                true_modulus_mpa: truth,
                touching: touching[o],
                located: report.is_some(),
                position_error_mm,
                placed: position_error_mm.is_some_and(|e| e <= PLACED_WITHIN_M * 1e3),
                estimate_mpa,
                first_contact_aspect: report.filter(|_| measured).and_then(|r| match &r.evidence {
                    Some(Evidence::Physics(p)) => p.first_contact_aspect,
                    _ => None,
                }),
                own_ln_se: interval
                    .filter(|i| measured && !i.calibrated)
                    .and_then(|i| i.ln_half_width68()),
                ln_error: estimate_mpa.map(|e| (e / truth).ln()),
                in_68: interval
                    .filter(|_| measured)
                    .and_then(|i| i.holds(truth, false)),
                in_95: interval
                    .filter(|_| measured)
                    .and_then(|i| i.holds(truth, true)),
                not_measured: report
                    .and_then(|r| r.not_measured.as_ref())
                    .map(|n| n.to_string()),
                nearest_report: report
                    .is_none()
                    .then(|| nearest(answer, top_centres[o]))
                    .flatten(),
            }
        })
        .collect();
    (rows, false_reports)
}

fn nearest(answer: &tactex_core::pipeline::Answer, c: [f64; 3]) -> Option<String> {
    let distance = |p: [f64; 3]| (p[0] - c[0]).hypot(p[1] - c[1]);
    let r = answer
        .objects
        .iter()
        .min_by(|a, b| distance(a.position_m).total_cmp(&distance(b.position_m)))?;
    Some(format!(
        "{} {:.0} mm away",
        r.label,
        distance(r.position_m) * 1e3
    ))
}

/// The median, where a rigid reading of a soft fruit counts as an infinite error (an
/// infinite middle value makes the median infinite).
fn median(mut v: Vec<f64>) -> Option<f64> {
    tactex_core::stats::median(&mut v)
}

fn rate(rows: &[&FruitRow], pick: impl Fn(&FruitRow) -> Option<bool>) -> Option<f64> {
    let v: Vec<bool> = rows.iter().filter_map(|r| pick(r)).collect();
    (!v.is_empty()).then(|| v.iter().filter(|b| **b).count() as f64 / v.len() as f64)
}

fn kind_result(kind: &str, rows: &[&FruitRow]) -> KindResult {
    let errors: Vec<f64> = rows
        .iter()
        .filter_map(|r| r.ln_error)
        .map(|e| {
            if e.is_finite() {
                e.abs()
            } else {
                f64::INFINITY
            }
        })
        .collect();
    KindResult {
        kind: kind.into(),
        fruits: rows.len(),
        located_and_measured: rate(rows, |r| Some(r.located && r.estimate_mpa.is_some()))
            .unwrap_or(0.0),
        median_abs_ln_error: median(errors.clone()),
        worst_abs_ln_error: errors.iter().copied().reduce(f64::max),
        coverage_68: rate(rows, |r| r.in_68),
        coverage_95: rate(rows, |r| r.in_95),
    }
}

fn opt(v: Option<f64>, digits: usize) -> String {
    v.map_or("-".into(), |v| format!("{v:.digits$}"))
}

pub fn markdown(report: &FruitReport) -> String {
    let mut s = format!("{}\n\n", report.protocol);
    s += &format!(
        "estimator {}, fidelity {}, intervals: {}\n\n",
        report.estimator, report.fidelity, report.intervals
    );
    s += "| kind | fruits | located+measured | median abs ln err | worst | 68% coverage | 95% coverage |\n";
    s += "|---|---:|---:|---:|---:|---:|---:|\n";
    for k in report.kinds.iter().chain(std::iter::once(&report.all)) {
        s += &format!(
            "| {} | {} | {:.3} | {} | {} | {} | {} |\n",
            k.kind,
            k.fruits,
            k.located_and_measured,
            opt(k.median_abs_ln_error, 3),
            opt(k.worst_abs_ln_error, 3),
            opt(k.coverage_68, 2),
            opt(k.coverage_95, 2)
        );
    }
    let c = &report.crowded;
    s += &format!(
        "\nCrowded tables: {} tables, {} fruits ({} touching a neighbour); report centre within 1 cm: {:.3} of all, {:.3} of those touching; {} reports matching no fruit ({} on the tables of one fruit).\n",
        c.tables,
        c.fruits,
        c.touching,
        c.placed,
        c.placed_touching,
        c.false_reports,
        report.false_reports_alone
    );
    s
}

fn plots(dir: &std::path::Path, report: &FruitReport, rows: &[FruitRow]) -> Result<()> {
    let categories: Vec<String> = report.kinds.iter().map(|k| k.kind.clone()).collect();
    plot::bars(
        &dir.join("ln_error.png"),
        &format!("|ln(E_est / E_true)| per kind ({})", report.estimator),
        "|ln error|",
        &categories,
        &[
            BarSeries {
                name: "median".into(),
                values: report
                    .kinds
                    .iter()
                    .map(|k| k.median_abs_ln_error.unwrap_or(0.0).min(3.0))
                    .collect(),
            },
            BarSeries {
                name: "worst".into(),
                values: report
                    .kinds
                    .iter()
                    .map(|k| k.worst_abs_ln_error.unwrap_or(0.0).min(3.0))
                    .collect(),
            },
        ],
        false,
    )?;
    plot::bars(
        &dir.join("coverage.png"),
        "Interval coverage per kind (targets 0.68 and 0.95)",
        "share of presses holding the truth",
        &categories,
        &[
            BarSeries {
                name: "68% interval".into(),
                values: report
                    .kinds
                    .iter()
                    .map(|k| k.coverage_68.unwrap_or(0.0))
                    .collect(),
            },
            BarSeries {
                name: "95% interval".into(),
                values: report
                    .kinds
                    .iter()
                    .map(|k| k.coverage_95.unwrap_or(0.0))
                    .collect(),
            },
        ],
        false,
    )?;
    let series: Vec<ScatterSeries> = ["alone", "crowded"]
        .iter()
        .map(|name| ScatterSeries {
            name: name.to_string(),
            points: rows
                .iter()
                .filter(|r| r.crowded == (*name == "crowded"))
                .filter_map(|r| {
                    let e = r.estimate_mpa.filter(|e| e.is_finite())?;
                    Some((r.true_modulus_mpa.ln(), e.ln()))
                })
                .collect(),
        })
        .collect();
    plot::predicted_vs_true(
        &dir.join("estimate_vs_true.png"),
        &format!("Estimated against true modulus ({})", report.estimator),
        "ln(E_true / MPa)",
        "ln(E_est / MPa)",
        [-2.5, 2.5],
        &series,
    )
}

pub(crate) fn run(args: &FruitEvalArgs) -> Result<()> {
    let (report, calibration) = evaluate(args)?;
    if let (Some(path), Some(c)) = (&args.calibrate, &calibration) {
        eprintln!(
            "wrote {} ({} presses, {} {})",
            path.display(),
            c.presses,
            c.bins.len(),
            if c.bins.len() == 1 { "bin" } else { "bins" }
        );
    }
    print_json_or_text(&report, args.json, || {
        print!("{}", markdown(&report));
        Ok(())
    })
}

/// Measures the default estimator's interval calibration through the profile at `profile`
/// (each kind alone at `placements` places, seed 1) and writes it beside the profile, where
/// every command that loads the estimator through that profile finds it.
pub(crate) fn measure_beside(
    profile: &std::path::Path,
    placements: usize,
) -> Result<(PathBuf, IntervalCalibration)> {
    let estimator: EstimatorChoice = crate::app::DEFAULT_ESTIMATOR
        .parse()
        .map_err(|e| anyhow::anyhow!("the default estimator: {e}"))?;
    let fidelity = Fidelity::default();
    let path =
        crate::app::estimator_choice::profile_intervals_path(profile, &estimator, fidelity.name());
    let args = FruitEvalArgs {
        placements,
        crowded: 0,
        kinds: Vec::new(),
        seed: 1,
        fidelity,
        sensor: Some(profile.to_path_buf()),
        estimator,
        intervals: None,
        calibrate: Some(path.clone()),
        device: DeviceChoice::Cpu,
        out: None,
        json: false,
    };
    if path.is_dir() {
        bail!("the intervals file {}: is a directory", path.display());
    }
    let (_, calibration) = evaluate(&args)?;
    let calibration = calibration.context("the interval calibration was not made")?;
    Ok((path, calibration))
}

/// Answers every table and scores it; with `--calibrate` also writes the calibration, which
/// it returns.
fn evaluate(args: &FruitEvalArgs) -> Result<(FruitReport, Option<IntervalCalibration>)> {
    ensure!(
        args.placements + args.crowded >= 1,
        "--placements, --crowded: ask for at least one table"
    );
    let catalog = FruitCatalog::builtin();
    let fidelity = args.fidelity.name();
    let sensor = crate::app::load_sensor(args.sensor.as_deref())?;
    let sensor_id = sensor.id();
    let estimator = match &args.calibrate {
        // The residuals do not depend on the intervals; the file is for new presses.
        Some(_) => args.estimator.open_uncalibrated("--estimator", &sensor)?,
        None => args.estimator.open(
            "--estimator",
            fidelity,
            args.intervals.as_deref(),
            &sensor,
            args.sensor.as_deref(),
        )?,
    };
    if let Some(path) = &args.calibrate
        && path.is_dir()
    {
        bail!("--calibrate {}: is a directory", path.display());
    }
    let renderer = crate::app::scene_renderer(args.device)?;
    let detector = DetectorChoice::parse("classical")?;
    let tables = tables(args, &catalog)?;
    let bar = ProgressBar::new(tables.len() as u64).with_style(
        ProgressStyle::with_template("eval fruits [{bar:30}] {pos}/{len} tables, eta {eta}")
            .expect("a valid template"),
    );
    let config = PipelineConfig::default();
    let per_table: Vec<(Vec<FruitRow>, usize)> = tables
        .par_iter()
        .map(|t| -> Result<(Vec<FruitRow>, usize)> {
            let twin = Twin {
                scene: &t.scene,
                seed: t.seed,
                sensor: &sensor,
                detector: &detector,
                renderer: &renderer,
                language: Language::OFFLINE,
                estimator: estimator.as_ref(),
                fidelity: args.fidelity,
                camera: &crate::app::camera_placement::CameraPlacement::default(),
            }
            .answer(PROMPT, &config, &|_| {})
            .with_context(|| {
                let what = if t.crowded { "crowded table" } else { "table" };
                format!("{what} {} ({})", t.index, t.kinds.join(", "))
            })?;
            bar.inc(1);
            Ok(score(t, &twin))
        })
        .collect::<Result<_>>()?;
    bar.finish_and_clear();
    let false_alone: usize = per_table
        .iter()
        .zip(&tables)
        .filter(|(_, t)| !t.crowded)
        .map(|(p, _)| p.1)
        .sum();
    let false_crowded: usize = per_table
        .iter()
        .zip(&tables)
        .filter(|(_, t)| t.crowded)
        .map(|(p, _)| p.1)
        .sum();
    let rows: Vec<FruitRow> = per_table.into_iter().flat_map(|p| p.0).collect();

    let protocol = format!(
        "each catalog kind alone at {} random places and yaws (stages in turn, every other at a modulus between stages), and {} crowded tables of 10-12 fruits, {:.0}% of them put against a neighbour; prompt {PROMPT:?}; camera noise on, classical detector; located: a report of the kind touches the fruit; placed: its centre within {:.0} mm of the fruit's outline centre",
        args.placements,
        args.crowded,
        CROWDED_TOUCHING_SHARE * 1e2,
        PLACED_WITHIN_M * 1e3
    );
    let mut calibration = None;
    if let Some(path) = &args.calibrate {
        let samples: Vec<HeldOutPress> = rows
            .iter()
            .filter_map(|r| {
                let e = r.estimate_mpa.filter(|e| e.is_finite() && *e > 0.0)?;
                Some(HeldOutPress {
                    ln_estimate: e.ln(),
                    residual: (r.true_modulus_mpa / e).ln(),
                    elongated: r.first_contact_aspect.is_some_and(is_elongated),
                    own_ln_se: r.own_ln_se,
                })
            })
            .collect();
        let command = format!(
            "tactex eval fruits --placements {} --crowded {} --seed {} --fidelity {fidelity} --estimator {}{} --calibrate FILE",
            args.placements,
            args.crowded,
            args.seed,
            args.estimator.flag_value(),
            match &args.sensor {
                Some(p) => format!(" --sensor {}", p.display()),
                None => String::new(),
            }
        );
        let mut fitted =
            IntervalCalibration::fit(estimator.name(), fidelity, &command, &samples, 3)?;
        fitted.sensor = Some(sensor_id.clone());
        write_json_atomic(path, &fitted)?;
        calibration = Some(fitted);
    }
    let mut names: Vec<String> = rows.iter().map(|r| r.kind.clone()).collect();
    names.sort();
    names.dedup();
    let all_rows: Vec<&FruitRow> = rows.iter().collect();
    let crowded: Vec<&FruitRow> = rows.iter().filter(|r| r.crowded).collect();
    let touching: Vec<&FruitRow> = crowded.iter().copied().filter(|r| r.touching).collect();
    let report = FruitReport {
        protocol,
        estimator: estimator.name().into(),
        fidelity: fidelity.into(),
        intervals: interval_source(args, fidelity, estimator.name(), &sensor_id)?,
        sensor: sensor_id,
        seed: args.seed,
        kinds: names
            .iter()
            .map(|k| {
                let of: Vec<&FruitRow> = rows.iter().filter(|r| &r.kind == k).collect();
                kind_result(k, &of)
            })
            .collect(),
        all: kind_result("all", &all_rows),
        false_reports_alone: false_alone,
        crowded: CrowdedResult {
            tables: args.crowded,
            false_reports: false_crowded,
            fruits: crowded.len(),
            touching: touching.len(),
            placed: rate(&crowded, |r| Some(r.placed)).unwrap_or(0.0),
            placed_touching: rate(&touching, |r| Some(r.placed)).unwrap_or(0.0),
        },
    };
    if let Some(out) = &args.out {
        let out = OutputDir::create("--out", out)?;
        let dir = out.path();
        write_json_atomic(&dir.join("fruits.json"), &rows)?;
        let scenes = dir.join("scenes");
        std::fs::create_dir_all(&scenes)
            .with_context(|| format!("{}: cannot create the directory", scenes.display()))?;
        for t in &tables {
            let file = scenes.join(format!("table-{}.toml", t.index));
            write_bytes_atomic(&file, t.scene.to_toml().as_bytes())?;
        }
        write_json_atomic(&dir.join("results.json"), &report)?;
        write_markdown_report(&dir.join("table.md"), &markdown(&report))?;
        plots(dir, &report, &rows)?;
        out.finish()?;
    }
    Ok((report, calibration))
}

/// Where the scored intervals come from, in words (as `EstimatorChoice::open` chose them).
fn interval_source(
    args: &FruitEvalArgs,
    fidelity: &str,
    estimator: &str,
    sensor: &ProfileId,
) -> Result<String> {
    let choice = &args.estimator;
    if args.calibrate.is_some() {
        return Ok("the estimator's own (this run measures a calibration)".into());
    }
    if let (None, Some(profile)) = (&args.intervals, &args.sensor)
        && let Beside::Found(path, _) = choice.look_beside(profile, fidelity, estimator, sensor)
    {
        return Ok(format!("{} (measured through this sensor)", path.display()));
    }
    Ok(match &args.intervals {
        Some(p) => format!("--intervals {}", p.display()),
        None => match crate::app::estimator_choice::builtin_interval_file(choice, fidelity, sensor)
        {
            Some(name) => format!("{name} (built in)"),
            None => format!(
                "the estimator's own (none is shipped for it through {sensor}; the shipped ones were measured through the built-in {})",
                SensorProfile::gelsight_mini().id().name
            ),
        },
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    #[derive(Parser)]
    struct Cli {
        #[command(flatten)]
        args: FruitEvalArgs,
    }

    #[test]
    fn every_kind_meets_each_of_its_stages_and_moduli_between_them() {
        let catalog = FruitCatalog::builtin();
        let args = Cli::parse_from(["t", "--placements", "6", "--crowded", "3"]).args;
        let tables = tables(&args, &catalog).unwrap();
        for fruit in &catalog.fruits {
            let alone: Vec<&Table> = tables
                .iter()
                .filter(|t| !t.crowded && t.kinds[0] == fruit.name)
                .collect();
            assert_eq!(alone.len(), 6, "{}", fruit.name);
            for stage in &fruit.stages {
                assert!(
                    alone.iter().any(|t| t.stages[0] == stage.name),
                    "{} never at {}",
                    fruit.name,
                    stage.name
                );
            }
            let (lo, hi) = fruit.stages.iter().fold((f64::MAX, 0.0f64), |(l, h), s| {
                (l.min(s.modulus_mpa), h.max(s.modulus_mpa))
            });
            let (lo, hi) = if hi / lo < 1.01 {
                (lo / SINGLE_STAGE_SPAN, hi * SINGLE_STAGE_SPAN)
            } else {
                (lo, hi)
            };
            let between: Vec<f64> = alone
                .iter()
                .filter(|t| t.stages[0] == "between")
                .map(|t| t.scene.objects[0].hardness.modulus_mpa().unwrap())
                .collect();
            assert_eq!(between.len(), 3);
            assert!(between.iter().all(|e| (lo..=hi).contains(e)), "{between:?}");
        }
        let crowded: Vec<&Table> = tables.iter().filter(|t| t.crowded).collect();
        assert_eq!(crowded.len(), 3);
        for t in crowded {
            assert!((10..=12).contains(&t.scene.objects.len()));
        }
    }

    #[test]
    fn a_kind_outside_the_catalog_is_named_in_the_error() {
        let catalog = FruitCatalog::builtin();
        let args = Cli::parse_from(["t", "--kinds", "durian"]).args;
        let e = tables(&args, &catalog).err().unwrap();
        assert!(
            format!("{e:#}").contains("--kinds: no fruit \"durian\""),
            "{e:#}"
        );
    }
}
