//! `tactex ask`: one question answered on the simulated twin (scene -> sim devices ->
//! pipeline), and the same wiring for evaluations that ask many questions.

use crate::detector_choice::{DetectorChoice, GroundTruth};
use crate::llm_explainer::{ExplainerChoice, explainer};
use anyhow::{Context, Result};
use clap::Args;
use std::path::PathBuf;
use std::sync::Arc;
use tactex_core::catalog::FruitCatalog;
use tactex_core::devices::RgbdCamera;
use tactex_core::estimate::HertzSlopeEstimator;
use tactex_core::explain::Explainer;
use tactex_core::geometry::{CameraIntrinsics, Pose};
use tactex_core::pipeline::{self, Answer, Devices, PipelineConfig};
use tactex_core::scene::Scene;
use tactex_sim::SimDevices;
use tactex_sim::camera::InstanceImage;
use tactex_sim::render_device::DeviceChoice;
use tactex_sim::scene_render::{SceneRenderer, open_scene_renderer};

#[derive(Args)]
pub struct AskArgs {
    /// Scene file (TOML); default scenes/demo.toml.
    #[arg(long)]
    pub scene: Option<PathBuf>,
    /// Seed of every random draw (sensor noise); same seed, same output.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Print one JSON object on stdout.
    #[arg(long)]
    pub json: bool,
    /// Leave out wall-clock times so that the output is byte-reproducible.
    #[arg(long)]
    pub reproducible: bool,
    /// Object detector: classical, yolo:FILE.onnx (a YOLOv8-seg export), or a
    /// perception-error model on the twin's ground truth (error-gsam, error-yolo).
    #[arg(long, default_value = "classical")]
    pub detector: String,
    /// Device that renders the camera's frames: cpu, gpu (any Vulkan adapter, software
    /// included) or auto (a hardware GPU if there is one). One clean render serves a
    /// whole question, so the CPU default costs little (see `tactex bench scene`).
    #[arg(long, default_value = "cpu")]
    pub device: DeviceChoice,
    /// Who writes the answer: template (deterministic, offline) or llm (an
    /// OpenAI-compatible endpoint from TACTEX_LLM_BASE_URL / TACTEX_LLM_MODEL /
    /// TACTEX_LLM_API_KEY or --llm-config; an ungrounded or failed reply falls back to the
    /// template with a notice).
    #[arg(long, value_enum, default_value = "template")]
    pub explainer: ExplainerChoice,
    /// TOML with base_url, model, api_key_env and timeout_s for --explainer llm.
    #[arg(long)]
    pub llm_config: Option<PathBuf>,
    /// The question.
    pub prompt: String,
}

/// The scene renderer `device` names, telling the user on stderr when `auto` fell back to
/// the CPU.
pub fn scene_renderer(device: DeviceChoice) -> Result<Arc<dyn SceneRenderer>> {
    let choice = open_scene_renderer(device)?;
    if let Some(note) = &choice.note {
        eprintln!("note: {note}");
    }
    Ok(choice.renderer)
}

/// An answer from the twin, with the ground truth an evaluation scores it against.
pub struct TwinAnswer {
    pub answer: Answer,
    /// Where each scene object came to rest (world frame, m), in the scene's order.
    pub true_centres_m: Vec<[f64; 3]>,
    /// The clean render's instance ids (object i is id i + 1) and the camera that took it.
    pub instances: InstanceImage,
    pub intrinsics: CameraIntrinsics,
    pub camera_pose: Pose,
}

