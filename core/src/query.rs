//! Prompt -> `Query`: rule-based, offline. Says clearly when a prompt cannot be grounded.

use crate::catalog::FruitCatalog;
use serde::Serialize;

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Intent {
    /// The property of named objects ("Identify the hardness of the lemon").
    Identify,
    /// The most/least of a property ("Which fruit is the softest?").
    Extreme,
    /// The property of every object, or of several named ones.
    Summarize,
    /// Two named objects against each other ("Is the mango harder than the avocado?").
    Compare,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Property {
    Hardness,
    Softness,
    Ripeness,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Extreme {
    Most,
    Least,
}

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Query {
    pub intent: Intent,
    pub property: Property,
    pub extreme: Option<Extreme>,
    /// Catalog names (singular) the prompt names, in the order named.
    pub targets: Vec<String>,
    /// The prompt is about every fruit on the table ("which fruit", "all fruits").
    pub all: bool,
    pub exclude: Vec<String>,
}

#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum QueryError {
    #[error("prompt: empty; ask e.g. \"Which fruit is the softest?\"")]
    Empty,
    #[error("prompt: names no known fruit in \"{prompt}\" (known: {known})")]
    NoTarget { prompt: String, known: String },
    #[error("prompt: over {max} characters")]
    TooLong { max: usize },
}

pub const MAX_PROMPT_CHARS: usize = 2000;

const GENERIC: &[&str] = &[
    "fruit",
    "fruits",
    "object",
    "objects",
    "item",
    "items",
    "everything",
    "all",
    "each",
    "every",
];
const SOFT_MOST: &[&str] = &[
    "softest",
    "squishiest",
    "squishier",
    "softer",
    "mushiest",
    "tenderest",
];
const HARD_MOST: &[&str] = &[
    "hardest", "firmest", "harder", "firmer", "stiffest", "toughest",
];
const RIPE_MOST: &[&str] = &["ripest", "riper"];

pub fn parse(prompt: &str, catalog: &FruitCatalog) -> Result<Query, QueryError> {
    let trimmed = prompt.trim();
    if trimmed.is_empty() {
        return Err(QueryError::Empty);
    }
    if trimmed.chars().count() > MAX_PROMPT_CHARS {
        return Err(QueryError::TooLong {
            max: MAX_PROMPT_CHARS,
        });
    }
    let lower = trimmed.to_lowercase();
    let words: Vec<&str> = lower
        .split(|c: char| !c.is_alphanumeric())
        .filter(|w| !w.is_empty())
        .collect();
    let has = |set: &[&str]| words.iter().any(|w| set.contains(w));
    let has_phrase = |p: &str| lower.contains(p);

    let mut targets = Vec::new();
    let mut exclude = Vec::new();
    let mut excluding = false;
    for w in &words {
        if matches!(*w, "except" | "excluding" | "but" | "without") {
            excluding = true;
            continue;
        }
        if let Some(f) = catalog.find_word(w) {
            let list = if excluding {
                &mut exclude
            } else {
                &mut targets
            };
            if !list.contains(&f.name) {
                list.push(f.name.clone());
            }
        }
    }
    let all = has(GENERIC) || !exclude.is_empty();
    if targets.is_empty() && !all {
        return Err(QueryError::NoTarget {
            prompt: trimmed.to_string(),
            known: catalog.names().join(", "),
        });
    }

    let least = has_phrase("least") || has_phrase("not as");
    let (property, superlative) = if has(SOFT_MOST) {
        (Property::Softness, true)
    } else if has(HARD_MOST) {
        (Property::Hardness, true)
    } else if has(RIPE_MOST) || (has_phrase("most ripe") || has_phrase("least ripe")) {
        (Property::Ripeness, true)
    } else if has(&["ripe", "ripeness", "unripe", "overripe", "ready"]) {
        (Property::Ripeness, false)
    } else if has(&["soft", "softness", "squishy", "tender"]) {
        (Property::Softness, has_phrase("most") || least)
    } else {
        (Property::Hardness, has_phrase("most") || least)
    };
    let comparative = words.iter().any(|w| {
        w.ends_with("er")
            && (SOFT_MOST.contains(w) || HARD_MOST.contains(w) || RIPE_MOST.contains(w))
    }) || has(&["compare", "versus", "vs"]);

    let intent = if comparative && targets.len() >= 2 {
        Intent::Compare
    } else if superlative {
        Intent::Extreme
    } else if all || targets.len() > 1 || has(&["summarize", "summarise", "describe", "list"]) {
        Intent::Summarize
    } else {
        Intent::Identify
    };
    let extreme =
        (intent == Intent::Extreme).then_some(if least { Extreme::Least } else { Extreme::Most });
    // A superlative over one named kind ("the softest banana") ranks the instances of it.
    let all = all && (intent != Intent::Extreme || targets.is_empty());
    Ok(Query {
        intent,
        property,
        extreme,
        targets,
        all,
        exclude,
    })
}

impl Query {
    /// Whether an object with this label is among those the query asks about.
    pub fn wants(&self, label: &str) -> bool {
        !self.exclude.iter().any(|e| e == label)
            && (self.all || self.targets.iter().any(|t| t == label))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn q(p: &str) -> Query {
        parse(p, &FruitCatalog::builtin()).unwrap()
    }

    #[test]
    fn softest_fruit_is_an_extreme_over_all() {
        let query = q("Which fruit is the softest?");
        assert_eq!(
            (query.intent, query.property, query.extreme, query.all),
            (
                Intent::Extreme,
                Property::Softness,
                Some(Extreme::Most),
                true
            )
        );
        let query = q("Which fruit is the hardest?");
        assert_eq!(
            (query.intent, query.property),
            (Intent::Extreme, Property::Hardness)
        );
    }

    #[test]
    fn identify_names_one_target() {
        let query = q("Identify the hardness of the lemon");
        assert_eq!(
            (query.intent, query.targets.clone(), query.all),
            (Intent::Identify, vec!["lemon".to_string()], false)
        );
    }

    #[test]
    fn softest_of_a_kind_and_comparisons() {
        let query = q("Which banana is the softest?");
        assert_eq!(
            (query.intent, query.targets.clone(), query.all),
            (Intent::Extreme, vec!["banana".to_string()], false)
        );
        let query = q("Is the mango harder than the avocado?");
        assert_eq!((query.intent, query.targets.len()), (Intent::Compare, 2));
        let query = q("Tell me how hard all fruits except the kiwi are");
        assert_eq!(
            (query.intent, query.all, query.exclude.clone()),
            (Intent::Summarize, true, vec!["kiwi".to_string()])
        );
    }

    #[test]
    fn unparseable_prompts_say_why() {
        let c = FruitCatalog::builtin();
        assert_eq!(parse("   ", &c), Err(QueryError::Empty));
        let e = parse("How hard is the pineapple?", &c)
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("prompt: names no known fruit"), "{e}");
        assert!(parse(&"a".repeat(MAX_PROMPT_CHARS + 1), &c).is_err());
    }
}
