//! Explanation: measured objects and the question -> answer text. One contract
//! (`Explainer`), a deterministic offline template (the default), the groundedness check
//! that any generated reply must pass, and the chat messages a language model is given.
//! The language-model client itself talks to a network peer, so it lives with the binary.

pub mod grounded;
pub mod llm_prompt;
pub mod location;
pub mod template;

pub use location::{LOCATION_BAND_M, location_words};
pub use template::TemplateExplainer;

use crate::catalog::FruitCatalog;
use crate::hardness::scale::HardnessReport;
use crate::query::threshold::Threshold;
use crate::query::{Extreme, Intent, Property, Query};
use serde::Serialize;

/// One measured object as the explainer sees it.
#[derive(Clone, Debug, Serialize)]
pub struct Measured {
    pub label: String,
    pub location: String,
    pub hardness: Option<HardnessReport>,
    /// The 68% and 95% modulus intervals (MPa; upper None: rigid or unbounded).
    pub interval_68_mpa: [Option<f64>; 2],
    pub interval_95_mpa: [Option<f64>; 2],
    pub ripeness: Option<String>,
    /// Why there is no hardness, when there is none (a sentence fragment).
    pub not_measured: Option<String>,
    /// What the fruit asked about are held against ("than the banana on the left").
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub reference: bool,
}

/// Everything an explanation may say: the question, what was measured, which objects answer
/// it, and which asked-for kinds were not found.
#[derive(Clone, Debug, Serialize)]
pub struct Facts {
    pub prompt: String,
    pub query: Query,
    pub objects: Vec<Measured>,
    /// Indices into `objects` that answer the query, in answer order.
    pub selected: Vec<usize>,
    pub not_found: Vec<String>,
}

/// The answer text and who wrote it.
#[derive(Clone, Debug, Serialize)]
pub struct Explanation {
    pub text: String,
    /// "template", or "llm:<model>" when a model's reply passed the groundedness check.
    pub explainer: String,
    /// Why a generated reply was not used (timeout, HTTP error, ungrounded claim).
    pub notice: Option<String>,
}

/// Turns facts into text. Infallible: an explainer that cannot answer falls back to the
/// template and says why in `notice`.
pub trait Explainer: Send + Sync {
    fn name(&self) -> &str;
    fn explain(&self, facts: &Facts) -> Explanation;
}

/// A stiffness key: the modulus, infinite when rigid, NaN when unmeasured.
pub(crate) fn stiffness(m: &Measured) -> f64 {
    m.hardness
        .map_or(f64::NAN, |h| h.modulus_mpa.unwrap_or(f64::INFINITY))
}

/// What a threshold question holds the fruit against: its value, or the measured hardness
/// of the object it names ("softer than the apple"); None when that object was not measured.
pub fn held_against(query: &Query, objects: &[Measured]) -> Option<Threshold> {
    query.threshold.clone().or_else(|| {
        let r = query.relation.as_ref()?;
        let readings: Vec<(&str, f64)> = objects
            .iter()
            // With a place ("than the banana on the left") grounding marked only the one there.
            .filter(|m| m.reference && m.hardness.is_some())
            .map(|m| (m.label.as_str(), stiffness(m)))
            .collect();
        r.resolve(&readings)
    })
}

/// Indices of `objects` that answer the query, in answer order.
pub fn select(query: &Query, objects: &[Measured], catalog: &FruitCatalog) -> Vec<usize> {
    let mut measured: Vec<usize> = (0..objects.len())
        .filter(|&i| objects[i].hardness.is_some())
        .collect();
    // How much of the asked property an object has.
    let key = |i: &usize| -> f64 {
        let m = &objects[*i];
        let e = stiffness(m);
        match query.property {
            Property::Hardness => e,
            Property::Softness => -e,
            // Ripeness: stiffness relative to the fruit's unripe stage, lower is riper.
            Property::Ripeness => -catalog
                .get(&m.label)
                .map_or(e, |f| e / f.stages[0].modulus_mpa),
        }
    };
    match query.intent {
        Intent::Summarize if query.ranked => {
            measured.sort_by(|a, b| key(b).total_cmp(&key(a)));
            measured
        }
        Intent::Threshold => {
            let against = held_against(query, objects);
            measured.retain(|&i| {
                query.asks_about(&objects[i].label, objects[i].reference)
                    && against
                        .as_ref()
                        .is_some_and(|t| t.holds_for(stiffness(&objects[i])))
            });
            measured.sort_by(|a, b| key(b).total_cmp(&key(a)));
            // A superlative beside the value picks one of them.
            match query.extreme {
                Some(Extreme::Most) => measured.truncate(1),
                Some(Extreme::Least) => measured = measured.pop().into_iter().collect(),
                None => {}
            }
            measured
        }
        Intent::Extreme => {
            let pick = |among: &mut dyn Iterator<Item = usize>| match query.extreme {
                Some(Extreme::Least) => among.min_by(|a, b| key(a).total_cmp(&key(b))),
                _ => among.max_by(|a, b| key(a).total_cmp(&key(b))),
            };
            let best = pick(&mut measured.iter().copied());
            // "Is the banana the softest?": the banana asked about (its kind's best), then
            // the fruit that beats it, if one does.
            let held_up = query.candidate.as_ref().and_then(|kind| {
                pick(
                    &mut measured
                        .iter()
                        .copied()
                        .filter(|&i| &objects[i].label == kind),
                )
            });
            match (held_up, best) {
                (Some(c), Some(b)) if objects[b].label != objects[c].label => vec![c, b],
                _ => best.into_iter().collect(),
            }
        }
        _ => measured,
    }
}
