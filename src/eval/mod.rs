//! Evaluations on the twin, each against a truth it did not tune on: grounding, hardness,
//! ripeness, the paper's query tiers, every catalog fruit alone and crowded, explanations.

use rand::seq::SliceRandom;
use rand_chacha::ChaCha8Rng;

pub mod explanations;
pub mod fruits;
pub mod grounding;
pub mod handeye;
pub mod hardness;
pub mod report_matching;
pub mod ripeness;
pub mod scenarios;

/// The paper's ten fruit kinds.
pub const PAPER_FRUIT_KINDS: [&str; 10] = [
    "mango", "lime", "lemon", "tomato", "banana", "avocado", "kiwi", "apple", "orange", "peach",
];

/// Distinct paper kinds other than `not`, shuffled, at most `n`.
pub(crate) fn other_paper_kinds(rng: &mut ChaCha8Rng, not: &[&str], n: usize) -> Vec<&'static str> {
    let mut pool: Vec<&'static str> = PAPER_FRUIT_KINDS
        .iter()
        .copied()
        .filter(|k| !not.contains(k))
        .collect();
    pool.shuffle(rng);
    pool.truncate(n);
    pool
}
