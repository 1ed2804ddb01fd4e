//! The flags that say how the twin answers (`ask`, `serve`), read into the library's
//! `TwinOptions`.

use crate::app::camera_placement::{CAMERA_ERROR_DEG_MAX, CAMERA_ERROR_MM_MAX};
use crate::app::estimator_choice::EstimatorChoice;
use crate::app::explainer_choice::ExplainerChoice;
use crate::app::flag_range::{choice, within};
use crate::app::parser_choice::ParserChoice;
use crate::app::twin_options::{DEFAULT_ESTIMATOR, TwinOptions};
use clap::Args;
use std::path::PathBuf;
use tactex_sim::contact::Fidelity;
use tactex_sim::render::device::DeviceChoice;

#[derive(Args, Clone, Debug)]
pub struct TwinFlags {
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
    #[arg(long, default_value = "template", value_parser = choice::<ExplainerChoice>(&ExplainerChoice::NAMES))]
    pub explainer: ExplainerChoice,
    /// Who reads the question: rules (offline) or llm (the endpoint --explainer llm uses;
    /// its reading must check out against the catalog, else the rules read it, with a
    /// notice).
    #[arg(long, default_value = "rules", value_parser = choice::<ParserChoice>(&ParserChoice::NAMES))]
    pub parser: ParserChoice,
    /// TOML with base_url, model, api_key_env and timeout_s for --explainer llm and
    /// --parser llm.
    #[arg(long)]
    pub llm_config: Option<PathBuf>,
    /// Contact physics of the sim GelSight: rigid, hertz, halfspace or layer (the default:
    /// the bonded 4 mm gel, the most faithful; see `tactex bench contact` for what each
    /// costs). A replay's is its session's.
    #[arg(long)]
    pub fidelity: Option<Fidelity>,
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
    /// Twin: how far the scene camera really stands from where the scene puts it (mm, 0 to
    /// 200), in a direction drawn from --camera-error-seed; the pipeline is not told.
    #[arg(long, default_value_t = 0.0, value_parser = within(0.0, CAMERA_ERROR_MM_MAX))]
    pub camera_error_mm: f64,
    /// Twin: how far it is really turned from the scene's pose (degrees, 0 to 20).
    #[arg(long, default_value_t = 0.0, value_parser = within(0.0, CAMERA_ERROR_DEG_MAX))]
    pub camera_error_deg: f64,
    /// Twin: draws the directions of the camera's misplacement.
    #[arg(long, default_value_t = 1)]
    pub camera_error_seed: u64,
    /// A hand-eye calibration (`tactex handeye --out`'s TOML): the pipeline believes its
    /// camera pose instead of the scene's.
    #[arg(long)]
    pub camera_calibration: Option<PathBuf>,
}

impl TwinFlags {
    pub(crate) fn options(&self) -> TwinOptions {
        TwinOptions {
            detector: self.detector.clone(),
            device: self.device,
            explainer: self.explainer,
            parser: self.parser,
            llm_config: self.llm_config.clone(),
            fidelity: self.fidelity.unwrap_or(Fidelity::Layer),
            estimator: self.estimator.clone(),
            intervals: self.intervals.clone(),
            sensor: self.sensor.clone(),
            camera_error_mm: self.camera_error_mm,
            camera_error_deg: self.camera_error_deg,
            camera_error_seed: self.camera_error_seed,
            camera_calibration: self.camera_calibration.clone(),
        }
    }
}
