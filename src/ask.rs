//! `tactex ask`: one question answered on the simulated twin (scene -> sim devices ->
//! pipeline), and the same wiring for evaluations that ask many questions.

use crate::detector_choice::{DetectorChoice, GroundTruth};
use crate::estimator_choice::EstimatorChoice;
use crate::llm_explainer::{ExplainerChoice, explainer};
use anyhow::{Context, Result, bail};
use clap::Args;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use tactex_core::catalog::FruitCatalog;
use tactex_core::devices::{Arm, RgbdCamera, TactileSensor};
use tactex_core::estimate::HardnessEstimator;
use tactex_core::explain::Explainer;
use tactex_core::geometry::{CameraIntrinsics, Pose};
use tactex_core::perception::detect::Detector;
use tactex_core::pipeline::{self, Answer, Devices, PipelineConfig, Progress};
use tactex_core::scene::Scene;
use tactex_core::sensor_profile::SensorProfile;
use tactex_hw::devices_toml::DevicesConfig;
use tactex_hw::session::{SessionRecorder, TwinRecord, open_session};
use tactex_sim::SimDevices;
use tactex_sim::camera::InstanceImage;
use tactex_sim::elastic::Fidelity;
use tactex_sim::render_device::DeviceChoice;
use tactex_sim::scene_render::{SceneRenderer, open_scene_renderer};
use tactex_sim::world::SharedWorld;

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
    #[command(flatten)]
    pub twin: TwinOptions,
    /// Devices: sim (the twin of --scene), hw (the real devices --devices names) or
    /// replay (a recorded --session).
    #[arg(long, value_enum, default_value = "sim")]
    pub backend: Backend,
    /// devices.toml for --backend hw: the xArm's address and base, the RealSense's V4L2
    /// nodes, intrinsics and pose, the GelSight Mini's node.
    #[arg(long)]
    pub devices: Option<PathBuf>,
    /// The recorded session that --backend replay runs from.
    #[arg(long)]
    pub session: Option<PathBuf>,
    /// Record every frame and move into a new session directory (replayable with
    /// --backend replay --session DIR).
    #[arg(long)]
    pub record: Option<PathBuf>,
    /// The sim GelSight's gel modulus (MPa) instead of the stock 0.3: what a softer or
    /// harder gel would see (--backend sim); 0.01 to 50 MPa.
    #[arg(long, value_parser = crate::flag_range::within(0.01, 50.0))]
    pub gel_modulus_mpa: Option<f64>,
    /// The question.
    pub prompt: String,
}

/// Where the devices' data comes from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Backend {
    Sim,
    Hw,
    Replay,
}

/// How the twin answers: the detector, the camera's render device and the explainer (shared
/// by `ask` and `serve`).
#[derive(Args)]
pub struct TwinOptions {
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
    /// Contact physics of the sim GelSight: rigid, hertz, halfspace or layer (the bonded
    /// 4 mm gel, the most faithful; see `tactex bench contact` for what each costs).
    #[arg(long, default_value = "layer")]
    pub fidelity: Fidelity,
    /// Hardness estimator that reads the presses: learned (the built-in model),
    /// indentation, hertz or FILE.onnx (a model with its card FILE.json beside it).
    #[arg(long, default_value = DEFAULT_ESTIMATOR)]
    pub estimator: EstimatorChoice,
    /// Interval calibration (JSON from `tactex eval fruits --calibrate`) the estimates' 68%
    /// and 95% intervals come from; unset: the one shipped for the estimator at --fidelity.
    #[arg(long)]
    pub intervals: Option<PathBuf>,
    /// Sensor profile (TOML: `tactex calibrate` writes one, `tactex sensor show --toml`
    /// prints the built-in one) the sim GelSight renders with; default the built-in GelSight
    /// Mini.
    #[arg(long)]
    pub sensor: Option<PathBuf>,
}

