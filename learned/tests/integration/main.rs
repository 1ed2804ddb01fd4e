//! tactex-learned's integration tests: the hardness model and the YOLO-seg detector on
//! probe models whose answers are known, in one test binary.

mod hardness_model;
mod yolo_seg;
