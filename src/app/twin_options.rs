//! The flags that say how the twin answers (detector, render device, explainer, fidelity,
//! estimator, intervals, sensor), shared by `ask`, `serve` and the evaluations, and what
//! they name once opened.

use crate::app::detector_choice::DetectorChoice;
use crate::app::estimator_choice::EstimatorChoice;
use crate::app::explainer_choice::{ExplainerChoice, explainer};
use crate::app::parser_choice::{ParserChoice, PromptParser};
use crate::app::scene::scene_renderer;
use crate::app::sensor::load_sensor;
use anyhow::{Result, bail};
use clap::Args;
use std::path::PathBuf;
use std::sync::Arc;
use tactex_core::explain::Explainer;
use tactex_core::hardness::estimate::HardnessEstimator;
use tactex_core::pipeline::Language;
use tactex_core::query::reader::PromptReader;
use tactex_core::tactile::sensor_profile::SensorProfile;
use tactex_sim::contact::Fidelity;
use tactex_sim::render::device::DeviceChoice;
use tactex_sim::render::scene::SceneRenderer;

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
    /// Who reads the question: rules (offline) or llm (the endpoint --explainer llm uses;
    /// its reading must check out against the catalog, else the rules read it, with a
    /// notice).
    #[arg(long, value_enum, default_value = "rules")]
    pub parser: ParserChoice,
    /// TOML with base_url, model, api_key_env and timeout_s for --explainer llm and
    /// --parser llm.
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
/// chosen by the per-kind evaluation on the twin's scene fruit (docs/performance.md).
pub const DEFAULT_ESTIMATOR: &str = "indentation";

/// What `TwinOptions` name, opened once: a YOLO model is loaded, a GPU adapter found, an
/// LLM endpoint's settings read.
pub struct OpenedTwin {
    pub detector: DetectorChoice,
    pub renderer: Arc<dyn SceneRenderer>,
    pub parser: Box<dyn PromptReader>,
    pub explainer: Box<dyn Explainer>,
    pub estimator: Box<dyn HardnessEstimator + Send + Sync>,
    pub fidelity: Fidelity,
    pub sensor: SensorProfile,
}

impl OpenedTwin {
    pub fn language(&self) -> Language<'_> {
        Language {
            reader: self.parser.as_ref(),
            explainer: self.explainer.as_ref(),
        }
    }
}

impl TwinOptions {
    /// The prompt's reader and the answer's writer, one LLM configuration shared by both.
    pub fn language(&self) -> Result<(Box<dyn PromptReader>, Box<dyn Explainer>)> {
        let uses_llm = self.parser == ParserChoice::Llm || self.explainer == ExplainerChoice::Llm;
        if let (Some(path), false) = (&self.llm_config, uses_llm) {
            bail!(
                "--llm-config {}: read only by --explainer llm or --parser llm",
                path.display()
            );
        }
        let config_for = |llm: bool| self.llm_config.as_ref().filter(|_| llm);
        Ok((
            Box::new(PromptParser::new(
                self.parser,
                config_for(self.parser == ParserChoice::Llm),
            )?),
            explainer(
                self.explainer,
                config_for(self.explainer == ExplainerChoice::Llm),
            )?,
        ))
    }

    pub fn open(&self) -> Result<OpenedTwin> {
        let sensor = load_sensor(self.sensor.as_deref())?;
        let estimator = self.estimator.open(
            "--estimator",
            self.fidelity.name(),
            self.intervals.as_deref(),
            &sensor,
            self.sensor.as_deref(),
        )?;
        if let (Some(profile), None) = (&self.sensor, &self.intervals)
            && let Some(note) = self
                .estimator
                .missing_intervals_note(profile, self.fidelity.name())
        {
            eprintln!("{note}");
        }
        let (parser, explainer) = self.language()?;
        Ok(OpenedTwin {
            detector: DetectorChoice::parse(&self.detector)?,
            renderer: scene_renderer(self.device)?,
            parser,
            explainer,
            estimator,
            fidelity: self.fidelity,
            sensor,
        })
    }
}
