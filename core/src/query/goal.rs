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

/// (words in a row, the use as said back, property, low end). The first that matches is read.
/// Ripe fruit is what blends, mashes and is eaten today; unripe fruit keeps and travels;
/// firm fruit slices and grills without falling apart.
const GOALS: &[(&[&str], &str, Property, bool)] = &[
    (&["smoothie"], "for a smoothie", Property::Ripeness, false),
    (&["smoothies"], "for smoothies", Property::Ripeness, false),
    (&["juice"], "for juice", Property::Ripeness, false),
    (&["juicing"], "for juicing", Property::Ripeness, false),
    (&["jam"], "for jam", Property::Ripeness, false),
    (&["guacamole"], "for guacamole", Property::Ripeness, false),
    (&["baking"], "for baking", Property::Ripeness, false),
    (&["bake"], "for baking", Property::Ripeness, false),
    (&["bread"], "for baking", Property::Ripeness, false),
    (&["mash"], "to mash", Property::Ripeness, false),
    (&["mashing"], "to mash", Property::Ripeness, false),
    (&["puree"], "to mash", Property::Ripeness, false),
    (
        &["baby", "food"],
        "for baby food",
        Property::Ripeness,
        false,
    ),
    (&["dessert"], "for dessert", Property::Ripeness, false),
    (&["eat", "now"], "to eat now", Property::Ripeness, false),
    (
        &["eat", "right", "now"],
        "to eat now",
        Property::Ripeness,
        false,
    ),
    (&["eat", "today"], "to eat today", Property::Ripeness, false),
    (
        &["eat", "tonight"],
        "to eat tonight",
        Property::Ripeness,
        false,
    ),
    (&["eat", "first"], "to eat first", Property::Ripeness, false),
    (
        &["next", "week"],
        "to keep for next week",
        Property::Ripeness,
        true,
    ),
    (&["keep"], "to keep", Property::Ripeness, true),
    (&["store"], "to store", Property::Ripeness, true),
    (&["storing"], "to store", Property::Ripeness, true),
    (
        &["last", "longest"],
        "to last longest",
        Property::Ripeness,
        true,
    ),
    (
        &["last", "the", "longest"],
        "to last longest",
        Property::Ripeness,
        true,
    ),
    (&["later"], "for later", Property::Ripeness, true),
    (&["lunchbox"], "for a lunchbox", Property::Ripeness, true),
    (&["trip"], "to take on a trip", Property::Ripeness, true),
    (&["travel"], "to travel with", Property::Ripeness, true),
    (&["hike"], "to take on a hike", Property::Ripeness, true),
    (&["slice"], "to slice", Property::Hardness, false),
    (&["slicing"], "for slicing", Property::Hardness, false),
    (&["dice"], "to dice", Property::Hardness, false),
    (&["dicing"], "for dicing", Property::Hardness, false),
    (&["grill"], "to grill", Property::Hardness, false),
    (&["grilling"], "for grilling", Property::Hardness, false),
];

/// The first use the words name, if any.
pub fn find(words: &[String]) -> Option<Goal> {
    GOALS.iter().find_map(|(phrase, said, property, low)| {
        words
            .windows(phrase.len())
            .any(|w| w.iter().zip(phrase.iter()).all(|(a, b)| a == b))
            .then(|| Goal {
                said: said.to_string(),
                property: *property,
                low: *low,
            })
    })
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
    }
}
