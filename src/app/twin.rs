//! A question answered on the twin: fresh sim devices of a scene, the pipeline on them, and
//! the ground truth an evaluation scores the answer against.

use crate::app::camera_placement::CameraPlacement;
use crate::app::detector_choice::{DetectorChoice, GroundTruth};
use crate::app::question::{Question, Recording};
use anyhow::{Context, Result};
use std::path::Path;
use std::sync::Arc;
use tactex_core::catalog::FruitCatalog;
use tactex_core::devices::RgbdCamera;
use tactex_core::geometry::{CameraIntrinsics, Pose};
use tactex_core::ground::detect::Detector;
use tactex_core::hardness::estimate::HardnessEstimator;
use tactex_core::pipeline::{self, Answer, Devices, Language, PipelineConfig, Progress};
use tactex_core::scene::Scene;
use tactex_core::tactile::sensor_profile::SensorProfile;
use tactex_hw::session::TwinRecord;
use tactex_sim::SimDevices;
use tactex_sim::contact::Fidelity;
use tactex_sim::devices::camera::InstanceImage;
use tactex_sim::render::scene::SceneRenderer;
use tactex_sim::world::SharedWorld;

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
    pub language: Language<'a>,
    pub estimator: &'a dyn HardnessEstimator,
    /// Contact physics of the sim GelSight.
    pub fidelity: Fidelity,
    /// Where the scene camera really stands against where the pipeline believes it does.
    pub camera: &'a CameraPlacement,
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
        self.camera.apply(&mut sim);
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
            self.language,
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
            // Where the instances were rendered from: the truth, not the belief.
            camera_pose: sim.world.lock().expect("world lock").camera_pose,
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
            language: self.language,
            config,
            fidelity: Some(self.fidelity),
            sensor: Some(self.sensor.id()),
        };
        let scene_toml =
            tactex_core::text_file::read_to_string(&self.scene.path).with_context(|| {
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
