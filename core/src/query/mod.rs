//! Prompt -> `Query`: rule-based, offline. Says clearly when a prompt cannot be grounded.

pub mod draft;
pub mod goal;
pub mod lexicon;
pub mod llm_prompt;
pub mod reader;
pub mod spelling;
pub mod threshold;

// The stage's face beside `Query` and `parse`: the reader trait a model may stand behind.
pub use reader::{PromptReader, ReadPrompt, RuleReader};

use crate::catalog::FruitCatalog;
use lexicon::Degree;
use serde::{Deserialize, Serialize};

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
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
    /// The objects past a value ("Which fruits are harder than 2 MPa?"), in `threshold`.
    Threshold,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Property {
    Hardness,
    Softness,
    Ripeness,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Extreme {
    Most,
    Least,
}

/// Qualifiers that narrow which objects a query is about.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Filters {
    /// A colour the object must show ("the yellow one"), one of `lexicon::COLOURS`.
    pub color: Option<String>,
    /// Position words the object's location must contain, in `explain::location_words`
    /// order: "left", "front", "left front", "centre".
    pub position: Option<String>,
    /// How many objects the prompt expects ("both bananas", "the two limes").
    pub count: Option<usize>,
    /// The one of those asked about that shows the camera the most or least ("the bigger
    /// lime", "the smallest of the apples").
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub size: Option<Size>,
}

/// Which end of size the prompt picks an object by.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Size {
    Largest,
    Smallest,
}

impl Size {
    /// As the typed query and `parse` say it.
    pub fn name(self) -> &'static str {
        match self {
            Size::Largest => "largest",
            Size::Smallest => "smallest",
        }
    }
}

/// A group of the catalog the prompt names ("the citrus fruits"), with its kinds.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CategoryFilter {
    pub name: String,
    /// How an answer names one of the group (the catalog's `noun`): "citrus fruit", "berry".
    pub noun: String,
    /// Catalog names (singular) of its kinds.
    pub members: Vec<String>,
}

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Query {
    pub intent: Intent,
    pub property: Property,
    pub extreme: Option<Extreme>,
    /// Catalog names (singular) the prompt names, in the order named.
    pub targets: Vec<String>,
    /// Groups of the catalog the prompt names ("citrus"): their kinds are asked about as the
    /// targets are.
    pub categories: Vec<CategoryFilter>,
    /// The prompt is about every fruit on the table ("which fruit", "all fruits"), or every
    /// one the filters keep.
    pub all: bool,
    pub exclude: Vec<String>,
    pub filters: Filters,
    /// The answer should order the objects ("rank the fruits from softest to hardest").
    pub ranked: bool,
    /// Fruits the prompt names that the catalog does not know ("pineapple").
    pub unknown: Vec<String>,
    /// The kind a yes/no question holds up to every fruit ("Is the banana the softest?",
    /// "Is the banana softer than the others?"): the extreme is over every fruit, and the
    /// answer says whether it is of this kind.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub candidate: Option<String>,
    /// Typing slips of fruit names read as the catalog's ("bananna" as banana), said back.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub corrected: Vec<spelling::Correction>,
    /// A value the objects are held against ("harder than 2 MPa"), for `Intent::Threshold`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub threshold: Option<threshold::Threshold>,
    /// Another object the objects are held against ("softer than the apple"), for
    /// `Intent::Threshold`: its value is its measured hardness.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub relation: Option<threshold::Relation>,
    /// What the fruit is wanted for ("for a smoothie"), when no property is named: it sets
    /// the property and end asked for, and the answer says it back.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub goal: Option<goal::Goal>,
}

#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum QueryError {
    #[error("prompt: empty; ask e.g. \"Which fruit is the softest?\"")]
    Empty,
    #[error("prompt: names no known fruit in \"{prompt}\" (known: {known})")]
    NoTarget { prompt: String, known: String },
    #[error("prompt: '{name}' is not in the fruit catalog (known: {known})")]
    UnknownFruit { name: String, known: String },
    #[error("prompt: over {max} characters")]
    TooLong { max: usize },
    #[error("prompt: hardness value '{value}': {message}")]
    BadThreshold { value: String, message: String },
    #[error("prompt: {what} is not read yet; {instead}")]
    Unsupported { what: String, instead: String },
}

pub const MAX_PROMPT_CHARS: usize = 2000;

/// Marks a break between list items (",", ";", ":", "/", "&") among the words.
const BREAK: &str = "|";

/// Lower-cased words with the lexicon's phrases rewritten ("ready to eat" -> "ripe"), and
/// whether each is followed by a list break ("lime, orange, apple": "orange" ends an item).
fn words_of(prompt: &str) -> (Vec<String>, Vec<bool>) {
    let spaced: String = prompt
        .to_lowercase()
        .chars()
        .map(lexicon::unaccented)
        .map(|c| match c {
            c if c.is_alphanumeric() => c.to_string(),
            ',' | ';' | ':' | '/' | '&' => format!(" {BREAK} "),
            _ => " ".into(),
        })
        .collect();
    let mut text = format!(
        " {} ",
        spaced.split_whitespace().collect::<Vec<_>>().join(" ")
    );
    for (phrase, with) in lexicon::PHRASES {
        text = text.replace(&format!(" {phrase} "), &format!(" {with} "));
    }
    let (mut words, mut breaks) = (Vec::new(), Vec::new());
    for w in text.split_whitespace() {
        if w == BREAK {
            if let Some(b) = breaks.last_mut() {
                *b = true;
            }
        } else {
            words.push(w.to_string());
            breaks.push(false);
        }
    }
    (words, breaks)
}

/// Words a quantifier may look past to reach its noun ("all of the three ripe bananas").
const LOOK_PAST: &[&str] = &[
    "the", "of", "these", "those", "my", "your", "ripe", "unripe",
];

/// The prompt trimmed, or why no parser reads it: empty, or over `MAX_PROMPT_CHARS`.
pub fn checked_prompt(prompt: &str) -> Result<&str, QueryError> {
    let trimmed = prompt.trim();
    if trimmed.is_empty() {
        return Err(QueryError::Empty);
    }
    if trimmed.chars().count() > MAX_PROMPT_CHARS {
        return Err(QueryError::TooLong {
            max: MAX_PROMPT_CHARS,
        });
    }
    Ok(trimmed)
}

