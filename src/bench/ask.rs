//! `tactex bench ask`: the main job's speed against its accuracy. Asks one question on a scene
//! `--reps` times at each `--fidelity`, and reports the median wall time of each pipeline
//! stage (the press and hardness stages together are what the twin's physics and estimator
//! cost) beside the estimates' |ln(E_est/E_true)| against the scene's true moduli. All rows
//! are measured in one run, so their ratios hold on a noisy machine.

use crate::app::estimator_choice::EstimatorChoice;
use crate::app::{Twin, load_sensor};
use crate::report::output::{OutputDir, write_json_atomic};
use crate::report::provenance::write_markdown_report;
use crate::report::summary::median;
use crate::report::tail::print_json_or_text;
use anyhow::{Context, Result, bail};
use clap::Args;
use indicatif::{ProgressBar, ProgressStyle};
use serde::Serialize;
use std::path::PathBuf;
use std::sync::Arc;
use tactex_core::catalog::FruitCatalog;
use tactex_core::pipeline::{Language, PipelineConfig};
use tactex_core::scene::Scene;
use tactex_sim::contact::Fidelity;
use tactex_sim::render::scene::{CpuSceneRenderer, SceneRenderer};

use crate::app::detector_choice::DetectorChoice;

#[derive(Args, Debug)]
pub struct AskBenchArgs {
    /// Scene file (TOML); default scenes/demo.toml.
    #[arg(long)]
    scene: Option<PathBuf>,
    /// The question asked.
    #[arg(long, default_value = "Which fruit is the softest?")]
    prompt: String,
    /// Contact physics to time, comma-separated.
    #[arg(long, value_delimiter = ',', default_values = ["rigid", "hertz", "halfspace", "layer"])]
    fidelity: Vec<Fidelity>,
    /// Hardness estimator: learned, indentation, hertz or FILE.onnx.
    #[arg(long, default_value = crate::app::DEFAULT_ESTIMATOR)]
    estimator: EstimatorChoice,
    /// Sensor profile the sim GelSight renders with (TOML); default the built-in GelSight
    /// Mini.
    #[arg(long)]
    sensor: Option<PathBuf>,
    /// Timed questions at each fidelity (the median is reported); one more, untimed, warms up; 1 to 1000.
    #[arg(long, value_parser = crate::app::flag_range::count::<usize>(1, 1000), default_value_t = 5)]
    reps: usize,
    /// Seed of the sim devices.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Print the report as JSON.
    #[arg(long)]
    json: bool,
    /// Write ask_bench.md and ask_bench.json here.
    #[arg(long)]
    out: Option<PathBuf>,
}

#[derive(Serialize)]
pub struct AskBenchRow {
    pub fidelity: String,
    /// Median wall time of each stage (ms), in pipeline order.
    pub stage_ms: Vec<(String, f64)>,
    /// Median of the press and hardness stages together, per question (ms).
    pub press_and_hardness_ms: f64,
    /// Median of the whole question, scene setup (settling, first render) included (ms).
    pub question_ms: f64,
    /// Objects measured of those the question named and the camera found.
    pub measured: usize,
    pub objects: usize,
    /// Median and largest |ln(E_est/E_true)| over the measured objects.
    pub median_abs_ln_error: Option<f64>,
    pub worst_abs_ln_error: Option<f64>,
}

#[derive(Serialize)]
pub struct AskBench {
    pub scene: String,
    pub prompt: String,
    pub estimator: String,
    pub reps: usize,
    pub threads: usize,
    pub rows: Vec<AskBenchRow>,
}

