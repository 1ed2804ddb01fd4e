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

pub type BoxedEstimator = Box<dyn HardnessEstimator + Send + Sync>;

/// An estimator chosen by name (`--estimator NAME`).
#[derive(Debug)]
pub struct NamedEstimator {
    pub name: &'static str,
    /// Other spellings `--estimator` takes.
    pub aliases: &'static [&'static str],
    /// A trained model built into the binary (`eval hardness --no-builtin-model` leaves it
    /// out), not a geometric reading.
    pub trained: bool,
    pub open: fn() -> Result<BoxedEstimator>,
}

/// Every estimator chosen by name: the one place a new one is registered. `ask`, `serve`,
/// `compare --session` and the evaluations take it by name from here, and `eval hardness`
/// scores every one, in this order.
pub const ESTIMATORS: &[NamedEstimator] = &[
    NamedEstimator {
        name: "hertz",
        aliases: &["hertz-slopes", "hertz_slopes"],
        trained: false,
        open: || Ok(Box::new(HertzSlopeEstimator::default())),
    },
    NamedEstimator {
        name: "indentation",
        aliases: &[],
        trained: false,
        open: || Ok(Box::new(IndentationEstimator::default())),
    },
    NamedEstimator {
        name: "learned",
        aliases: &[],
        trained: true,
        open: || Ok(Box::new(tactex_learned::builtin::builtin_small()?)),
    },
];

/// A hardness estimator by name, or a trained model file.
#[derive(Clone, Debug)]
pub enum EstimatorChoice {
    /// One of `ESTIMATORS`: the built-in trained CNN (learned), the layer-aware split of the
    /// gel's integrated indentation (indentation), the Hertz half-space fit of the slope
    /// field (hertz).
    Named(&'static NamedEstimator),
    /// A trained model of the same contract (NAME.onnx with its card NAME.json beside it).
    Model(PathBuf),
}

impl PartialEq for EstimatorChoice {
    fn eq(&self, other: &Self) -> bool {
        match (self, other) {
            (Self::Named(a), Self::Named(b)) => a.name == b.name,
            (Self::Model(a), Self::Model(b)) => a == b,
            _ => false,
        }
    }
}

impl EstimatorChoice {
    /// The registered estimator called `name`.
    pub fn named(name: &str) -> Option<Self> {
        ESTIMATORS
            .iter()
            .find(|e| e.name == name || e.aliases.contains(&name))
            .map(Self::Named)
    }
}

/// What `--estimator` takes, for errors: the registered names, or a model file.
fn estimator_values() -> String {
    let names: Vec<&str> = ESTIMATORS.iter().map(|e| e.name).collect();
    format!("{} or FILE.onnx", names.join(", "))
}

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
        let s = s.trim();
        if let Some(named) = Self::named(s) {
            return Ok(named);
        }
        if s.to_ascii_lowercase().ends_with(".onnx") {
            return Ok(Self::Model(PathBuf::from(s)));
        }
        Err(format!(
            "unknown estimator {s:?} (use {})",
            estimator_values()
        ))
    }
}

/// Why `estimator` cannot read the presses `sensor` makes (the protocol's frames), if it
/// cannot.
pub fn unreadable(estimator: &dyn HardnessEstimator, sensor: &SensorProfile) -> Option<String> {
    let frames = tactex_core::press::protocol::PressProtocol::default().frames;
    estimator.cannot_read(&sensor.spec, frames)
}

/// Refuses, before any press is made, an estimator that cannot read `sensor`'s presses;
/// `what` names it as the user chose it ("--estimator learned", "--model m.onnx").
pub fn check_reads(
    estimator: &dyn HardnessEstimator,
    what: &str,
    sensor: &SensorProfile,
) -> Result<()> {
    match unreadable(estimator, sensor) {
        Some(why) => bail!("{what}: cannot read the presses of {}: {why}", sensor.id()),
        None => Ok(()),
    }
}

impl EstimatorChoice {
    /// The value of `--estimator` that names this choice.
    pub fn flag_value(&self) -> String {
        match self {
            Self::Named(e) => e.name.into(),
            Self::Model(path) => path.display().to_string(),
        }
    }

