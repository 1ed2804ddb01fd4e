//! The chat messages that ask a language model to read a prompt as a `QueryDraft`: the
//! fields and the catalog's names, then worked examples that are the rule parser's own
//! readings (so both parsers mean the same by every field), then the prompt.

use super::draft::QueryDraft;
use super::{lexicon, parse};
use crate::catalog::FruitCatalog;
use serde_json::{Value, json};

/// A reading is a lookup, not prose: the most likely tokens.
pub const TEMPERATURE: f64 = 0.0;

/// Prompts whose rule readings are the examples: one of each kind of question.
const EXAMPLES: &[&str] = &[
    "Which fruit is the softest?",
    "Is the mango harder than the avocado?",
    "Sort the citrus fruits by how soft they are",
    "Which fruits are harder than 2 MPa?",
    "Find me a fruit that is softer than the apple",
    "How firm is the yellow one on the left?",
    "Which fruit would you recommend for a smoothie today?",
    "Which fruit is the softest, not counting the kiwi and the pineapple?",
];

/// The instructions: what each field means and which names are allowed.
pub fn system_role(catalog: &FruitCatalog) -> String {
    let groups: Vec<&str> = catalog.categories.iter().map(|c| c.name.as_str()).collect();
    format!(
        "You read a question about fruit on a table, which a robot answers by pressing each \
         fruit with a tactile sensor, into one JSON object and nothing else. Fields: \
         intent (identify: one fruit's property; extreme: the most or least of a property; \
         summarize: several or every fruit, ranked if asked for an order; compare: two fruit \
         against each other; threshold: the fruit past a value or past another fruit); \
         property (hardness, softness or ripeness); extreme (most, least or null); targets \
         (fruit named, singular catalog names, in the order named); categories (groups named: \
         {groups}); all (true when the question is about every fruit, or every one the \
         filters keep); exclude (fruit left out); color (one of {colours}, or null); position \
         (left, right, front, back, centre or two of them such as \"left front\", or null); \
         count (how many the question expects, or null); size (\"largest\" or \"smallest\" \
         when one is picked by size: \"the bigger lime\", or null); ranked (an order was asked for); \
         unknown (fruit named that are not in the catalog); threshold ({{\"harder\": bool, \
         \"value\": \"2 MPa\"}} with the unit: MPa, kPa, Shore A or Shore 00, or null); \
         relation ({{\"harder\": bool, \"reference\": catalog name, \"also\": [further \
         catalog names], \"ripeness\": bool}} for \"softer than the apple\" or \"than the \
         apple and the mango\", ripeness true for \"riper than the one on the left\" between \
         two of one kind (harder: less ripe), or null); goal (what the fruit is wanted for, as said back to the user: \
         \"for a smoothie\", or null). Catalog names: {names}.",
        colours = lexicon::COLOURS.join(", "),
        names = catalog.names().join(", "),
        groups = groups.join(", "),
    )
}

/// The messages for one prompt: the instructions, the worked examples as turns, the prompt.
pub fn messages(prompt: &str, catalog: &FruitCatalog) -> Value {
    let mut turns = vec![json!({"role": "system", "content": system_role(catalog)})];
    for example in EXAMPLES {
        // Every example is read by the rules; one they refuse is left out, not made up.
        let Ok(query) = parse(example, catalog) else {
            continue;
        };
        let draft = serde_json::to_string(&QueryDraft::of(&query)).unwrap_or_default();
        turns.push(json!({"role": "user", "content": example}));
        turns.push(json!({"role": "assistant", "content": draft}));
    }
    turns.push(json!({"role": "user", "content": prompt}));
    Value::Array(turns)
}

/// The JSON object in a model's reply: models wrap it in prose or a code fence.
pub fn reply_object(reply: &str) -> Option<&str> {
    let start = reply.find('{')?;
    let end = reply.rfind('}')?;
    (start < end).then(|| &reply[start..=end])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_example_is_a_rule_reading_and_the_prompt_comes_last() {
        let catalog = FruitCatalog::builtin();
        let m = messages("Which one is ripest?", &catalog);
        let turns = m.as_array().unwrap();
        assert_eq!(turns.len(), 2 + 2 * EXAMPLES.len());
        assert_eq!(turns.last().unwrap()["content"], "Which one is ripest?");
        for pair in turns[1..turns.len() - 1].chunks(2) {
            let draft: QueryDraft =
                serde_json::from_str(pair[1]["content"].as_str().unwrap()).unwrap();
            let rules = parse(pair[0]["content"].as_str().unwrap(), &catalog).unwrap();
            assert_eq!(draft.checked(&catalog), Ok(rules));
        }
        assert!(turns[0]["content"].as_str().unwrap().contains("citrus"));
    }

    #[test]
    fn the_object_is_found_inside_a_fence_or_prose() {
        assert_eq!(reply_object("```json\n{\"a\": 1}\n```"), Some("{\"a\": 1}"));
        assert_eq!(reply_object("Here: {\"a\": {}} done"), Some("{\"a\": {}}"));
        assert_eq!(reply_object("no object"), None);
    }
}
