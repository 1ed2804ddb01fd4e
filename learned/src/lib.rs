//! tactex-learned: the learned models behind tactex-core's traits.
//!
//! Everything that runs a neural network lives here, so that core stays free of runtimes and
//! dynamic loading: the ONNX runtime choice (`runtime`: tract by default, ONNX Runtime when
//! `ORT_DYLIB_PATH` names it), the metadata an ONNX file carries (`metadata`), the learned
//! hardness estimator (`hardness_model`, a `HardnessEstimator`), the YOLO-seg fruit detector
//! (`yolo_seg`, a `Detector`) and the hardness model built into the binary (`builtin`).

pub mod builtin;
pub mod hardness_model;
pub mod metadata;
pub mod runtime;
pub mod yolo_seg;
