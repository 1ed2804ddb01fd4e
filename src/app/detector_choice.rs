//! Which detector a command runs: `classical` (colour and depth, no weights), `yolo:FILE` (a
//! YOLOv8-seg ONNX export), or the perception-error models `error-gsam` and `error-yolo`
//! (the twin's ground truth perturbed with the paper's measured detector statistics).

use anyhow::{Context, Result, bail};
use tactex_core::catalog::FruitCatalog;
use tactex_core::ground::detect::{ClassicalDetector, Detector};
use tactex_learned::yolo_seg::YoloSegDetector;
use tactex_sim::devices::camera::InstanceImage;
use tactex_sim::perception_error::{ErrorProfile, PerceptionErrorDetector};

pub const KNOWN: &str = "classical, yolo:FILE.onnx, error-gsam, error-yolo";

pub enum DetectorChoice {
    Classical,
    Yolo(Box<YoloSegDetector>),
    PerceptionError(ErrorProfile),
}

/// The twin's ground truth for one view: instance ids (0 background, i + 1 object i) and
/// each object's label.
pub struct GroundTruth<'a> {
    pub instances: &'a InstanceImage,
    pub labels: &'a [String],
}

impl DetectorChoice {
    /// Parses a detector name; a YOLO model is loaded (and checked) here, once.
    pub fn parse(spec: &str) -> Result<Self> {
        if let Some(file) = spec.strip_prefix("yolo:") {
            if file.trim().is_empty() {
                bail!("--detector: 'yolo:' names no model; give yolo:FILE.onnx");
            }
            let path = std::path::Path::new(file);
            // A model that is not there is missing, not a model that cannot be read.
            crate::app::file_input::present(path, "cannot read model file")
                .context("--detector")?;
            return Ok(Self::Yolo(Box::new(YoloSegDetector::load(path)?)));
        }
        if spec == "classical" {
            return Ok(Self::Classical);
        }
        match ErrorProfile::by_name(spec) {
            Some(profile) if spec.starts_with("error-") => Ok(Self::PerceptionError(profile)),
            _ => bail!("--detector: unknown detector '{spec}' (known: {KNOWN})"),
        }
    }

    /// The detector for one view; the perception-error models need its ground truth.
    pub fn detector<'a>(
        &'a self,
        catalog: &'a FruitCatalog,
        truth: Option<GroundTruth<'_>>,
        seed: u64,
    ) -> Result<Box<dyn Detector + 'a>> {
        Ok(match self {
            Self::Classical => Box::new(ClassicalDetector::new(catalog)),
            Self::Yolo(model) => Box::new(model.as_ref()),
            Self::PerceptionError(profile) => {
                let Some(truth) = truth else {
                    bail!("--detector: the perception-error models need the twin's ground truth");
                };
                Box::new(PerceptionErrorDetector::new(
                    profile.clone(),
                    truth.instances.clone(),
                    truth.labels.to_vec(),
                    seed,
                ))
            }
        })
    }
}
