//! `tactex eval grounding`: the paper's grounding protocol on the twin. 40 instances (4 of
//! each of 10 fruit kinds) in random scenes of 1 to 5 fruits, prompt "I want to know the
//! hardness of the [fruit]"; per detector: success (the touch point lies on the right fruit),
//! confidence, IoU against the true mask, and the centroid error in the table plane against
//! the true centroid (the paper's centroid, refined mask included, computed on noise-free
//! depth and the true mask),
//! with and without the mask refinement and the 10-frame depth median.

use crate::app::camera_placement::CameraPlacement;
use crate::app::detector_choice::{DetectorChoice, GroundTruth};
use crate::eval::PAPER_FRUIT_KINDS;
use crate::report::output::{OutputDir, write_json_atomic};
use crate::report::plot::{self, StageGroup};
use crate::report::provenance::write_markdown_report;
use crate::report::tail::print_json_or_text;
use anyhow::{Context, Result};
use clap::Args;
use glam::DVec3;
use image::GrayImage;
use indicatif::{ProgressBar, ProgressStyle};
use rand::SeedableRng;
use rand::seq::SliceRandom;
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;
use serde::Serialize;
use std::path::PathBuf;
use std::sync::Arc;
use tactex_core::catalog::FruitCatalog;
use tactex_core::devices::RgbdCamera;
use tactex_core::frames::DepthImage;
use tactex_core::ground::centroid::median_depth;
use tactex_core::ground::detect::RgbdView;
use tactex_core::ground::grounding::locate;
use tactex_core::query;
use tactex_core::stats::{self, Alternative};
use tactex_sim::SimDevices;
use tactex_sim::datagen::scene_random::{Variation, random_scene};
use tactex_sim::devices::camera::instance_mask;
use tactex_sim::render::device::DeviceChoice;
use tactex_sim::render::scene::SceneRenderer;

#[derive(Args)]
#[command(allow_negative_numbers = true)]
pub struct GroundingEvalArgs {
    /// Detectors to compare: classical, yolo:FILE.onnx (a YOLOv8-seg export), error-gsam,
    /// error-yolo (perception-error models).
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "classical,error-gsam,error-yolo"
    )]
    pub detector: Vec<String>,
    /// Instances per fruit kind (the paper: 4), 1-100.
    #[arg(long, default_value_t = 4)]
    pub per_kind: usize,
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Depth frames in the median (the paper: 10), 1-100.
    #[arg(long, default_value_t = 10)]
    pub depth_frames: usize,
    /// The centroid error tolerance of the one-sample t-test (mm; the paper: 5), (0, 1000].
    #[arg(long, default_value_t = 5.0)]
    pub tolerance_mm: f64,
    #[arg(long)]
    pub json: bool,
    /// Write results.json, table.md and PNG plots here.
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Device that renders the scenes: cpu (the default, so that the figures never depend
    /// on the machine), gpu (any Vulkan adapter) or auto (a hardware GPU if there is one).
    #[arg(long, default_value = "cpu")]
    pub device: DeviceChoice,
    /// How far the scene camera really stands from where the scene puts it (mm, 0 to 200),
    /// in a direction drawn from --camera-error-seed; the centroids are located with the
    /// camera's believed pose and scored against the truth.
    #[arg(long, default_value_t = 0.0)]
    pub camera_error_mm: f64,
    /// How far it is really turned (degrees, 0 to 20).
    #[arg(long, default_value_t = 0.0)]
    pub camera_error_deg: f64,
    /// Draws the directions of the camera's misplacement.
    #[arg(long, default_value_t = 1)]
    pub camera_error_seed: u64,
    /// A hand-eye calibration (`tactex handeye --out`'s TOML) whose camera pose is believed
    /// instead of the scene's.
    #[arg(long)]
    pub camera_calibration: Option<PathBuf>,
}

/// One detector on one instance.
#[derive(Clone, Debug, Serialize)]
struct Trial {
    fruit: String,
    scene_fruits: usize,
    found: bool,
    success: bool,
    confidence: Option<f64>,
    iou: Option<f64>,
    /// Centroid error (mm): refined inner mask on the depth median; neither; each alone.
    error_mm: Option<f64>,
    error_raw_mm: Option<f64>,
    error_refine_only_mm: Option<f64>,
    error_median_only_mm: Option<f64>,
}