    /// Loads the estimator with its own intervals, checked to read `sensor`'s presses;
    /// `flag` names the option in errors.
    pub fn open_uncalibrated(&self, flag: &str, sensor: &SensorProfile) -> Result<BoxedEstimator> {
        let estimator: BoxedEstimator = match self {
            Self::Named(e) => (e.open)()?,
            Self::Model(path) => {
                // A model that is not there is missing, not a model that cannot be read.
                crate::app::file_input::present(path, "cannot read model file")
                    .with_context(|| flag.to_string())?;
                if !path.is_file() {
                    bail!("{flag} {}: not a model file (a folder)", path.display());
                }
                Box::new(tactex_learned::builtin::from_file(flag, path)?)
            }
        };
        check_reads(
            estimator.as_ref(),
            &format!("{flag} {}", self.flag_value()),
            sensor,
        )?;
        Ok(estimator)
    }

    /// Loads the estimator with calibrated intervals: from `intervals` (a file `eval fruits
    /// --calibrate` wrote) when given, else the one measured through the sensor profile at
    /// `profile` and kept beside it (`profile_intervals_path`), else the calibration shipped
    /// for it at `fidelity`, else its own intervals, which say that they are not calibrated.
    /// A calibration applies only to the `sensor` its presses were read through: the shipped
    /// ones were measured on the built-in Mini, and a calibrated profile reads with errors of
    /// its own.
    pub fn open(
        &self,
        flag: &str,
        fidelity: &str,
        intervals: Option<&Path>,
        sensor: &SensorProfile,
        profile: Option<&Path>,
    ) -> Result<BoxedEstimator> {
        let inner = self.open_uncalibrated(flag, sensor)?;
        let sensor = &sensor.id();
        let calibration = match intervals {
            Some(path) => {
                Some(self.measured_intervals(path, "--intervals", inner.name(), sensor)?)
            }
            None => match profile {
                Some(profile) => self.intervals_beside(profile, fidelity, inner.name(), sensor),
                None => builtin_intervals(self, fidelity, sensor)?,
            },
        };
        Ok(match calibration {
            Some(calibration) => Box::new(Calibrated { inner, calibration }),
            None => inner,
        })
    }

    /// A calibration file, checked to be for this estimator and measured through `sensor`;
    /// `what` names it in errors.
    fn measured_intervals(
        &self,
        path: &Path,
        what: &str,
        estimator: &str,
        sensor: &ProfileId,
    ) -> Result<IntervalCalibration> {
        let text = tactex_core::text_file::read_to_string(path)
            .with_context(|| format!("{what} {}: cannot read", path.display()))?;
        let c = IntervalCalibration::parse(&text, &format!("{what} {}", path.display()))?;
        if c.estimator != estimator {
            bail!(
                "{what} {}: calibrated for the {} estimator, not {estimator}",
                path.display(),
                c.estimator,
            );
        }
        let through = c.measured_through();
        if &through != sensor {
            bail!(
                "{what} {}: measured through the sensor {through}, not {sensor} (the one in use); \
                 make one with `tactex eval fruits --sensor PROFILE --calibrate FILE`",
                path.display(),
            );
        }
        Ok(c)
    }

    /// The calibration kept beside the sensor profile at `profile`, when there is one and it
    /// was measured through this profile as it is now (said on stderr); None when there is
    /// none (`missing_intervals_note` says so where a command wants it said) or it is stale
    /// (a note says why and how to make it again).
    fn intervals_beside(
        &self,
        profile: &Path,
        fidelity: &str,
        estimator: &str,
        sensor: &ProfileId,
    ) -> Option<IntervalCalibration> {
        match self.look_beside(profile, fidelity, estimator, sensor) {
            Beside::Found(path, c) => {
                eprintln!(
                    "note: intervals measured through this sensor: {}",
                    path.display()
                );
                Some(*c)
            }
            Beside::Missing(_) => None,
            Beside::Stale(path, e) => {
                eprintln!(
                    "note: {e:#}; the intervals are the estimator's own (the profile changed since?); {}",
                    self.how_to_measure(profile, fidelity, &path)
                );
                None
            }
        }
    }

