//! Benchmarks of the product's stages (run them on a release build; they report medians).

pub mod ask;
pub mod contact;
pub mod datagen;
pub mod render;
pub mod scene;
