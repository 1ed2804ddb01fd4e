//! The flags that say how the twin answers (detector, render device, explainer, fidelity,
//! estimator, intervals, sensor), shared by `ask`, `serve` and the evaluations, and what
//! they name once opened.

use crate::app::camera_placement::CameraPlacement;
use crate::app::detector_choice::DetectorChoice;
use crate::app::estimator_choice::EstimatorChoice;
use crate::app::explainer_choice::{ExplainerChoice, explainer};
use crate::app::parser_choice::{ParserChoice, PromptParser};
use crate::app::request_json::parsed;
use crate::app::scene::scene_renderer;
use crate::app::sensor::load_sensor;
use anyhow::{Result, bail};
use serde::Deserialize;
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

/// How the twin answers: the detector, the camera's render device, who reads the question
/// and writes the answer, the contact physics, the estimator and its intervals, the sensor
/// (shared by `ask`, `serve` and the hardware path). The CLI's flags of the same names
/// (`cli::TwinFlags`) and Python's keywords map onto it; `Default` is their defaults.
#[derive(Clone, Debug, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct TwinOptions {
    /// Object detector: classical, yolo:FILE.onnx (a YOLOv8-seg export), or a
    /// perception-error model on the twin's ground truth (error-gsam, error-yolo).
    pub detector: String,
    /// Device that renders the camera's frames: cpu, gpu or auto.
    #[serde(deserialize_with = "parsed")]
    pub device: DeviceChoice,
    /// Who writes the answer: template or llm.
    #[serde(deserialize_with = "parsed")]
    pub explainer: ExplainerChoice,
    /// Who reads the question: rules or llm.
    #[serde(deserialize_with = "parsed")]
    pub parser: ParserChoice,
    /// TOML with base_url, model, api_key_env and timeout_s for the llm explainer and parser.
    pub llm_config: Option<PathBuf>,
    /// Contact physics of the sim GelSight.
    #[serde(deserialize_with = "parsed")]
    pub fidelity: Fidelity,
    /// Hardness estimator that reads the presses (a name or a model file).
    #[serde(deserialize_with = "parsed")]
    pub estimator: EstimatorChoice,
    /// Interval calibration the estimates' intervals come from; None: the one shipped.
    pub intervals: Option<PathBuf>,
    /// Sensor profile the sim GelSight renders with; None: the built-in GelSight Mini.
    pub sensor: Option<PathBuf>,
    /// How far the twin's scene camera really stands from where the scene puts it (mm).
    pub camera_error_mm: f64,
    /// How far it is really turned from the scene's pose (degrees).
    pub camera_error_deg: f64,
    /// Draws the directions of the camera's misplacement.
    pub camera_error_seed: u64,
    /// A hand-eye calibration (`tactex handeye`'s TOML) whose camera pose the pipeline
    /// believes instead of the scene's.
    pub camera_calibration: Option<PathBuf>,
}

impl Default for TwinOptions {
    fn default() -> Self {
        Self {
            detector: "classical".into(),
            device: DeviceChoice::Cpu,
            explainer: ExplainerChoice::Template,
            parser: ParserChoice::Rules,
            llm_config: None,
            fidelity: Fidelity::Layer,
            estimator: DEFAULT_ESTIMATOR
                .parse()
                .expect("the default estimator is registered"),
            intervals: None,
            sensor: None,
            camera_error_mm: 0.0,
            camera_error_deg: 0.0,
            camera_error_seed: 1,
            camera_calibration: None,
        }
    }
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
    pub camera: CameraPlacement,
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
        let camera = self.camera_placement()?;
        Ok(OpenedTwin {
            detector: DetectorChoice::parse(&self.detector)?,
            renderer: scene_renderer(self.device)?,
            parser,
            explainer,
            estimator,
            fidelity: self.fidelity,
            sensor,
            camera,
        })
    }

    /// The scene camera's placement these options describe, its calibration file read.
    pub fn camera_placement(&self) -> Result<CameraPlacement> {
        CameraPlacement::checked(
            self.camera_error_mm,
            self.camera_error_deg,
            self.camera_error_seed,
            self.camera_calibration.as_deref(),
        )
    }
}
