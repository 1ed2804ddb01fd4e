//! The press stage: where on a fruit to press (`site`, from the depth points of the fruit
//! and of everything near it) and the paper's press protocol (`protocol`: no-contact
//! frames, the contact search, 8 frames from first contact), once for every backend.

pub mod protocol;
pub mod site;

// The stage's face: the probe a backend implements, the protocol, and where to press.
pub use protocol::{PressError, PressOutcome, PressProbe, PressProtocol, Pressed, run_press};
pub use site::{PressSite, press_site};