#[derive(Serialize)]
struct DetectorSummary {
    name: String,
    instances: usize,
    success_rate: f64,
    success_rate_ci95: [f64; 2],
    found: usize,
    confidence_mean: f64,
    confidence_ci95: Option<[f64; 2]>,
    iou_median: f64,
    iou_mean: f64,
    iou_ci95: Option<[f64; 2]>,
    centroid_error_mm_mean: f64,
    centroid_error_mm_ci95: Option<[f64; 2]>,
    centroid_error_mm_raw_mean: f64,
    centroid_error_mm_refine_only_mean: f64,
    centroid_error_mm_median_only_mean: f64,
    centroid_error_mm_max: f64,
}

#[derive(Serialize)]
struct NamedTest {
    name: String,
    statistic: f64,
    p: f64,
    df: Option<f64>,
}

#[derive(Serialize)]
struct Report {
    protocol: String,
    seed: u64,
    detectors: Vec<DetectorSummary>,
    tests: Vec<NamedTest>,
    trials: Vec<(String, Vec<Trial>)>,
}

fn iou(a: &GrayImage, b: &GrayImage) -> f64 {
    let (mut inter, mut union) = (0usize, 0usize);
    for (p, q) in a.pixels().zip(b.pixels()) {
        let (x, y) = (p[0] > 0, q[0] > 0);
        inter += (x && y) as usize;
        union += (x || y) as usize;
    }
    if union == 0 {
        0.0
    } else {
        inter as f64 / union as f64
    }
}

/// The fruit kinds of instance i: its own kind first, then distinct distractors.
fn instance_kinds(i: usize, per_kind: usize, seed: u64) -> (String, Vec<&'static str>) {
    let kind = PAPER_FRUIT_KINDS[i / per_kind];
    let n = 1 + i % 5;
    let mut rng = ChaCha8Rng::seed_from_u64(seed.wrapping_mul(1000).wrapping_add(i as u64));
    let mut others: Vec<&str> = PAPER_FRUIT_KINDS
        .iter()
        .copied()
        .filter(|k| *k != kind)
        .collect();
    others.shuffle(&mut rng);
    let mut kinds = vec![kind];
    kinds.extend(others.into_iter().take(n - 1));
    (kind.to_string(), kinds)
}

