//! The product's commands, each a thin layer over the application layer (`crate::app`) and
//! the libraries: ask a question, press, parse, calibrate-free sensor tools, the arm.

pub mod arm;
pub mod ask;
pub mod board;
pub mod contact;
pub mod detect;
pub mod handeye;
pub mod markers;
pub mod parse;
pub mod press;
pub mod read;
pub mod scene;
pub mod sensor;