pub fn parse(prompt: &str, catalog: &FruitCatalog) -> Result<Query, QueryError> {
    let trimmed = checked_prompt(prompt)?;
    let threshold = threshold::find(trimmed)?;
    let (words, breaks) = words_of(trimmed);
    let (words, corrected) = spelling::corrected(words, catalog);
    let at = |i: usize| words.get(i).map(String::as_str);
    let is_fruit = |w: &str| catalog.find_word(w).is_some();
    let is_noun = |w: &str| is_fruit(w) || lexicon::GENERIC_NOUNS.contains(&w);
    // The first noun after position i, looking past articles, counts and colours.
    let noun_after = |i: usize| -> Option<&str> {
        words[i + 1..]
            .iter()
            .map(String::as_str)
            .take(4)
            .find(|w| {
                !(LOOK_PAST.contains(w)
                    || lexicon::count_word(w).is_some()
                    || lexicon::COLOURS.contains(w))
            })
            .filter(|w| is_noun(w))
    };
    let has = |set: &[&str]| words.iter().any(|w| set.contains(&w.as_str()));

    let mut targets: Vec<String> = Vec::new();
    let mut categories: Vec<CategoryFilter> = Vec::new();
    // Words already read as part of a category's phrase ("stone fruits").
    let mut consumed_until = 0;
    let mut exclude: Vec<String> = Vec::new();
    let mut unknown: Vec<String> = Vec::new();
    let mut filters = Filters::default();
    let mut positions: Vec<&str> = Vec::new();
    let mut excluding = false;
    let mut relation: Option<threshold::Relation> = None;
    // The word after the last reference and its place ("than the apple| and the mango").
    let mut reference_end = 0;
    // Where the reference stands ("than the left banana", "than the banana on the left").
    let mut reference_positions: Vec<&str> = Vec::new();
    // "riper than the mango": a fruit held against another kind's ripeness.
    let mut ripeness_reference: Option<String> = None;
    let mut generic = false;
    // "all", "every", "fruits": a summary; "the fruit on the left", "the yellow one": one.
    let mut generic_plural = false;
    let mut plural = false;
    // (property, degree, points to the low end)
    let mut properties: Vec<(Property, Degree, bool)> = Vec::new();
    // "as hard as the mango": a comparison of equals.
    let mut as_much = false;
    for (i, w) in words.iter().enumerate() {
        let w = w.as_str();
        let prev = if i > 0 { at(i - 1) } else { None };
        if i < consumed_until {
            continue;
        }
        if lexicon::EXCLUDING.contains(&w) {
            excluding = true;
            continue;
        }
        if lexicon::COLOUR_COMPARATIVES.contains(&w) {
            return Err(QueryError::Unsupported {
                what: format!("colour held against colour ('{w}')"),
                instead: "ask how ripe or how hard, e.g. \"Is the apple riper than the banana?\""
                    .into(),
            });
        }
        // "the second banana", "the first one": an instance by count.
        if lexicon::ORDINALS.contains(&w)
            && words[i + 1..].iter().take(2).any(|n| {
                (is_noun(n) && n != "fruit")
                    || n == "ones"
                    || (w != "last"
                        && lexicon::property_word(n)
                            .is_some_and(|p| p.degree == Degree::Superlative))
            })
        {
            return Err(QueryError::Unsupported {
                what: format!("a fruit picked by count ('{w}')"),
                instead: "tell them apart by place, e.g. \"Is the banana on the left riper than the one on the right?\"".into(),
            });
        }
        let rest: Vec<&str> = words[i..].iter().take(3).map(String::as_str).collect();
        if let Some((category, n)) = catalog.category_at(&rest) {
            // "Which non-citrus fruit ...?", "a fruit that isn't citrus": read as the group
            // itself it answered about the citrus.
            if !excluding && prev.is_some_and(lexicon::negates) {
                return Err(QueryError::Unsupported {
                    what: format!(
                        "a group turned around by '{}'",
                        if prev == Some("t") {
                            "not"
                        } else {
                            prev.unwrap_or_default()
                        }
                    ),
                    instead: format!(
                        "say \"except the {} fruits\", e.g. \"Which fruit except the {} fruits is the softest?\"",
                        category.name, category.name
                    ),
                });
            }
            // "softer than the citrus fruits": a group to hold against is not read yet.
            if threshold::comparison_before(&words, i).is_some()
                || (relation.is_some()
                    && reference_end > 0
                    && joins_references(&words, &breaks, reference_end, i, is_fruit))
            {
                return Err(QueryError::Unsupported {
                    what: format!("holding fruit against a group ({})", category.name),
                    instead: "name the fruit to hold against, e.g. \"softer than the lime and the lemon\"".into(),
                });
            }
            consumed_until = i + n;
            let members = catalog.members(&category.name);
            if excluding {
                for m in members {
                    if !exclude.contains(&m) {
                        exclude.push(m);
                    }
                }
            } else if !categories.iter().any(|c| c.name == category.name) {
                categories.push(CategoryFilter {
                    name: category.name.clone(),
                    noun: category.noun.clone(),
                    members,
                });
            }
            let last = rest[n - 1];
            plural |= !excluding && last.ends_with('s') && !last.ends_with("us");
            continue;
        }
        if lexicon::COLOURS.contains(&w) {
            // A fruit name is a fruit before it is a colour: in a list ("mango, lime, orange,
            // apple", "the lime orange and apple") it is one of the items.
            let listed = is_fruit(w)
                && (breaks[i] || prev.is_some_and(is_fruit) || (i > 0 && breaks[i - 1]));
            let names_noun = !breaks[i]
                && at(i + 1).is_some_and(|n| is_noun(n) || lexicon::COLOURS.contains(&n));
            // "the orange" is the fruit, "the orange one" a colour. "Is the banana green?"
            // asks about ripeness; "the green apple" filters by colour.
            if names_noun && !listed {
                filters.color.get_or_insert_with(|| w.to_string());
                continue;
            }
            if w == "green" {
                // "the least green" is the ripest, as "the least ripe" is the greenest.
                let (degree, flipped) = match prev {
                    Some("most") => (Degree::Superlative, false),
                    Some("least") => (Degree::Superlative, true),
                    Some("more") => (Degree::Comparative, false),
                    Some("less") => (Degree::Comparative, true),
                    _ => (Degree::Base, false),
                };
                properties.push((Property::Ripeness, degree, !flipped));
                continue;
            }
            if !is_fruit(w) {
                filters.color.get_or_insert_with(|| w.to_string());
                continue;
            }
        }
        if let Some(f) = catalog.find_word(w) {
            if let Some(less_ripe) = threshold::ripeness_comparison_before(&words, i) {
                // "Is the banana on the left riper than the banana on the right?": two of
                // one kind, held against each other as "softer than" is.
                if relation.is_none() && threshold.is_none() && targets == [f.name.as_str()] {
                    let (r, places, end) = relation_at(&words, i, (less_ripe, true), &f.name);
                    relation = Some(r);
                    reference_positions.extend(places);
                    (consumed_until, reference_end) = (consumed_until.max(end), end);
                    continue;
                }
                ripeness_reference.get_or_insert_with(|| f.name.clone());
            }
            // "softer than the apple": the apple is what the others are held against.
            if let Some(harder) = threshold::comparison_before(&words, i) {
                // "softer than the mango but harder than the banana", "softer than the apple
                // and harder than 1 MPa": one bound at a time, as for values.
                // "softer than the apple and softer than the mango": the same bound, twice.
                if let Some(r) = relation.as_mut()
                    && r.harder == harder
                    && r.position.is_none()
                    && reference_positions.is_empty()
                    && threshold.is_none()
                    && place_after(&words, i + 1).is_none()
                {
                    if f.name != r.reference && !r.also.contains(&f.name) {
                        r.also.push(f.name.clone());
                    }
                    reference_end = i + 1;
                    continue;
                }
                if let Some(first) = relation.as_ref().map(|r| format!("the {}", r.reference)) {
                    return Err(second_bound(&f.name, &first));
                }
                if let Some(t) = &threshold {
                    return Err(second_bound(&f.name, &t.said));
                }
                let (r, places, end) = relation_at(&words, i, (harder, false), &f.name);
                relation = Some(r);
                reference_positions.extend(places);
                (consumed_until, reference_end) = (consumed_until.max(end), end);
                continue;
            }
            // "softer than the apple and the mango", "than the lime, the kiwi and the
            // tomato": a further reference, past which the fruit must be too; "or" leaves open
            // which one, so it is refused. A list after a comma that ends in "or" names the
            // fruit asked about ("Which is softer than the lime, the banana or the tomato?").
            if let Some(r) = relation.as_mut()
                && reference_end > 0
                && joins_references(&words, &breaks, reference_end, i, is_fruit)
            {
                let value = format!("the {}", f.name);
                if words[reference_end..i].iter().any(|w| w == "or") {
                    return Err(QueryError::BadThreshold {
                        value,
                        message: format!(
                            "'or' leaves open which fruit to hold against: say 'the {} and the {}' for both, or ask about one",
                            r.reference, f.name
                        ),
                    });
                }
                if !reference_positions.is_empty()
                    || place_after(&words, i + 1).is_some()
                    || words[reference_end..i]
                        .iter()
                        .any(|w| lexicon::position_word(w).is_some())
                {
                    return Err(QueryError::BadThreshold {
                        value,
                        message:
                            "a place beside several fruit to hold against: ask about one at a time"
                                .into(),
                    });
                }
                if f.name != r.reference && !r.also.contains(&f.name) {
                    r.also.push(f.name.clone());
                }
                reference_end = i + 1;
                continue;
            }
            let list = if excluding {
                &mut exclude
            } else {
                &mut targets
            };
            if !list.contains(&f.name) {
                list.push(f.name.clone());
            }
            plural |= !excluding && w != f.name && w.ends_with('s');
            continue;
        }
        if lexicon::OTHER_FRUITS.contains(&w) {
            let name = lexicon::singular(w);
            // "softer than the pineapple", "than the apple and the pineapple": there is
            // nothing to hold the fruit against.
            if threshold::comparison_before(&words, i).is_some()
                || (relation.is_some()
                    && reference_end > 0
                    && joins_references(&words, &breaks, reference_end, i, is_fruit))
            {
                return Err(QueryError::UnknownFruit {
                    name,
                    known: catalog.names().join(", "),
                });
            }
            if !unknown.contains(&name) {
                unknown.push(name);
            }
            continue;
        }
        // "Which banana is softer than the one on the left?": "one" after a comparison
        // stands for the one kind asked about.
        if w == "one"
            && relation.is_none()
            && threshold.is_none()
            && categories.is_empty()
            && let [kind] = targets.as_slice()
            && let Some((harder, ripeness)) = threshold::any_comparison_before(&words, i)
        {
            let (r, places, end) = relation_at(&words, i, (harder, ripeness), kind);
            relation = Some(r);
            reference_positions.extend(places);
            (consumed_until, reference_end) = (consumed_until.max(end), end);
            continue;
        }
        if lexicon::GENERIC.contains(&w) {
            // "softer than the fruit on the left", "than the yellow one": a reference named
            // by place or colour alone read as the softest fruit there.
            if relation.is_none()
                && threshold.is_none()
                && !(w == "one" && targets.len() == 1)
                // "softer than the others" is the softest, as it read before.
                && prev != Some("other")
                && w != "others"
                && !noun_after(i).is_some_and(is_fruit)
                && threshold::any_comparison_before(&words, i).is_some()
            {
                return Err(QueryError::Unsupported {
                    what: format!(
                        "a fruit to hold against not named by its kind ('than the ... {w}')"
                    ),
                    instead: "name it, e.g. \"softer than the banana on the left\"".into(),
                });
            }
            // "kiwi fruit", "all bananas", "one of the limes": the word belongs to a fruit
            // name, not to every fruit.
            let after_fruit = prev.is_some_and(is_fruit);
            let quantifies_fruit = noun_after(i).is_some_and(is_fruit);
            if !(after_fruit || quantifies_fruit) {
                generic = true;
                generic_plural |= !matches!(w, "fruit" | "object" | "item" | "thing" | "one");
            }
            continue;
        }
        if let Some(n) = lexicon::count_word(w) {
            // "than both the apple and the mango" counts the references, not the fruit asked.
            let of_references =
                prev == Some("than") || (prev == Some("the") && i >= 2 && words[i - 2] == "than");
            if !of_references && (noun_after(i).is_some() || w == "both") {
                filters.count.get_or_insert(n);
            }
            continue;
        }
        // "the bigger lime", "the smallest of the apples", "the big one": one object by size
        // ("bigger than the apple" compares sizes, which the twin does not answer).
        if let Some(size) = lexicon::size_word(w) {
            let compares = at(i + 1) == Some("than");
            // "the small fruits" describes them, it does not pick one: a base size word
            // before a plural picks nothing.
            let base = matches!(w, "big" | "large" | "huge" | "small" | "little" | "tiny");
            let picks = at(i + 1).is_some_and(|n| {
                let plural = lexicon::singular(n) != n;
                n == "of"
                    || n == "one"
                    || (is_noun(n) && !(base && plural))
                    || lexicon::COLOURS.contains(&n)
            });
            if compares {
                return Err(QueryError::Unsupported {
                    what: format!("size against another fruit ('{w} than')"),
                    instead: "ask how hard, soft or ripe the fruit are".into(),
                });
            }
            // "harder than the smaller apple": the reference picked by size is not read (the
            // size would pick among the fruit asked about, and answer about one).
            if picks && threshold::any_comparison_before(&words, i).is_some() {
                return Err(QueryError::Unsupported {
                    what: format!("a fruit to hold against picked by size ('than the {w}')"),
                    instead: "tell them apart by place, e.g. \"Is the apple on the left harder than the one on the right?\"".into(),
                });
            }
            if picks {
                filters.size.get_or_insert(size);
            }
            continue;
        }
        if let Some(p) = lexicon::position_word(w) {
            // "left" and "right" are positions only in place ("on the left", "the right
            // one", "leftmost"): "is that right?" is not.
            let placed = !matches!(w, "left" | "right")
                || prev.is_some_and(|p| {
                    matches!(
                        p,
                        "the" | "on" | "to" | "at" | "far" | "most" | "your" | "my"
                    ) || lexicon::position_word(p).is_some()
                })
                || at(i + 1).is_some_and(|n| n == "side" || is_noun(n));
            // "than the left banana": the reference's place.
            let of_reference = (i + 1..words.len().min(i + 3))
                .find(|&j| is_fruit(&words[j]) || words[j] == "one")
                .is_some_and(|j| threshold::any_comparison_before(&words, j).is_some());
            // "Is the left banana harder than the right?": a bare place after the comparison
            // is the one there of the kind asked about.
            let bare = !of_reference
                && relation.is_none()
                && threshold.is_none()
                && categories.is_empty()
                && !at(i + 1).is_some_and(|n| is_noun(n) || n == "one");
            if bare
                && let [kind] = targets.as_slice()
                && let Some((harder, ripeness)) = threshold::any_comparison_before(&words, i)
            {
                let (r, _, end) = relation_at(&words, i, (harder, ripeness), kind);
                relation = Some(r);
                reference_positions.push(p);
                reference_end = end;
                continue;
            }
            if of_reference {
                reference_positions.push(p);
            } else if placed && !positions.contains(&p) {
                positions.push(p);
            }
            continue;
        }
        if let Some(pw) = lexicon::property_word(w) {
            // "Which fruit is not soft?" read as the softest; "not softer than" is read
            // where the comparison is.
            // "not the softest", "isn't too hard": a negation a few filler words back.
            let negated = words[..i]
                .iter()
                .rev()
                .take(4)
                .find(|w| {
                    !matches!(
                        w.as_str(),
                        "the" | "too" | "so" | "very" | "most" | "least" | "quite" | "really"
                    )
                })
                .is_some_and(|w| lexicon::negates(w));
            if negated && at(i + 1) != Some("than") {
                return Err(QueryError::Unsupported {
                    what: format!("a property turned around ('not {w}')"),
                    instead: "ask for its opposite, e.g. \"Which fruit is the hardest?\" for \"not soft\"".into(),
                });
            }
            // "as hard as the mango" compares the two, as "harder than" does.
            let as_as = prev == Some("as")
                && at(i + 1) == Some("as")
                && words[i + 2..].iter().take(3).any(|w| is_fruit(w));
            as_much |= as_as;
            let (degree, flipped) = match (pw.degree, prev) {
                (Degree::Base, _) if as_as => (Degree::Comparative, false),
                (Degree::Base, Some("most")) => (Degree::Superlative, false),
                (Degree::Base, Some("least")) => (Degree::Superlative, true),
                (Degree::Base, Some("more")) => (Degree::Comparative, false),
                (Degree::Base, Some("less")) => (Degree::Comparative, true),
                (d, _) => (d, false),
            };
            properties.push((pw.property, degree, pw.inverted ^ flipped));
        }
    }
    // "Which banana is riper, the left or the right one?": a choice between the two places
    // picks among the kind at either, not the one at the first.
    if targets.len() == 1
        && relation.is_none()
        && words.iter().any(|w| w == "or")
        && matches!(
            positions.as_slice(),
            ["left", "right"] | ["right", "left"] | ["front", "back"] | ["back", "front"]
        )
    {
        positions.clear();
    }
    // "Which fruit for a smoothie?": the use names the property when no word does, and is
    // read as its superlative ("the ripest").
    let goal = properties.is_empty().then(|| goal::find(&words)).flatten();
    if properties.is_empty()
        && let Some(d) = goal::denied(&words)
    {
        return Err(QueryError::Unsupported {
            what: format!("a use turned around ('{}' ... '{}')", d.by, d.said),
            instead: format!(
                "ask for the fruit that suits it, e.g. \"Which fruit is best {}?\", or name the property, e.g. \"Which fruit is the {}?\"",
                d.said, d.opposite
            ),
        });
    }
    if let Some(g) = &goal {
        properties.push((g.property, Degree::Superlative, g.low));
    }
    // "Which fruit is softer than the?": a comparison that names nothing to hold against
    // would otherwise read as the softest.
    if let Some(t) = words.iter().rposition(|w| w == "than")
        && words[t + 1..].iter().all(|w| {
            matches!(
                w.as_str(),
                "the" | "a" | "an" | "that" | "this" | "my" | "your" | BREAK
            )
        })
    {
        return Err(QueryError::BadThreshold {
            value: words[t..].join(" "),
            message: "names nothing to hold the fruit against; say e.g. 'softer than 2 MPa' or 'softer than the apple'".into(),
        });
    }
    // "Is the mango harder than the avocado?" compares two named fruit, the reference one of
    // them; "Which apple is softer than the lime?" holds the named ones against it.
    let yes_no = words.first().is_some_and(|w| {
        matches!(
            w.as_str(),
            "is" | "are" | "was" | "does" | "do" | "can" | "isn" | "aren" | "wasn"
        )
    });
    // "Is the banana on the right softer than the banana on the left?": two of one kind, told
    // apart by place, stay the fruit asked about (at its place) held against the one at the
    // reference's place.
    let same_kind = relation
        .as_ref()
        .is_some_and(|r| targets.len() == 1 && targets[0] == r.reference && r.also.is_empty());
    // "Is the left banana harder than the other one?": the other is across the table.
    if same_kind && reference_positions.is_empty() {
        reference_positions.extend(positions.iter().filter_map(|p| match *p {
            "left" => Some("right"),
            "right" => Some("left"),
            "front" => Some("back"),
            "back" => Some("front"),
            _ => None,
        }));
        // "Is the middle banana harder than the other one?": no place across from it.
        if !positions.is_empty() && reference_positions.is_empty() {
            return Err(QueryError::Unsupported {
                what: format!(
                    "'the other' beside the {} at the {}",
                    targets[0],
                    positions.join(" ")
                ),
                instead: format!(
                    "say where the other stands, e.g. \"than the {} on the left\"",
                    targets[0]
                ),
            });
        }
    }
    let same_kind_by_place = same_kind && !reference_positions.is_empty();
    // "Is the big apple softer than the other one?": a size picks one among the fruit asked
    // about, and the other would be the same apple.
    // "Is the green banana riper than the brown one?": the colour filter would keep the
    // green one alone, and the comparison have nothing to hold it against.
    if same_kind && let Some(colour) = &filters.color {
        return Err(QueryError::Unsupported {
            what: format!("two {}s told apart by colour ('{colour}')", targets[0]),
            instead: format!(
                "tell them apart by place, e.g. \"Is the {0} on the left riper than the one on the right?\"",
                targets[0]
            ),
        });
    }
    if same_kind && filters.size.is_some() {
        return Err(QueryError::Unsupported {
            what: format!("two {}s told apart by size", targets[0]),
            instead: format!(
                "tell them apart by place, e.g. \"Is the {0} on the left harder than the one on the right?\"",
                targets[0]
            ),
        });
    }
    // A place on either side of a yes/no question about two kinds ("Is the left banana
    // softer than the lime?", "Is the lime harder than the banana on the left?") is that
    // side's alone: it stays a relation, whose reference the place filter leaves alone (as a
    // comparison of the two, the place filtered the lime away).
    let placed = !positions.is_empty() || !reference_positions.is_empty();
    if let Some(r) =
        relation.take_if(|_| yes_no && !targets.is_empty() && !same_kind_by_place && !placed)
    {
        // A yes/no question against several ("Is the banana harder than both the tomato
        // and the avocado?") would answer about the first alone.
        if let Some(other) = r.also.first() {
            return Err(QueryError::Unsupported {
                what: format!(
                    "a yes/no comparison with the {} and the {other}",
                    r.reference
                ),
                instead: format!(
                    "ask e.g. \"Which fruit is {} than the {} and the {other}?\"",
                    r.relation(),
                    r.reference
                ),
            });
        }
        targets.push(r.reference);
    }
    // "Is the banana riper than the mango?" compares; "Which fruit is riper than the
    // banana?" would hold every fruit against one, which is not read yet.
    if let Some(name) = ripeness_reference
        && !yes_no
    {
        return Err(QueryError::Unsupported {
            what: format!("ripeness against another fruit (than the {name})"),
            instead:
                "ask e.g. \"Which fruit is the ripest?\" or \"Is the mango riper than the banana?\""
                    .into(),
        });
    }
    targets.retain(|t| !exclude.contains(t));
    filters.position = position_phrase(&positions);
    if let Some(r) = relation.as_mut() {
        r.position = position_phrase(&reference_positions);
    }

    let known = || catalog.names().join(", ");
    let filtered = filters.color.is_some() || filters.position.is_some();
    // "Is anything harder than 2 MPa?", "What should I keep for next week?": a value or a
    // use with nothing named is about every fruit.
    // "What's ripe?", "Which is softest?": a question word and a property, nothing named.
    let asks_which = words
        .first()
        .is_some_and(|w| matches!(w.as_str(), "what" | "whats" | "which"))
        && !properties.is_empty();
    let all = generic
        || !exclude.is_empty()
        || (targets.is_empty()
            && (filtered
                || ((threshold.is_some() || relation.is_some() || goal.is_some() || asks_which)
                    && categories.is_empty()
                    && unknown.is_empty())));
    if targets.is_empty() && categories.is_empty() && !all {
        return Err(match unknown.first() {
            Some(name) => QueryError::UnknownFruit {
                name: name.clone(),
                known: known(),
            },
            None => QueryError::NoTarget {
                prompt: trimmed.to_string(),
                known: known(),
            },
        });
    }

    let superlatives = properties
        .iter()
        .filter(|p| p.1 == Degree::Superlative)
        .count();
    let ranked = has(lexicon::RANKING)
        || (has(&["list"]) && has(&["by"]))
        || (superlatives >= 2 && has(&["from"]) && has(&["to"]));
    // The property and direction come from the first property word: "from softest to
    // hardest" ranks by softness.
    // A superlative names what is asked before a passing word ("Don't press too hard:
    // which fruit is softest?").
    let (mut property, _, flipped) = properties
        .iter()
        .find(|p| p.1 == Degree::Superlative && !ranked)
        .or(properties.first())
        .copied()
        .unwrap_or((Property::Hardness, Degree::Base, false));
    if let Some(harder) = threshold
        .as_ref()
        .map(|t| t.harder)
        // Ripeness within one kind is worded as ripeness ("Is the left banana riper ...?").
        .or(relation.as_ref().filter(|r| !r.ripeness).map(|r| r.harder))
    {
        property = if harder {
            Property::Hardness
        } else {
            Property::Softness
        };
    }
    let comparative = properties.iter().any(|p| p.1 == Degree::Comparative);
    // "Which avocado is ready to eat?", "which one is soft?": selects one, as the
    // superlative does; "which fruits are ripe?" asks about each.
    let selects = words.first().is_some_and(|w| w == "which")
        && !properties.is_empty()
        && !(plural || generic_plural);
    let superlative = superlatives > 0 || selects;
    let intent = if threshold.is_some() || relation.is_some() {
        Intent::Threshold
    } else if ranked {
        Intent::Summarize
    } else if (comparative || has(lexicon::COMPARING)) && targets.len() >= 2 {
        Intent::Compare
    } else if superlative || comparative {
        // "Which of the two bananas is softer?" picks one of a kind.
        Intent::Extreme
    } else if generic_plural
        || !exclude.is_empty()
        || targets.len() > 1
        || plural
        || filters.count.is_some_and(|n| n > 1)
        // "Describe the avocado", "tell me how firm the avocado is": one object is identified.
        || (has(lexicon::SUMMARISING) && (targets.len() != 1 || generic))
    {
        Intent::Summarize
    } else {
        Intent::Identify
    };
    let mut extreme = (intent == Intent::Extreme).then_some(if flipped {
        Extreme::Least
    } else {
        Extreme::Most
    });
    // "the softest fruit harder than 2 MPa": the value narrows, the superlative picks one
    // (unless the fruit past it are ranked, "from hardest to softest").
    if intent == Intent::Threshold
        && !ranked
        && let Some(&(p, _, low)) = properties.iter().find(|p| p.1 == Degree::Superlative)
    {
        property = p;
        extreme = Some(if low { Extreme::Least } else { Extreme::Most });
    }
    // Named kinds bound an extreme, a comparison or an identification ("which fruit is
    // softer, the kiwi or the peach"); a summary may add "all other fruits" to named ones.
    let mut all =
        all && (matches!(intent, Intent::Summarize | Intent::Threshold) || targets.is_empty());
    // "Is the banana the softest?", "Is the banana softer than the others?": the fruit named
    // before the property word, and no fruit after it ("Is the banana the softest banana?"
    // stays among the bananas), is held up to every fruit. A place, colour, count, size or
    // group would pick among instances, which this reading does not.
    let first_property = words
        .iter()
        .position(|w| lexicon::property_word(w).is_some());
    // "softer than the others": every other fruit, as a superlative is.
    let than_others = words
        .windows(3)
        .any(|w| w[0] == "than" && w[1] == "the" && matches!(w[2].as_str(), "others" | "other"));
    let candidate = match (intent, targets.as_slice(), first_property) {
        (Intent::Extreme, [kind], Some(p))
            if yes_no
                && (superlatives > 0 || than_others)
                && goal.is_none()
                && categories.is_empty()
                && words[..p].iter().any(|w| is_fruit(w))
                && !words[p..].iter().any(|w| is_fruit(w)) =>
        {
            Some(kind.clone())
        }
        _ => None,
    };
    if let Some(kind) = &candidate {
        // A place, colour, count or size picks among instances, and several asked at once
        // leave open which must win: neither is held up to the rest yet.
        if filters != Filters::default() || plural {
            return Err(QueryError::Unsupported {
                what: if plural {
                    format!("several {kind}s held up to every other fruit")
                } else {
                    format!(
                        "one {kind} picked by place, colour or size held up to every other fruit"
                    )
                },
                instead: format!(
                    "ask \"Which fruit is the {}?\" and read where the {kind} stands",
                    superlative_word(property, extreme)
                ),
            });
        }
        targets.clear();
        all = true;
    }
    // "Which fruit is as hard as the apple?": fruit alike within the uncertainty is no set
    // the answer picks yet; "Is the apple as hard as the mango?" compares the two.
    if as_much && intent != Intent::Compare {
        return Err(QueryError::Unsupported {
            what: "fruit as hard (soft, ripe) as another".into(),
            instead: "compare two by name, e.g. \"Is the apple as hard as the mango?\", or ask \"Which fruit is harder than the apple?\"".into(),
        });
    }
    Ok(Query {
        intent,
        property,
        extreme,
        targets,
        categories,
        all,
        exclude,
        filters,
        ranked,
        unknown,
        candidate,
        corrected,
        threshold,
        relation,
        // A use names an end: a comparison of two or one fruit's reading has none to say.
        goal: goal.filter(|_| !matches!(intent, Intent::Compare | Intent::Identify)),
    })
}

