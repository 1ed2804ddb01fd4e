//! `tactex eval ripeness`: the paper's Table III on the twin. Each fruit of the table (mango,
//! lime and tomato pairs; banana and avocado trios) is pressed 20 times per ripeness stage
//! with the paper's pose jitter, the estimator reads each press, and one-sided Mann-Whitney U
//! tests ask whether each harder stage reads harder than each softer one (Holm-corrected
//! within a fruit). Raw predictions go into the JSON so anyone can recompute the tests.
//!
//! One specimen per stage, as in the paper; its flesh varies from spot to spot by a
//! log-normal factor (`--spot-spread`, log-sd 0.1 by default: within-fruit firmness of
//! penetrometer surveys varies by 10-20 %), so the 20 presses differ in flesh as well as pose.

use crate::app::estimator_choice::EstimatorChoice;
use crate::report::output::OutputDir;
use crate::report::plot::{self, StageGroup};
use crate::report::tail::print_json_or_text;
use anyhow::{Context, Result, bail};
use clap::Args;
use indicatif::{ProgressBar, ProgressStyle};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};
use rayon::prelude::*;
use serde::Serialize;
use std::path::PathBuf;
use tactex_core::catalog::FruitCatalog;
use tactex_core::hardness::scale::{modulus_to_shore_00, modulus_to_shore_a};
use tactex_core::press::protocol::PressProtocol;
use tactex_core::stats::{
    Alternative, MannWhitneyMethod, holm_bonferroni, mann_whitney_u, quantile,
};
use tactex_sim::contact::{ContactSolver, Fidelity};
use tactex_sim::datagen::tactile_sample::{
    SampleDraw, SensorDraw, ShapeDraw, ShapeFamily, press_with_redraws,
};
use tactex_sim::render::gel::CpuRenderer;

/// The paper's Table III fruits.
const TABLE_III: [&str; 5] = ["mango", "lime", "tomato", "banana", "avocado"];

#[derive(Args, Debug)]
pub struct RipenessEvalArgs {
    /// Hardness estimator: learned, indentation, hertz or FILE.onnx.
    #[arg(long, default_value = "indentation")]
    estimator: EstimatorChoice,
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Presses per ripeness stage; 3 to 10000.
    #[arg(long, value_parser = crate::app::flag_range::count::<u32>(3, 10_000), default_value_t = 20)]
    presses: u32,
    /// Fruits to press (catalog names; default the paper's Table III).
    #[arg(long, value_delimiter = ',')]
    fruits: Vec<String>,
    /// Log-sd of the flesh modulus from spot to spot within a fruit; 0 to 1.
    #[arg(long, value_parser = crate::app::flag_range::within(0.0, 1.0), default_value_t = 0.1, allow_negative_numbers = true)]
    spot_spread: f64,
    /// Fidelity level of the presses.
    #[arg(long, default_value = "layer")]
    fidelity: String,
    /// Sensor profile the presses are rendered with and read through (TOML); default the
    /// built-in GelSight Mini.
    #[arg(long)]
    sensor: Option<PathBuf>,
    #[arg(long)]
    json: bool,
    /// Write ripeness.json and ripeness.png (predictions by stage) here.
    #[arg(long)]
    out: Option<PathBuf>,
}

#[derive(Serialize)]
struct StageResult {
    stage: String,
    true_modulus_mpa: f64,
    true_shore_a: f64,
    predictions: Vec<f64>,
    median: f64,
    q25: f64,
    q75: f64,
    failures: u32,
}

#[derive(Serialize)]
struct StageTest {
    harder: String,
    softer: String,
    u: f64,
    p: f64,
    p_holm: f64,
}

#[derive(Serialize)]
struct FruitResult {
    fruit: String,
    stages: Vec<StageResult>,
    tests: Vec<StageTest>,
}

#[derive(Serialize)]
struct RipenessEval {
    estimator: String,
    unit: &'static str,
    seed: u64,
    presses: u32,
    spot_spread: f64,
    fidelity: String,
    /// The sensor the presses were rendered with and read through.
    sensor: tactex_core::tactile::sensor_profile::ProfileId,
    fruits: Vec<FruitResult>,
}