/// The estimator `ask`, `serve`, `compare --session` and `eval scenarios` use unless told:
/// chosen by the per-kind evaluation on the twin's scene fruit (README, "Hardness").
pub const DEFAULT_ESTIMATOR: &str = "indentation";

/// What `TwinOptions` name, opened once: a YOLO model is loaded, a GPU adapter found, an
/// LLM endpoint's settings read.
pub struct OpenedTwin {
    pub detector: DetectorChoice,
    pub renderer: Arc<dyn SceneRenderer>,
    pub explainer: Box<dyn Explainer>,
    pub estimator: Box<dyn HardnessEstimator + Send + Sync>,
    pub fidelity: Fidelity,
    pub sensor: SensorProfile,
}

impl TwinOptions {
    pub fn open(&self) -> Result<OpenedTwin> {
        Ok(OpenedTwin {
            detector: DetectorChoice::parse(&self.detector)?,
            renderer: scene_renderer(self.device)?,
            explainer: explainer(self.explainer, self.llm_config.as_ref())?,
            estimator: self.estimator.open(
                "--estimator",
                self.fidelity.name(),
                self.intervals.as_deref(),
            )?,
            fidelity: self.fidelity,
            sensor: load_sensor(self.sensor.as_deref())?,
        })
    }
}

/// A scene file a question can be asked about: it parses (`Scene::load`) and, placed in the
/// twin's world, every object rests where the file puts it, fits the table, and the camera
/// stands outside them. `scene check`, `ask`, `serve`, `twin` and `bench ask` all load
/// through here, so that what one refuses the others refuse with the same message.
pub fn load_scene(
    path: &Path,
    catalog: &FruitCatalog,
) -> Result<(Scene, tactex_sim::world::SimWorld)> {
    let scene = Scene::load(path, catalog)?;
    let world = tactex_sim::world::SimWorld::from_scene(&scene)?;
    world
        .check_as_placed()
        .map_err(|why| anyhow::anyhow!("{}: {why}", path.display()))?;
    Ok((scene, world))
}

/// The profile at `path` (`--sensor`), or the built-in GelSight Mini.
pub fn load_sensor(path: Option<&Path>) -> Result<SensorProfile> {
    match path {
        Some(p) => SensorProfile::load(p).map_err(|e| anyhow::anyhow!("--sensor: {e}")),
        None => Ok(SensorProfile::gelsight_mini()),
    }
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
    /// The settled world, for evaluations that need more of the truth (meshes, contacts).
    pub world: SharedWorld,
    /// The clean render's instance ids (object i is id i + 1) and the camera that took it.
    pub instances: InstanceImage,
    pub intrinsics: CameraIntrinsics,
    pub camera_pose: Pose,
}

/// What a question on the twin runs on: the scene, its sim devices' seed, the detector, the
/// camera's renderer and the explainer.
pub struct Twin<'a> {
    pub scene: &'a Scene,
    pub seed: u64,
    /// The sim tactile sensor (the stock GelSight Mini unless a profile or a what-if asks
    /// otherwise).
    pub sensor: &'a SensorProfile,
    pub detector: &'a DetectorChoice,
    pub renderer: &'a Arc<dyn SceneRenderer>,
    pub explainer: &'a dyn Explainer,
    pub estimator: &'a dyn HardnessEstimator,
    /// Contact physics of the sim GelSight.
    pub fidelity: Fidelity,
}

/// The sim devices of one question and what an evaluation needs from the twin beside them.
struct Prepared<'d> {
    sim: SimDevices,
    detector: Box<dyn Detector + 'd>,
    instances: InstanceImage,
    true_centres_m: Vec<[f64; 3]>,
}