/// How a refusal names the superlative asked for: "softest", "least ripe".
fn superlative_word(property: Property, extreme: Option<Extreme>) -> &'static str {
    let least = extreme == Some(Extreme::Least);
    match (property, least) {
        (Property::Hardness, false) | (Property::Softness, true) => "hardest",
        (Property::Softness, false) | (Property::Hardness, true) => "softest",
        (Property::Ripeness, false) => "ripest",
        (Property::Ripeness, true) => "least ripe",
    }
}

/// The place words of "on the left", "at the back", "in the front corner" starting at word
/// `i`, and the index past them; None when no place follows.
/// A relation to `kind` named at word `i` (harder or less ripe, by ripeness), the reference's place words ("than the banana on
/// the left", "than the apple at the back": the place is the reference's, not a filter on
/// the fruit asked about) and the word after the reference and its place.
fn relation_at(
    words: &[String],
    i: usize,
    (harder, ripeness): (bool, bool),
    kind: &str,
) -> (threshold::Relation, Vec<&'static str>, usize) {
    let relation = threshold::Relation {
        harder,
        reference: kind.to_string(),
        also: Vec::new(),
        position: None,
        ripeness,
    };
    match place_after(words, i + 1) {
        Some((places, end)) => (relation, places, end),
        None => (relation, Vec::new(), i + 1),
    }
}

