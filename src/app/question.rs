//! One question on any devices, optionally recorded into a replayable session.

use anyhow::{Context, Result};
use std::path::Path;
use tactex_core::catalog::FruitCatalog;
use tactex_core::devices::{Arm, RgbdCamera, TactileSensor};
use tactex_core::ground::detect::Detector;
use tactex_core::hardness::estimate::HardnessEstimator;
use tactex_core::pipeline::{self, Answer, Devices, Language, PipelineConfig};
use tactex_hw::session::{SessionRecorder, TwinRecord};
use tactex_sim::contact::Fidelity;

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
    pub language: Language<'q>,
    pub config: &'q PipelineConfig,
    /// The sim GelSight's contact physics, when the devices are the twin's.
    pub fidelity: Option<Fidelity>,
    /// The tactile sensor's profile, when one is known.
    pub sensor: Option<tactex_core::tactile::sensor_profile::ProfileId>,
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
            self.language,
            self.config,
        )?;
        answer.fidelity = self.fidelity.map(|f| f.name().into());
        answer.sensor = self.sensor.clone();
        Ok(answer)
    }
}