/// The press stream of (fruit, stage, press, attempt): its own ChaCha seed.
fn press_rng(seed: u64, fruit: usize, stage: usize, press: u32, attempt: u32) -> ChaCha8Rng {
    let mut key = [0u8; 32];
    key[..8].copy_from_slice(&seed.to_le_bytes());
    key[8..12].copy_from_slice(&(fruit as u32).to_le_bytes());
    key[12..16].copy_from_slice(&(stage as u32).to_le_bytes());
    key[16..20].copy_from_slice(&press.to_le_bytes());
    key[20..24].copy_from_slice(&attempt.to_le_bytes());
    key[24..32].copy_from_slice(b"ripeness");
    ChaCha8Rng::from_seed(key)
}

struct Job {
    fruit: usize,
    stage: usize,
    press: u32,
}

pub(crate) fn run(args: &RipenessEvalArgs) -> Result<()> {
    let fidelity: Fidelity = args
        .fidelity
        .parse()
        .map_err(|e| anyhow::anyhow!("--fidelity: {e}"))?;
    let catalog = FruitCatalog::builtin();
    let names: Vec<String> = if args.fruits.is_empty() {
        TABLE_III.iter().map(|s| s.to_string()).collect()
    } else {
        args.fruits.clone()
    };
    let mut fruits = Vec::new();
    for name in &names {
        let spec = catalog
            .get(name)
            .with_context(|| format!("--fruits: no fruit {name:?} in the catalog"))?;
        if !spec.has_ripeness() {
            bail!("--fruits: {name} has a single ripeness stage in the catalog");
        }
        fruits.push(spec.clone());
    }
    let profile = crate::app::load_sensor(args.sensor.as_deref())?;
    let estimator = args.estimator.open(
        "--estimator",
        fidelity.name(),
        None,
        &profile,
        args.sensor.as_deref(),
    )?;
    // The sensor as it is, unrandomised: a lab's validation run on one sensor.
    let sensor = SensorDraw::of(std::sync::Arc::new(profile));
    let protocol = PressProtocol::default();
    let jobs: Vec<Job> = fruits
        .iter()
        .enumerate()
        .flat_map(|(f, spec)| {
            (0..spec.stages.len()).flat_map(move |s| {
                (0..args.presses).map(move |k| Job {
                    fruit: f,
                    stage: s,
                    press: k,
                })
            })
        })
        .collect();
    let bar = ProgressBar::new(jobs.len() as u64).with_style(
        ProgressStyle::with_template("eval ripeness [{bar:30}] {pos}/{len} presses, eta {eta}")
            .expect("a valid template"),
    );
    // Each press: Some(Shore A) or None where the estimator could not read it.
    let readings: Vec<Option<f64>> = jobs
        .par_iter()
        .map_init(ContactSolver::new, |solver, job| -> Result<Option<f64>> {
            let spec = &fruits[job.fruit];
            let stage = &spec.stages[job.stage];
            let (draw, press) = press_with_redraws(solver, &catalog, &protocol, |attempt| {
                let mut rng = press_rng(args.seed, job.fruit, job.stage, job.press, attempt);
                let spot: f64 = StandardNormal.sample(&mut rng);
                let modulus_mpa = stage.modulus_mpa * (args.spot_spread * spot).exp();
                SampleDraw {
                    index: job.press as u64,
                    attempt,
                    family: ShapeFamily::Fruit,
                    shape: ShapeDraw::Fruit {
                        fruit: spec.name.clone(),
                        size_mm: spec.size_m.map(|v| v * 1e3),
                    },
                    modulus_mpa,
                    shore_a: modulus_to_shore_a(modulus_mpa),
                    shore_00: modulus_to_shore_00(modulus_mpa),
                    object_poisson: spec.poisson,
                    offset_mm: [rng.random_range(-5.0..=5.0), rng.random_range(-5.0..=5.0)],
                    yaw_deg: rng.random_range(0.0..=45.0),
                    fidelity,
                    sensor: sensor.clone(),
                    phase_mm: rng.random_range(0.0..protocol.step_mm),
                    noise_seed: rng.random(),
                }
            })
            .with_context(|| format!("{} {} press {}", spec.name, stage.name, job.press))?;
            let sequence = press.sequence(press.render(&mut CpuRenderer, &draw.optics())?);
            bar.inc(1);
            Ok(estimator
                .estimate(&sequence, &draw.spec())
                .ok()
                .map(|h| h.hardness.shore_a()))
        })
        .collect::<Result<_>>()?;
    bar.finish_and_clear();

    let mut results = Vec::new();
    let mut groups = Vec::new();
    for (f, spec) in fruits.iter().enumerate() {
        let mut stages = Vec::new();
        for (s, stage) in spec.stages.iter().enumerate() {
            let all: Vec<Option<f64>> = jobs
                .iter()
                .zip(&readings)
                .filter(|(j, _)| j.fruit == f && j.stage == s)
                .map(|(_, r)| *r)
                .collect();
            let predictions: Vec<f64> = all.iter().flatten().copied().collect();
            if predictions.len() < 3 {
                bail!(
                    "{} {}: the estimator read only {} of {} presses",
                    spec.name,
                    stage.name,
                    predictions.len(),
                    all.len()
                );
            }
            groups.push(StageGroup {
                label: format!("{} {}", spec.name, stage.name),
                values: predictions.clone(),
                truth: Some(modulus_to_shore_a(stage.modulus_mpa)),
            });
            stages.push(StageResult {
                stage: stage.name.clone(),
                true_modulus_mpa: stage.modulus_mpa,
                true_shore_a: modulus_to_shore_a(stage.modulus_mpa),
                median: quantile(&predictions, 0.5)?,
                q25: quantile(&predictions, 0.25)?,
                q75: quantile(&predictions, 0.75)?,
                failures: (all.len() - predictions.len()) as u32,
                predictions,
            });
        }
        // Stages run hardest first: every harder stage against every softer one.
        let pairs: Vec<(usize, usize)> = (0..stages.len())
            .flat_map(|h| (h + 1..stages.len()).map(move |s| (h, s)))
            .collect();
        let mut tests = Vec::new();
        for (h, s) in &pairs {
            let r = mann_whitney_u(
                &stages[*h].predictions,
                &stages[*s].predictions,
                Alternative::Greater,
                MannWhitneyMethod::Auto,
            )?;
            tests.push((r.statistic, r.p_value));
        }
        let p: Vec<f64> = tests.iter().map(|t| t.1).collect();
        let p_holm = holm_bonferroni(&p)?;
        results.push(FruitResult {
            fruit: spec.name.clone(),
            tests: pairs
                .iter()
                .zip(tests.iter().zip(p_holm))
                .map(|((h, s), ((u, p), p_holm))| StageTest {
                    harder: stages[*h].stage.clone(),
                    softer: stages[*s].stage.clone(),
                    u: *u,
                    p: *p,
                    p_holm,
                })
                .collect(),
            stages,
        });
    }
    let report = RipenessEval {
        estimator: estimator.name().to_string(),
        unit: "Shore A",
        seed: args.seed,
        presses: args.presses,
        spot_spread: args.spot_spread,
        fidelity: fidelity.to_string(),
        sensor: sensor.base.id(),
        fruits: results,
    };
    if let Some(out) = &args.out {
        let out = OutputDir::create("--out", out)?;
        let dir = out.path();
        crate::report::output::write_json_atomic(&dir.join("ripeness.json"), &report)?;
        plot::stage_groups(
            &dir.join("ripeness.png"),
            &format!(
                "Hardness by ripeness stage ({}, {} presses each; black: true)",
                report.estimator, args.presses
            ),
            "predicted hardness (Shore A)",
            &groups,
        )?;
        out.finish()?;
    }
    print_json_or_text(&report, args.json, || {
        println!(
            "{} estimator, {} presses per stage on {}, Shore A: median [q25, q75]",
            report.estimator, args.presses, report.sensor
        );
        for f in &report.fruits {
            let stages: Vec<String> = f
                .stages
                .iter()
                .map(|s| format!("{} {:.1} [{:.1}, {:.1}]", s.stage, s.median, s.q25, s.q75))
                .collect();
            println!("{:<8} {}", f.fruit, stages.join("  "));
            for t in &f.tests {
                println!(
                    "         {} > {}: U = {:.0}, p = {:.2e}, Holm p = {:.2e}",
                    t.harder, t.softer, t.u, t.p, t.p_holm
                );
            }
        }
        if let Some(dir) = &args.out {
            println!("wrote {}", dir.join("ripeness.png").display());
        }
        Ok(())
    })?;
    Ok(())
}
