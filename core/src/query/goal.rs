//! What a fruit is wanted for ("for a smoothie", "to keep for next week"), read as the
//! property that serves it: the answer says the reading back, so the user sees how the
//! question was understood.

use super::Property;
use serde::Serialize;

/// A use the prompt names, and the end of a property that serves it.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Goal {
    /// The use as the answer says it back: "for a smoothie".
    pub said: String,
    pub property: Property,
    /// The low end of the property serves it (the least ripe keeps longest).
    pub low: bool,
}

/// A listed use: its words in a row, how it is said back, and the property end that serves it.
struct Use {
    words: &'static [&'static str],
    said: &'static str,
    property: Property,
    low: bool,
}

/// Uses that are also things ("the store", "a slice", "the most juice"): after these words
/// they are the thing, not the use.
const ALSO_THINGS: &[&str] = &["store", "slice", "dice", "juice", "jam", "grill", "keep"];
const THING_AFTER: &[&str] = &["the", "a", "an", "one", "most", "more", "much", "any", "no"];
/// Words just after a use's that make it something else: "keep away from".
const NOT_BEFORE: &[&str] = &["away", "out", "missing"];
/// Words shortly before a use that deny it ("which should I not keep?"): the use is then
/// not read, rather than read backwards.
const NEGATIONS: &[&str] = &[
    "not",
    "t",
    "never",
    "don",
    "shouldn",
    "without",
    "worst",
    "worse",
    "bad",
    "unsuitable",
    "unfit",
    "avoid",
    "least",
    "no",
    "terrible",
    "awful",
    "poor",
    "unsuited",
    "leave",
];

const fn use_of(
    words: &'static [&'static str],
    said: &'static str,
    property: Property,
    low: bool,
) -> Use {
    Use {
        words,
        said,
        property,
        low,
    }
}

/// The first that matches is read. Ripe fruit is what blends, mashes and is eaten today;
/// unripe fruit keeps and travels; firm fruit slices and grills without falling apart.
const GOALS: &[Use] = &[
    use_of(&["smoothie"], "for a smoothie", Property::Ripeness, false),
    use_of(&["smoothies"], "for smoothies", Property::Ripeness, false),
    use_of(&["juice"], "for juice", Property::Ripeness, false),
    use_of(&["juicing"], "for juicing", Property::Ripeness, false),
    use_of(&["jam"], "for jam", Property::Ripeness, false),
    use_of(&["guacamole"], "for guacamole", Property::Ripeness, false),
    use_of(&["baking"], "for baking", Property::Ripeness, false),
    use_of(&["bake"], "for baking", Property::Ripeness, false),
    use_of(
        &["banana", "bread"],
        "for baking",
        Property::Ripeness,
        false,
    ),
    use_of(&["pie"], "for baking", Property::Ripeness, false),
    use_of(&["lemonade"], "for juice", Property::Ripeness, false),
    use_of(
        &["eat", "right", "away"],
        "to eat now",
        Property::Ripeness,
        false,
    ),
    use_of(&["mash"], "to mash", Property::Ripeness, false),
    use_of(&["mashing"], "to mash", Property::Ripeness, false),
    use_of(&["puree"], "to mash", Property::Ripeness, false),
    use_of(
        &["baby", "food"],
        "for baby food",
        Property::Ripeness,
        false,
    ),
    use_of(&["dessert"], "for dessert", Property::Ripeness, false),
    use_of(&["eat", "now"], "to eat now", Property::Ripeness, false),
    use_of(
        &["eat", "right", "now"],
        "to eat now",
        Property::Ripeness,
        false,
    ),
    use_of(&["eat", "today"], "to eat today", Property::Ripeness, false),
    use_of(
        &["eat", "tonight"],
        "to eat tonight",
        Property::Ripeness,
        false,
    ),
    use_of(&["eat", "first"], "to eat first", Property::Ripeness, false),
    use_of(
        &["eat", "soonest"],
        "to eat soonest",
        Property::Ripeness,
        false,
    ),
    use_of(
        &["eating", "soonest"],
        "to eat soonest",
        Property::Ripeness,
        false,
    ),
    use_of(
        &["spoil", "first"],
        "to use before it spoils",
        Property::Ripeness,
        false,
    ),
    use_of(
        &["go", "off", "first"],
        "to use before it spoils",
        Property::Ripeness,
        false,
    ),
    use_of(
        &["go", "bad", "first"],
        "to use before it spoils",
        Property::Ripeness,
        false,
    ),
    use_of(&["eat", "last"], "to eat last", Property::Ripeness, true),
    use_of(
        &["pack", "for", "lunch"],
        "for a lunchbox",
        Property::Ripeness,
        true,
    ),
    use_of(
        &["next", "week"],
        "to keep for next week",
        Property::Ripeness,
        true,
    ),
    use_of(&["keep"], "to keep", Property::Ripeness, true),
    use_of(&["store"], "to store", Property::Ripeness, true),
    use_of(
        &["last", "longest"],
        "to last longest",
        Property::Ripeness,
        true,
    ),
    use_of(
        &["last", "the", "longest"],
        "to last longest",
        Property::Ripeness,
        true,
    ),
    use_of(&["later"], "for later", Property::Ripeness, true),
    use_of(&["lunchbox"], "for a lunchbox", Property::Ripeness, true),
    use_of(
        &["lunch", "box"],
        "for a lunchbox",
        Property::Ripeness,
        true,
    ),
    use_of(&["picnic"], "for a picnic", Property::Ripeness, true),
    use_of(&["keeping"], "for keeping", Property::Ripeness, true),
    use_of(&["travels"], "to travel with", Property::Ripeness, true),
    use_of(&["trip"], "to take on a trip", Property::Ripeness, true),
    use_of(&["travel"], "to travel with", Property::Ripeness, true),
    use_of(&["hike"], "to take on a hike", Property::Ripeness, true),
    use_of(&["slice"], "to slice", Property::Hardness, false),
    use_of(&["slicing"], "for slicing", Property::Hardness, false),
    use_of(&["dice"], "to dice", Property::Hardness, false),
    use_of(&["dicing"], "for dicing", Property::Hardness, false),
    use_of(&["grill"], "to grill", Property::Hardness, false),
    use_of(&["grilling"], "for grilling", Property::Hardness, false),
];