fn run_instance(
    i: usize,
    args: &GroundingEvalArgs,
    detectors: &[DetectorChoice],
    catalog: &FruitCatalog,
    renderer: &Arc<dyn SceneRenderer>,
    placement: &CameraPlacement,
) -> Result<Vec<Trial>> {
    let seed = args.seed.wrapping_mul(7919).wrapping_add(i as u64);
    let (fruit, kinds) = instance_kinds(i, args.per_kind, args.seed);
    let scene = random_scene(&kinds, catalog, seed, &Variation::default())?;
    let mut sim = SimDevices::from_scene(&scene, seed)?;
    sim.camera.set_renderer(renderer.clone());
    placement.apply(&mut sim);
    let clean = sim.camera.clean()?.clone();
    // The centroids are located from where the camera is believed to stand, and scored
    // against the truth, seen from where it stands.
    let (k, pose) = (sim.camera.intrinsics(), sim.camera.pose());
    let true_pose = sim.world.lock().expect("world lock").camera_pose;
    let frames = (0..args.depth_frames)
        .map(|_| sim.camera.capture())
        .collect::<Result<Vec<_>, _>>()?;
    let depths: Vec<&DepthImage> = frames.iter().map(|f| &f.depth_m).collect();
    let median = median_depth(&depths).context("depth frames differ in size")?;
    let clean_depth = DepthImage::from_raw(
        k.width,
        k.height,
        clean.depth_m.iter().map(|z| *z as f32).collect(),
    )
    .context("clean depth size")?;
    // The target is object 0 (instance id 1); it is the only one of its kind.
    let truth_mask = instance_mask(&clean.instances, 1);
    // The true centroid is the paper's centroid on perfect data: the refined true mask over
    // noise-free depth.
    let truth_centroid = locate(&truth_mask, true, &clean_depth, &k, &true_pose)
        .context("the target is not visible")?
        .surface;
    let labels: Vec<String> = scene.objects.iter().map(|o| o.label.clone()).collect();
    let query = query::parse(
        &format!("I want to know the hardness of the {fruit}"),
        catalog,
    )?;
    let view = RgbdView {
        color: &frames[0].color,
        depth: &median,
        intrinsics: &k,
        pose: &pose,
    };
    let to_cam = true_pose.inverse();
    let on_target = |p: DVec3| -> bool {
        k.project(to_cam.transform_point(p))
            .and_then(|(u, v)| k.pixel_at(u, v))
            .is_some_and(|(x, y)| clean.instances.get_pixel(x, y)[0] == 1)
    };
    let error_mm = |mask: &GrayImage, refine: bool, depth: &DepthImage| {
        locate(mask, refine, depth, &k, &pose).map(|at| horizontal_mm(at.surface, truth_centroid))
    };
    let mut trials = Vec::new();
    for choice in detectors {
        let truth = GroundTruth {
            instances: &clean.instances,
            labels: &labels,
        };
        let detector = choice.detector(catalog, Some(truth), seed)?;
        let best = detector
            .detect_for(&view, &query)?
            .into_iter()
            .max_by(|a, b| a.score.total_cmp(&b.score));
        let trial = match best {
            None => Trial {
                fruit: fruit.clone(),
                scene_fruits: kinds.len(),
                found: false,
                success: false,
                confidence: None,
                iou: None,
                error_mm: None,
                error_raw_mm: None,
                error_refine_only_mm: None,
                error_median_only_mm: None,
            },
            Some(d) => {
                let at = locate(&d.mask, true, &median, &k, &pose);
                Trial {
                    fruit: fruit.clone(),
                    scene_fruits: kinds.len(),
                    found: true,
                    success: at.as_ref().is_some_and(|a| on_target(a.touch)),
                    confidence: Some(d.score),
                    iou: Some(iou(&d.mask, &truth_mask)),
                    error_mm: at.map(|a| horizontal_mm(a.surface, truth_centroid)),
                    error_raw_mm: error_mm(&d.mask, false, &frames[0].depth_m),
                    error_refine_only_mm: error_mm(&d.mask, true, &frames[0].depth_m),
                    error_median_only_mm: error_mm(&d.mask, false, &median),
                }
            }
        };
        trials.push(trial);
    }
    Ok(trials)
}

/// Where the arm hovers is what matters: the error in the table plane (mm). The height of
/// the paper's centroid depends on which part of the surface the mask keeps, by design.
fn horizontal_mm(estimate: DVec3, truth: DVec3) -> f64 {
    estimate.truncate().distance(truth.truncate()) * 1e3
}

fn mean(v: &[f64]) -> f64 {
    tactex_core::stats::mean(v).unwrap_or(f64::NAN)
}

fn summarise(name: &str, trials: &[Trial]) -> Result<DetectorSummary> {
    let n = trials.len();
    let ok = trials.iter().filter(|t| t.success).count();
    let values =
        |f: fn(&Trial) -> Option<f64>| -> Vec<f64> { trials.iter().filter_map(f).collect() };
    let conf = values(|t| t.confidence);
    let ious = values(|t| t.iou);
    let err = values(|t| t.error_mm);
    Ok(DetectorSummary {
        name: name.to_string(),
        instances: n,
        success_rate: ok as f64 / n as f64,
        success_rate_ci95: stats::proportion_interval(ok, n, 0.95)?,
        found: conf.len(),
        confidence_mean: mean(&conf),
        confidence_ci95: stats::mean_interval(&conf, 0.95).ok(),
        iou_median: stats::quantile(&ious, 0.5).unwrap_or(f64::NAN),
        iou_mean: mean(&ious),
        iou_ci95: stats::mean_interval(&ious, 0.95).ok(),
        centroid_error_mm_mean: mean(&err),
        centroid_error_mm_ci95: stats::mean_interval(&err, 0.95).ok(),
        centroid_error_mm_raw_mean: mean(&values(|t| t.error_raw_mm)),
        centroid_error_mm_refine_only_mean: mean(&values(|t| t.error_refine_only_mm)),
        centroid_error_mm_median_only_mean: mean(&values(|t| t.error_median_only_mm)),
        centroid_error_mm_max: err.iter().copied().fold(f64::NAN, f64::max),
    })
}

