//! `--estimator`: which hardness estimator reads the presses (`ask`, `serve`, `compare
//! --session`, `eval scenarios`, `eval ripeness`, `eval fruits`), and the calibration its
//! intervals come from (`--intervals`, or the one shipped for it at the twin's fidelity).

use anyhow::{Context, Result, bail};
use std::path::{Path, PathBuf};
use std::str::FromStr;
use tactex_core::hardness::estimate::{HardnessEstimator, HertzSlopeEstimator};
use tactex_core::hardness::indentation_estimator::IndentationEstimator;
use tactex_core::hardness::interval_calibration::{Calibrated, IntervalCalibration};
use tactex_core::tactile::sensor_profile::{ProfileId, SensorProfile};

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

/// Interval calibrations shipped with the binary, made by `tactex eval fruits --calibrate`
/// on held-out presses: (`--estimator` value, fidelity, file name, text).
const BUILTIN_INTERVALS: &[(&str, &str, &str, &str)] = &[
    (
        "learned",
        "layer",
        "models/intervals/learned-layer.json",
        include_str!("../../models/intervals/learned-layer.json"),
    ),
    (
        "indentation",
        "layer",
        "models/intervals/indentation-layer.json",
        include_str!("../../models/intervals/indentation-layer.json"),
    ),
    (
        "hertz",
        "layer",
        "models/intervals/hertz-layer.json",
        include_str!("../../models/intervals/hertz-layer.json"),
    ),
];

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

pub type BoxedEstimator = Box<dyn HardnessEstimator + Send + Sync>;

impl EstimatorChoice {
    /// The value of `--estimator` that names this choice.
    pub fn flag_value(&self) -> String {
        match self {
            Self::Learned => "learned".into(),
            Self::Indentation => "indentation".into(),
            Self::Hertz => "hertz".into(),
            Self::Model(path) => path.display().to_string(),
        }
    }

    /// Loads the estimator with its own intervals; `flag` names the option in errors.
    pub fn open_uncalibrated(&self, flag: &str) -> Result<BoxedEstimator> {
        Ok(match self {
            Self::Learned => Box::new(tactex_learned::builtin::builtin_small()?),
            Self::Indentation => Box::new(IndentationEstimator::default()),
            Self::Hertz => Box::new(HertzSlopeEstimator::default()),
            Self::Model(path) => {
                if !path.is_file() {
                    bail!("{flag} {}: no such model file", path.display());
                }
                Box::new(tactex_learned::builtin::from_file(flag, path)?)
            }
        })
    }

    /// Loads the estimator with calibrated intervals: from `intervals` (a file `eval fruits
    /// --calibrate` wrote) when given, else the calibration shipped for it at `fidelity`,
    /// else its own intervals, which say that they are not calibrated. A calibration applies
    /// only to the `sensor` its presses were read through: the shipped ones were measured on
    /// the built-in Mini, and a calibrated profile reads with errors of its own.
    pub fn open(
        &self,
        flag: &str,
        fidelity: &str,
        intervals: Option<&Path>,
        sensor: &ProfileId,
    ) -> Result<BoxedEstimator> {
        let inner = self.open_uncalibrated(flag)?;
        let calibration = match intervals {
            Some(path) => {
                let text = std::fs::read_to_string(path)
                    .with_context(|| format!("--intervals {}: cannot read", path.display()))?;
                let c =
                    IntervalCalibration::parse(&text, &format!("--intervals {}", path.display()))?;
                if c.estimator != inner.name() {
                    bail!(
                        "--intervals {}: calibrated for the {} estimator, not {}",
                        path.display(),
                        c.estimator,
                        inner.name()
                    );
                }
                let through = c.measured_through();
                if &through != sensor {
                    bail!(
                        "--intervals {}: measured through the sensor {through}, not {sensor} (the one in use); \
                         make one with `tactex eval fruits --sensor PROFILE --calibrate FILE`",
                        path.display(),
                    );
                }
                Some(c)
            }
            None => builtin_intervals(self, fidelity, sensor)?,
        };
        Ok(match calibration {
            Some(calibration) => Box::new(Calibrated { inner, calibration }),
            None => inner,
        })
    }
}

/// The calibration shipped for `choice` at `fidelity` read through `sensor`: (file name,
/// text). A model file given by path has none (its name may be the built-in's, its residuals
/// are not), and every shipped one was measured through the built-in Mini.
fn builtin_entry(
    choice: &EstimatorChoice,
    fidelity: &str,
    sensor: &ProfileId,
) -> Option<(&'static str, &'static str)> {
    if matches!(choice, EstimatorChoice::Model(_)) || sensor != &SensorProfile::gelsight_mini().id()
    {
        return None;
    }
    let flag = choice.flag_value();
    BUILTIN_INTERVALS
        .iter()
        .find(|(e, f, _, _)| *e == flag && *f == fidelity)
        .map(|(_, _, file, text)| (*file, *text))
}

/// The name of the calibration shipped for `choice` at `fidelity` through `sensor`, if one is.
pub fn builtin_interval_file(
    choice: &EstimatorChoice,
    fidelity: &str,
    sensor: &ProfileId,
) -> Option<&'static str> {
    builtin_entry(choice, fidelity, sensor).map(|(file, _)| file)
}

fn builtin_intervals(
    choice: &EstimatorChoice,
    fidelity: &str,
    sensor: &ProfileId,
) -> Result<Option<IntervalCalibration>> {
    builtin_entry(choice, fidelity, sensor)
        .map(|(file, text)| {
            IntervalCalibration::parse(text, &format!("{file} (built in)")).map_err(Into::into)
        })
        .transpose()
}