impl<'a> Twin<'a> {
    fn prepare(&self, catalog: &'a FruitCatalog) -> Result<Prepared<'a>> {
        let mut sim =
            SimDevices::with_sensor(self.scene, self.seed, self.sensor.clone(), self.fidelity)?;
        sim.camera.set_renderer(self.renderer.clone());
        let instances = sim.camera.clean()?.instances.clone();
        let labels: Vec<String> = self.scene.objects.iter().map(|o| o.label.clone()).collect();
        // Only the perception-error models look at the ground truth.
        let truth =
            matches!(self.detector, DetectorChoice::PerceptionError(_)).then_some(GroundTruth {
                instances: &instances,
                labels: &labels,
            });
        let detector = self.detector.detector(catalog, truth, self.seed)?;
        let true_centres_m = {
            let world = sim.world.lock().expect("world lock");
            world.objects.iter().map(|o| o.centre.to_array()).collect()
        };
        Ok(Prepared {
            sim,
            detector,
            instances,
            true_centres_m,
        })
    }

    /// Answers `prompt` on fresh sim devices of the scene, telling `on_progress` what
    /// happens.
    pub fn answer(
        &self,
        prompt: &str,
        config: &PipelineConfig,
        on_progress: &dyn Fn(Progress),
    ) -> Result<TwinAnswer> {
        let catalog = FruitCatalog::builtin();
        let Prepared {
            mut sim,
            detector,
            instances,
            true_centres_m,
        } = self.prepare(&catalog)?;
        let mut answer = pipeline::answer_with_progress(
            prompt,
            &catalog,
            Devices {
                camera: &mut sim.camera,
                tactile: &mut sim.tactile,
                arm: &mut sim.arm,
            },
            detector.as_ref(),
            self.estimator,
            self.explainer,
            config,
            on_progress,
        )?;
        answer.fidelity = Some(self.fidelity.name().into());
        answer.sensor = Some(self.sensor.id());
        Ok(TwinAnswer {
            answer,
            true_centres_m,
            world: sim.world.clone(),
            intrinsics: sim.camera.intrinsics(),
            camera_pose: sim.camera.pose(),
            instances,
        })
    }

    /// [`Twin::answer`], recording every frame and move into a session in `dir`.
    pub fn answer_recorded(
        &self,
        prompt: &str,
        config: &PipelineConfig,
        dir: &Path,
    ) -> Result<Answer> {
        let catalog = FruitCatalog::builtin();
        let mut prepared = self.prepare(&catalog)?;
        let sim = &mut prepared.sim;
        let devices = Devices {
            camera: &mut sim.camera,
            tactile: &mut sim.tactile,
            arm: &mut sim.arm,
        };
        let question = Question {
            prompt,
            catalog: &catalog,
            detector: prepared.detector.as_ref(),
            estimator: self.estimator,
            explainer: self.explainer,
            config,
            fidelity: Some(self.fidelity),
            sensor: Some(self.sensor.id()),
        };
        let scene_toml = std::fs::read_to_string(&self.scene.path).with_context(|| {
            format!("{}: cannot read the scene again", self.scene.path.display())
        })?;
        let scene_path = std::path::absolute(&self.scene.path).unwrap_or(self.scene.path.clone());
        question.ask(
            devices,
            Some(Recording {
                dir,
                backend: "sim",
                twin: Some(TwinRecord {
                    scene_toml,
                    scene_path: scene_path.display().to_string(),
                    seed: self.seed,
                    fidelity: Some(self.fidelity.name().into()),
                    sensor: Some(self.sensor.id()),
                }),
            }),
        )
    }
}

/// Where `Question::ask` records a session: a new directory, the backend's name, and the sim
/// world when the backend is the twin.
pub struct Recording<'r> {
    pub dir: &'r Path,
    pub backend: &'r str,
    pub twin: Option<TwinRecord>,
}

/// One question and what answers it, apart from the devices.
pub struct Question<'q> {
    pub prompt: &'q str,
    pub catalog: &'q FruitCatalog,
    pub detector: &'q dyn Detector,
    pub estimator: &'q dyn HardnessEstimator,
    pub explainer: &'q dyn Explainer,
    pub config: &'q PipelineConfig,
    /// The sim GelSight's contact physics, when the devices are the twin's.
    pub fidelity: Option<Fidelity>,
    /// The tactile sensor's profile, when one is known.
    pub sensor: Option<tactex_core::sensor_profile::ProfileId>,
}

