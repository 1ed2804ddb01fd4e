//! tactex-sim's integration tests, one module per area, in one test binary.
//! `cargo test -p tactex-sim --test integration gel_render::` runs one module.

mod arm_kinematics;
mod common;
mod contact_extremes;
mod contact_mechanics;
mod fruit_footprint;
mod gel_render;
mod golden_images;
mod hardness_estimators;
mod scene_render;
mod touching_fruit;