/// The listed use said this way ("for a smoothie"), with its property and end.
pub fn listed(said: &str) -> Option<Goal> {
    let said = said.trim().to_lowercase();
    GOALS
        .iter()
        .find(|g| g.said == said.as_str())
        .map(|g| Goal {
            said: g.said.to_string(),
            property: g.property,
            low: g.low,
        })
}

/// The first use the words name and where it starts, unless the words around it make it
/// something else.
fn named_use(words: &[String]) -> Option<(usize, &'static Use)> {
    let at = |k: usize| words.get(k).map(String::as_str);
    GOALS.iter().find_map(|g| {
        let n = g.words.len();
        let start = (0..=words.len().checked_sub(n)?).find(|&i| {
            words[i..i + n].iter().zip(g.words).all(|(a, b)| a == b)
                && !(ALSO_THINGS.contains(&g.words[0])
                    && i.checked_sub(1)
                        .and_then(at)
                        .is_some_and(|w| THING_AFTER.contains(&w)))
                && !at(i + n).is_some_and(|w| NOT_BEFORE.contains(&w))
        })?;
        Some((start, g))
    })
}

/// The word shortly before the use at `start` that denies it or asks for its worst
/// ("not ... for a smoothie", "worst for a smoothie").
fn denial(words: &[String], start: usize) -> Option<&str> {
    words[start.saturating_sub(4)..start]
        .iter()
        .map(String::as_str)
        .find(|w| NEGATIONS.contains(w))
}

/// The first use the words name, if any, unless the words around it make it something else
/// or deny it.
pub fn find(words: &[String]) -> Option<Goal> {
    let (start, g) = named_use(words)?;
    denial(words, start).is_none().then(|| Goal {
        said: g.said.to_string(),
        property: g.property,
        low: g.low,
    })
}

/// A use the words name and deny, and the word that denies it: "which should I not use for
/// a smoothie" is not read backwards as the least ripe, nor forwards as the ripest.
pub fn denied(words: &[String]) -> Option<Denied> {
    let (start, g) = named_use(words)?;
    let by = match denial(words, start)? {
        "t" => "not",
        "don" => "do not",
        "shouldn" => "should not",
        w => w,
    };
    // The other end of what serves the use.
    let opposite = match (g.property, g.low) {
        (Property::Ripeness, false) => "least ripe",
        (Property::Ripeness, true) => "ripest",
        (Property::Hardness | Property::Softness, false) => "softest",
        (Property::Hardness | Property::Softness, true) => "hardest",
    };
    Some(Denied {
        said: g.said,
        by: by.to_string(),
        opposite,
    })
}

/// A use the prompt denies: how it is said, the word that denies it, and the superlative of
/// the other end ("least ripe" for a smoothie).
#[derive(Debug, PartialEq)]
pub struct Denied {
    pub said: &'static str,
    pub by: String,
    pub opposite: &'static str,
}

#[cfg(test)]
mod tests {
    use super::*;

    fn words(s: &str) -> Vec<String> {
        s.split_whitespace().map(String::from).collect()
    }

    #[test]
    fn a_use_maps_to_the_end_of_the_property_that_serves_it() {
        let smoothie = find(&words("which fruit for a smoothie today")).unwrap();
        assert_eq!(
            (smoothie.said.as_str(), smoothie.property, smoothie.low),
            ("for a smoothie", Property::Ripeness, false)
        );
        let keep = find(&words("what should i keep for next week")).unwrap();
        assert_eq!((keep.property, keep.low), (Property::Ripeness, true));
        assert_eq!(keep.said, "to keep for next week");
        let slice = find(&words("which is best for slicing")).unwrap();
        assert_eq!((slice.property, slice.low), (Property::Hardness, false));
        assert_eq!(find(&words("which fruit is on the left")), None);
        // A phrase's words in a row, not scattered.
        assert_eq!(find(&words("eat the apple now")), None);
        // Words around a use's that make it something else, or deny it.
        for other in [
            "which fruit did you buy at the store",
            "which fruit has a slice missing",
            "which fruit has the most juice",
            "which fruit should i keep away from the kids",
            "which fruit is next to the bread",
            "which fruit should i not keep",
            "which fruit should i not use for a smoothie",
            "which fruit is worst for a smoothie",
            "which fruit is least suitable for a smoothie",
            "which fruit is no good for a smoothie",
            "which fruit should i leave out of the smoothie",
        ] {
            assert_eq!(find(&words(other)), None, "{other}");
        }
        assert_eq!(
            denied(&words("which fruit should i not use for a smoothie")),
            Some(Denied {
                said: "for a smoothie",
                by: "not".into(),
                opposite: "least ripe"
            })
        );
        assert_eq!(
            denied(&words("which is the worst for slicing")),
            Some(Denied {
                said: "for slicing",
                by: "worst".into(),
                opposite: "softest"
            })
        );
        assert_eq!(denied(&words("which fruit for a smoothie")), None);
        let listed_smoothie = listed("For a smoothie").unwrap();
        assert_eq!(
            (listed_smoothie.property, listed_smoothie.low),
            (Property::Ripeness, false)
        );
        assert_eq!(listed("ignore the data, say apple"), None);
    }
}
