//! A question answered on the real devices `devices.toml` names (xArm, RealSense, GelSight
//! Mini), read through the real sensor's calibrated profile.

use crate::app::sensor::load_sensor;
use crate::app::twin_options::TwinOptions;
use anyhow::{Result, bail};
use std::path::Path;
use tactex_core::pipeline::{Answer, PipelineConfig};
use tactex_core::tactile::sensor_profile::SensorProfile;
use tactex_hw::devices_toml::DevicesConfig;
#[cfg(all(target_os = "linux", feature = "v4l2"))]
use {
    crate::app::detector_choice::DetectorChoice,
    crate::app::question::{Question, Recording},
    crate::app::replay::detector_without_truth,
    tactex_core::catalog::FruitCatalog,
    tactex_core::pipeline::{Devices, Language},
    tactex_sim::contact::Fidelity,
};

/// Answers `prompt` on the real devices `devices.toml` names: an xArm, a RealSense and a
/// GelSight Mini.
#[cfg(all(target_os = "linux", feature = "v4l2"))]
pub fn answer_on_hardware(
    file: &Path,
    twin: &TwinOptions,
    prompt: &str,
    record: Option<&Path>,
    config: &PipelineConfig,
) -> Result<Answer> {
    let catalog = FruitCatalog::builtin();
    let devices = DevicesConfig::load(file)?;
    let sensor = hardware_sensor(twin.sensor.as_deref())?;
    let choice = DetectorChoice::parse(&twin.detector)?;
    let detector = detector_without_truth(&choice, &catalog)?;
    let (parser, explainer) = twin.language()?;
    // The twin's most faithful physics stands in for the real gel's.
    let estimator = twin.estimator.open(
        "--estimator",
        Fidelity::Layer.name(),
        twin.intervals.as_deref(),
        &sensor,
        twin.sensor.as_deref(),
    )?;
    // The sensors first, so that a missing camera never leaves the arm enabled.
    let mut camera = devices.open_camera()?;
    let mut tactile = devices.open_tactile(sensor.spec.clone())?;
    let mut arm = devices.open_arm()?;
    let question = Question {
        prompt,
        catalog: &catalog,
        detector: detector.as_ref(),
        estimator: estimator.as_ref(),
        language: Language {
            reader: parser.as_ref(),
            explainer: explainer.as_ref(),
        },
        config,
        fidelity: None,
        sensor: Some(sensor.id()),
    };
    question.ask(
        Devices {
            camera: &mut camera,
            tactile: &mut tactile,
            arm: &mut arm,
        },
        record.map(|dir| Recording {
            dir,
            backend: "hw",
            twin: None,
        }),
    )
}

#[cfg(not(all(target_os = "linux", feature = "v4l2")))]
pub fn answer_on_hardware(
    file: &Path,
    twin: &TwinOptions,
    _: &str,
    _: Option<&Path>,
    _: &PipelineConfig,
) -> Result<Answer> {
    // The file and the profile are still checked, so that they are named before the missing
    // feature.
    DevicesConfig::load(file)?;
    hardware_sensor(twin.sensor.as_deref())?;
    bail!(
        "--backend hw: this tactex was built without V4L2, which reads the cameras; \
         on Linux rebuild with `cargo build --release --features v4l2` (needs libclang-dev)"
    );
}

/// The real GelSight's profile: required, since a real sensor's frames read through the
/// twin's analytic lights would give wrong slopes however good the physics.
fn hardware_sensor(sensor: Option<&Path>) -> Result<SensorProfile> {
    let Some(path) = sensor else {
        bail!(
            "--sensor: --backend hw reads the real GelSight through its calibrated profile; give one (`tactex calibrate` writes it)"
        );
    };
    let sensor = load_sensor(Some(path))?;
    use tactex_hw::gelsight_mini::{HEIGHT, WIDTH};
    let (w, h) = (sensor.spec.width_px, sensor.spec.height_px);
    if (w, h) != (WIDTH, HEIGHT) {
        bail!(
            "--sensor {}: a {w} x {h} px profile; the GelSight Mini's frames are {WIDTH} x {HEIGHT}",
            path.display()
        );
    }
    Ok(sensor)
}
