//! A question answered from a recorded session, and the detector for devices without truth.

use crate::app::detector_choice::DetectorChoice;
use crate::app::question::Question;
use crate::app::twin_options::TwinOptions;
use anyhow::{Context, Result, anyhow, bail};
use std::path::Path;
use tactex_core::catalog::FruitCatalog;
use tactex_core::ground::detect::Detector;
use tactex_core::pipeline::{Answer, Devices, PipelineConfig};
use tactex_hw::session::{MANIFEST, open_session};
use tactex_sim::contact::Fidelity;

/// Answers `prompt` from the recorded session in `dir`: its frames in the order they were
/// taken, its moves checked against the pipeline's. The estimates' intervals are the ones
/// calibrated at the session's fidelity, where it was recorded on the twin.
pub fn answer_on_replay(
    dir: &Path,
    options: &TwinOptions,
    prompt: &str,
    config: &PipelineConfig,
) -> Result<Answer> {
    let catalog = FruitCatalog::builtin();
    let (manifest, mut camera, mut tactile, mut arm) = open_session(dir).context("--session")?;
    // A session recorded on the twin says at which fidelity, and the answer repeats it.
    let fidelity = match manifest.twin.as_ref().and_then(|t| t.fidelity.as_deref()) {
        Some(f) => Some(f.parse::<Fidelity>().map_err(|e| {
            anyhow!(
                "--session: {}: twin.fidelity: {}",
                dir.join(MANIFEST).display(),
                tactex_core::printable::printable(&e.chars().take(200).collect::<String>())
            )
        })?),
        None => None,
    };
    let opened = TwinOptions {
        fidelity: fidelity.unwrap_or(options.fidelity),
        ..options.clone()
    }
    .open()?;
    let detector = detector_without_truth(&opened.detector, &catalog)?;
    let question = Question {
        prompt,
        catalog: &catalog,
        detector: detector.as_ref(),
        estimator: opened.estimator.as_ref(),
        language: opened.language(),
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
        answer.fidelity = fidelity.map(|f| f.name().into());
        answer.sensor = twin.sensor;
    }
    Ok(answer)
}

/// The detector for devices that know no ground truth (real ones, or a replay of them).
pub fn detector_without_truth<'a>(
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
