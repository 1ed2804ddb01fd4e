//! `tactex eval scenarios`: the TactEx paper's integrated evaluation (its Table II tiers) on
//! the twin. Each run is a seeded random scene and one question; the full pipeline answers it
//! (camera with noise, detector, presses, hardness, explanation) and the answer is scored
//! against the scene's ground truth:
//!
//! * object level: each object the question asks about is identified (a report of its kind
//!   whose touch point lies on it, as in `eval grounding`), measured (a hardness estimate) and
//!   communicated (named in the answer; for "which X is softest" with its location words);
//! * scenario level: every asked-for object succeeds, nothing is reported that is not there,
//!   and the hardness order is right (the chosen extreme is the true one; every pair of asked
//!   objects whose true moduli differ by more than `ORDER_RATIO` is ordered correctly).
//!
//! Tiers: 1 the property of one object, 2 the most/least of several of one kind, 3 the
//! property of named objects, 4 the property of all objects. Targets rotate through the
//! paper's ten fruit kinds (tier 2 through the eight that have ripeness stages), so that each
//! kind is asked about equally often.

use crate::app::detector_choice::DetectorChoice;
use crate::app::estimator_choice::EstimatorChoice;
use crate::app::{Twin, TwinAnswer};
use crate::eval::report_matching::match_reports;
use crate::eval::{PAPER_FRUIT_KINDS, other_paper_kinds};
use crate::report::output::{OutputDir, write_json_atomic};
use crate::report::plot::{self, BarSeries};
use crate::report::provenance::write_markdown_report;
use crate::report::tail::print_json_or_text;
use anyhow::{Context, Result, bail};
use clap::Args;
use indicatif::{ProgressBar, ProgressStyle};
use rand::SeedableRng;
use rand::seq::SliceRandom;
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;
use serde::Serialize;
use std::path::PathBuf;
use tactex_core::catalog::FruitCatalog;
use tactex_core::pipeline::{Language, PipelineConfig};
use tactex_core::scene::Scene;
use tactex_sim::contact::Fidelity;
use tactex_sim::datagen::scene_random::{Variation, random_scene};
use tactex_sim::render::device::DeviceChoice;

/// Pairs whose true moduli differ by less than this factor are not judged for order: the
/// twin's hardness estimates scatter by about 10%, as the paper's did.
pub const ORDER_RATIO: f64 = 1.25;
/// Scene draws tried for a tier-2 scene whose fruits of one kind are at distinct stages.
const TIER2_DRAWS: u64 = 64;

#[derive(Args)]
pub struct ScenarioEvalArgs {
    /// Runs per tier (the paper: 10); 1 to 1000.
    #[arg(long, value_parser = crate::app::flag_range::count::<usize>(1, 1000), default_value_t = 10)]
    pub runs: usize,
    /// Detectors to compare: classical, yolo:FILE.onnx, error-gsam, error-yolo.
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "classical,error-gsam,error-yolo"
    )]
    pub detector: Vec<String>,
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Only these tiers (comma-separated, 1-4); all four if unset.
    #[arg(long, value_delimiter = ',')]
    pub tiers: Vec<u8>,
    #[arg(long)]
    pub json: bool,
    /// Write results.json, runs.json, table.md and PNG plots here.
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Device that renders the scenes: cpu (the default, so that the figures never depend
    /// on the machine), gpu or auto.
    #[arg(long, default_value = "cpu")]
    pub device: DeviceChoice,
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
}

/// One question on one scene, before any detector answers it.
#[derive(Clone, Debug, Serialize)]
pub struct Scenario {
    pub tier: u8,
    pub run: usize,
    pub seed: u64,
    pub prompt: String,
    /// Kinds in the scene, in the scene's order.
    pub kinds: Vec<String>,
    /// Indices of the scene objects the question asks about.
    pub asked: Vec<usize>,
    /// Tier 2: the index of the true answer.
    pub extreme: Option<usize>,
    #[serde(skip)]
    pub scene: Scene,
}

