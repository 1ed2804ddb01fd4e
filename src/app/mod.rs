//! The application layer every front end shares (the commands, the chat page, the xArm
//! twin, the evaluations and, next, the Python package): loading scenes and sensor profiles,
//! choosing the detector, estimator and explainer, and answering a question on the twin, on
//! the real devices or from a recorded session.

pub mod ball_presses;
pub mod camera_placement;
pub mod detector_choice;
pub mod error_kind;
pub mod estimator_choice;
pub mod explainer_choice;
pub mod file_input;
pub mod flag_range;
pub mod hand_eye;
pub mod hardware;
pub mod image_input;
pub mod llm_chat;
pub mod parser_choice;
pub mod press_options;
pub mod press_steps;
pub mod question;
pub mod replay;
pub mod request_json;
pub mod sample_space;
pub mod scene;
pub mod sensor;
pub mod single_press;
pub mod tactile_samples;
pub mod twin;
pub mod twin_options;

pub use image_input::{load_rgb, load_tactile_frame};
pub use scene::{default_scene, load_scene, scene_renderer};
pub use sensor::{load_sensor, with_gel_modulus};
pub use twin::{Twin, TwinAnswer};
pub use twin_options::{DEFAULT_ESTIMATOR, OpenedTwin, TwinOptions};