impl Question<'_> {
    /// Answers on `devices`; with `record`, everything they deliver and are asked to do is
    /// written into a new session directory.
    pub fn ask<C: RgbdCamera, T: TactileSensor, A: Arm>(
        &self,
        devices: Devices<'_, C, T, A>,
        record: Option<Recording<'_>>,
    ) -> Result<Answer> {
        let Some(Recording { dir, backend, twin }) = record else {
            return self.answer(devices);
        };
        let recorder = SessionRecorder::create(dir).context("--record")?;
        if let Some(twin) = twin {
            recorder.twin(twin);
        }
        let answer = self.answer(Devices {
            camera: &mut recorder.camera(devices.camera),
            tactile: &mut recorder.tactile(devices.tactile),
            arm: &mut recorder.arm(devices.arm)?,
        })?;
        let json = serde_json::to_value(&answer).context("serialising the answer")?;
        recorder
            .finish(backend, self.prompt, Some(json))
            .context("--record")?;
        Ok(answer)
    }

    /// The pipeline on `devices`, the answer naming the twin's fidelity when there is one.
    fn answer<C: RgbdCamera, T: TactileSensor, A: Arm>(
        &self,
        devices: Devices<'_, C, T, A>,
    ) -> Result<Answer> {
        let mut answer = pipeline::answer(
            self.prompt,
            self.catalog,
            devices,
            self.detector,
            self.estimator,
            self.explainer,
            self.config,
        )?;
        answer.fidelity = self.fidelity.map(|f| f.name().into());
        answer.sensor = self.sensor.clone();
        Ok(answer)
    }
}

/// Answers `prompt` from the recorded session in `dir`: its frames in the order they were
/// taken, its moves checked against the pipeline's.
pub fn answer_on_replay(
    dir: &Path,
    opened: &OpenedTwin,
    prompt: &str,
    config: &PipelineConfig,
) -> Result<Answer> {
    let (choice, explainer) = (&opened.detector, opened.explainer.as_ref());
    let catalog = FruitCatalog::builtin();
    let (manifest, mut camera, mut tactile, mut arm) = open_session(dir).context("--session")?;
    let detector = detector_without_truth(choice, &catalog)?;
    let question = Question {
        prompt,
        catalog: &catalog,
        detector: detector.as_ref(),
        estimator: opened.estimator.as_ref(),
        explainer,
        config,
        fidelity: None,
        sensor: None,
    };
    let mut answer = question.ask(
        Devices {
            camera: &mut camera,
            tactile: &mut tactile,
            arm: &mut arm,
        },
        None,
    )?;
    // A session recorded on the twin replays the twin's frames: it says at which fidelity.
    if let Some(twin) = manifest.twin {
        answer.fidelity = twin.fidelity;
        answer.sensor = twin.sensor;
    }
    Ok(answer)
}

/// The detector for devices that know no ground truth (real ones, or a replay of them).
fn detector_without_truth<'a>(
    choice: &'a DetectorChoice,
    catalog: &'a FruitCatalog,
) -> Result<Box<dyn Detector + 'a>> {
    if matches!(choice, DetectorChoice::PerceptionError(_)) {
        bail!(
            "--detector: the perception-error models need the twin's ground truth; use classical or yolo:FILE"
        );
    }
    choice.detector(catalog, None, 0)
}

