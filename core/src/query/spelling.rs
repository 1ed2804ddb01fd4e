//! Misspelt fruit names ("bananna", "aple", "avacado") read as the catalog's, and said back:
//! dropped silently, a misspelt fruit changed the question without a word. Only typing slips
//! are taken (one edit, two in names of seven letters or more, the first letter kept), and
//! never an English word one edit from a fruit ("apply", "peace", "lines").

use crate::catalog::FruitCatalog;
use serde::Serialize;

/// A word of the prompt read as a catalog word it is a slip of.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct Correction {
    pub said: String,
    pub read: String,
}

/// English words a typing slip away from a catalog word: they mean themselves.
const ENGLISH: &[&str] = &[
    "apply", "ample", "ampler", "applied", "peace", "perch", "poach", "pooch", "lines", "liked",
    "likes", "limbs", "mange", "manga", "mangy", "bandana", "bandanas", "lemony", "orangy", "line",
    "like", "limb", "lima", "time", "peaces", "lemma", "lemmas", "peachy", "mangle", "mangles",
    "mangled", "applet", "applets", "limey", "orangey",
];

/// The catalog word `word` is a typing slip of, if exactly one is that near.
pub fn slip_of(word: &str, catalog: &FruitCatalog) -> Option<String> {
    if word.chars().count() < 4
        || !word.chars().all(|c| c.is_ascii_lowercase())
        || catalog.find_word(word).is_some()
        || super::lexicon::OTHER_FRUITS.contains(&word)
        || super::lexicon::COLOUR_COMPARATIVES.contains(&word)
        || super::lexicon::property_word(word).is_some()
        || ENGLISH.contains(&word)
    {
        return None;
    }
    let mut best: Option<(usize, &str)> = None;
    let mut tied = false;
    for fruit in &catalog.fruits {
        let names = [fruit.name.as_str(), fruit.plural.as_str()];
        for target in names
            .into_iter()
            .chain(fruit.synonyms.iter().map(String::as_str))
        {
            if target.chars().next() != word.chars().next() {
                continue;
            }
            // A four-letter word is taken only as a letter left out ("aple", "kiwi" kept).
            if word.len() == 4 && target.len() <= word.len() {
                continue;
            }
            let allowed = if target.len() >= 7 { 2 } else { 1 };
            let d = edits(word, target);
            if d == 0 || d > allowed {
                continue;
            }
            match best {
                Some((b, name)) if d == b && name != fruit.name => tied = true,
                Some((b, _)) if d >= b => {}
                _ => {
                    best = Some((d, fruit.name.as_str()));
                    tied = false;
                }
            }
        }
    }
    // The plural's word when the slip is nearer the plural ("tomatos"): the reader counts a
    // plural as asking about every one of the kind.
    best.filter(|_| !tied).map(|(_, name)| {
        let fruit = catalog.get(name).expect("a catalog name");
        let (to_plural, to_name) = (edits(word, &fruit.plural), edits(word, &fruit.name));
        if to_plural < to_name || (to_plural == to_name && word.ends_with('s')) {
            fruit.plural.clone()
        } else {
            fruit.name.clone()
        }
    })
}

/// The words with every typing slip of a catalog word replaced, and what was replaced.
pub fn corrected(words: Vec<String>, catalog: &FruitCatalog) -> (Vec<String>, Vec<Correction>) {
    let mut corrections: Vec<Correction> = Vec::new();
    let words = words
        .into_iter()
        .map(|w| match slip_of(&w, catalog) {
            Some(read) => {
                if !corrections.iter().any(|c| c.said == w) {
                    corrections.push(Correction {
                        said: w,
                        read: read.clone(),
                    });
                }
                read
            }
            None => w,
        })
        .collect();
    (words, corrections)
}

/// Edits (insert, delete, substitute, swap two neighbours) between two words: the optimal
/// string alignment distance.
fn edits(a: &str, b: &str) -> usize {
    let (a, b): (Vec<char>, Vec<char>) = (a.chars().collect(), b.chars().collect());
    let mut d = vec![vec![0usize; b.len() + 1]; a.len() + 1];
    for (i, row) in d.iter_mut().enumerate() {
        row[0] = i;
    }
    for (j, cell) in d[0].iter_mut().enumerate() {
        *cell = j;
    }
    for i in 1..=a.len() {
        for j in 1..=b.len() {
            let cost = usize::from(a[i - 1] != b[j - 1]);
            let mut v = (d[i - 1][j] + 1)
                .min(d[i][j - 1] + 1)
                .min(d[i - 1][j - 1] + cost);
            if i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1] {
                v = v.min(d[i - 2][j - 2] + 1);
            }
            d[i][j] = v;
        }
    }
    d[a.len()][b.len()]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn typing_slips_of_fruit_names_read_as_the_fruit() {
        let c = FruitCatalog::builtin();
        for (said, read) in [
            ("bananna", "banana"),
            ("aple", "apple"),
            ("appel", "apple"),
            ("avacado", "avocado"),
            ("avocadoe", "avocado"),
            ("tomatos", "tomatoes"),
            ("strawbery", "strawberry"),
            ("lemmon", "lemon"),
            ("bananas", "bananas"),
            ("peech", "peach"),
            ("mangoe", "mango"),
        ] {
            if said == read {
                assert_eq!(slip_of(said, &c), None, "{said} is a catalog word");
            } else {
                assert_eq!(slip_of(said, &c).as_deref(), Some(read), "{said}");
            }
        }
    }

    #[test]
    fn english_words_near_a_fruit_mean_themselves() {
        let c = FruitCatalog::builtin();
        for w in [
            "apply",
            "peace",
            "lines",
            "line",
            "time",
            "like",
            "fine",
            "ample",
            "lime",
            "kiwi",
            "soft",
            "softest",
            "riper",
            "which",
            "left",
            "right",
            "pineapple",
            "melon",
            "orange",
            "range",
            "peel",
            "pear",
            "table",
            "change",
            "grange",
            "banal",
            "manage",
        ] {
            assert_eq!(slip_of(w, &c), None, "{w}");
        }
    }

    #[test]
    fn edits_count_a_swap_as_one() {
        assert_eq!(edits("appel", "apple"), 1);
        assert_eq!(edits("aple", "apple"), 1);
        assert_eq!(edits("kitten", "sitting"), 3);
        assert_eq!(edits("", "abc"), 3);
    }
}
