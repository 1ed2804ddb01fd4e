//! Data generation on the twin: randomised press sequences (`tactile_sample`) pressed by
//! core's protocol on the solver alone (`press_protocol`), and random scenes
//! (`scene_random`) for detector training and evaluations.

pub mod press_protocol;
pub mod scene_random;
pub mod tactile_sample;