fn place_after(words: &[String], i: usize) -> Option<(Vec<&'static str>, usize)> {
    let mut j = i;
    // "in the middle" and "in front" arrive as one word ("centre", "front").
    let rewritten = words
        .get(j)
        .is_some_and(|w| matches!(w.as_str(), "centre" | "front"));
    if !rewritten {
        if !words
            .get(j)
            .is_some_and(|w| matches!(w.as_str(), "on" | "at" | "in" | "to"))
        {
            return None;
        }
        j += 1;
        // "on the left", "on your left" (the one asking stands where the camera looks from).
        if words
            .get(j)
            .is_some_and(|w| matches!(w.as_str(), "the" | "your" | "my"))
        {
            j += 1;
        }
    }
    let mut places = Vec::new();
    while let Some(p) = words.get(j).and_then(|w| lexicon::position_word(w)) {
        places.push(p);
        j += 1;
    }
    if places.is_empty() {
        return None;
    }
    if words
        .get(j)
        .is_some_and(|w| matches!(w.as_str(), "side" | "corner" | "one"))
    {
        j += 1;
    }
    Some((places, j))
}

/// A second bound beside a first ("softer than the mango but harder than the banana").
/// Whether the words from `end` (just after a reference and its place) to the fruit at `i`
/// join it to the references: "and (the)", "as well as", "plus", "and also", "both", a
/// "ripe" or a colour or a place before it, or a comma in a list that ends in "and" (a list
/// ending in "or" names the fruit asked about: "softer than the lime, the banana or the
/// tomato"). A place among them is for the caller to refuse.
fn joins_references(
    words: &[String],
    breaks: &[bool],
    end: usize,
    i: usize,
    is_fruit: impl Fn(&str) -> bool + Copy,
) -> bool {
    if end > i {
        return false;
    }
    let gap = &words[end..i];
    let joiner = gap
        .iter()
        .any(|w| matches!(w.as_str(), "and" | "or" | "plus" | "nor") || w == "well");
    let comma = end > 0 && breaks[end - 1] && list_ends_with_and(words, i, is_fruit);
    (joiner || comma)
        && gap.iter().all(|w| {
            matches!(
                w.as_str(),
                "and"
                    | "or"
                    | "the"
                    | "a"
                    | "an"
                    | "both"
                    | "as"
                    | "well"
                    | "plus"
                    | "also"
                    | "ripe"
                    | "unripe"
                    | "that"
                    | "this"
                    | "of"
                    | "each"
                    | "all"
            ) || lexicon::COLOURS.contains(&w.as_str())
                || lexicon::position_word(w).is_some()
        })
}

