//! tactex: the TactEx twin's application library, under the `tactex` command line, the chat
//! page and the Python package.
//!
//! `app` is the layer every front end shares (scenes, sensor profiles, the detector,
//! estimator and explainer choices, a question on the twin, the real devices or a replay);
//! `commands`, `serve` (the chat page), `xarm_twin` (the twin as an xArm controller),
//! `sim2real`, `eval`, `datagen` and `bench` are the products built on it; `report` is what
//! they write (atomic files, plots, arrays); `cli` is the clap surface and its dispatch.
//! Dependencies point one way: products -> app -> tactex-{core,sim,hw,learned}.

pub mod app;
#[cfg(feature = "plots")]
pub mod bench;
pub mod cli;
pub mod commands;
pub mod datagen;
#[cfg(feature = "plots")]
pub mod eval;
pub mod report;
#[cfg(feature = "servers")]
pub mod serve;
pub mod sim2real;
#[cfg(feature = "servers")]
pub mod xarm_twin;
