//! The trained hardness model shipped with the binary (models/hardness-small.onnx and its
//! card, see models/hardness-small.md), so that evaluations run from any directory.

use crate::hardness_model::OnnxEstimator;
use anyhow::{Context, Result};
use std::path::Path;

const SMALL_ONNX: &[u8] = include_bytes!("../../models/hardness-small.onnx");
const SMALL_CARD: &str = include_str!("../../models/hardness-small.json");

/// The built-in small CNN (trained on primitives; scored on unseen shapes in its card).
pub fn builtin_small() -> Result<OnnxEstimator> {
    OnnxEstimator::from_bytes(
        "models/hardness-small.onnx (built in)",
        SMALL_ONNX,
        "models/hardness-small.json (built in)",
        SMALL_CARD,
    )
    .context("loading the built-in hardness model")
}

/// A model file given on the command line (`option` names the flag in errors).
pub fn from_file(option: &str, path: &Path) -> Result<OnnxEstimator> {
    OnnxEstimator::load(path).with_context(|| format!("{option} {}", path.display()))
}