fn tests(per: &[(String, Vec<Trial>)], tolerance_mm: f64) -> Vec<NamedTest> {
    let errors = |t: &[Trial]| -> Vec<f64> { t.iter().filter_map(|t| t.error_mm).collect() };
    let mut out = Vec::new();
    let mut push = |name: String, r: Result<stats::TestResult, stats::StatsError>| {
        if let Ok(r) = r {
            out.push(NamedTest {
                name,
                statistic: r.statistic,
                p: r.p_value,
                df: r.df,
            });
        }
    };
    for (a, ta) in per {
        push(
            format!("one-sample t: {a} centroid error < {tolerance_mm} mm"),
            stats::one_sample_t(&errors(ta), tolerance_mm, Alternative::Less),
        );
        // Paired by instance: how much the refinement and the median lower the error.
        let gain: Vec<f64> = ta
            .iter()
            .filter_map(|t| Some(t.error_raw_mm? - t.error_mm?))
            .collect();
        push(
            format!("paired t: {a} raw minus refined centroid error > 0"),
            stats::one_sample_t(&gain, 0.0, Alternative::Greater),
        );
    }
    for (i, (a, ta)) in per.iter().enumerate() {
        for (b, tb) in &per[i + 1..] {
            push(
                format!("Welch t: centroid error {a} vs {b}"),
                stats::welch_t(&errors(ta), &errors(tb), Alternative::TwoSided),
            );
            let iou = |t: &[Trial]| -> Vec<f64> { t.iter().filter_map(|t| t.iou).collect() };
            push(
                format!("Welch t: IoU {a} vs {b}"),
                stats::welch_t(&iou(ta), &iou(tb), Alternative::TwoSided),
            );
        }
    }
    out
}

fn table(report: &Report) -> String {
    let ci = |c: Option<[f64; 2]>, digits: usize| {
        c.map_or("-".to_string(), |[a, b]| {
            format!("[{a:.digits$}, {b:.digits$}]")
        })
    };
    let mut s = String::from(
        "| detector | success | 95% CI | confidence | IoU median | IoU mean | centroid error (mm) | 95% CI | raw | refine only | median only |\n|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    for d in &report.detectors {
        s += &format!(
            "| {} | {}/{} ({:.3}) | {} | {:.3} | {:.3} | {:.3} | {:.2} | {} | {:.2} | {:.2} | {:.2} |\n",
            d.name,
            (d.success_rate * d.instances as f64).round(),
            d.instances,
            d.success_rate,
            ci(Some(d.success_rate_ci95), 3),
            d.confidence_mean,
            d.iou_median,
            d.iou_mean,
            d.centroid_error_mm_mean,
            ci(d.centroid_error_mm_ci95, 2),
            d.centroid_error_mm_raw_mean,
            d.centroid_error_mm_refine_only_mean,
            d.centroid_error_mm_median_only_mean,
        );
    }
    s += "\n| test | statistic | p |\n|---|---|---|\n";
    for t in &report.tests {
        s += &format!("| {} | {:.3} | {:.3e} |\n", t.name, t.statistic, t.p);
    }
    s
}

/// Bounds on the work one run may ask for.
const MAX_PER_KIND: usize = 100;
const MAX_DEPTH_FRAMES: usize = 100;

