//! The hardness stage: the scales (`scale`: Shore A, Shore 00, modulus and the conversions)
//! and reading hardness from a press sequence: the `HardnessEstimator` trait and the Hertz
//! slope fit (`estimate`), the integrated-indentation estimator (`indentation_estimator`)
//! with the bonded layer's compliance (`layer_compliance`, `gel_share_fit`), and intervals
//! whose coverage is measured (`interval_calibration`). The learned estimator is in
//! tactex-learned.

pub mod border_level;
pub mod estimate;
pub mod gel_share_fit;
pub mod indentation_estimator;
pub mod interval_calibration;
pub mod layer_compliance;
pub mod scale;

// The stage's face: its trait, what it reads and hands on, and the estimators core holds.
pub use estimate::{
    EstimateError, Evidence, HardnessEstimate, HardnessEstimator, HertzSlopeEstimator,
    ModulusInterval, PressSequence,
};
pub use indentation_estimator::IndentationEstimator;
pub use scale::Hardness;