/// How one detector's answer to one scenario scored.
#[derive(Clone, Debug, Serialize)]
pub struct RunScore {
    pub tier: u8,
    pub run: usize,
    pub detector: String,
    pub prompt: String,
    pub asked: usize,
    pub identified: usize,
    pub measured: usize,
    pub communicated: usize,
    /// Asked objects identified, measured and communicated.
    pub object_successes: usize,
    /// Reports matching no fruit of their kind where they were placed.
    pub false_reports: usize,
    /// What went wrong, for reading: missed fruits and false reports with positions (mm).
    pub notes: Vec<String>,
    pub order_correct: bool,
    pub scenario_success: bool,
    pub answer: String,
    pub timing: Vec<StageLatency>,
}

#[derive(Clone, Debug, Serialize)]
pub struct StageLatency {
    pub stage: String,
    pub wall_ms: f64,
    pub sim_s: f64,
}

#[derive(Clone, Debug, Serialize)]
pub struct TierResult {
    pub tier: u8,
    pub runs: usize,
    /// Object-level success rate: asked objects identified, measured and communicated.
    pub ol_sr: f64,
    /// Scenario-level success rate.
    pub sl_sr: f64,
    /// Mean per stage over the runs.
    pub latency: Vec<StageLatency>,
}

#[derive(Clone, Debug, Serialize)]
pub struct DetectorResult {
    pub name: String,
    pub tiers: Vec<TierResult>,
}

#[derive(Clone, Debug, Serialize)]
pub struct ScenarioReport {
    pub protocol: String,
    pub seed: u64,
    pub detectors: Vec<DetectorResult>,
}

const TIER_NAMES: [&str; 4] = [
    "property of one object",
    "most/least of one kind",
    "property of named objects",
    "property of all objects",
];

/// The kinds with more than one ripeness stage: fruits of one kind can differ in hardness.
fn staged_kinds(catalog: &FruitCatalog) -> Vec<&'static str> {
    PAPER_FRUIT_KINDS
        .iter()
        .copied()
        .filter(|k| catalog.get(k).is_some_and(|f| f.stages.len() > 1))
        .collect()
}

fn true_modulus(scene: &Scene, i: usize) -> f64 {
    scene.objects[i]
        .hardness
        .modulus_mpa()
        .unwrap_or(f64::INFINITY)
}

/// The scenario of `run` in `tier`: its scene, question and what the question asks about.
pub fn scenario(tier: u8, run: usize, seed: u64, catalog: &FruitCatalog) -> Result<Scenario> {
    let base = seed
        .wrapping_mul(1_000_003)
        .wrapping_add(tier as u64 * 10_007)
        .wrapping_add(run as u64);
    let mut rng = ChaCha8Rng::seed_from_u64(base);
    let variation = Variation::default();
    let build = |kinds: Vec<&str>, scene_seed: u64| -> Result<(Vec<String>, Scene)> {
        let scene = random_scene(&kinds, catalog, scene_seed, &variation)
            .with_context(|| format!("tier {tier} run {run}: scene"))?;
        Ok((kinds.iter().map(|k| k.to_string()).collect(), scene))
    };
    let target = PAPER_FRUIT_KINDS[(run + tier as usize) % PAPER_FRUIT_KINDS.len()];
    let (prompt, kinds, scene, asked, extreme) = match tier {
        1 => {
            let mut kinds = vec![target];
            kinds.extend(other_paper_kinds(&mut rng, &[target], run % 4));
            kinds.shuffle(&mut rng);
            let (names, scene) = build(kinds, base)?;
            let asked = vec![names.iter().position(|k| k == target).expect("placed")];
            let prompt = format!("What is the hardness of the {target}?");
            (prompt, names, scene, asked, None)
        }
        2 => {
            let staged = staged_kinds(catalog);
            let target = staged[run % staged.len()];
            let softest = run.is_multiple_of(2);
            let mut kinds = vec![target; 2 + run % 2];
            kinds.extend(other_paper_kinds(&mut rng, &[target], run % 3));
            kinds.shuffle(&mut rng);
            // Fruits of one kind at one stage have one modulus and no softest: draw again
            // until the true extreme stands apart.
            let mut found = None;
            for draw in 0..TIER2_DRAWS {
                let (names, scene) = build(kinds.clone(), base.wrapping_add(draw << 32))?;
                let same: Vec<usize> = (0..names.len()).filter(|&i| names[i] == target).collect();
                let key = |i: &usize| {
                    let e = true_modulus(&scene, *i);
                    if softest { e } else { -e }
                };
                let best = *same
                    .iter()
                    .min_by(|a, b| key(a).total_cmp(&key(b)))
                    .expect("two");
                let apart = same.iter().filter(|&&i| i != best).all(|&i| {
                    let (a, b) = (true_modulus(&scene, best), true_modulus(&scene, i));
                    a.max(b) / a.min(b) > ORDER_RATIO
                });
                if apart {
                    found = Some((names, scene, same, best));
                    break;
                }
            }
            let Some((names, scene, same, best)) = found else {
                bail!(
                    "tier 2 run {run}: no draw of {TIER2_DRAWS} put the {target}s at distinct stages"
                );
            };
            let word = if softest { "softest" } else { "hardest" };
            let prompt = format!("Which {target} is the {word}?");
            (prompt, names, scene, same, Some(best))
        }
        3 => {
            let second = other_paper_kinds(&mut rng, &[target], 1)[0];
            let mut kinds = vec![target, second];
            kinds.extend(other_paper_kinds(&mut rng, &[target, second], run % 3));
            kinds.shuffle(&mut rng);
            let (names, scene) = build(kinds, base)?;
            let asked = [target, second]
                .iter()
                .map(|k| names.iter().position(|n| n == k).expect("placed"))
                .collect();
            let prompt = format!("Tell me the hardness of the {target} and the {second}.");
            (prompt, names, scene, asked, None)
        }
        4 => {
            let n = 3 + run % 3;
            let mut kinds = vec![target];
            kinds.extend(other_paper_kinds(&mut rng, &[target], n - 1));
            kinds.shuffle(&mut rng);
            let (names, scene) = build(kinds, base)?;
            let asked = (0..names.len()).collect();
            let prompt = "Describe the hardness of all the fruits.".to_string();
            (prompt, names, scene, asked, None)
        }
        other => bail!("--tiers: {other} is not a tier (1-4)"),
    };
    Ok(Scenario {
        tier,
        run,
        seed: base,
        prompt,
        kinds,
        asked,
        extreme,
        scene,
    })
}