/// Answers `prompt` on the real devices `devices.toml` names: an xArm, a RealSense and a
/// GelSight Mini.
#[cfg(all(target_os = "linux", feature = "v4l2"))]
fn answer_on_hardware(file: &Path, args: &AskArgs, config: &PipelineConfig) -> Result<Answer> {
    let catalog = FruitCatalog::builtin();
    let devices = DevicesConfig::load(file)?;
    let sensor = hardware_sensor(args)?;
    let choice = DetectorChoice::parse(&args.twin.detector)?;
    let detector = detector_without_truth(&choice, &catalog)?;
    let explainer = explainer(args.twin.explainer, args.twin.llm_config.as_ref())?;
    // The twin's most faithful physics stands in for the real gel's.
    let estimator = args.twin.estimator.open(
        "--estimator",
        Fidelity::Layer.name(),
        args.twin.intervals.as_deref(),
    )?;
    // The sensors first, so that a missing camera never leaves the arm enabled.
    let mut camera = devices.open_camera()?;
    let mut tactile = devices.open_tactile(sensor.spec.clone())?;
    let mut arm = devices.open_arm()?;
    let question = Question {
        prompt: &args.prompt,
        catalog: &catalog,
        detector: detector.as_ref(),
        estimator: estimator.as_ref(),
        explainer: explainer.as_ref(),
        config,
        fidelity: None,
        sensor: Some(sensor.id()),
    };
    question.ask(
        Devices {
            camera: &mut camera,
            tactile: &mut tactile,
            arm: &mut arm,
        },
        args.record.as_deref().map(|dir| Recording {
            dir,
            backend: "hw",
            twin: None,
        }),
    )
}

#[cfg(not(all(target_os = "linux", feature = "v4l2")))]
fn answer_on_hardware(file: &Path, args: &AskArgs, _: &PipelineConfig) -> Result<Answer> {
    // The file and the profile are still checked, so that they are named before the missing
    // feature.
    DevicesConfig::load(file)?;
    hardware_sensor(args)?;
    bail!(
        "--backend hw: this tactex was built without V4L2, which reads the cameras; \
         on Linux rebuild with `cargo build --release --features v4l2` (needs libclang-dev)"
    );
}

/// The real GelSight's profile: required, since a real sensor's frames read through the
/// twin's analytic lights would give wrong slopes however good the physics.
fn hardware_sensor(args: &AskArgs) -> Result<SensorProfile> {
    let Some(path) = &args.twin.sensor else {
        bail!(
            "--sensor: --backend hw reads the real GelSight through its calibrated profile; give one (`tactex calibrate` writes it)"
        );
    };
    let sensor = load_sensor(Some(path))?;
    use tactex_hw::gelsight_mini::{HEIGHT, WIDTH};
    let (w, h) = (sensor.spec.width_px, sensor.spec.height_px);
    if (w, h) != (WIDTH, HEIGHT) {
        bail!(
            "--sensor {}: a {w} x {h} px profile; the GelSight Mini's frames are {WIDTH} x {HEIGHT}",
            path.display()
        );
    }
    Ok(sensor)
}