pub(crate) fn run(args: &AskBenchArgs) -> Result<()> {
    if args.fidelity.is_empty() {
        bail!("--fidelity: name at least one of rigid, hertz, halfspace, layer");
    }
    let catalog = FruitCatalog::builtin();
    tactex_core::query::parse(&args.prompt, &catalog).context("--prompt")?;
    let path = args.scene.clone().unwrap_or_else(crate::app::default_scene);
    let (scene, _) = crate::app::load_scene(&path, &catalog)?;
    let sensor = load_sensor(args.sensor.as_deref())?;
    let detector = DetectorChoice::parse("classical")?;
    let renderer: Arc<dyn SceneRenderer> = Arc::new(CpuSceneRenderer);
    let config = PipelineConfig::default();
    let bar = ProgressBar::new((args.fidelity.len() * (args.reps + 1)) as u64).with_style(
        ProgressStyle::with_template("{msg:>10} [{bar:30}] {pos}/{len} {elapsed}")
            .expect("valid template")
            .progress_chars("=> "),
    );
    let mut rows = Vec::new();
    let mut estimator_name = String::new();
    for &fidelity in &args.fidelity {
        bar.set_message(fidelity.name());
        let estimator = args.estimator.open(
            "--estimator",
            fidelity.name(),
            None,
            &sensor,
            args.sensor.as_deref(),
        )?;
        estimator_name = estimator.name().to_string();
        let twin = Twin {
            scene: &scene,
            seed: args.seed,
            sensor: &sensor,
            detector: &detector,
            renderer: &renderer,
            language: Language::OFFLINE,
            estimator: estimator.as_ref(),
            fidelity,
            camera: &crate::app::camera_placement::CameraPlacement::default(),
        };
        let mut stages: Vec<(String, Vec<f64>)> = Vec::new();
        let (mut pair, mut whole) = (Vec::new(), Vec::new());
        let mut errors = Vec::new();
        let (mut measured, mut objects) = (0, 0);
        for rep in 0..=args.reps {
            let started = std::time::Instant::now();
            let answered = twin.answer(&args.prompt, &config, &|_| {})?;
            let question_ms = started.elapsed().as_secs_f64() * 1e3;
            bar.inc(1);
            if rep == 0 {
                // The warm-up question: the same answer, caches and pages cold.
                let (e, m, n) = ln_errors(&answered, &scene);
                errors = e;
                (measured, objects) = (m, n);
                continue;
            }
            whole.push(question_ms);
            let mut both = 0.0;
            for t in &answered.answer.timing {
                let ms = t.wall_ms.unwrap_or(0.0);
                if t.stage == "press" || t.stage == "hardness" {
                    both += ms;
                }
                match stages.iter_mut().find(|(s, _)| s == &t.stage) {
                    Some((_, v)) => v.push(ms),
                    None => stages.push((t.stage.clone(), vec![ms])),
                }
            }
            pair.push(both);
        }
        let abs: Vec<f64> = errors.iter().map(|e| e.abs()).collect();
        rows.push(AskBenchRow {
            fidelity: fidelity.name().into(),
            stage_ms: stages.into_iter().map(|(s, v)| (s, median(v))).collect(),
            press_and_hardness_ms: median(pair),
            question_ms: median(whole),
            measured,
            objects,
            median_abs_ln_error: (!abs.is_empty()).then(|| median(abs.clone())),
            worst_abs_ln_error: abs.iter().copied().reduce(f64::max),
        });
    }
    bar.finish_and_clear();
    let report = AskBench {
        scene: path.display().to_string(),
        prompt: args.prompt.clone(),
        estimator: estimator_name,
        reps: args.reps,
        threads: std::thread::available_parallelism().map_or(1, |n| n.get()),
        rows,
    };
    if let Some(out) = &args.out {
        let out = OutputDir::create("--out", out)?;
        let dir = out.path();
        write_markdown_report(&dir.join("ask_bench.md"), &markdown(&report))?;
        write_json_atomic(&dir.join("ask_bench.json"), &report)?;
        out.finish()?;
    }
    print_json_or_text(&report, args.json, || {
        print!("{}", markdown(&report));
        Ok(())
    })?;
    Ok(())
}

/// ln(E_est/E_true) of each measured object against the scene object nearest its reported
/// position (within 3 cm), with how many were measured of how many reported.
fn ln_errors(answered: &crate::app::TwinAnswer, scene: &Scene) -> (Vec<f64>, usize, usize) {
    let objects = &answered.answer.objects;
    let mut errors = Vec::new();
    for report in objects {
        let Some(estimate) = report.hardness.and_then(|h| h.modulus_mpa) else {
            continue;
        };
        let nearest = answered
            .true_centres_m
            .iter()
            .zip(&scene.objects)
            .map(|(c, o)| {
                let d = (c[0] - report.position_m[0]).hypot(c[1] - report.position_m[1]);
                (d, o)
            })
            .min_by(|a, b| a.0.total_cmp(&b.0));
        if let Some((d, truth)) = nearest
            && d < 0.03
            && let Some(true_mpa) = truth.hardness.modulus_mpa()
        {
            errors.push((estimate / true_mpa).ln());
        }
    }
    let measured = objects.iter().filter(|o| o.hardness.is_some()).count();
    (errors, measured, objects.len())
}

fn markdown(r: &AskBench) -> String {
    let stage_names: Vec<&str> = r
        .rows
        .first()
        .map(|row| row.stage_ms.iter().map(|(s, _)| s.as_str()).collect())
        .unwrap_or_default();
    let mut out = format!(
        "`{}` on {}, estimator {}, {} threads: medians of {} questions per fidelity (wall ms).\n\n",
        r.prompt, r.scene, r.estimator, r.threads, r.reps
    );
    out += "| fidelity |";
    for s in &stage_names {
        out += &format!(" {s} |");
    }
    out += " press + hardness | question | measured | median abs ln error | worst |\n|---|";
    out += &"---:|".repeat(stage_names.len() + 5);
    out += "\n";
    let fmt = |v: Option<f64>| v.map_or("-".to_string(), |v| format!("{v:.3}"));
    for row in &r.rows {
        out += &format!("| {} |", row.fidelity);
        for (_, ms) in &row.stage_ms {
            out += &format!(" {ms:.0} |");
        }
        out += &format!(
            " {:.0} | {:.0} | {}/{} | {} | {} |\n",
            row.press_and_hardness_ms,
            row.question_ms,
            row.measured,
            row.objects,
            fmt(row.median_abs_ln_error),
            fmt(row.worst_abs_ln_error)
        );
    }
    out
}