/// Whether the list of fruit from word `i` on ("the kiwi and the tomato", "the kiwi, the
/// tomato and the lime") is joined by "and" before anything else.
fn list_ends_with_and(words: &[String], i: usize, is_fruit: impl Fn(&str) -> bool) -> bool {
    words[i..]
        .iter()
        .map(String::as_str)
        .find(|w| !(is_fruit(w) || matches!(*w, "the" | "a" | "an")))
        == Some("and")
}

fn second_bound(name: &str, first: &str) -> QueryError {
    QueryError::BadThreshold {
        value: format!("the {name}"),
        message: format!("a second comparison beside {first}: ask about one at a time"),
    }
}

/// Position words in `explain::location_words` order: left/right/centre, then front/back.
pub(crate) fn position_phrase(positions: &[&str]) -> Option<String> {
    let lr = positions
        .iter()
        .find(|p| matches!(**p, "left" | "right"))
        .copied();
    let fb = positions
        .iter()
        .find(|p| matches!(**p, "front" | "back"))
        .copied();
    match (lr, fb) {
        (Some(a), Some(b)) => Some(format!("{a} {b}")),
        (Some(a), None) | (None, Some(a)) => Some(a.to_string()),
        (None, None) => positions.contains(&"centre").then(|| "centre".to_string()),
    }
}

