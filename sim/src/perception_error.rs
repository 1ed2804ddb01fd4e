//! The perception-error model: a `Detector` that reads the twin's ground truth (instance
//! masks) and perturbs it the way a learned detector errs: it misses objects, reports a
//! confidence, and returns masks that are shifted and have a ragged boundary. Profiles are
//! set after the TactEx paper's YOLOv8 and Grounded-SAM (GSAM) comparison, for ablations of
//! the rest of the pipeline against detector quality.

use crate::devices::camera::{InstanceImage, instance_mask};
use image::{GrayImage, Luma};
use imageproc::distance_transform::Norm;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};
use std::sync::Mutex;
use tactex_core::ground::detect::{DetectError, Detection, Detector, RgbdView};
use tactex_core::ground::mask::mask_box;

/// How one detector errs.
#[derive(Clone, Debug, PartialEq)]
pub struct ErrorProfile {
    pub name: String,
    /// Chance that an object is not detected at all.
    pub miss_rate: f64,
    /// Confidence: mean and standard deviation (clamped to [0.05, 0.99]).
    pub confidence_mean: f64,
    pub confidence_sd: f64,
    /// 1-sigma shift of the whole mask per image axis (pixels).
    pub shift_sigma_px: f64,
    /// Largest boundary error (pixels): the mask is eroded or dilated by 0..=this.
    pub boundary_px: u8,
}

impl ErrorProfile {
    /// Grounded-SAM as the paper found it: the higher success (0.9) and mask quality (the
    /// paper's best IoU, 0.942), at a lower confidence than YOLO. The shift and boundary are
    /// set so that the twin's measured IoU comes out near 0.94 (see `eval grounding`).
    pub fn gsam() -> Self {
        Self {
            name: "error-gsam".into(),
            miss_rate: 0.10,
            confidence_mean: 0.55,
            confidence_sd: 0.12,
            shift_sigma_px: 0.8,
            boundary_px: 1,
        }
    }

    /// YOLOv8-seg as the paper found it: success 0.85, confident (higher scores than GSAM)
    /// but coarser masks. Its IoU is not quoted in the issue that specifies this model; the
    /// coarser boundary (2 px) and shift (1.5 px) stand for "GSAM is more robust for
    /// fine-grained segmentation" and are assumptions, not the paper's figures.
    pub fn yolo() -> Self {
        Self {
            name: "error-yolo".into(),
            miss_rate: 0.15,
            confidence_mean: 0.82,
            confidence_sd: 0.08,
            shift_sigma_px: 1.5,
            boundary_px: 2,
        }
    }

    pub fn by_name(name: &str) -> Option<Self> {
        match name {
            "error-gsam" | "gsam" => Some(Self::gsam()),
            "error-yolo" | "yolo" => Some(Self::yolo()),
            _ => None,
        }
    }
}

/// Ground truth perturbed by an `ErrorProfile`.
pub struct PerceptionErrorDetector {
    profile: ErrorProfile,
    /// Label of instance id i + 1.
    labels: Vec<String>,
    instances: InstanceImage,
    rng: Mutex<ChaCha8Rng>,
}

impl PerceptionErrorDetector {
    /// `instances` from `SimCamera::clean`, `labels` in the world's object order.
    pub fn new(
        profile: ErrorProfile,
        instances: InstanceImage,
        labels: Vec<String>,
        seed: u64,
    ) -> Self {
        Self {
            profile,
            labels,
            instances,
            rng: Mutex::new(ChaCha8Rng::seed_from_u64(seed ^ 0xde7e_c7e5)),
        }
    }
}

impl Detector for PerceptionErrorDetector {
    fn name(&self) -> &str {
        &self.profile.name
    }

    fn detect(&self, view: &RgbdView<'_>) -> Result<Vec<Detection>, DetectError> {
        let (w, h) = self.instances.dimensions();
        if view.color.dimensions() != (w, h) {
            return Err(DetectError::Model {
                detector: self.profile.name.clone(),
                message: format!(
                    "view is {}x{}, the ground truth {w}x{h}",
                    view.color.width(),
                    view.color.height()
                ),
            });
        }
        let mut rng = self.rng.lock().map_err(|_| DetectError::Model {
            detector: self.profile.name.clone(),
            message: "random state poisoned".into(),
        })?;
        let p = &self.profile;
        let shift = Normal::new(0.0, p.shift_sigma_px.max(1e-9)).expect("valid");
        let confidence = Normal::new(p.confidence_mean, p.confidence_sd.max(1e-9)).expect("valid");
        let mut out = Vec::new();
        for (i, label) in self.labels.iter().enumerate() {
            let id = (i + 1) as u16;
            let truth = instance_mask(&self.instances, id);
            // Draw every number whether or not the object is missed, so that one object's
            // miss does not change the next one's draws.
            let missed = rng.random::<f64>() < p.miss_rate;
            let (dx, dy) = (
                shift.sample(&mut *rng).round() as i64,
                shift.sample(&mut *rng).round() as i64,
            );
            let radius = rng.random_range(0..=p.boundary_px);
            let grow = rng.random::<bool>();
            let score = confidence.sample(&mut *rng).clamp(0.05, 0.99);
            if missed || truth.pixels().all(|v| v[0] == 0) {
                continue;
            }
            let ragged = match (radius, grow) {
                (0, _) => truth,
                (r, true) => imageproc::morphology::dilate(&truth, Norm::L2, r),
                (r, false) => imageproc::morphology::erode(&truth, Norm::L2, r),
            };
            let mask = GrayImage::from_fn(w, h, |x, y| {
                let (sx, sy) = (x as i64 - dx, y as i64 - dy);
                if sx >= 0 && sy >= 0 && (sx as u32) < w && (sy as u32) < h {
                    *ragged.get_pixel(sx as u32, sy as u32)
                } else {
                    Luma([0])
                }
            });
            let Some((bbox, _)) = mask_box(&mask) else {
                continue;
            };
            out.push(Detection {
                label: label.clone(),
                score,
                bbox,
                mask,
                size_m: [0.0; 3],
            });
        }
        Ok(out)
    }
}
