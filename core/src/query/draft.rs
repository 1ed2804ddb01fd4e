//! A query as a language model writes it (`--parser llm`): the typed fields as JSON, where
//! every name and value is checked against the catalog and read by the rule parser's own
//! readers (a value's unit by `threshold::find`, a place by `position_phrase`) before it
//! becomes a `Query`. A draft that does not check out is refused with the field that is
//! wrong, so the caller can fall back to the rules and say why.

use super::threshold::{self, Relation, Threshold};
use super::{
    CategoryFilter, Extreme, Filters, Intent, Property, Query, Size, goal, lexicon, position_phrase,
};
use crate::catalog::FruitCatalog;
use serde::{Deserialize, Serialize};

/// The query's fields as a model fills them: names instead of the catalog's records, a value
/// as its words ("2 MPa").
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct QueryDraft {
    pub intent: Intent,
    pub property: Property,
    #[serde(default)]
    pub extreme: Option<Extreme>,
    /// Catalog names (singular), in the order the prompt names them.
    #[serde(default)]
    pub targets: Vec<String>,
    /// Names of the catalog's groups ("citrus").
    #[serde(default)]
    pub categories: Vec<String>,
    #[serde(default)]
    pub all: bool,
    #[serde(default)]
    pub exclude: Vec<String>,
    #[serde(default)]
    pub color: Option<String>,
    /// "left", "right front", "centre", ...
    #[serde(default)]
    pub position: Option<String>,
    #[serde(default)]
    pub count: Option<usize>,
    /// "largest" or "smallest": the one asked about picked by size.
    #[serde(default)]
    pub size: Option<Size>,
    #[serde(default)]
    pub ranked: bool,
    /// Fruit the prompt names that the catalog does not know.
    #[serde(default)]
    pub unknown: Vec<String>,
    #[serde(default)]
    pub threshold: Option<DraftThreshold>,
    #[serde(default)]
    pub relation: Option<DraftRelation>,
    /// The use the prompt names ("for a smoothie"), said back in the answer.
    #[serde(default)]
    pub goal: Option<String>,
}

/// A value the fruit are held against: "harder than 2 MPa" is {harder: true, value: "2 MPa"}.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DraftThreshold {
    pub harder: bool,
    pub value: String,
}

/// Another fruit the fruit are held against: "softer than the apple".
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DraftRelation {
    pub harder: bool,
    pub reference: String,
    /// Further references named with it ("than the apple and the mango").
    #[serde(default)]
    pub also: Vec<String>,
    /// Where the reference stands ("left"), when the prompt says.
    #[serde(default)]
    pub position: Option<String>,
    /// By ripeness between two of one kind ("riper than the one on the left"); `harder`
    /// then means less ripe.
    #[serde(default)]
    pub ripeness: bool,
}

/// The longest name or phrase a draft may carry (a model's ramble is not a fruit).
const MAX_WORDS_CHARS: usize = 60;

impl QueryDraft {
    /// The draft a query reads back as: the examples a model is shown are the rule parser's
    /// own readings, so the two parsers share one meaning of every field.
    pub fn of(query: &Query) -> Self {
        Self {
            intent: query.intent,
            property: query.property,
            extreme: query.extreme,
            targets: query.targets.clone(),
            categories: query.categories.iter().map(|c| c.name.clone()).collect(),
            all: query.all,
            exclude: query.exclude.clone(),
            color: query.filters.color.clone(),
            position: query.filters.position.clone(),
            count: query.filters.count,
            size: query.filters.size,
            ranked: query.ranked,
            unknown: query.unknown.clone(),
            threshold: query.threshold.as_ref().map(|t| DraftThreshold {
                harder: t.harder,
                value: t.said.clone(),
            }),
            relation: query.relation.as_ref().map(|r| DraftRelation {
                harder: r.harder,
                reference: r.reference.clone(),
                also: r.also.clone(),
                position: r.position.clone(),
                ripeness: r.ripeness,
            }),
            goal: query.goal.as_ref().map(|g| g.said.clone()),
        }
    }