/// Answers `prompt` on the twin of `scene`: the sim devices seeded with `seed`, the camera
/// rendering through `renderer`, grounding with `choice`.
pub fn answer_on_twin(
    scene: &Scene,
    seed: u64,
    choice: &DetectorChoice,
    renderer: &Arc<dyn SceneRenderer>,
    explainer: &dyn Explainer,
    prompt: &str,
    config: &PipelineConfig,
) -> Result<TwinAnswer> {
    let catalog = FruitCatalog::builtin();
    let mut sim = SimDevices::from_scene(scene, seed)?;
    sim.camera.set_renderer(renderer.clone());
    let instances = sim.camera.clean()?.instances.clone();
    let labels: Vec<String> = scene.objects.iter().map(|o| o.label.clone()).collect();
    // Only the perception-error models look at the ground truth.
    let truth = matches!(choice, DetectorChoice::PerceptionError(_)).then_some(GroundTruth {
        instances: &instances,
        labels: &labels,
    });
    let detector = choice.detector(&catalog, truth, seed)?;
    let true_centres_m = {
        let world = sim.world.lock().expect("world lock");
        world.objects.iter().map(|o| o.centre.to_array()).collect()
    };
    let answer = pipeline::answer(
        prompt,
        &catalog,
        Devices {
            camera: &mut sim.camera,
            tactile: &mut sim.tactile,
            arm: &mut sim.arm,
        },
        detector.as_ref(),
        &HertzSlopeEstimator::default(),
        explainer,
        config,
    )?;
    Ok(TwinAnswer {
        answer,
        true_centres_m,
        intrinsics: sim.camera.intrinsics(),
        camera_pose: sim.camera.pose(),
        instances,
    })
}

pub fn run(args: &AskArgs) -> Result<()> {
    let catalog = FruitCatalog::builtin();
    // The prompt is checked before the scene is built so that a bad question fails fast.
    tactex_core::query::parse(&args.prompt, &catalog)?;
    let path = args.scene.clone().unwrap_or_else(crate::default_scene);
    let scene = Scene::load(&path, &catalog)?;
    let choice = DetectorChoice::parse(&args.detector)?;
    let renderer = scene_renderer(args.device)?;
    let explainer = explainer(args.explainer, args.llm_config.as_ref())?;
    let config = PipelineConfig {
        measure_wall_time: !args.reproducible,
        ..PipelineConfig::default()
    };
    let answer = answer_on_twin(
        &scene,
        args.seed,
        &choice,
        &renderer,
        explainer.as_ref(),
        &args.prompt,
        &config,
    )?
    .answer;
    if args.json {
        println!(
            "{}",
            serde_json::to_string_pretty(&answer).context("serialising the answer")?
        );
    } else {
        print_answer(&answer);
    }
    Ok(())
}

fn print_answer(a: &Answer) {
    if let Some(notice) = &a.explain_notice {
        eprintln!("note: {notice}");
    }
    println!("{}\n", a.answer);
    println!(
        "{:<3} {:<11} {:<13} {:>24} {:>9} {:>9} {:>10}  ripeness",
        "#", "object", "location", "position (m)", "Shore A", "Shore 00", "E (MPa)"
    );
    for (i, o) in a.objects.iter().enumerate() {
        let p = o.position_m;
        let (sa, s00, e) = match &o.hardness {
            Some(h) => (
                format!("{:.1}", h.shore_a),
                format!("{:.1}", h.shore_00),
                h.modulus_mpa.map_or("rigid".into(), |e| format!("{e:.3}")),
            ),
            None => ("-".into(), "-".into(), "-".into()),
        };
        let mark = if a.selected.contains(&i) { "*" } else { " " };
        println!(
            "{mark}{i:<2} {:<11} {:<13} {:>24} {sa:>9} {s00:>9} {e:>10}  {}",
            o.label,
            o.location,
            format!("({:+.3}, {:+.3}, {:.3})", p[0], p[1], p[2]),
            o.ripeness.as_deref().unwrap_or("-")
        );
        for w in &o.warnings {
            println!("    warning: {w}");
        }
    }
    println!("\n{:<10} {:>10} {:>12}", "stage", "wall (ms)", "robot (s)");
    for t in &a.timing {
        let wall = t.wall_ms.map_or("-".into(), |v| format!("{v:.1}"));
        let sim = t.sim_s.map_or("-".into(), |v| format!("{v:.2}"));
        println!("{:<10} {wall:>10} {sim:>12}", t.stage);
    }
}