/// Scores one answer against the scenario's ground truth.
pub fn score(scenario: &Scenario, detector: &str, twin: &TwinAnswer) -> RunScore {
    let answer = &twin.answer;
    let centres = &twin.true_centres_m;
    let of_object = match_reports(answer, &scenario.kinds, twin);
    let text = answer.answer.to_lowercase();
    let estimate = |r: usize| {
        answer.objects[r]
            .hardness
            .map(|h| h.modulus_mpa.unwrap_or(f64::INFINITY))
    };
    let (mut identified, mut measured, mut communicated, mut successes) = (0, 0, 0, 0);
    for &o in &scenario.asked {
        let Some(r) = of_object[o] else { continue };
        identified += 1;
        let is_measured = estimate(r).is_some();
        measured += is_measured as usize;
        let report = &answer.objects[r];
        // Tier 2 names one fruit of several alike: only the chosen one is described, by
        // its location; the others are measured, not communicated.
        let is_communicated = match scenario.extreme {
            Some(best) if o != best => answer.selected.iter().all(|&s| s != r),
            Some(_) => {
                answer.selected == [r]
                    && text.contains(&format!("{} at the {}", report.label, report.location))
            }
            None => text.contains(&report.label),
        };
        communicated += is_communicated as usize;
        successes += (is_measured && is_communicated) as usize;
    }
    let mut notes = Vec::new();
    for &o in &scenario.asked {
        if of_object[o].is_none() {
            let c = centres[o];
            notes.push(format!(
                "missed the {} resting at ({:.0}, {:.0}) mm",
                scenario.kinds[o],
                c[0] * 1e3,
                c[1] * 1e3
            ));
        }
    }
    let false_reports = (0..answer.objects.len())
        .filter(|r| !of_object.contains(&Some(*r)))
        .inspect(|&r| {
            let p = answer.objects[r].position_m;
            notes.push(format!(
                "reported a {} at ({:.0}, {:.0}) mm",
                answer.objects[r].label,
                p[0] * 1e3,
                p[1] * 1e3
            ));
        })
        .count();
    let order_correct = match scenario.extreme {
        Some(best) => of_object[best].is_some_and(|r| answer.selected == [r]),
        None => scenario.asked.iter().all(|&a| {
            scenario.asked.iter().all(|&b| {
                let (ta, tb) = (
                    true_modulus(&scenario.scene, a),
                    true_modulus(&scenario.scene, b),
                );
                if ta <= tb * ORDER_RATIO {
                    return true;
                }
                // a is truly harder than b by more than the ratio: so must the estimates be.
                match (
                    of_object[a].and_then(estimate),
                    of_object[b].and_then(estimate),
                ) {
                    (Some(ea), Some(eb)) => ea > eb,
                    _ => false,
                }
            })
        }),
    };
    let scenario_success = successes == scenario.asked.len()
        && false_reports == 0
        && order_correct
        && answer.not_found.is_empty();
    RunScore {
        tier: scenario.tier,
        run: scenario.run,
        detector: detector.to_string(),
        prompt: scenario.prompt.clone(),
        asked: scenario.asked.len(),
        identified,
        measured,
        communicated,
        object_successes: successes,
        false_reports,
        notes,
        order_correct,
        scenario_success,
        answer: answer.answer.clone(),
        timing: answer
            .timing
            .iter()
            .map(|t| StageLatency {
                stage: t.stage.clone(),
                wall_ms: t.wall_ms.unwrap_or(0.0),
                sim_s: t.sim_s.unwrap_or(0.0),
            })
            .collect(),
    }
}