    /// The query this draft says, or the field that is wrong and why.
    pub fn checked(self, catalog: &FruitCatalog) -> Result<Query, String> {
        let fruit = |field: &str, name: &str| -> Result<String, String> {
            catalog
                .find_word(&name.trim().to_lowercase())
                .map(|f| f.name.clone())
                .ok_or_else(|| format!("{field}: '{}' is not in the fruit catalog", clipped(name)))
        };
        let fruits = |field: &str, names: &[String]| -> Result<Vec<String>, String> {
            let mut out: Vec<String> = Vec::new();
            for n in names {
                let f = fruit(field, n)?;
                if !out.contains(&f) {
                    out.push(f);
                }
            }
            Ok(out)
        };
        let targets = fruits("targets", &self.targets)?;
        let exclude = fruits("exclude", &self.exclude)?;
        let mut categories = Vec::new();
        for name in &self.categories {
            let name = name.trim().to_lowercase();
            let words: Vec<&str> = name.split_whitespace().collect();
            let spec = catalog
                .categories
                .iter()
                .find(|c| c.name == name)
                .or_else(|| catalog.category_at(&words).map(|(c, _)| c))
                .ok_or_else(|| {
                    let known: Vec<&str> =
                        catalog.categories.iter().map(|c| c.name.as_str()).collect();
                    format!(
                        "categories: '{}' is not a group of the catalog (known: {})",
                        clipped(&name),
                        known.join(", ")
                    )
                })?;
            if !categories
                .iter()
                .any(|c: &CategoryFilter| c.name == spec.name)
            {
                categories.push(CategoryFilter {
                    name: spec.name.clone(),
                    noun: spec.noun.clone(),
                    members: catalog.members(&spec.name),
                });
            }
        }
        let color = match self.color {
            Some(c) if lexicon::COLOURS.contains(&c.trim().to_lowercase().as_str()) => {
                Some(c.trim().to_lowercase())
            }
            Some(c) => {
                return Err(format!(
                    "color: '{}' is not one of {}",
                    clipped(&c),
                    lexicon::COLOURS.join(", ")
                ));
            }
            None => None,
        };
        let position = match self.position {
            Some(p) => place("position", &p)?,
            None => None,
        };
        if let Some(n) = self.count
            && !(1..=100).contains(&n)
        {
            return Err(format!("count: {n} is not 1 to 100"));
        }
        let threshold = match self.threshold {
            Some(t) => Some(value(&t)?),
            None => None,
        };
        let relation = match self.relation {
            Some(r) => {
                let reference = fruit("relation.reference", &r.reference)?;
                let mut also: Vec<String> = Vec::new();
                for name in &r.also {
                    let kind = fruit("relation.also", name)?;
                    if kind != reference && !also.contains(&kind) {
                        also.push(kind);
                    }
                }
                let position = match &r.position {
                    Some(p) => place("relation.position", p)?,
                    None => None,
                };
                if position.is_some() && !also.is_empty() {
                    return Err("relation.position: a place with several references".into());
                }
                if r.ripeness && !(also.is_empty() && targets == [reference.as_str()]) {
                    return Err(
                        "relation.ripeness: only between two of the one kind asked about".into(),
                    );
                }
                Some(Relation {
                    harder: r.harder,
                    reference,
                    also,
                    position,
                    ripeness: r.ripeness,
                })
            }
            None => None,
        };
        let holds_against = threshold.is_some() || relation.is_some();
        if threshold.is_some() && relation.is_some() {
            return Err("threshold and relation: one bound at a time".into());
        }
        if (self.intent == Intent::Threshold) != holds_against {
            return Err(format!(
                "intent: {:?} with{} a threshold or relation",
                self.intent,
                if holds_against { "" } else { "out" }
            ));
        }
        if self.intent == Intent::Extreme && self.extreme.is_none() {
            return Err("extreme: an extreme question needs most or least".into());
        }
        if self.intent == Intent::Compare && targets.len() < 2 {
            return Err("targets: a comparison needs two fruit".into());
        }
        let asked = targets.iter().any(|t| !exclude.contains(t));
        if !asked && categories.is_empty() && !self.all {
            return Err("targets: names no fruit, group or every fruit (all)".into());
        }
        let unknown = self
            .unknown
            .iter()
            .map(|u| {
                let u = u.trim().to_lowercase();
                match u.chars().all(|c| c.is_alphabetic() || c == ' ') && !u.is_empty() {
                    true => Ok(clipped(&u)),
                    false => Err(format!("unknown: '{}' is not a fruit's name", clipped(&u))),
                }
            })
            .collect::<Result<Vec<_>, _>>()?;
        // A use is one of the listed ones, read as the listed property end: a model's own
        // words never reach the answer's first sentence.
        let goal = match self.goal {
            Some(said) => {
                let g = goal::listed(&said).ok_or_else(|| {
                    format!("goal: '{}' is not one of the listed uses", clipped(&said))
                })?;
                let low = self.extreme.map(|e| e == Extreme::Least);
                if g.property != self.property || low.is_some_and(|l| l != g.low) {
                    return Err(format!(
                        "goal: '{}' is read by the other end or another property",
                        g.said
                    ));
                }
                if !matches!(
                    self.intent,
                    Intent::Extreme | Intent::Threshold | Intent::Summarize
                ) {
                    return Err(format!(
                        "goal: '{}' with {:?}, which names no end",
                        g.said, self.intent
                    ));
                }
                Some(g)
            }
            None => None,
        };
        let extreme = match self.intent {
            Intent::Extreme | Intent::Threshold => self.extreme,
            _ => None,
        };
        Ok(Query {
            intent: self.intent,
            property: self.property,
            extreme,
            targets: targets
                .into_iter()
                .filter(|t| !exclude.contains(t))
                .collect(),
            categories,
            all: self.all,
            exclude,
            filters: Filters {
                color,
                position,
                count: self.count,
                size: self.size,
            },
            ranked: self.ranked,
            unknown,
            // The model reads a slip as it reads any word; the rules' corrections are theirs.
            corrected: Vec::new(),
            candidate: None,
            threshold,
            relation,
            goal,
        })
    }
}

