//! The tactex package's end-to-end tests, one module per area, in one test binary: one
//! link of the workspace instead of one per file. `cargo test --test integration ask::`
//! runs one module.

mod arm;
mod ask;
mod board;
mod cli;
mod datagen;
mod datagen_scenes;
mod detect;
mod eval;
mod handeye;
mod hw_backend;
mod input_bounds;
mod numeric_flags;
mod outputs;
mod press;
mod qa_corpus;
mod sensor_profile;
mod serve;
mod serve_browser;
mod serve_process;
mod session;
mod sim_to_real;
mod twin;
mod twin_sdk;
