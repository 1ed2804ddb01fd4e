//! Sim-to-real: fitting a sensor profile from ball presses, and scoring the twin's renders
//! and recorded sessions against real frames.

pub mod calibrate;
pub mod compare;
pub mod compare_session;
pub mod contact_circle_score;
pub mod reading_score;
