//! The chat messages a language model gets: the TactEx paper's role, the rules that keep a
//! reply checkable by `grounded::check`, and the facts as JSON. Pure text; the client that
//! sends them is the binary's.

use super::template::{likely_range_mpa, range_words};
use super::{Facts, Measured};
use serde_json::{Value, json};

/// The paper's system role, with rules that make every claim traceable to the data.
pub const SYSTEM_ROLE: &str = "You turn object data into scene descriptions, explain and \
interpret tactile levels. Rules: use only the objects and values in the data; never invent a \
fruit, number, ripeness or position. Answer the question in one to three short sentences for \
an operator. For every object with \"answers\": true give its label, its location words, its \
hardness with the unit as given (Shore and MPa) and its ripeness when present. Say plainly \
which asked-for fruits were not found. Every number carries its unit. No lists, no markdown.";

/// Sampling temperature: near-deterministic, as in the paper.
pub const TEMPERATURE: f64 = 0.1;

fn object(i: usize, m: &Measured, facts: &Facts) -> Value {
    let hardness = m.hardness.map(|h| match h.modulus_mpa {
        None => json!({ "rigid": true }),
        Some(e) => {
            json!({
                "shore": h.shore_words(),
                "modulus": format!("{e:.2} MPa"),
                "likely_range_68_percent": likely_range_mpa(m).map(range_words),
            })
        }
    });
    json!({
        "label": m.label,
        "location": m.location,
        "hardness": hardness,
        "ripeness": m.ripeness,
        "answers": facts.selected.contains(&i),
        "answer_rank": facts.selected.iter().position(|&s| s == i).map(|r| r + 1),
    })
}

/// The facts as the model sees them.
fn facts_json(facts: &Facts) -> Value {
    json!({
        "question": facts.prompt,
        "asked_property": facts.query.property,
        "objects": facts.objects.iter().enumerate().map(|(i, m)| object(i, m, facts)).collect::<Vec<_>>(),
        "not_found": facts.not_found,
        "unknown_to_catalog": facts.query.unknown,
    })
}

/// `[system, user]` messages of an OpenAI-style chat completion.
pub fn messages(facts: &Facts) -> Value {
    json!([
        { "role": "system", "content": SYSTEM_ROLE },
        { "role": "user", "content": format!("Data: {}\nQuestion: {}", facts_json(facts), facts.prompt) },
    ])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::catalog::FruitCatalog;
    use crate::hardness::scale::Hardness;

    #[test]
    fn the_model_sees_every_value_the_check_accepts() {
        let catalog = FruitCatalog::builtin();
        let query = crate::query::parse("Which fruit is the softest?", &catalog).unwrap();
        let facts = Facts {
            prompt: "Which fruit is the softest?".into(),
            query,
            objects: vec![Measured {
                label: "banana".into(),
                location: "left front".into(),
                hardness: Some(Hardness::ModulusMpa(0.8).into()),
                interval_68_mpa: [Some(0.72), Some(0.88)],
                interval_95_mpa: [Some(0.6), Some(1.0)],
                ripeness: Some("ripe".into()),
                not_measured: None,
                reference: false,
            }],
            selected: vec![0],
            not_found: vec!["kiwi".into()],
        };
        let m = messages(&facts);
        assert_eq!(m[0]["content"], SYSTEM_ROLE);
        let user = m[1]["content"].as_str().unwrap();
        for needle in [
            "\"label\":\"banana\"",
            "\"location\":\"left front\"",
            "0.80 MPa",
            "\"likely_range_68_percent\":\"0.72 MPa to 0.88 MPa\"",
            "24 Shore A",
            "\"ripeness\":\"ripe\"",
            "\"not_found\":[\"kiwi\"]",
            "\"answers\":true",
        ] {
            assert!(user.contains(needle), "{needle} missing from {user}");
        }
    }
}