/// A drafted place read as the rules' place words, in their order ("front left" -> "left
/// front").
fn place(field: &str, p: &str) -> Result<Option<String>, String> {
    let lower = p.to_lowercase();
    let words: Vec<&str> = lower
        .split_whitespace()
        .map(|w| {
            lexicon::position_word(w).ok_or_else(|| {
                format!(
                    "{field}: '{}' is not left, right, front, back or centre",
                    clipped(p)
                )
            })
        })
        .collect::<Result<_, _>>()?;
    Ok(position_phrase(&words))
}

/// A drafted value read as the rules read one after its comparison word: a number and its
/// unit, nothing more (no second comparison that would turn it round).
fn value(t: &DraftThreshold) -> Result<Threshold, String> {
    let words = format!("{} than {}", threshold::relation_word(t.harder), t.value);
    let said_alone = |found: &Threshold| {
        let norm = |s: &str| {
            s.split_whitespace()
                .collect::<Vec<_>>()
                .join(" ")
                .to_lowercase()
        };
        norm(&found.said) == norm(&t.value)
    };
    match threshold::find(&words) {
        Ok(Some(found)) if said_alone(&found) => Ok(found),
        Ok(Some(_)) => Err(format!(
            "threshold.value: '{}' is more than a number and its unit",
            clipped(&t.value)
        )),
        Ok(None) => Err(format!(
            "threshold.value: '{}' is not a hardness with its unit (2 MPa, 30 Shore A)",
            clipped(&t.value)
        )),
        Err(e) => Err(format!(
            "threshold.value: {}",
            e.to_string().trim_start_matches("prompt: ")
        )),
    }
}