pub fn run(args: &AskArgs) -> Result<()> {
    let catalog = FruitCatalog::builtin();
    // The prompt is checked before any device is opened so that a bad question fails fast.
    tactex_core::query::parse(&args.prompt, &catalog)?;
    let config = PipelineConfig {
        measure_wall_time: !args.reproducible,
        ..PipelineConfig::default()
    };
    if args.devices.is_some() && args.backend != Backend::Hw {
        bail!("--devices: only with --backend hw");
    }
    if args.gel_modulus_mpa.is_some() && args.backend != Backend::Sim {
        bail!("--gel-modulus-mpa: only with --backend sim (a real gel is what it is)");
    }
    let answer = match args.backend {
        Backend::Hw => {
            let Some(file) = &args.devices else {
                bail!("--backend hw: needs --devices FILE (devices.toml: arm, camera, tactile)");
            };
            answer_on_hardware(file, args, &config)?
        }
        Backend::Replay => {
            let Some(dir) = &args.session else {
                bail!("--backend replay: needs --session DIR (a directory `--record` wrote)");
            };
            if args.record.is_some() {
                bail!("--record: a replay is already a recording; record from --backend sim");
            }
            let opened = args.twin.open()?;
            answer_on_replay(dir, &opened, &args.prompt, &config)?
        }
        Backend::Sim => {
            if args.session.is_some() {
                bail!("--session: only with --backend replay");
            }
            let path = args.scene.clone().unwrap_or_else(crate::default_scene);
            let (scene, _) = load_scene(&path, &catalog)?;
            let opened = args.twin.open()?;
            let sensor = with_gel_modulus(opened.sensor.clone(), args.gel_modulus_mpa)?;
            let twin = Twin {
                scene: &scene,
                seed: args.seed,
                sensor: &sensor,
                detector: &opened.detector,
                renderer: &opened.renderer,
                explainer: opened.explainer.as_ref(),
                estimator: opened.estimator.as_ref(),
                fidelity: opened.fidelity,
            };
            match &args.record {
                Some(dir) => twin.answer_recorded(&args.prompt, &config, dir)?,
                None => twin.answer(&args.prompt, &config, &|_| {})?.answer,
            }
        }
    };
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

/// `sensor` with its gel's modulus replaced when one is given (`--gel-modulus-mpa`).
pub fn with_gel_modulus(
    mut sensor: SensorProfile,
    gel_modulus_mpa: Option<f64>,
) -> Result<SensorProfile> {
    if let Some(e) = gel_modulus_mpa {
        // Beyond these the gel is no gel: a foam or a rubber outside the layer model's range.
        if !(e.is_finite() && (0.01..=50.0).contains(&e)) {
            bail!("--gel-modulus-mpa: {e} is outside 0.01..50 MPa");
        }
        sensor.spec.gel.modulus_mpa = e;
    }
    Ok(sensor)
}

fn print_answer(a: &Answer) {
    if let Some(notice) = &a.explain_notice {
        eprintln!("note: {notice}");
    }
    // An LLM's answer is outside text: its lines kept, any control characters shown.
    let answer: Vec<String> = a
        .answer
        .lines()
        .map(tactex_core::printable::printable)
        .collect();
    println!("{}\n", answer.join("\n"));
    println!(
        "{:<3} {:<11} {:<13} {:>24} {:>9} {:>9} {:>10} {:>13} {:>13}  ripeness",
        "#",
        "object",
        "location",
        "position (m)",
        "Shore A",
        "Shore 00",
        "E (MPa)",
        "68% (MPa)",
        "95% (MPa)"
    );
    let range = |r: [Option<f64>; 2]| match r {
        [Some(lo), Some(hi)] => format!("{lo:.2}-{hi:.2}"),
        [Some(lo), None] => format!("> {lo:.2}"),
        _ => "-".into(),
    };
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
        let (p68, p95) = o.interval.as_ref().map_or(("-".into(), "-".into()), |v| {
            (range(v.p68_mpa), range(v.p95_mpa))
        });
        println!(
            "{mark}{i:<2} {:<11} {:<13} {:>24} {sa:>9} {s00:>9} {e:>10} {p68:>13} {p95:>13}  {}",
            o.label,
            o.location,
            format!("({:+.3}, {:+.3}, {:.3})", p[0], p[1], p[2]),
            o.ripeness.as_deref().unwrap_or("-")
        );
        if let Some(why) = &o.not_measured {
            println!("    not measured: {why}");
        }
        for w in &o.warnings {
            println!("    warning: {w}");
        }
        if let Some(tactex_core::estimate::Evidence::Learned(l)) = &o.evidence
            && let Some(note) = &l.other_sensor
        {
            println!("    note: {note}");
        }
    }
    println!("\n{:<10} {:>10} {:>12}", "stage", "wall (ms)", "robot (s)");
    for t in &a.timing {
        let wall = t.wall_ms.map_or("-".into(), |v| format!("{v:.1}"));
        let sim = t.sim_s.map_or("-".into(), |v| format!("{v:.2}"));
        println!("{:<10} {wall:>10} {sim:>12}", t.stage);
    }
}
