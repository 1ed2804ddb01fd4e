//! The press stage: where on a fruit to press (`site`, from the depth points of the fruit
//! and of everything near it) and the paper's press protocol (`protocol`: no-contact
//! frames, the contact search, 8 frames from first contact), once for every backend.

pub mod protocol;
pub mod site;
