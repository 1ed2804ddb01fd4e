//! `tactex ask`: one question answered on the twin, the real devices or a recorded session.

use crate::app::flag_range::choice;
use crate::app::hardware::answer_on_hardware;
use crate::app::parser_choice::ParserChoice;
use crate::app::press_options::fields::GEL_MODULUS_MPA;
use crate::app::replay::answer_on_replay;
use crate::app::request_json::parsed;
use crate::app::scene::{default_scene, load_scene};
use crate::app::sensor::with_gel_modulus;
use crate::app::twin::Twin;
use crate::app::twin_options::TwinOptions;
use crate::cli::twin_flags::TwinFlags;
use crate::report::tail::print_json_or_text;
use anyhow::{Result, bail};
use clap::Args;
use serde::Deserialize;
use std::path::PathBuf;
use tactex_core::catalog::FruitCatalog;
use tactex_core::pipeline::{Answer, PipelineConfig};

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
    pub twin: TwinFlags,
    /// Devices: sim (the twin of --scene), hw (the real devices --devices names) or
    /// replay (a recorded --session).
    #[arg(long, default_value = "sim", value_parser = choice::<Backend>(&Backend::NAMES))]
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
    #[arg(long, value_parser = GEL_MODULUS_MPA.parser())]
    pub gel_modulus_mpa: Option<f64>,
    /// The question.
    pub prompt: String,
}

impl AskArgs {
    /// The question as the library takes it.
    pub(crate) fn request(&self) -> AskRequest {
        AskRequest {
            prompt: self.prompt.clone(),
            scene: self.scene.clone(),
            seed: self.seed,
            reproducible: self.reproducible,
            twin: self.twin.options(),
            backend: self.backend,
            devices: self.devices.clone(),
            session: self.session.clone(),
            record: self.record.clone(),
            gel_modulus_mpa: self.gel_modulus_mpa,
        }
    }
}

/// One question and how to answer it: `tactex ask`'s flags and Python's `tactex.ask`
/// keywords map onto it (field for flag, `--gel-modulus-mpa` is `gel_modulus_mpa`).
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AskRequest {
    pub prompt: String,
    /// Scene file (TOML) for the sim backend; None: scenes/demo.toml.
    #[serde(default)]
    pub scene: Option<PathBuf>,
    /// Seed of every random draw (sensor noise).
    #[serde(default)]
    pub seed: u64,
    /// Leave out wall-clock times so that the answer is byte-reproducible.
    #[serde(default)]
    pub reproducible: bool,
    #[serde(default)]
    pub twin: TwinOptions,
    #[serde(default, deserialize_with = "parsed")]
    pub backend: Backend,
    /// devices.toml for the hw backend.
    #[serde(default)]
    pub devices: Option<PathBuf>,
    /// The recorded session the replay backend runs from.
    #[serde(default)]
    pub session: Option<PathBuf>,
    /// Record every frame and move into a new session directory.
    #[serde(default)]
    pub record: Option<PathBuf>,
    /// The sim GelSight's gel modulus (MPa) instead of the profile's.
    #[serde(default)]
    pub gel_modulus_mpa: Option<f64>,
}

/// Where the devices' data comes from.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Backend {
    #[default]
    Sim,
    Hw,
    Replay,
}

impl Backend {
    pub const NAMES: [&'static str; 3] = ["sim", "hw", "replay"];
}

impl std::str::FromStr for Backend {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s.trim().to_ascii_lowercase().as_str() {
            "sim" => Ok(Self::Sim),
            "hw" => Ok(Self::Hw),
            "replay" => Ok(Self::Replay),
            _ => Err(format!("unknown backend {s:?} (sim, hw or replay)")),
        }
    }
}

/// The answer `tactex ask` prints, as a value (the Python package's `ask` returns it).
pub fn answer(args: &AskRequest) -> Result<Answer> {
    if let Some(e) = args.gel_modulus_mpa {
        GEL_MODULUS_MPA.check(e)?;
    }
    let catalog = FruitCatalog::builtin();
    // The prompt is checked before any device is opened so that a bad question fails fast
    // (a model may read what the rules refuse: with --parser llm it is read in the pipeline).
    if args.twin.parser == ParserChoice::Rules {
        tactex_core::query::parse(&args.prompt, &catalog)?;
    }
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
    if args.backend != Backend::Sim {
        // The twin's camera rig: a real camera stands where it stands, and a recorded one
        // stood where it did.
        let rig = &args.twin;
        if rig.camera_calibration.is_some() {
            bail!(
                "--camera-calibration: only with --backend sim (on --backend hw give it in devices.toml: [camera] calibration = \"FILE\")"
            );
        }
        for (flag, error) in [
            ("--camera-error-mm", rig.camera_error_mm),
            ("--camera-error-deg", rig.camera_error_deg),
        ] {
            if error != 0.0 {
                bail!("{flag}: only with --backend sim (the twin's camera rig)");
            }
        }
    }
    let answer = match args.backend {
        Backend::Hw => {
            let Some(file) = &args.devices else {
                bail!("--backend hw: needs --devices FILE (devices.toml: arm, camera, tactile)");
            };
            answer_on_hardware(
                file,
                &args.twin,
                &args.prompt,
                args.record.as_deref(),
                &config,
            )?
        }
        Backend::Replay => {
            let Some(dir) = &args.session else {
                bail!("--backend replay: needs --session DIR (a directory `--record` wrote)");
            };
            if args.record.is_some() {
                bail!("--record: a replay is already a recording; record from --backend sim");
            }
            if args.scene.is_some() {
                bail!(
                    "--scene: only with --backend sim (a replay's objects are the ones its session recorded)"
                );
            }
            answer_on_replay(dir, &args.twin, &args.prompt, &config)?
        }
        Backend::Sim => {
            if args.session.is_some() {
                bail!("--session: only with --backend replay");
            }
            let path = args.scene.clone().unwrap_or_else(default_scene);
            let (scene, _) = load_scene(&path, &catalog)?;
            let opened = args.twin.open()?;
            let sensor = with_gel_modulus(opened.sensor.clone(), args.gel_modulus_mpa)?;
            let twin = Twin {
                scene: &scene,
                seed: args.seed,
                sensor: &sensor,
                detector: &opened.detector,
                renderer: &opened.renderer,
                language: opened.language(),
                estimator: opened.estimator.as_ref(),
                fidelity: opened.fidelity,
                camera: &opened.camera,
            };
            match &args.record {
                Some(dir) => twin.answer_recorded(&args.prompt, &config, dir)?,
                None => twin.answer(&args.prompt, &config, &|_| {})?.answer,
            }
        }
    };
    Ok(answer)
}

pub(crate) fn run(args: &AskArgs) -> Result<()> {
    if let (Backend::Replay, Some(f)) = (args.backend, args.twin.fidelity) {
        bail!(
            "--fidelity {}: a replay reads the frames its session recorded, at the session's fidelity; the flag is for --backend sim",
            f.name()
        );
    }
    let answer = answer(&args.request())?;
    print_json_or_text(&answer, args.json, || {
        print_answer(&answer);
        Ok(())
    })
}

fn print_answer(a: &Answer) {
    for notice in [&a.parse_notice, &a.explain_notice].into_iter().flatten() {
        eprintln!("note: {}", tactex_core::printable::printable(notice));
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
        if let Some(tactex_core::hardness::estimate::Evidence::Learned(l)) = &o.evidence
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