impl Query {
    /// Whether an object with this label is among those the query asks about: of a kind
    /// asked about and not the relation's reference.
    pub fn wants(&self, label: &str) -> bool {
        self.asks_about_kind(label) && !self.is_reference(label)
    }

    /// Whether the prompt asks about this kind (named, in a group named, or every fruit),
    /// the reference's kind included: "Which banana is softer than the banana on the left?"
    /// asks about the bananas that are not the reference.
    pub fn asks_about_kind(&self, label: &str) -> bool {
        let named = self.targets.iter().any(|t| t == label);
        let grouped = self
            .categories
            .iter()
            .any(|c| c.members.iter().any(|m| m == label));
        // A group bounds "all": "of all the fruit, which citrus is softest" is about the citrus.
        let every = self.all && self.categories.is_empty();
        !self.exclude.iter().any(|e| e == label) && (every || named || grouped)
    }

    /// Whether this object is among those the query asks about: of a kind asked about and
    /// not marked by grounding as what the others are held against (the one at the
    /// reference's place, or, without a place, every one of the reference's kind).
    pub fn asks_about(&self, label: &str, is_reference: bool) -> bool {
        !is_reference && self.asks_about_kind(label)
    }

    /// Whether the answer needs this object pressed: it is asked about, or it is what the
    /// others are held against.
    pub fn needs(&self, label: &str) -> bool {
        self.wants(label) || self.is_reference(label)
    }

    /// Whether objects with this label are the relation's reference ("than the apple").
    pub fn is_reference(&self, label: &str) -> bool {
        self.relation
            .as_ref()
            .is_some_and(|r| r.holds_against(label))
    }

    /// How the answer names what was asked about: "fruit", "citrus fruit", "lime or lemon".
    pub fn asked_kind(&self) -> String {
        let mut kinds = self.targets.clone();
        kinds.extend(self.categories.iter().map(|c| c.noun.clone()));
        if kinds.is_empty() || (self.all && self.categories.is_empty()) {
            "fruit".into()
        } else {
            kinds.join(" or ")
        }
    }
}

/// Whether location words ("left front") satisfy a position filter ("left", "left front").
pub fn position_matches(filter: &str, location: &str) -> bool {
    let at: Vec<&str> = location.split(' ').collect();
    filter.split(' ').all(|w| at.contains(&w))
}

impl Filters {
    /// Whether an object of this colour name passes the colour filter (if any).
    pub fn colour_matches(&self, colour: &str) -> bool {
        self.color.as_deref().is_none_or(|c| c == colour)
    }

