//! Evaluations on the twin, each against a truth it did not tune on: grounding, hardness,
//! ripeness, the paper's query tiers, every catalog fruit alone and crowded, explanations.

pub mod explanations;
pub mod fruits;
pub mod grounding;
pub mod hardness;
pub mod ripeness;
pub mod scenarios;

/// The paper's ten fruit kinds.
pub const PAPER_FRUIT_KINDS: [&str; 10] = [
    "mango", "lime", "lemon", "tomato", "banana", "avocado", "kiwi", "apple", "orange", "peach",
];