fn tier_result(tier: u8, runs: &[&RunScore]) -> TierResult {
    let asked: usize = runs.iter().map(|r| r.asked).sum();
    let ok: usize = runs.iter().map(|r| r.object_successes).sum();
    let n = runs.len().max(1) as f64;
    let stages: Vec<String> = runs
        .first()
        .map(|r| r.timing.iter().map(|t| t.stage.clone()).collect())
        .unwrap_or_default();
    let latency = stages
        .iter()
        .map(|stage| {
            let of = |f: fn(&StageLatency) -> f64| {
                runs.iter()
                    .flat_map(|r| r.timing.iter().filter(|t| &t.stage == stage).map(f))
                    .sum::<f64>()
                    / n
            };
            StageLatency {
                stage: stage.clone(),
                wall_ms: of(|t| t.wall_ms),
                sim_s: of(|t| t.sim_s),
            }
        })
        .collect();
    TierResult {
        tier,
        runs: runs.len(),
        ol_sr: ok as f64 / asked.max(1) as f64,
        sl_sr: runs.iter().filter(|r| r.scenario_success).count() as f64 / n,
        latency,
    }
}

pub fn markdown(report: &ScenarioReport) -> String {
    let mut s = format!("{}\n\n", report.protocol);
    s += "| detector | tier | runs | OL-SR | SL-SR | wall s | robot s |\n";
    s += "|---|---|---:|---:|---:|---:|---:|\n";
    for d in &report.detectors {
        for t in &d.tiers {
            let wall: f64 = t.latency.iter().map(|l| l.wall_ms).sum::<f64>() / 1e3;
            let sim: f64 = t.latency.iter().map(|l| l.sim_s).sum();
            s += &format!(
                "| {} | {} {} | {} | {:.3} | {:.3} | {wall:.2} | {sim:.1} |\n",
                d.name,
                t.tier,
                TIER_NAMES[t.tier as usize - 1],
                t.runs,
                t.ol_sr,
                t.sl_sr
            );
        }
    }
    s
}

fn plots(dir: &std::path::Path, report: &ScenarioReport) -> Result<()> {
    let tiers: Vec<u8> = report.detectors[0].tiers.iter().map(|t| t.tier).collect();
    let categories: Vec<String> = tiers.iter().map(|t| format!("tier {t}")).collect();
    for (file, title, pick) in [
        (
            "object_success.png",
            "Object-level success rate",
            (|t: &TierResult| t.ol_sr) as fn(&TierResult) -> f64,
        ),
        ("scenario_success.png", "Scenario-level success rate", |t| {
            t.sl_sr
        }),
    ] {
        let series: Vec<BarSeries> = report
            .detectors
            .iter()
            .map(|d| BarSeries {
                name: d.name.clone(),
                values: d.tiers.iter().map(pick).collect(),
            })
            .collect();
        plot::bars(
            &dir.join(file),
            title,
            "success rate",
            &categories,
            &series,
            false,
        )?;
    }
    // Latency per stage and tier, of the first detector (the stages are the pipeline's).
    let first = &report.detectors[0];
    let stages: Vec<String> = first.tiers[0]
        .latency
        .iter()
        .map(|l| l.stage.clone())
        .collect();
    for (file, title, unit, pick) in [
        (
            "latency_wall.png",
            "Wall-clock time per stage",
            "s",
            (|l: &StageLatency| l.wall_ms / 1e3) as fn(&StageLatency) -> f64,
        ),
        (
            "latency_robot.png",
            "Simulated robot time per stage",
            "s",
            |l| l.sim_s,
        ),
    ] {
        let series: Vec<BarSeries> = stages
            .iter()
            .map(|stage| BarSeries {
                name: stage.clone(),
                values: first
                    .tiers
                    .iter()
                    .map(|t| {
                        t.latency
                            .iter()
                            .find(|l| &l.stage == stage)
                            .map_or(0.0, pick)
                    })
                    .collect(),
            })
            .collect();
        plot::bars(
            &dir.join(file),
            &format!("{title} ({})", first.name),
            unit,
            &categories,
            &series,
            true,
        )?;
    }
    Ok(())
}

