//! A learned hardness model (ONNX, trained by `models/train/`) behind `HardnessEstimator`.
//!
//! A model is two files: `NAME.onnx`, mapping raw frames [batch, 1 + K, H, W, 3] (the first
//! contact frame, then the K frames it reads, RGB 0..255 as float) to `ln_modulus_mpa`
//! [batch, 1], and its card `NAME.json` giving the input and output names, which press frames
//! to feed, the frame size and the model's held-out RMSE in ln(E). Differences and resizing are
//! inside the graph, so the estimator feeds frames as recorded. The uncertainty combines that
//! held-out RMSE with the spread of the answers over the four flips of the input.

use crate::runtime::{OnnxError, backend, open_session};
use image::RgbImage;
use ort::session::Session;
use ort::value::Tensor;
use serde::Deserialize;
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use tactex_core::hardness::estimate::{
    EstimateError, Evidence, HardnessEstimate, HardnessEstimator, LearnedEvidence, ModulusInterval,
    PressSequence,
};
use tactex_core::hardness::scale::Hardness;
use tactex_core::tactile::spec::TactileSpec;

pub const MODEL_FORMAT: &str = "tactex-hardness-model/1";

/// The model card fields the estimator needs (the card holds more: recipe, metrics).
#[derive(Clone, Debug, Deserialize)]
pub struct ModelCard {
    pub format: String,
    pub model: String,
    pub input: String,
    pub output: String,
    /// Press frames fed, 0-based; the first is the first contact frame.
    pub frame_picks: Vec<usize>,
    pub height: u32,
    pub width: u32,
    /// RMSE of ln(E) on held-out shapes.
    pub ln_modulus_rmse: f64,
    /// The sensor profile its training data was drawn around (`datagen tactile --sensor`
    /// randomises around it): the family of sensors whose frames it has seen. Absent on
    /// cards written before profiles.
    #[serde(default)]
    pub sensor: Option<CardSensor>,
}

#[derive(Clone, Debug, Deserialize)]
pub struct CardSensor {
    pub name: String,
    #[serde(default)]
    pub sha256: Option<String>,
}

impl ModelCard {
    fn check(&self) -> Result<(), String> {
        if self.format != MODEL_FORMAT {
            return Err(format!(
                "format: '{}', expected '{MODEL_FORMAT}'",
                self.format
            ));
        }
        if self.frame_picks.len() < 2
            || self.frame_picks[0] != 0
            || self.frame_picks.windows(2).any(|w| w[0] >= w[1])
        {
            return Err(format!(
                "frame_picks: {:?} must list at least two frames, start at 0 (the first contact frame) and rise",
                self.frame_picks
            ));
        }
        if self.width == 0 || self.height == 0 {
            return Err("width, height: must be positive".into());
        }
        if !(self.ln_modulus_rmse.is_finite() && self.ln_modulus_rmse > 0.0) {
            return Err(format!(
                "ln_modulus_rmse: {} is not a positive number",
                self.ln_modulus_rmse
            ));
        }
        Ok(())
    }
}

pub struct OnnxEstimator {
    name: String,
    label: String,
    card: ModelCard,
    backend: String,
    // ort runs a session through &mut; estimators are shared across threads.
    session: Mutex<Session>,
}

/// The card of `model.onnx` is `model.json` beside it.
fn card_path(model: &Path) -> PathBuf {
    model.with_extension("json")
}

impl OnnxEstimator {
    /// The model at `path` with its card beside it (`card_path`).
    pub fn load(path: &Path) -> Result<Self, OnnxError> {
        let card_file = card_path(path);
        let card =
            tactex_core::text_file::read_to_string(&card_file).map_err(|e| OnnxError::Model {
                path: card_file.display().to_string(),
                reason: format!(
                    "cannot read the model card that must sit beside {}: {e}",
                    path.display()
                ),
            })?;
        let bytes = crate::runtime::read_model_file(path)?;
        Self::from_bytes(
            &path.display().to_string(),
            &bytes,
            &card_file.display().to_string(),
            &card,
        )
    }

    /// A model held in memory (`label` and `card_label` name it in errors and evidence).
    pub fn from_bytes(
        label: &str,
        onnx: &[u8],
        card_label: &str,
        card_json: &str,
    ) -> Result<Self, OnnxError> {
        let bad_card = |reason: String| OnnxError::Model {
            path: card_label.to_string(),
            reason,
        };
        let card: ModelCard = serde_json::from_str(card_json).map_err(|e| {
            bad_card(format!(
                "not a model card: {}",
                tactex_core::file_failure::json_failure(card_json, &e)
            ))
        })?;
        card.check().map_err(bad_card)?;
        let session = open_session(label, onnx)?;
        let bad_model = |reason: String| OnnxError::Model {
            path: label.to_string(),
            reason,
        };
        if !session.inputs().iter().any(|i| i.name() == card.input) {
            return Err(bad_model(format!(
                "has no input '{}' (its card's input)",
                card.input
            )));
        }
        if !session.outputs().iter().any(|o| o.name() == card.output) {
            return Err(bad_model(format!(
                "has no output '{}' (its card's output)",
                card.output
            )));
        }
        Ok(Self {
            name: format!("onnx_{}", card.model),
            label: label.to_string(),
            backend: backend()?.name(),
            card,
            session: Mutex::new(session),
        })
    }

    pub fn card(&self) -> &ModelCard {
        &self.card
    }