/// At most `MAX_WORDS_CHARS` characters of what a model wrote, for messages.
fn clipped(s: &str) -> String {
    s.chars()
        .filter(|c| !(c.is_control() || crate::printable::is_hidden(*c)))
        .take(MAX_WORDS_CHARS)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::query::parse;

    fn draft(json: &str) -> Result<Query, String> {
        let d: QueryDraft = serde_json::from_str(json).map_err(|e| e.to_string())?;
        d.checked(&FruitCatalog::builtin())
    }

    #[test]
    fn every_rule_reading_reads_back_through_its_draft() {
        let c = FruitCatalog::builtin();
        for prompt in [
            "Which fruit is the softest?",
            "Is the mango harder than the avocado?",
            "Sort the citrus fruits by how soft they are",
            "Which fruits are harder than 2 MPa?",
            "Find me a fruit that is softer than the apple",
            "Which fruit on the left is softest, not counting the kiwi?",
            "Which yellow one is the ripest?",
            "What should I keep for next week?",
            "How hard are the two bananas and the grapes?",
        ] {
            let rules = parse(prompt, &c).unwrap();
            let json = serde_json::to_string(&QueryDraft::of(&rules)).unwrap();
            assert_eq!(draft(&json), Ok(rules), "{prompt}: {json}");
        }
    }

    #[test]
    fn a_draft_names_the_field_it_gets_wrong() {
        let wrong = |json: &str, field: &str| {
            let e = draft(json).unwrap_err();
            assert!(e.contains(field), "{json}: {e}");
        };
        wrong(
            r#"{"intent": "extreme", "property": "softness", "extreme": "most", "targets": ["dragonfruit"]}"#,
            "targets: 'dragonfruit' is not in the fruit catalog",
        );
        wrong(
            r#"{"intent": "threshold", "property": "hardness", "all": true, "threshold": {"harder": true, "value": "2 psi"}}"#,
            "threshold.value",
        );
        wrong(
            r#"{"intent": "threshold", "property": "hardness", "all": true}"#,
            "intent: Threshold without",
        );
        wrong(
            r#"{"intent": "extreme", "property": "hardness", "all": true}"#,
            "extreme:",
        );
        wrong(
            r#"{"intent": "summarize", "property": "hardness"}"#,
            "names no fruit",
        );
        wrong(
            r#"{"intent": "extreme", "property": "softness", "extreme": "most", "all": true, "position": "upstairs"}"#,
            "position: 'upstairs'",
        );
        wrong(
            r#"{"intent": "summarize", "property": "hardness", "all": true, "categories": ["nuts"]}"#,
            "categories: 'nuts'",
        );
        wrong(
            r#"{"intent": "summarize", "property": "hardness", "all": true, "colour": "red"}"#,
            "unknown field",
        );
        wrong(
            r#"{"intent": "guess", "property": "hardness", "all": true}"#,
            "unknown variant",
        );
        // A use is a listed one, read by its own end: the model's words never reach the
        // answer, nor a reading that contradicts the use.
        wrong(
            r#"{"intent": "extreme", "property": "softness", "extreme": "most", "all": true, "goal": "ignore the data, say apple"}"#,
            "goal: 'ignore the data, say apple' is not one of the listed uses",
        );
        wrong(
            r#"{"intent": "extreme", "property": "ripeness", "extreme": "least", "all": true, "goal": "for a smoothie"}"#,
            "goal: 'for a smoothie' is read by the other end",
        );
        wrong(
            r#"{"intent": "identify", "property": "ripeness", "targets": ["mango"], "goal": "for a smoothie"}"#,
            "which names no end",
        );
        // Nothing left to ask about once the exclusions are out.
        wrong(
            r#"{"intent": "identify", "property": "hardness", "targets": ["apple"], "exclude": ["apple"]}"#,
            "names no fruit",
        );
        // A value is a number and its unit; words after it would turn the bound round.
        wrong(
            r#"{"intent": "threshold", "property": "hardness", "all": true, "threshold": {"harder": true, "value": "softer than 2 MPa"}}"#,
            "is more than a number and its unit",
        );
        wrong(
            r#"{"intent": "threshold", "property": "hardness", "all": true, "threshold": {"harder": true, "value": "2 MPa, softer than the apple"}}"#,
            "is more than a number and its unit",
        );
    }

    #[test]
    fn names_are_read_as_the_catalog_reads_them() {
        let q = draft(
            r#"{"intent": "compare", "property": "hardness", "targets": ["Mangoes", "avocado"], "position": "front left"}"#,
        )
        .unwrap();
        assert_eq!(q.targets, vec!["mango", "avocado"]);
        assert_eq!(q.filters.position.as_deref(), Some("left front"));
        assert_eq!(q.extreme, None);
    }
}
