//! The words the prompt parser knows: property words with their degree, colours, positions,
//! counts, and the phrases it rewrites before reading word by word.

use super::Property;

/// How a property word grades: "soft", "softer", "softest".
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Degree {
    Base,
    Comparative,
    Superlative,
}

/// A property word: its property, degree, and whether it points the other way along it
/// ("unripe" and "green" are the low end of ripeness).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PropertyWord {
    pub property: Property,
    pub degree: Degree,
    pub inverted: bool,
}

const fn word(property: Property, degree: Degree, inverted: bool) -> PropertyWord {
    PropertyWord {
        property,
        degree,
        inverted,
    }
}

/// Property words, synonyms included (firm/hard, squishy/soft, ready to eat/ripe, green/unripe).
pub fn property_word(w: &str) -> Option<PropertyWord> {
    use Degree::*;
    use Property::*;
    Some(match w {
        "hard" | "hardness" | "firm" | "firmness" | "stiff" | "stiffness" | "solid" | "tough"
        | "rigid" | "rigidity" | "crunchy" | "crisp" => word(Hardness, Base, false),
        "harder" | "firmer" | "stiffer" | "tougher" | "crunchier" => {
            word(Hardness, Comparative, false)
        }
        "hardest" | "firmest" | "stiffest" | "toughest" | "crunchiest" => {
            word(Hardness, Superlative, false)
        }
        "soft" | "softness" | "squishy" | "squishiness" | "mushy" | "tender" | "spongy"
        | "squashy" | "squeezable" => word(Softness, Base, false),
        "softer" | "squishier" | "mushier" | "tenderer" | "squashier" => {
            word(Softness, Comparative, false)
        }
        "softest" | "squishiest" | "mushiest" | "tenderest" | "squashiest" => {
            word(Softness, Superlative, false)
        }
        "ripe" | "ripeness" | "overripe" | "mature" | "ripened" => word(Ripeness, Base, false),
        "riper" => word(Ripeness, Comparative, false),
        "ripest" => word(Ripeness, Superlative, false),
        "unripe" | "unripened" | "immature" => word(Ripeness, Base, true),
        "unriper" => word(Ripeness, Comparative, true),
        "unripest" => word(Ripeness, Superlative, true),
        "greener" => word(Ripeness, Comparative, true),
        "greenest" => word(Ripeness, Superlative, true),
        _ => return None,
    })
}

/// Words that make the prompt about every fruit on the table (or every one the filters keep).
pub const GENERIC: &[&str] = &[
    "fruit",
    "fruits",
    "object",
    "objects",
    "item",
    "items",
    "thing",
    "things",
    "everything",
    "all",
    "each",
    "every",
    "one",
    "ones",
    "produce",
    "anything",
];

/// Nouns a colour or count can qualify besides fruit names.
pub const GENERIC_NOUNS: &[&str] = &[
    "fruit", "fruits", "object", "objects", "item", "items", "thing", "things", "one", "ones",
];

/// Colour names the filters know, as the detector names observed colours.
pub const COLOURS: &[&str] = &[
    "red", "orange", "yellow", "green", "brown", "purple", "pink",
];

/// Colours compared ("yellower than"): the twin reads hardness and ripeness, not colour.
pub const COLOUR_COMPARATIVES: &[&str] = &[
    "yellower",
    "redder",
    "browner",
    "oranger",
    "pinker",
    "purpler",
    "yellowest",
    "reddest",
    "brownest",
    "pinkest",
    "orangest",
    "purplest",
];

/// Ordinals that would pick an instance by count ("the second banana"): which is first is
/// not something the camera's view settles.
pub const ORDINALS: &[&str] = &[
    "first", "second", "third", "fourth", "fifth", "1st", "2nd", "3rd", "4th", "5th", "last",
];

/// Words after which the fruit names are exclusions.
/// Whether a word turns what follows around: "not", "no", "never", "non-", the "t" of
/// "isn't" ("not harder than" is softer; "not soft" is refused).
pub fn negates(w: &str) -> bool {
    matches!(w, "not" | "no" | "never" | "t" | "non")
}

pub const EXCLUDING: &[&str] = &["except", "excluding", "without", "besides", "but"];

/// Verbs that ask for every named object's value.
pub const SUMMARISING: &[&str] = &[
    "summarize",
    "summarise",
    "summary",
    "describe",
    "list",
    "report",
    "overview",
    "tell",
];

/// Verbs that ask for an order.
pub const RANKING: &[&str] = &["rank", "ranking", "order", "sort", "arrange"];

pub const COMPARING: &[&str] = &["compare", "comparison", "versus", "vs", "than"];

/// Position words: (word, canonical position). The canonical ones match
/// `explain::location_words`.
pub fn position_word(w: &str) -> Option<&'static str> {
    Some(match w {
        "left" | "leftmost" | "lefthand" => "left",
        "right" | "rightmost" | "righthand" => "right",
        "centre" | "center" | "middle" | "central" | "centremost" => "centre",
        "front" | "frontmost" | "nearest" | "closest" => "front",
        "back" | "rear" | "backmost" | "farthest" | "furthest" => "back",
        _ => return None,
    })
}

