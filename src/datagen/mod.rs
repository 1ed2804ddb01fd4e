//! Synthetic data sets: tactile press sequences, RGB-D scenes, ball-press calibration sets.

pub mod ball_presses;
pub mod scenes;
pub mod tactile;