pub(crate) fn run(args: &GroundingEvalArgs) -> Result<()> {
    anyhow::ensure!(
        (1..=MAX_PER_KIND).contains(&args.per_kind),
        "--per-kind: {}, expected 1..={MAX_PER_KIND}",
        args.per_kind
    );
    anyhow::ensure!(
        (1..=MAX_DEPTH_FRAMES).contains(&args.depth_frames),
        "--depth-frames: {}, expected 1..={MAX_DEPTH_FRAMES}",
        args.depth_frames
    );
    anyhow::ensure!(
        args.tolerance_mm.is_finite() && args.tolerance_mm > 0.0 && args.tolerance_mm <= 1000.0,
        "--tolerance-mm: {}, expected a distance in (0, 1000] mm",
        args.tolerance_mm
    );
    anyhow::ensure!(!args.detector.is_empty(), "--detector: name at least one");
    let placement = CameraPlacement::checked(
        args.camera_error_mm,
        args.camera_error_deg,
        args.camera_error_seed,
        args.camera_calibration.as_deref(),
    )?;
    let catalog = FruitCatalog::builtin();
    let detectors = args
        .detector
        .iter()
        .map(|spec| DetectorChoice::parse(spec))
        .collect::<Result<Vec<_>>>()?;
    let renderer = crate::app::scene_renderer(args.device)?;
    let n = PAPER_FRUIT_KINDS.len() * args.per_kind;
    let bar = ProgressBar::new(n as u64).with_style(
        ProgressStyle::with_template("eval grounding [{bar:30}] {pos}/{len} instances, eta {eta}")
            .expect("a valid template"),
    );
    let rows: Vec<Vec<Trial>> = (0..n)
        .into_par_iter()
        .map(|i| {
            let r = run_instance(i, args, &detectors, &catalog, &renderer, &placement)
                .with_context(|| format!("instance {i}"));
            bar.inc(1);
            r
        })
        .collect::<Result<_>>()?;
    bar.finish_and_clear();
    let per: Vec<(String, Vec<Trial>)> = args
        .detector
        .iter()
        .enumerate()
        .map(|(d, name)| (name.clone(), rows.iter().map(|r| r[d].clone()).collect()))
        .collect();
    let report = Report {
        protocol: format!(
            "{} instances ({} of each of {} fruit kinds) in scenes of 1 to 5 fruits; depth median of {} frames; noise on",
            n,
            args.per_kind,
            PAPER_FRUIT_KINDS.len(),
            args.depth_frames
        ),
        seed: args.seed,
        detectors: per
            .iter()
            .map(|(name, t)| summarise(name, t))
            .collect::<Result<_>>()?,
        tests: tests(&per, args.tolerance_mm),
        trials: per,
    };
    let md = table(&report);
    if let Some(out) = &args.out {
        let out = OutputDir::create("--out", out)?;
        let dir = out.path();
        write_json_atomic(&dir.join("results.json"), &report)?;
        write_markdown_report(&dir.join("table.md"), &md)?;
        let groups = |f: fn(&Trial) -> Option<f64>, raw: Option<fn(&Trial) -> Option<f64>>| {
            let mut g = Vec::new();
            for (name, t) in &report.trials {
                if let Some(r) = raw {
                    g.push(StageGroup {
                        label: format!("{name} raw"),
                        values: t.iter().filter_map(r).collect(),
                        truth: None,
                    });
                }
                g.push(StageGroup {
                    label: if raw.is_some() {
                        format!("{name} refined")
                    } else {
                        name.clone()
                    },
                    values: t.iter().filter_map(f).collect(),
                    truth: None,
                });
            }
            g.retain(|g| !g.values.is_empty());
            g
        };
        plot::stage_groups(
            &dir.join("centroid_error.png"),
            "Centroid error: raw (one frame, full mask) and refined (inner mask, depth median)",
            "centroid error (mm)",
            &groups(|t| t.error_mm, Some(|t| t.error_raw_mm)),
        )?;
        plot::stage_groups(
            &dir.join("iou.png"),
            "Mask IoU against the true instance mask",
            "IoU",
            &groups(|t| t.iou, None),
        )?;
        out.finish()?;
    }
    let summary = serde_json::json!({
        "protocol": report.protocol,
        "seed": report.seed,
        "detectors": report.detectors,
        "tests": report.tests,
    });
    print_json_or_text(&summary, args.json, || {
        println!("{}\n\n{md}", report.protocol);
        Ok(())
    })
}
