//! `--estimator`: which hardness estimator reads the presses (`ask`, `serve`, `compare
//! --session`, `eval scenarios`, `eval ripeness`).

use anyhow::{Result, bail};
use std::path::PathBuf;
use std::str::FromStr;
use tactex_core::estimate::{HardnessEstimator, HertzSlopeEstimator};
use tactex_core::indentation_estimator::IndentationEstimator;

/// A hardness estimator by name, or a trained model file.
#[derive(Clone, Debug, PartialEq)]
pub enum EstimatorChoice {
    /// The built-in trained CNN (models/hardness-small.onnx).
    Learned,
    /// Layer-aware split of the gel's integrated indentation (any shape, bonded gel).
    Indentation,
    /// Hertz half-space fit of the slope field.
    Hertz,
    /// A trained model of the same contract (NAME.onnx with its card NAME.json beside it).
    Model(PathBuf),
}

/// What `--estimator` takes, for help texts and errors.
pub const ESTIMATOR_VALUES: &str = "learned, indentation, hertz or FILE.onnx";

impl FromStr for EstimatorChoice {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s.trim() {
            "learned" => Ok(Self::Learned),
            "indentation" => Ok(Self::Indentation),
            "hertz" | "hertz-slopes" | "hertz_slopes" => Ok(Self::Hertz),
            path if path.to_ascii_lowercase().ends_with(".onnx") => {
                Ok(Self::Model(PathBuf::from(path)))
            }
            other => Err(format!(
                "unknown estimator {other:?} (use {ESTIMATOR_VALUES})"
            )),
        }
    }
}

impl EstimatorChoice {
    /// Loads the estimator; `flag` names the option in errors.
    pub fn open(&self, flag: &str) -> Result<Box<dyn HardnessEstimator + Send + Sync>> {
        Ok(match self {
            Self::Learned => Box::new(crate::learned_model::builtin_small()?),
            Self::Indentation => Box::new(IndentationEstimator::default()),
            Self::Hertz => Box::new(HertzSlopeEstimator::default()),
            Self::Model(path) => {
                if !path.is_file() {
                    bail!("{flag} {}: no such model file", path.display());
                }
                Box::new(crate::learned_model::from_file(flag, path)?)
            }
        })
    }
}