    /// ln(E / MPa) for each of the four flips (none, left-right, up-down, both) of the input.
    fn run_flips(&self, frames: &[&RgbImage]) -> Result<Vec<f64>, EstimateError> {
        let (w, h) = (self.card.width as usize, self.card.height as usize);
        let per_frame = w * h * 3;
        let mut data = vec![0f32; 4 * frames.len() * per_frame];
        for flip in 0..4 {
            for (k, frame) in frames.iter().enumerate() {
                let base = (flip * frames.len() + k) * per_frame;
                for (x, y, p) in frame.enumerate_pixels() {
                    let (x, y) = (x as usize, y as usize);
                    let xs = if flip & 1 == 1 { w - 1 - x } else { x };
                    let ys = if flip & 2 == 2 { h - 1 - y } else { y };
                    let at = base + (ys * w + xs) * 3;
                    for c in 0..3 {
                        data[at + c] = f32::from(p[c]);
                    }
                }
            }
        }
        let failed = |reason: String| EstimateError::Model(format!("{}: {reason}", self.label));
        let shape = [4usize, frames.len(), h, w, 3];
        let input = Tensor::from_array((shape, data)).map_err(|e| failed(e.to_string()))?;
        let mut session = self
            .session
            .lock()
            .map_err(|_| failed("a previous run panicked".into()))?;
        let outputs = session
            .run(ort::inputs![self.card.input.as_str() => input])
            .map_err(|e| failed(format!("inference failed: {e}")))?;
        let (out_shape, values) = outputs[self.card.output.as_str()]
            .try_extract_tensor::<f32>()
            .map_err(|e| failed(format!("output '{}': {e}", self.card.output)))?;
        if values.len() != 4 {
            return Err(failed(format!(
                "output '{}' has shape {out_shape:?}, expected [4, 1] for a batch of 4",
                self.card.output
            )));
        }
        let values: Vec<f64> = values.iter().map(|&v| f64::from(v)).collect();
        if values.iter().any(|v| !v.is_finite()) {
            return Err(failed(format!(
                "output '{}' is not finite: {values:?}",
                self.card.output
            )));
        }
        Ok(values)
    }
}

impl HardnessEstimator for OnnxEstimator {
    fn name(&self) -> &str {
        &self.name
    }

    fn cannot_read(&self, spec: &TactileSpec, frames: usize) -> Option<String> {
        let last = *self.card.frame_picks.last().expect("checked at load");
        if last >= frames {
            return Some(format!(
                "its card's frame_picks read press frame {} of {frames}",
                last + 1
            ));
        }
        let (w, h) = (self.card.width, self.card.height);
        ((w, h) != (spec.width_px, spec.height_px)).then(|| {
            format!(
                "it reads {w} x {h} frames (its card's width, height) and the sensor makes {} x {}; a model for this sensor is trained on its frames (datagen tactile --sensor)",
                spec.width_px, spec.height_px
            )
        })
    }

    fn estimate(
        &self,
        press: &PressSequence,
        spec: &TactileSpec,
    ) -> Result<HardnessEstimate, EstimateError> {
        let last = *self.card.frame_picks.last().expect("checked at load");
        if press.frames.len() <= last {
            return Err(EstimateError::BadSequence(format!(
                "model {} reads press frame {} but the sequence has {} frames",
                self.name,
                last + 1,
                press.frames.len()
            )));
        }
        let frames: Vec<&RgbImage> = self
            .card
            .frame_picks
            .iter()
            .map(|&k| &press.frames[k].image)
            .collect();
        for (&k, f) in self.card.frame_picks.iter().zip(&frames) {
            if f.dimensions() != (self.card.width, self.card.height) {
                return Err(EstimateError::BadSequence(format!(
                    "frame {} is {}x{} but model {} reads {}x{} frames",
                    k + 1,
                    f.width(),
                    f.height(),
                    self.name,
                    self.card.width,
                    self.card.height
                )));
            }
        }
        let ln = self.run_flips(&frames)?;
        let mean = ln.iter().sum::<f64>() / ln.len() as f64;
        let spread =
            (ln.iter().map(|v| (v - mean) * (v - mean)).sum::<f64>() / ln.len() as f64).sqrt();
        let sigma = spread.hypot(self.card.ln_modulus_rmse);
        let hardness = Hardness::from_modulus_mpa(mean.exp()).map_err(|e| {
            EstimateError::Model(format!("{}: output ln(E) = {mean}: {e}", self.label))
        })?;
        Ok(HardnessEstimate {
            hardness,
            interval: ModulusInterval::log_normal(
                mean,
                sigma,
                "the model card's held-out RMSE and the flip spread (not calibrated)",
            ),
            evidence: Evidence::Learned(LearnedEvidence {
                model: self.label.clone(),
                backend: self.backend.clone(),
                frames_used: self.card.frame_picks.clone(),
                flip_spread_ln: spread,
                heldout_rmse_ln: self.card.ln_modulus_rmse,
                trained_on_sensor: self.card.sensor.as_ref().map(|s| s.name.clone()),
                // The held-out RMSE was measured on the training sensor's family; on another
                // sensor's frames it is not a measured figure, and the evidence says so.
                other_sensor: self
                    .card
                    .sensor
                    .as_ref()
                    .filter(|s| s.name != spec.model)
                    .map(|s| {
                        format!(
                            "reading frames of sensor '{}' with a model trained on sensor '{}'; its held-out error was not measured here",
                            spec.model, s.name
                        )
                    }),
            }),
        })
    }
}