    /// Whether an object at these location words passes the position filter (if any).
    pub fn position_matches(&self, location: &str) -> bool {
        self.position
            .as_deref()
            .is_none_or(|p| position_matches(p, location))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn q(p: &str) -> Query {
        parse(p, &FruitCatalog::builtin()).unwrap_or_else(|e| panic!("{p}: {e}"))
    }

    fn names(v: &[&str]) -> Vec<String> {
        v.iter().map(|s| s.to_string()).collect()
    }

    #[test]
    fn tier_1_identifies_the_property_of_one_object() {
        for p in [
            "Identify the hardness of the lemon",
            "I want to know the hardness of the lemon",
            "How hard is the lemon?",
            "how firm is the lemon",
        ] {
            let query = q(p);
            assert_eq!(
                (
                    query.intent,
                    query.property,
                    query.targets.clone(),
                    query.all
                ),
                (
                    Intent::Identify,
                    Property::Hardness,
                    names(&["lemon"]),
                    false
                ),
                "{p}"
            );
        }
        let query = q("Is the avocado ripe?");
        assert_eq!(
            (query.intent, query.property),
            (Intent::Identify, Property::Ripeness)
        );
    }

    #[test]
    fn tier_2_picks_the_most_or_least_of_a_kind() {
        let cases = [
            (
                "Which banana is the softest?",
                Property::Softness,
                Extreme::Most,
            ),
            ("the softest banana", Property::Softness, Extreme::Most),
            ("which lemon is ripest", Property::Ripeness, Extreme::Most),
            (
                "Which lemon is the most ripe?",
                Property::Ripeness,
                Extreme::Most,
            ),
            (
                "Which lemon is least ripe?",
                Property::Ripeness,
                Extreme::Least,
            ),
            (
                "Which banana is the greenest?",
                Property::Ripeness,
                Extreme::Least,
            ),
            ("Find the firmest banana", Property::Hardness, Extreme::Most),
            (
                "Which banana is the least hard?",
                Property::Hardness,
                Extreme::Least,
            ),
            (
                "Which of the two bananas is squishier?",
                Property::Softness,
                Extreme::Most,
            ),
        ];
        for (p, property, extreme) in cases {
            let query = q(p);
            assert_eq!(
                (query.intent, query.property, query.extreme, query.all),
                (Intent::Extreme, property, Some(extreme), false),
                "{p}"
            );
            let t = if p.contains("banana") {
                "banana"
            } else {
                "lemon"
            };
            assert_eq!(query.targets, names(&[t]), "{p}");
        }
    }

    #[test]
    fn tier_3_summarises_named_objects() {
        let query = q("Summarize the hardness of the mango and the kiwi");
        assert_eq!(
            (query.intent, query.targets.clone(), query.all),
            (Intent::Summarize, names(&["mango", "kiwi"]), false)
        );
        let query = q("How ripe are the lemon, the lime and the peach?");
        assert_eq!(
            (query.intent, query.property, query.targets.len()),
            (Intent::Summarize, Property::Ripeness, 3)
        );
    }

    #[test]
    fn tier_4_summarises_all_fruits() {
        for p in [
            "Summarize the hardness of all fruits",
            "Describe how hard every fruit is",
            "How firm is each item on the table?",
        ] {
            let query = q(p);
            assert_eq!(
                (query.intent, query.all, query.targets.len()),
                (Intent::Summarize, true, 0),
                "{p}"
            );
        }
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
        let query = q("Which fruit is ready to eat?");
        assert_eq!(
            (query.intent, query.property, query.extreme),
            (Intent::Extreme, Property::Ripeness, Some(Extreme::Most))
        );
    }

    #[test]
    fn which_of_one_kind_with_a_plain_property_selects_among_them() {
        let query = q("Which avocado is ready to eat?");
        assert_eq!(
            (query.intent, query.property, query.extreme, query.targets),
            (
                Intent::Extreme,
                Property::Ripeness,
                Some(Extreme::Most),
                names(&["avocado"])
            )
        );
        let query = q("Which banana is soft?");
        assert_eq!(query.intent, Intent::Extreme);
        let query = q("Which bananas are ripe?");
        assert_eq!(query.intent, Intent::Summarize);
        let query = q("Is the avocado ripe?");
        assert_eq!(query.intent, Intent::Identify);
    }

    #[test]
    fn a_fruit_name_in_a_list_is_a_fruit_not_a_colour() {
        for prompt in [
            "mango, lime, orange, apple: which is the softest?",
            "Of the mango, the orange and the apple, which is softest?",
            "lime orange apple mango which is softest",
            "orange, mango: which is softer?",
        ] {
            let query = q(prompt);
            assert!(
                query.targets.contains(&"orange".to_string()),
                "{prompt}: {query:?}"
            );
            assert_eq!(query.filters.color, None, "{prompt}");
        }
        let query = q("Is the orange one riper than the green apple?");
        assert_eq!(query.filters.color.as_deref(), Some("orange"));
        let query = q("Which is softer, the orange apple or the banana?");
        assert_eq!(query.filters.color.as_deref(), Some("orange"));
    }

    #[test]
    fn comparisons_between_named_objects() {
        let query = q("Is the mango harder than the avocado?");
        assert_eq!(
            (query.intent, query.property, query.extreme),
            (Intent::Compare, Property::Hardness, None)
        );
        assert_eq!(query.targets, names(&["mango", "avocado"]));
        let query = q("Which is softer, the kiwi or the peach?");
        assert_eq!(
            (query.intent, query.property),
            (Intent::Compare, Property::Softness)
        );
        let query = q("Compare the apple and the orange");
        assert_eq!(
            (query.intent, query.targets.clone()),
            (Intent::Compare, names(&["apple", "orange"]))
        );
        let query = q("Is the lime less ripe than the lemon?");
        assert_eq!(
            (query.intent, query.property),
            (Intent::Compare, Property::Ripeness)
        );
        let query = q("Which fruit is softest, the kiwi or the mango?");
        assert_eq!(
            (query.intent, query.all, query.targets.len()),
            (Intent::Extreme, false, 2)
        );
    }

    #[test]
    fn rankings_order_every_object() {
        let query = q("Rank the fruits from softest to hardest");
        assert_eq!(
            (query.intent, query.ranked, query.property, query.all),
            (Intent::Summarize, true, Property::Softness, true)
        );
        let query = q("Order the bananas by ripeness");
        assert_eq!(
            (
                query.intent,
                query.ranked,
                query.property,
                query.targets.clone()
            ),
            (
                Intent::Summarize,
                true,
                Property::Ripeness,
                names(&["banana"])
            )
        );
    }

    #[test]
    fn plurals_and_counts() {
        let query = q("How soft are both bananas?");
        assert_eq!(
            (
                query.intent,
                query.targets.clone(),
                query.filters.count,
                query.all
            ),
            (Intent::Summarize, names(&["banana"]), Some(2), false)
        );
        let query = q("Tell me the firmness of the two limes");
        assert_eq!(
            (query.intent, query.filters.count, query.property),
            (Intent::Summarize, Some(2), Property::Hardness)
        );
        let query = q("How hard are all 3 apples?");
        assert_eq!(
            (query.filters.count, query.all, query.targets.clone()),
            (Some(3), false, names(&["apple"]))
        );
        let query = q("How hard are the tomatoes?");
        assert_eq!(query.intent, Intent::Summarize);
    }

    #[test]
    fn synonyms_map_to_the_catalog_and_properties() {
        assert_eq!(q("How squishy is the peach?").property, Property::Softness);
        assert_eq!(q("How firm is the kiwifruit?").targets, names(&["kiwi"]));
        assert!(!q("Is the kiwi fruit soft?").all);
        assert_eq!(q("Is the mango ready-to-eat?").property, Property::Ripeness);
        let query = q("Is the banana still green?");
        assert_eq!(
            (query.property, query.filters.color.clone()),
            (Property::Ripeness, None)
        );
        assert_eq!(
            q("Which mango is the most unripe?").extreme,
            Some(Extreme::Least)
        );
        assert_eq!(q("How stiff are the mangos?").targets, names(&["mango"]));
    }

    #[test]
    fn filters_by_colour_and_position() {
        let query = q("How hard is the fruit on the left?");
        assert_eq!(
            (query.intent, query.all, query.filters.position.clone()),
            (Intent::Identify, true, Some("left".to_string()))
        );
        let query = q("How soft is the yellow one?");
        assert_eq!(
            (query.all, query.filters.color.clone()),
            (true, Some("yellow".to_string()))
        );
        let query = q("Is the orange one riper than the green apple?");
        assert_eq!(query.filters.color.as_deref(), Some("orange"));
        assert_eq!(query.targets, names(&["apple"]));
        let query = q("How firm is the orange?");
        assert_eq!(
            (query.targets.clone(), query.filters.color.clone()),
            (names(&["orange"]), None)
        );
        let query = q("Which fruit in the front right is the softest?");
        assert_eq!(query.filters.position.as_deref(), Some("right front"));
        let query = q("How hard is the leftmost banana?");
        assert_eq!(
            (query.filters.position.as_deref(), query.targets.clone()),
            (Some("left"), names(&["banana"]))
        );
        let query = q("Is that right, the apple is hard?");
        assert_eq!(query.filters.position, None);
        let query = q("How hard is the fruit in the middle?");
        assert_eq!(query.filters.position.as_deref(), Some("centre"));
    }

    #[test]
    fn exclusions() {
        let query = q("Tell me how hard all fruits except the kiwi are");
        assert_eq!(
            (query.intent, query.all, query.exclude.clone()),
            (Intent::Summarize, true, names(&["kiwi"]))
        );
        let query = q("Which fruit other than the banana and the lime is the softest?");
        assert_eq!(
            (query.intent, query.all, query.exclude.clone()),
            (Intent::Extreme, true, names(&["banana", "lime"]))
        );
        assert!(!query.wants("banana") && query.wants("apple"));
    }

    /// What the pipeline keeps: the label wanted, the colour and the position matching.
    fn admits(q: &Query, label: &str, location: &str, colour: Option<&str>) -> bool {
        q.wants(label)
            && colour.map_or(q.filters.color.is_none(), |c| q.filters.colour_matches(c))
            && q.filters.position_matches(location)
    }

    #[test]
    fn filters_admit_by_label_colour_and_location() {
        let query = q("How hard is the yellow fruit on the left?");
        assert!(admits(&query, "lemon", "left front", Some("yellow")));
        assert!(!admits(&query, "lemon", "right front", Some("yellow")));
        assert!(!admits(&query, "lime", "left", Some("green")));
        let query = q("How hard is the banana at the front left?");
        assert!(admits(&query, "banana", "left front", None));
        assert!(!admits(&query, "banana", "left back", None));
    }

    #[test]
    fn unparseable_prompts_say_why() {
        let c = FruitCatalog::builtin();
        assert_eq!(parse("   ", &c), Err(QueryError::Empty));
        let e = parse("How hard is the pineapple?", &c)
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("prompt: 'pineapple' is not in the fruit catalog"),
            "{e}"
        );
        let e = parse("What is the weather like?", &c)
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("prompt: names no known fruit"), "{e}");
        assert!(parse(&"a".repeat(MAX_PROMPT_CHARS + 1), &c).is_err());
        // An unknown fruit beside known ones is kept, so the answer can say so.
        let query = parse("Compare the kiwi and the grapes", &c).unwrap();
        assert_eq!(
            (query.targets.clone(), query.unknown.clone()),
            (names(&["kiwi"]), names(&["grape"]))
        );
    }

    #[test]
    fn a_use_names_the_property_when_no_word_does() {
        let smoothie = q("Which fruit would you recommend for a smoothie today?");
        assert_eq!(smoothie.intent, Intent::Extreme);
        assert_eq!(
            (smoothie.property, smoothie.extreme),
            (Property::Ripeness, Some(Extreme::Most))
        );
        assert!(smoothie.all);
        assert_eq!(smoothie.goal.unwrap().said, "for a smoothie");
        // Nothing named: every fruit, as for a value.
        let keep = q("What should I keep for next week?");
        assert!(keep.all);
        assert_eq!(
            (keep.property, keep.extreme),
            (Property::Ripeness, Some(Extreme::Least))
        );
        let slicing = q("Which apple is best for slicing?");
        assert_eq!(slicing.targets, names(&["apple"]));
        assert_eq!(
            (slicing.property, slicing.extreme),
            (Property::Hardness, Some(Extreme::Most))
        );
        let ranked = q("Rank the fruits for a smoothie");
        assert_eq!((ranked.intent, ranked.ranked), (Intent::Summarize, true));
        assert_eq!(ranked.property, Property::Ripeness);
        // A property the prompt names is what it asks; the use is only context.
        let said = q("Which is the softest fruit for a smoothie?");
        assert_eq!(said.property, Property::Softness);
        assert_eq!(said.goal, None);
    }

    #[test]
    fn a_category_of_the_catalog_asks_about_its_kinds() {
        let citrus = q("Sort the citrus fruits by how soft they are");
        assert_eq!(
            (citrus.intent, citrus.property, citrus.ranked),
            (Intent::Summarize, Property::Softness, true)
        );
        assert_eq!(citrus.categories.len(), 1);
        assert_eq!(
            citrus.categories[0].members,
            names(&["lime", "lemon", "orange"])
        );
        assert!(citrus.wants("lemon") && !citrus.wants("apple"));
        assert_eq!(citrus.asked_kind(), "citrus fruit");

        let stone = q("Which stone fruit is the softest?");
        assert_eq!(
            (stone.intent, stone.extreme),
            (Intent::Extreme, Some(Extreme::Most))
        );
        assert!(stone.wants("peach") && stone.wants("mango") && !stone.wants("lime"));
        assert_eq!(stone.asked_kind(), "stone fruit");

        // "of all the fruit" does not widen a group.
        let of_all = q("Of all the fruits, which tropical one is the hardest?");
        assert!(
            of_all.wants("banana") && !of_all.wants("apple"),
            "{of_all:?}"
        );

        assert_eq!(q("How ripe are the berries?").intent, Intent::Summarize);

        let but = q("Which fruit is the softest, except the citrus?");
        assert!(but.categories.is_empty());
        assert_eq!(but.exclude, names(&["lime", "lemon", "orange"]));
        assert!(but.wants("apple") && !but.wants("orange"));

        // A fruit whose name holds a group's word is the fruit.
        let straw = q("Is the strawberry softer than the apple?");
        assert_eq!(
            (straw.intent, straw.targets.clone()),
            (Intent::Compare, names(&["strawberry", "apple"]))
        );
        assert!(straw.categories.is_empty());
    }
}