/// Size words: which end of size they pick ("the bigger lime", "the smallest apple").
pub fn size_word(w: &str) -> Option<super::Size> {
    use super::Size::{Largest, Smallest};
    Some(match w {
        "big" | "bigger" | "biggest" | "large" | "larger" | "largest" | "huge" => Largest,
        "small" | "smaller" | "smallest" | "little" | "tiny" | "tinier" | "tiniest" => Smallest,
        _ => return None,
    })
}

/// Small counts ("both", "the two limes", "all 3 apples").
pub fn count_word(w: &str) -> Option<usize> {
    Some(match w {
        "both" | "two" | "pair" => 2,
        "three" => 3,
        "four" => 4,
        "five" => 5,
        "six" => 6,
        "seven" => 7,
        "eight" => 8,
        "nine" => 9,
        "ten" => 10,
        _ => return w.parse().ok().filter(|n| (2..=100).contains(n)),
    })
}

/// Phrases rewritten to one word before the prompt is read word by word. Longer phrases first.
pub const PHRASES: &[(&str, &str)] = &[
    // "the left-hand banana": the hyphen is a space by then.
    ("left hand", "left"),
    ("right hand", "right"),
    ("ready to be eaten", "ripe"),
    ("ready to eat", "ripe"),
    ("good to eat", "ripe"),
    ("not yet ripe", "unripe"),
    ("not ripe", "unripe"),
    ("still green", "unripe"),
    ("not as", "less"),
    // "the hardest fruit that is not the avocado", "for a smoothie, not the banana": the
    // fruit after is left out.
    ("that is not", "except"),
    ("that isn t", "except"),
    ("which is not", "except"),
    ("which isn t", "except"),
    ("| not the", "| except the"),
    // "softer than all the other fruit", "than everything else": every other fruit.
    ("than all of the others", "than the others"),
    ("than all the others", "than the others"),
    ("than all the other", "than the other"),
    ("than all others", "than the others"),
    ("than all other", "than the other"),
    ("than any other", "than the other"),
    ("than every other", "than the other"),
    ("than everything else", "than the others"),
    ("than anything else", "than the others"),
    ("than all the rest", "than the others"),
    ("than the rest", "than the others"),
    ("other than", "except"),
    ("apart from", "except"),
    ("but not", "except"),
    ("leaving out", "except"),
    ("not counting", "except"),
    ("not including", "except"),
    ("with the exception of", "except"),
    ("in the middle", "centre"),
    ("in front", "front"),
    ("far side", "back"),
    ("near side", "front"),
    ("how about", "tell"),
    ("what about", "tell"),
];

/// A Latin letter with its accent taken off ("léft", "açaí", "purée" as typed on a
/// keyboard set for another language), others as they are.
pub fn unaccented(c: char) -> char {
    match c {
        'à' | 'á' | 'â' | 'ä' | 'ã' | 'å' | 'ā' => 'a',
        'è' | 'é' | 'ê' | 'ë' | 'ē' => 'e',
        'ì' | 'í' | 'î' | 'ï' | 'ī' => 'i',
        'ò' | 'ó' | 'ô' | 'ö' | 'õ' | 'ō' => 'o',
        'ù' | 'ú' | 'û' | 'ü' | 'ū' => 'u',
        'ç' => 'c',
        'ñ' => 'n',
        'ý' | 'ÿ' => 'y',
        c => c,
    }
}

/// Common fruits the catalog does not know, so that a prompt naming one says so by name
/// rather than "names no known fruit".
pub const OTHER_FRUITS: &[&str] = &[
    "pineapple",
    "pineapples",
    "pear",
    "pears",
    "grape",
    "grapes",
    "plum",
    "plums",
    "cherry",
    "cherries",
    "melon",
    "melons",
    "watermelon",
    "watermelons",
    "papaya",
    "papayas",
    "coconut",
    "coconuts",
    "apricot",
    "apricots",
    "nectarine",
    "nectarines",
    "grapefruit",
    "grapefruits",
    "blueberry",
    "blueberries",
    "raspberry",
    "raspberries",
    "fig",
    "figs",
    "pomegranate",
    "pomegranates",
    "potato",
    "potatoes",
    "cucumber",
    "cucumbers",
    "onion",
    "onions",
    "egg",
    "eggs",
];

/// The singular of an `OTHER_FRUITS` word, for messages.
pub fn singular(w: &str) -> String {
    if let Some(stem) = w.strip_suffix("ies") {
        format!("{stem}y")
    } else if let Some(stem) = w.strip_suffix("oes") {
        format!("{stem}o")
    } else if w.ends_with("fruits") || (w.ends_with('s') && !w.ends_with("ss")) {
        w[..w.len() - 1].to_string()
    } else {
        w.to_string()
    }
}