pub(crate) fn run(args: &ScenarioEvalArgs) -> Result<()> {
    anyhow::ensure!(!args.detector.is_empty(), "--detector: name at least one");
    let tiers: Vec<u8> = if args.tiers.is_empty() {
        vec![1, 2, 3, 4]
    } else {
        args.tiers.clone()
    };
    if let Some(bad) = tiers.iter().find(|t| !(1..=4).contains(*t)) {
        bail!("--tiers: {bad} is not a tier (1-4)");
    }
    let catalog = FruitCatalog::builtin();
    let detectors = args
        .detector
        .iter()
        .map(|spec| DetectorChoice::parse(spec))
        .collect::<Result<Vec<_>>>()?;
    let renderer = crate::app::scene_renderer(args.device)?;
    let sensor = crate::app::load_sensor(args.sensor.as_deref())?;
    let estimator = args.estimator.open(
        "--estimator",
        args.fidelity.name(),
        None,
        &sensor,
        args.sensor.as_deref(),
    )?;
    let scenarios = tiers
        .iter()
        .flat_map(|&t| (0..args.runs).map(move |r| (t, r)))
        .map(|(t, r)| scenario(t, r, args.seed, &catalog))
        .collect::<Result<Vec<_>>>()?;
    let jobs: Vec<(usize, usize)> = (0..scenarios.len())
        .flat_map(|s| (0..detectors.len()).map(move |d| (s, d)))
        .collect();
    let bar = ProgressBar::new(jobs.len() as u64).with_style(
        ProgressStyle::with_template("eval scenarios [{bar:30}] {pos}/{len} questions, eta {eta}")
            .expect("a valid template"),
    );
    let config = PipelineConfig::default();
    let scores: Vec<RunScore> = jobs
        .par_iter()
        .map(|&(s, d)| -> Result<RunScore> {
            let sc = &scenarios[s];
            let twin = Twin {
                scene: &sc.scene,
                seed: sc.seed,
                sensor: &sensor,
                detector: &detectors[d],
                renderer: &renderer,
                language: Language::OFFLINE,
                estimator: estimator.as_ref(),
                fidelity: args.fidelity,
                camera: &crate::app::camera_placement::CameraPlacement::default(),
            }
            .answer(&sc.prompt, &config, &|_| {})
            .with_context(|| format!("tier {} run {}: {}", sc.tier, sc.run, args.detector[d]))?;
            bar.inc(1);
            Ok(score(sc, &args.detector[d], &twin))
        })
        .collect::<Result<_>>()?;
    bar.finish_and_clear();
    let report = ScenarioReport {
        protocol: format!(
            "{} runs per tier on seeded random scenes (targets rotate through {} fruit kinds), camera noise on; a report identifies a fruit when its touch point lies on it; pairs whose true moduli differ by more than {ORDER_RATIO}x must be ordered right",
            args.runs,
            PAPER_FRUIT_KINDS.len(),
        ),
        seed: args.seed,
        detectors: args
            .detector
            .iter()
            .map(|name| DetectorResult {
                name: name.clone(),
                tiers: tiers
                    .iter()
                    .map(|&t| {
                        let runs: Vec<&RunScore> = scores
                            .iter()
                            .filter(|r| &r.detector == name && r.tier == t)
                            .collect();
                        tier_result(t, &runs)
                    })
                    .collect(),
            })
            .collect(),
    };
    if let Some(out) = &args.out {
        let out = OutputDir::create("--out", out)?;
        let dir = out.path();
        write_json_atomic(&dir.join("runs.json"), &scores)?;
        write_json_atomic(&dir.join("results.json"), &report)?;
        write_markdown_report(&dir.join("table.md"), &markdown(&report))?;
        plots(dir, &report)?;
        out.finish()?;
    }
    print_json_or_text(&report, args.json, || {
        print!("{}", markdown(&report));
        Ok(())
    })?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use tactex_core::devices::RgbdCamera;
    use tactex_core::explain::location_words;
    use tactex_core::hardness::scale::Hardness;
    use tactex_core::pipeline::{Answer, ObjectReport};
    use tactex_sim::SimDevices;

    /// The twin's ground truth for a scenario, and a perfect answer: one report per asked
    /// object touching its highest point, with its true modulus scaled by `estimate_scale[i]`.
    fn perfect(sc: &Scenario, estimate_scale: &[f64]) -> TwinAnswer {
        let mut sim = SimDevices::from_scene(&sc.scene, sc.seed).unwrap();
        let instances = sim.camera.clean().unwrap().instances.clone();
        let centres: Vec<[f64; 3]> = {
            let world = sim.world.lock().unwrap();
            world.objects.iter().map(|o| o.centre.to_array()).collect()
        };
        // The highest point of the mesh lies on the fruit as the camera sees it (a banana's
        // centre does not: it curves around it).
        let top = |i: usize| {
            let world = sim.world.lock().unwrap();
            let v = world.objects[i].mesh.vertices.iter();
            v.max_by(|a, b| a.z.total_cmp(&b.z)).unwrap().to_array()
        };
        let objects: Vec<ObjectReport> = sc
            .asked
            .iter()
            .map(|&i| ObjectReport {
                label: sc.kinds[i].clone(),
                reference: false,
                detection_score: 0.9,
                position_m: centres[i],
                surface_centroid_m: top(i),
                location: location_words(centres[i][0], centres[i][1]),
                hardness: Some(
                    Hardness::ModulusMpa(true_modulus(&sc.scene, i) * estimate_scale[i]).into(),
                ),
                interval: None,
                ripeness: None,
                evidence: None,
                contact_search_mm: None,
                contact: None,
                not_measured: None,
                warnings: Vec::new(),
            })
            .collect();
        let catalog = FruitCatalog::builtin();
        let query = tactex_core::query::parse(&sc.prompt, &catalog).unwrap();
        let measured: Vec<tactex_core::explain::Measured> = objects
            .iter()
            .map(|o| tactex_core::explain::Measured {
                label: o.label.clone(),
                location: o.location.clone(),
                hardness: o.hardness,
                interval_68_mpa: [None, None],
                interval_95_mpa: [None, None],
                ripeness: None,
                not_measured: None,
                reference: o.reference,
            })
            .collect();
        let selected = tactex_core::explain::select(&query, &measured, &catalog);
        let text = tactex_core::explain::template::explain(&query, &measured, &selected, &[]);
        TwinAnswer {
            answer: Answer {
                query,
                objects,
                selected,
                answer: text,
                not_found: Vec::new(),
                estimator: "test".into(),
                contact_criterion: String::new(),
                fidelity: None,
                sensor: None,
                explainer: "template".into(),
                explain_notice: None,
                parser: "rules".into(),
                parse_notice: None,
                timing: Vec::new(),
                presses: Vec::new(),
            },
            true_centres_m: centres,
            world: sim.world.clone(),
            instances,
            intrinsics: sim.camera.intrinsics(),
            camera_pose: sim.camera.pose(),
        }
    }

    #[test]
    fn a_right_answer_succeeds_and_a_mislabelled_report_fails() {
        let catalog = FruitCatalog::builtin();
        let sc = scenario(3, 1, 5, &catalog).unwrap();
        let ones = vec![1.0; sc.kinds.len()];
        let twin = perfect(&sc, &ones);
        let s = score(&sc, "test", &twin);
        assert!(s.scenario_success, "{s:?}");
        assert_eq!(s.object_successes, 2);
        // The same report under another kind's name identifies nothing and is false.
        let mut wrong = perfect(&sc, &ones);
        let other = PAPER_FRUIT_KINDS
            .iter()
            .find(|k| !sc.kinds.iter().any(|n| n == *k))
            .unwrap();
        wrong.answer.objects[0].label = other.to_string();
        let s = score(&sc, "test", &wrong);
        assert!(!s.scenario_success);
        assert_eq!((s.identified, s.false_reports), (1, 1), "{s:?}");
        // A touch point off the fruit (on the table) does not identify it.
        let mut off = perfect(&sc, &ones);
        off.answer.objects[1].surface_centroid_m = [0.29, 0.0, 0.0];
        assert!(!score(&sc, "test", &off).scenario_success);
    }

    #[test]
    fn hardness_order_must_match_the_truth_where_it_is_clear() {
        let catalog = FruitCatalog::builtin();
        // Tier 4 asks about every fruit; find a run with two clearly different moduli.
        let sc = (0..10)
            .map(|r| scenario(4, r, 2, &catalog).unwrap())
            .find(|sc| {
                let e: Vec<f64> = (0..sc.kinds.len())
                    .map(|i| true_modulus(&sc.scene, i))
                    .collect();
                let (lo, hi) = e
                    .iter()
                    .fold((f64::MAX, 0.0f64), |(l, h), v| (l.min(*v), h.max(*v)));
                hi / lo > 2.0 * ORDER_RATIO
            })
            .unwrap();
        let n = sc.kinds.len();
        assert!(score(&sc, "test", &perfect(&sc, &vec![1.0; n])).order_correct);
        // Estimates 10% off keep the order of clearly different fruits...
        let jitter: Vec<f64> = (0..n).map(|i| if i % 2 == 0 { 1.1 } else { 0.9 }).collect();
        assert!(score(&sc, "test", &perfect(&sc, &jitter)).order_correct);
        // ...but swapping the softest and the hardest is wrong.
        let e: Vec<f64> = (0..n).map(|i| true_modulus(&sc.scene, i)).collect();
        let soft = (0..n).min_by(|a, b| e[*a].total_cmp(&e[*b])).unwrap();
        let hard = (0..n).max_by(|a, b| e[*a].total_cmp(&e[*b])).unwrap();
        let mut swap = vec![1.0; n];
        swap[soft] = e[hard] / e[soft] * 1.2;
        swap[hard] = e[soft] / e[hard] / 1.2;
        let s = score(&sc, "test", &perfect(&sc, &swap));
        assert!(!s.order_correct && !s.scenario_success, "{s:?}");
    }

    #[test]
    fn tier_two_scenes_hold_one_kind_at_distinct_stages_and_the_pick_is_judged() {
        let catalog = FruitCatalog::builtin();
        let staged = staged_kinds(&catalog);
        assert_eq!(staged.len(), 8, "{staged:?}");
        for run in 0..staged.len() {
            let sc = scenario(2, run, 3, &catalog).unwrap();
            assert!(sc.asked.len() >= 2);
            let best = sc.extreme.unwrap();
            let e = true_modulus(&sc.scene, best);
            for &i in sc.asked.iter().filter(|&&i| i != best) {
                let other = true_modulus(&sc.scene, i);
                assert!(e.max(other) / e.min(other) > ORDER_RATIO, "{}", sc.prompt);
            }
        }
        let sc = scenario(2, 0, 3, &catalog).unwrap();
        let n = sc.kinds.len();
        let right = perfect(&sc, &vec![1.0; n]);
        assert!(score(&sc, "test", &right).scenario_success);
        // Picking another fruit of the kind is a failed scenario.
        let mut wrong = perfect(&sc, &vec![1.0; n]);
        let best_report = wrong.answer.selected[0];
        wrong.answer.selected = vec![(best_report + 1) % wrong.answer.objects.len()];
        let s = score(&sc, "test", &wrong);
        assert!(!s.scenario_success && !s.order_correct, "{s:?}");
    }

    #[test]
    fn every_tier_asks_about_every_kind_equally_often() {
        let catalog = FruitCatalog::builtin();
        for tier in [1u8, 3] {
            let mut asked: Vec<String> = (0..PAPER_FRUIT_KINDS.len())
                .map(|r| {
                    let sc = scenario(tier, r, 1, &catalog).unwrap();
                    sc.kinds[sc.asked[0]].clone()
                })
                .collect();
            asked.sort();
            asked.dedup();
            assert_eq!(asked.len(), PAPER_FRUIT_KINDS.len(), "tier {tier}");
        }
    }
}