    /// The note for a profile with no calibration beside it: its intervals are the
    /// estimator's own, and the command that measures them. None when one is there.
    pub fn missing_intervals_note(&self, profile: &Path, fidelity: &str) -> Option<String> {
        let path = profile_intervals_path(profile, self, fidelity);
        (!path.is_file()).then(|| {
            format!(
                "note: --sensor {}: the intervals are the estimator's own, not measured through this sensor; {}",
                profile.display(),
                self.how_to_measure(profile, fidelity, &path)
            )
        })
    }

    fn how_to_measure(&self, profile: &Path, fidelity: &str, path: &Path) -> String {
        format!(
            "measure them with `tactex eval fruits --sensor {} --fidelity {fidelity} --estimator {} --calibrate {}` (used from then on)",
            profile.display(),
            self.flag_value(),
            path.display()
        )
    }

    /// What lies beside the profile at `profile` for this estimator at `fidelity`.
    pub fn look_beside(
        &self,
        profile: &Path,
        fidelity: &str,
        estimator: &str,
        sensor: &ProfileId,
    ) -> Beside {
        let path = profile_intervals_path(profile, self, fidelity);
        if !path.is_file() {
            return Beside::Missing(path);
        }
        match self.measured_intervals(&path, "intervals", estimator, sensor) {
            Ok(c) => Beside::Found(path, Box::new(c)),
            Err(e) => Beside::Stale(path, e),
        }
    }
}

/// An interval calibration beside a sensor profile: found and measured through it, missing,
/// or there but not for this estimator or this profile (why, in the error).
pub enum Beside {
    Found(PathBuf, Box<IntervalCalibration>),
    Missing(PathBuf),
    Stale(PathBuf, anyhow::Error),
}

/// Where the interval calibration measured through the profile at `profile` for `choice` at
/// `fidelity` is kept: beside it, `NAME.ESTIMATOR-FIDELITY.intervals.json` for `NAME.toml`
/// (a model file's estimator by its file stem).
pub fn profile_intervals_path(profile: &Path, choice: &EstimatorChoice, fidelity: &str) -> PathBuf {
    let estimator = match choice {
        EstimatorChoice::Model(path) => path
            .file_stem()
            .map_or_else(|| "model".into(), |s| s.to_string_lossy().into_owned()),
        other => other.flag_value(),
    };
    let stem = profile
        .file_stem()
        .map_or_else(|| "profile".into(), |s| s.to_string_lossy().into_owned());
    profile.with_file_name(format!("{stem}.{estimator}-{fidelity}.intervals.json"))
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

#[cfg(test)]
mod tests {
    use super::*;

    fn through(sensor: Option<ProfileId>) -> String {
        let (_, _, _, text) = BUILTIN_INTERVALS
            .iter()
            .find(|(e, ..)| *e == "indentation")
            .expect("shipped");
        let mut c = IntervalCalibration::parse(text, "shipped").expect("valid");
        c.sensor = sensor;
        serde_json::to_string(&c).expect("serialisable")
    }

    #[test]
    fn a_profiles_own_intervals_are_found_beside_it_only_when_measured_through_it() {
        let dir = tempfile::tempdir().expect("a temporary directory");
        let profile = dir.path().join("mine.toml");
        let mine = ProfileId {
            name: "mine".into(),
            sha256: "ab".repeat(32),
        };
        let choice = EstimatorChoice::named("indentation").unwrap();
        let beside = profile_intervals_path(&profile, &choice, "layer");
        assert_eq!(
            beside.file_name().and_then(|n| n.to_str()),
            Some("mine.indentation-layer.intervals.json")
        );
        let found = || choice.intervals_beside(&profile, "layer", "indentation", &mine);
        assert!(found().is_none(), "no file beside the profile");
        std::fs::write(&beside, through(Some(mine.clone()))).expect("written");
        assert_eq!(found().and_then(|c| c.sensor), Some(mine.clone()));
        // Measured through the built-in Mini (or the profile before an edit): not used.
        std::fs::write(&beside, through(None)).expect("written");
        assert!(found().is_none());
        // Given as --intervals through another sensor, a file is refused outright.
        std::fs::write(&beside, through(Some(mine.clone()))).expect("written");
        let mini = SensorProfile::gelsight_mini();
        let e = choice
            .open("--estimator", "layer", Some(&beside), &mini, None)
            .err()
            .expect("refused");
        assert!(
            format!("{e:#}").contains("measured through the sensor"),
            "{e:#}"
        );
    }
}
