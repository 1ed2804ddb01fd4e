//! A value the question holds the fruit against: "harder than 2 MPa", "softer than 30 Shore
//! A", "a Shore 00 above 60". The value is read with the hardness scale's own parser (MPa,
//! kPa, Shore A, Shore 00), and the direction from the words just before it.

use super::QueryError;
use crate::hardness::scale::{Hardness, HardnessReport};
use serde::Serialize;

/// How far before the value a direction word may stand ("harder than about 2 MPa").
const DIRECTION_REACH: usize = 4;

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Threshold {
    /// The fruit asked for are harder than the value (false: softer).
    pub harder: bool,
    /// The value as a modulus (MPa); infinite for "rigid".
    pub modulus_mpa: f64,
    /// The value as the prompt gave it, with its unit: "2 MPa", "30 Shore A".
    pub said: String,
}

impl Threshold {
    /// Whether a fruit of this modulus (MPa; infinite: rigid) is past the value.
    pub fn holds_for(&self, modulus_mpa: f64) -> bool {
        if self.harder {
            modulus_mpa > self.modulus_mpa
        } else {
            modulus_mpa < self.modulus_mpa
        }
    }

    /// "harder" or "softer", as the answer words the relation.
    pub fn relation(&self) -> &'static str {
        relation_word(self.harder)
    }

    /// The value on every scale; None for "rigid".
    fn report(&self) -> Option<HardnessReport> {
        Hardness::from_modulus_mpa(self.modulus_mpa)
            .ok()
            .map(HardnessReport::from)
    }

    /// The value as said and on the other scale: "2 MPa (57 Shore A)", "30 Shore A (0.97 MPa)".
    pub fn words(&self) -> String {
        match self.report() {
            None => self.said.clone(),
            Some(_) if self.said.contains("Shore") => {
                format!("{} ({:.2} MPa)", self.said, self.modulus_mpa)
            }
            Some(r) => format!("{} ({})", self.said, r.shore_words()),
        }
    }

    /// The numbers `words` may print, for the groundedness check: the modulus (MPa, kPa)
    /// and both Shore scales.
    pub fn values(&self) -> Vec<f64> {
        self.report().map_or_else(Vec::new, |r| {
            vec![
                self.modulus_mpa,
                self.modulus_mpa * 1e3,
                r.shore_a,
                r.shore_00,
            ]
        })
    }
}

/// The word for a direction against a value or a fruit.
pub(crate) fn relation_word(harder: bool) -> &'static str {
    if harder { "harder" } else { "softer" }
}

/// The relation's word: by ripeness within one kind the harder is the less ripe.
pub(crate) fn comparison_word(harder: bool, ripeness: bool) -> &'static str {
    match (ripeness, harder) {
        (false, _) => relation_word(harder),
        (true, true) => "less ripe",
        (true, false) => "riper",
    }
}

/// Another object the question holds the fruit against ("softer than the apple"): its
/// value is the reference's measured hardness, known once it is pressed.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Relation {
    /// The fruit asked for are harder than the reference (false: softer).
    pub harder: bool,
    /// The reference's catalog name.
    pub reference: String,
    /// Further references named with it ("softer than the apple and the mango"): the fruit
    /// asked for are past every one of them.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub also: Vec<String>,
    /// Where the reference stands, when the prompt says ("than the banana on the left"):
    /// only the one there is held against, in `explain::location_words` order. Only for a
    /// single reference.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub position: Option<String>,
    /// Ripeness between two of one kind ("Is the banana on the left riper than the one on
    /// the right?"): every catalog kind softens as it ripens, so within a kind the riper is
    /// the softer; `harder` then means less ripe. Across kinds stages are not comparable by
    /// modulus, and such a question is a comparison of the kinds' stages instead.
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub ripeness: bool,
}

impl Relation {
    /// "harder" or "softer" ("less ripe" or "riper"), as the answer words the relation.
    pub fn relation(&self) -> &'static str {
        comparison_word(self.harder, self.ripeness)
    }

    /// The references' catalog names, in the order named.
    pub fn kinds(&self) -> impl Iterator<Item = &str> {
        std::iter::once(self.reference.as_str()).chain(self.also.iter().map(String::as_str))
    }

    /// Whether objects of this kind are held against.
    pub fn holds_against(&self, label: &str) -> bool {
        self.kinds().any(|k| k == label)
    }

    /// The references as the answer names them after "the": "banana", "banana at the left",
    /// "apple and the mango".
    pub fn named(&self) -> String {
        match &self.position {
            Some(p) => format!("{} at the {p}", self.reference),
            None => self.kinds().collect::<Vec<_>>().join(" and the "),
        }
    }

    /// The value of the references' measured moduli (MPa; infinite: rigid), given with each
    /// object's kind, as a threshold: past every one of them ("softer than the apples" is
    /// softer than the softest apple; "than the apple and the mango" than the softer of
    /// the two). None when a reference's kind has no measured object.
    pub fn resolve(&self, readings: &[(&str, f64)]) -> Option<Threshold> {
        let past = |b: f64, e: f64| if self.harder { b.max(e) } else { b.min(e) };
        let several = !self.also.is_empty();
        let mut bound: Option<f64> = None;
        let mut phrases = Vec::new();
        for kind in self.kinds() {
            let moduli: Vec<f64> = readings
                .iter()
                .filter(|(k, _)| *k == kind)
                .map(|(_, e)| *e)
                .collect();
            let (&first, rest) = moduli.split_first()?;
            let kind_bound = rest.iter().fold(first, |b, &e| past(b, e));
            bound = Some(bound.map_or(kind_bound, |b| past(b, kind_bound)));
            let which = match (moduli.len(), self.harder) {
                (1, _) => "the",
                (_, true) => "the hardest",
                (_, false) => "the softest",
            };
            let named = if several {
                kind.to_string()
            } else {
                self.named()
            };
            phrases.push((
                kind_bound,
                if kind_bound.is_finite() && self.position.is_some() {
                    format!("{which} {named}, at {kind_bound:.2} MPa")
                } else if kind_bound.is_finite() {
                    format!("{which} {named} at {kind_bound:.2} MPa")
                } else {
                    format!("{which} {named}, which is rigid")
                },
            ));
        }
        // The reference that bounds comes last, where the value's other scale follows it.
        let bound = bound?;
        if let Some(k) = phrases.iter().position(|(b, _)| *b == bound) {
            let last = phrases.remove(k);
            phrases.push(last);
        }
        let phrases: Vec<String> = phrases.into_iter().map(|(_, p)| p).collect();
        let said = match phrases.as_slice() {
            [one] => one.clone(),
            [a, b] => format!("both {a} and {b}"),
            [init @ .., last] => format!("each of {} and {last}", init.join(", ")),
            [] => return None,
        };
        Some(Threshold {
            harder: self.harder,
            modulus_mpa: bound,
            said,
        })
    }
}

/// Whether the words just before word `i` compare ripeness with it ("riper than (the) X",
/// "less ripe than X", "greener than X"), and if so whether the fruit asked about is the
/// less ripe (true: "greener", "less ripe") or the riper.
pub fn ripeness_comparison_before(words: &[String], i: usize) -> Option<bool> {
    let k = than_before(words, i)?.checked_sub(1)?;
    let before = k.checked_sub(1).map(|m| words[m].as_str());
    let (less_ripe, at) = match (before, words[k].as_str()) {
        (_, "riper" | "readier") => (false, k),
        (_, "greener") => (true, k),
        (Some(more @ ("more" | "less")), base @ ("ripe" | "mature" | "green")) => {
            ((more == "less") == (base != "green"), k - 1)
        }
        _ => return None,
    };
    let negated = at > 0 && super::lexicon::negates(&words[at - 1]);
    Some(less_ripe != negated)
}

/// Either comparison before word `i`: (harder or less ripe, by ripeness).
pub fn any_comparison_before(words: &[String], i: usize) -> Option<(bool, bool)> {
    comparison_before(words, i)
        .map(|h| (h, false))
        .or(ripeness_comparison_before(words, i).map(|h| (h, true)))
}

/// The index of "than" just before word `i`, past articles and what describes the fruit
/// ("than that ripe yellow banana").
fn than_before(words: &[String], i: usize) -> Option<usize> {
    let mut j = i.checked_sub(1)?;
    while matches!(
        words[j].as_str(),
        "the"
            | "a"
            | "an"
            | "that"
            | "this"
            | "my"
            | "your"
            | "ripe"
            | "unripe"
            | "both"
            | "either"
            | "other"
            | "each"
            | "all"
            | "of"
    ) || super::lexicon::COLOURS.contains(&words[j].as_str())
        || super::lexicon::position_word(&words[j]).is_some()
        // "than the two apples" (a numeral there would be a value: "than 2 MPa").
        || (super::lexicon::count_word(&words[j]).is_some()
            && words[j].chars().all(char::is_alphabetic))
    {
        j = j.checked_sub(1)?;
    }
    (words[j] == "than").then_some(j)
}

/// Which way the words just before word `i` compare it, when they do: "softer than (the)
/// X", "not harder than X", "less firm than X". Some(true): harder than X.
pub fn comparison_before(words: &[String], i: usize) -> Option<bool> {
    let k = than_before(words, i)?.checked_sub(1)?;
    // "less firm than", "more soft than": a base property word after "more" or "less".
    let before_k = k.checked_sub(1).map(|m| words[m].as_str());
    let (harder, at) = match (before_k, words[k].as_str()) {
        (Some(more @ ("more" | "less")), base) => {
            let soft = matches!(base, "soft" | "squishy" | "tender" | "mushy");
            let hard = matches!(base, "hard" | "firm" | "stiff" | "solid" | "tough");
            if !(soft || hard) {
                return None;
            }
            ((more == "more") == hard, k - 1)
        }
        (_, "more" | "less") => return None,
        _ => (direction(words, k)?, k),
    };
    let negated = at > 0 && super::lexicon::negates(&words[at - 1]);
    Some(harder != negated)
}

/// Lower-cased words, a number kept whole with its sign and decimal point ("-2", ".5",
/// "2.5"; "2,5" too, to be refused by name), and ">", "<" read as "above", "below".
fn tokens(prompt: &str) -> Vec<String> {
    let chars: Vec<char> = prompt
        .to_lowercase()
        .chars()
        .map(super::lexicon::unaccented)
        .collect();
    let mut out = Vec::new();
    let mut word = String::new();
    for (i, &c) in chars.iter().enumerate() {
        let prev = i.checked_sub(1).map(|k| chars[k]);
        let next_digit = chars.get(i + 1).is_some_and(|d| d.is_ascii_digit());
        let prev_digit = prev.is_some_and(|d| d.is_ascii_digit());
        let sign = matches!(c, '-' | '\u{2212}')
            && next_digit
            && word.is_empty()
            && !prev.is_some_and(char::is_alphanumeric);
        if c.is_alphanumeric() || (c == '.' && next_digit) || (c == ',' && prev_digit && next_digit)
        {
            word.push(c);
        } else if sign {
            word.push('-');
        } else {
            if !word.is_empty() {
                out.push(std::mem::take(&mut word));
            }
            match c {
                '>' | '\u{2265}' => out.push("above".into()),
                '<' | '\u{2264}' => out.push("below".into()),
                _ => {}
            }
        }
    }
    if !word.is_empty() {
        out.push(word);
    }
    out
}

/// Whether a word is a number as written: "2", "2.5", ".5", "-2".
fn is_number(w: &str) -> bool {
    let w = w.strip_prefix('-').unwrap_or(w);
    let w = w.strip_prefix('.').unwrap_or(w);
    w.starts_with(|c: char| c.is_ascii_digit())
}

/// Units of hardness or pressure the answer does not read, as they follow a number.
const OTHER_UNITS: &[&str] = &[
    "pa", "gpa", "psi", "ksi", "bar", "pascal", "pascals", "n", "newton", "newtons",
];

/// The direction said after a value: "3 MPa or more", "1 MPa and below".
fn direction_after(words: &[String], end: usize) -> Option<bool> {
    let link = words.get(end + 1).map(String::as_str);
    if !matches!(link, Some("or" | "and")) {
        return None;
    }
    match words.get(end + 2).map(String::as_str)? {
        "more" | "above" | "over" | "higher" | "harder" | "firmer" | "greater" | "up" => Some(true),
        "less" | "below" | "under" | "lower" | "softer" | "fewer" | "down" => Some(false),
        _ => None,
    }
}

/// Which way a word before the value points: Some(true) harder, Some(false) softer.
fn direction(words: &[String], i: usize) -> Option<bool> {
    let w = words[i].as_str();
    let prev = i.checked_sub(1).map(|j| words[j].as_str());
    let next = words.get(i + 1).map(String::as_str);
    // "more soft", "less soft": the property word after turns the comparison round.
    let soft_next = next.is_some_and(|n| matches!(n, "soft" | "squishy" | "tender"));
    match w {
        "harder" | "firmer" | "stiffer" | "tougher" | "crunchier" | "above" | "over"
        | "exceeding" | "exceed" | "exceeds" | "greater" | "higher" | "beyond" => Some(true),
        "softer" | "squishier" | "mushier" | "squashier" | "tenderer" | "below" | "under"
        | "lower" | "beneath" => Some(false),
        "more" => Some(!soft_next),
        "less" => Some(soft_next),
        "least" if prev == Some("at") => Some(true),
        "most" if prev == Some("at") => Some(false),
        _ => None,
    }
}

/// Whether a word before the value compares ("than", a direction word), so that a bare
/// number after it must have been meant as a hardness.
fn compares(words: &[String], i: usize) -> bool {
    words[i] == "than" || direction(words, i).is_some()
}

/// The threshold the prompt states, if it states one. An error names a value the prompt
/// compares against without a unit, in a unit not read, off its scale, without saying which
/// way, or beside a second value.
pub fn find(prompt: &str) -> Result<Option<Threshold>, QueryError> {
    // "mPa", as written, is the millipascal: a slip for MPa, but not one to guess.
    if let Some(at) = prompt.match_indices("mPa").map(|(k, _)| k).find(|&k| {
        !prompt[..k].ends_with(char::is_alphabetic)
            && !prompt[k + 3..].starts_with(char::is_alphanumeric)
    }) {
        let number: String = prompt[..at]
            .trim_end()
            .chars()
            .rev()
            .take_while(|c| c.is_ascii_digit() || *c == '.')
            .collect::<Vec<_>>()
            .into_iter()
            .rev()
            .collect();
        return Err(QueryError::BadThreshold {
            value: format!("{number} mPa").trim().to_string(),
            message: "mPa is the millipascal; write MPa for megapascals (2 MPa) or kPa".into(),
        });
    }
    let words = tokens(prompt);
    let mut found: Option<Threshold> = None;
    // Words read as a value's unit ("60 Shore 00": the "00" is not a second number).
    let mut read_until = 0;
    for i in 0..words.len() {
        let names_scale = i > 0 && words[i - 1] == "shore";
        // "NaN MPa", "inf MPa", "two MPa", "２ MPa": a value the number reader does not take,
        // which would otherwise drop the bound without a word.
        let w = words[i].as_str();
        let unreadable = matches!(w, "nan" | "inf" | "infinity")
            || (super::lexicon::count_word(w).is_some() && w.chars().all(char::is_alphabetic))
            || w.chars().any(|c| c.is_numeric() && !c.is_ascii_digit());
        if unreadable
            && words
                .get(i + 1)
                .is_some_and(|u| matches!(u.as_str(), "mpa" | "kpa" | "shore"))
        {
            return Err(QueryError::BadThreshold {
                value: w.to_string(),
                message: "write the value in plain digits, e.g. 2 MPa or 30 Shore A".into(),
            });
        }
        if i < read_until || names_scale || !is_number(&words[i]) {
            continue;
        }
        let bad = |message: String| QueryError::BadThreshold {
            value: words[i].clone(),
            message,
        };
        let before = (i.saturating_sub(DIRECTION_REACH)..i)
            .rev()
            .find_map(|j| direction(&words, j).map(|d| (j, d)))
            .map(|(j, harder)| {
                // "not harder than 2 MPa", "no softer than", "isn't firmer than".
                let negated = j > 0 && super::lexicon::negates(&words[j - 1]);
                harder != negated
            });
        // "1 000 kPa", "1'000 kPa": digit groups split into two numbers, the first of which
        // would be read alone.
        let group = |w: &str| w.len() == 3 && w.chars().all(|c| c.is_ascii_digit());
        if words[i].chars().all(|c| c.is_ascii_digit())
            && words.get(i + 1).is_some_and(|w| group(w))
        {
            let mut end = i + 1;
            while words.get(end + 1).is_some_and(|w| group(w)) {
                end += 1;
            }
            return Err(QueryError::BadThreshold {
                value: words[i..=end].join(" "),
                message: format!(
                    "write the number without spaces or marks between its digits ({})",
                    words[i..=end].concat()
                ),
            });
        }
        if words[i].contains(',') && words[i].contains('.') {
            return Err(bad(format!(
                "write it without the comma ({})",
                words[i].replace(',', "")
            )));
        }
        if let Some((whole, rest)) = words[i].split_once(',') {
            // "1,000 kPa" groups thousands, or is 1.000 written the European way.
            let grouped = !whole.is_empty()
                && rest
                    .split(',')
                    .all(|g| g.len() == 3 && g.chars().all(|c| c.is_ascii_digit()));
            return Err(bad(if grouped {
                format!(
                    "reads as {} or as {}: write it without the comma",
                    words[i].replace(',', ""),
                    words[i].replacen(',', ".", 1)
                )
            } else {
                "write the number with a decimal point (2.5 MPa)".into()
            }));
        }
        let (value, said, end) = match value_at(&words, i) {
            Some(Ok(found)) => found,
            Some(Err(message)) => return Err(bad(message)),
            None => {
                if let Some(unit) = words
                    .get(i + 1)
                    .filter(|u| OTHER_UNITS.contains(&u.as_str()))
                {
                    return Err(bad(format!(
                        "the unit '{unit}' is not one I read; say MPa, kPa, Shore A or Shore 00"
                    )));
                }
                if words.get(i + 1).is_some_and(|w| w == "shore") {
                    return Err(bad(
                        "the Shore scale is not one I read; say Shore A or Shore 00".into(),
                    ));
                }
                if before.is_some() && i > 0 && compares(&words, i - 1) {
                    return Err(bad(
                        "has no unit; say e.g. 2 MPa, 30 Shore A or 60 Shore 00".into(),
                    ));
                }
                continue;
            }
        };
        read_until = end + 1;
        let Some(harder) = before.or_else(|| direction_after(&words, end)) else {
            return Err(QueryError::BadThreshold {
                value: said.clone(),
                message: format!("say which way: harder than {said}, or softer than {said}"),
            });
        };
        if let Some(first) = &found {
            return Err(QueryError::BadThreshold {
                value: said,
                message: format!(
                    "a second value beside {}: ask about one at a time",
                    first.said
                ),
            });
        }
        found = Some(Threshold {
            harder,
            modulus_mpa: value.modulus_mpa().unwrap_or(f64::INFINITY),
            said,
        });
    }
    Ok(found)
}

/// The hardness value whose number is word `i`, as said, and the index of its last word:
/// its unit after it ("2 MPa", "30 Shore A", "2mpa", "30 ShoreA") or its scale before it
/// ("Shore A above 40"). None: no unit; Err: not a hardness, or off its scale.
fn value_at(words: &[String], i: usize) -> Option<Result<(Hardness, String, usize), String>> {
    let number = &words[i];
    let unit_after: Vec<&str> = words[i + 1..].iter().take(3).map(String::as_str).collect();
    let after = match unit_after.as_slice() {
        // N/mm2 is the megapascal; the units spelt out are read as their symbols.
        ["n", "mm2" | "mm²", ..] => Some(("mpa".to_string(), i + 2)),
        ["n", "mm", "2", ..] | ["n", "per", "mm2" | "mm²"] => Some(("mpa".to_string(), i + 3)),
        ["megapascal" | "megapascals", ..] => Some(("mpa".to_string(), i + 1)),
        ["kilopascal" | "kilopascals", ..] => Some(("kpa".to_string(), i + 1)),
        ["shore", s, ..] if matches!(*s, "a" | "00" | "oo") => Some((format!("shore {s}"), i + 2)),
        ["shorea", ..] => Some(("shore a".to_string(), i + 1)),
        ["shore00" | "shoreoo", ..] => Some(("shore 00".to_string(), i + 1)),
        [u, ..] if matches!(*u, "mpa" | "kpa" | "a" | "00" | "oo") => Some((u.to_string(), i + 1)),
        _ => None,
    };
    // A scale named before the value: "a Shore A hardness above 40".
    let before = || {
        (0..i).rev().take(DIRECTION_REACH + 2).find_map(|j| {
            (words[j] == "shore")
                .then(|| words.get(j + 1))
                .flatten()
                .filter(|s| matches!(s.as_str(), "a" | "00" | "oo"))
                .map(|s| (format!("shore {s}"), i))
        })
    };
    let attached = number.trim_start_matches(|c: char| c.is_ascii_digit() || c == '.' || c == '-');
    // "2e3 kPa", "1e-400 MPa" (split at its sign): an exponent, which the answer's scales
    // do not print back; said plainly it is read.
    if attached
        .strip_prefix('e')
        .is_some_and(|rest| rest.chars().all(|c| c.is_ascii_digit()))
    {
        return Some(Err(
            "write the number in plain digits, without an exponent (e.g. 2000 kPa)".into(),
        ));
    }
    if !attached.is_empty() {
        // "2mpa", "30a"; "2j", "3rd" are no values at all.
        let h = Hardness::parse(number).ok()?;
        return Some(Ok((h, unit_said(number, ""), i)));
    }
    let (text, said, end) = if let Some((unit, end)) = after.or_else(before) {
        (format!("{number} {unit}"), unit_said(number, &unit), end)
    } else {
        return None;
    };
    Some(
        Hardness::parse(&text)
            .map(|h| (h, said, end))
            .map_err(|e| e.to_string()),
    )
}

/// The value as an answer says it: "2 MPa", "30 Shore A", "60 Shore 00".
fn unit_said(number: &str, unit: &str) -> String {
    let (digits, attached) = number.split_at(
        number
            .find(|c: char| !(c.is_ascii_digit() || c == '.' || c == '-'))
            .unwrap_or(number.len()),
    );
    let unit = if unit.is_empty() { attached } else { unit };
    let unit = match unit.trim_start_matches("shore").trim() {
        "mpa" => "MPa",
        "kpa" => "kPa",
        "a" => "Shore A",
        "00" | "oo" => "Shore 00",
        other => other,
    };
    format!("{digits} {unit}")
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::hardness::scale::shore_a_to_modulus_mpa;

    fn words(text: &str) -> Vec<String> {
        text.split(' ').map(str::to_string).collect()
    }

    #[test]
    fn a_comparison_before_a_name_says_which_way() {
        let at_end = |t: &str| {
            let w = words(t);
            comparison_before(&w, w.len() - 1)
        };
        assert_eq!(at_end("softer than the apple"), Some(false));
        assert_eq!(at_end("harder than apple"), Some(true));
        assert_eq!(at_end("not harder than the apple"), Some(false));
        assert_eq!(at_end("less firm than the apple"), Some(false));
        assert_eq!(at_end("more soft than the apple"), Some(false));
        assert_eq!(at_end("less soft than my apple"), Some(true));
        assert_eq!(at_end("bigger than the apple"), None);
        assert_eq!(at_end("the apple"), None);
        assert_eq!(at_end("than the apple"), None);
        assert_eq!(at_end("more than the apple"), None);
    }

    #[test]
    fn a_ripeness_comparison_says_which_is_the_less_ripe() {
        let at_end = |t: &str| {
            let w = words(t);
            ripeness_comparison_before(&w, w.len() - 1)
        };
        assert_eq!(at_end("riper than the banana"), Some(false));
        assert_eq!(at_end("readier than the banana"), Some(false));
        assert_eq!(at_end("greener than the banana"), Some(true));
        assert_eq!(at_end("more ripe than the banana"), Some(false));
        assert_eq!(at_end("less ripe than the banana"), Some(true));
        assert_eq!(at_end("less mature than the banana"), Some(true));
        assert_eq!(at_end("more green than the banana"), Some(true));
        assert_eq!(at_end("less green than the banana"), Some(false));
        assert_eq!(at_end("not riper than the banana"), Some(true));
        assert_eq!(at_end("softer than the banana"), None);
        assert_eq!(at_end("ripe than the banana"), None);
        // Worded as the relation's answer.
        assert_eq!(comparison_word(false, true), "riper");
        assert_eq!(comparison_word(true, true), "less ripe");
        assert_eq!(comparison_word(true, false), "harder");
    }

    #[test]
    fn a_relation_holds_the_fruit_past_every_measured_reference() {
        let softer = Relation {
            position: None,
            harder: false,
            reference: "apple".into(),
            also: Vec::new(),
            ripeness: false,
        };
        assert_eq!(softer.resolve(&[]), None);
        assert_eq!(softer.resolve(&[("mango", 3.0)]), None);
        let one = softer.resolve(&[("apple", 3.25)]).unwrap();
        assert_eq!(one.said, "the apple at 3.25 MPa");
        assert!(one.holds_for(3.0) && !one.holds_for(3.25));
        let two = softer.resolve(&[("apple", 3.25), ("apple", 2.0)]).unwrap();
        assert_eq!(
            (two.modulus_mpa, two.said.as_str()),
            (2.0, "the softest apple at 2.00 MPa")
        );
        let harder = Relation {
            position: None,
            harder: true,
            ..softer.clone()
        };
        assert_eq!(
            harder
                .resolve(&[("apple", 3.25), ("apple", 2.0)])
                .unwrap()
                .modulus_mpa,
            3.25
        );
        // Several references: past each of them, each said with its reading; one of them
        // unmeasured leaves nothing to hold against.
        let both = Relation {
            also: vec!["mango".into()],
            ..softer
        };
        let t = both
            .resolve(&[("mango", 3.36), ("apple", 3.29), ("lime", 1.7)])
            .unwrap();
        assert_eq!(t.modulus_mpa, 3.29);
        assert_eq!(
            t.said,
            "both the mango at 3.36 MPa and the apple at 3.29 MPa"
        );
        assert_eq!(both.resolve(&[("apple", 3.29)]), None);
        assert_eq!(both.named(), "apple and the mango");
        assert!(both.holds_against("mango") && !both.holds_against("lime"));
        assert_eq!(
            harder.resolve(&[("apple", f64::INFINITY)]).unwrap().said,
            "the apple, which is rigid"
        );
    }

    fn read(prompt: &str) -> Threshold {
        find(prompt)
            .unwrap()
            .unwrap_or_else(|| panic!("no threshold in {prompt:?}"))
    }

    #[test]
    fn values_and_directions_are_read_in_every_unit() {
        for (prompt, harder, mpa, said) in [
            ("Which fruits are harder than 2 MPa?", true, 2.0, "2 MPa"),
            (
                "Which fruits are harder than 2.5 mpa?",
                true,
                2.5,
                "2.5 MPa",
            ),
            ("Show me fruit firmer than 2MPa", true, 2.0, "2 MPa"),
            ("anything softer than 800 kPa?", false, 0.8, "800 kPa"),
            ("fruits with a hardness above 1.5 MPa", true, 1.5, "1.5 MPa"),
            ("which ones are below 1 MPa", false, 1.0, "1 MPa"),
            ("Which fruit is less hard than 3 MPa?", false, 3.0, "3 MPa"),
            ("Is any fruit more than 4 MPa hard?", true, 4.0, "4 MPa"),
            ("fruit that is less soft than 1 MPa", true, 1.0, "1 MPa"),
            (
                "Which fruits are not harder than 2 MPa?",
                false,
                2.0,
                "2 MPa",
            ),
            ("Which fruit is no softer than 1 MPa?", true, 1.0, "1 MPa"),
            ("Which one isn't firmer than 3 MPa?", false, 3.0, "3 MPa"),
            ("Which fruits are harder than .5 MPa?", true, 0.5, ".5 MPa"),
            ("Which fruits are 3 MPa or more?", true, 3.0, "3 MPa"),
            ("fruits of 1 MPa or less", false, 1.0, "1 MPa"),
            ("Which fruits are > 2 MPa?", true, 2.0, "2 MPa"),
            ("Which fruits are < 2 MPa?", false, 2.0, "2 MPa"),
        ] {
            let t = read(prompt);
            assert_eq!(t.harder, harder, "{prompt}");
            assert!((t.modulus_mpa - mpa).abs() < 1e-4 * mpa, "{prompt}: {t:?}");
            assert_eq!(t.said, said, "{prompt}");
        }
        for (prompt, harder, shore_a) in [
            ("Which fruits are softer than 30 Shore A?", false, 30.0),
            ("fruits harder than 45 shore a", true, 45.0),
            ("any fruit with a Shore A hardness over 40?", true, 40.0),
            ("softer than 30A please", false, 30.0),
            ("fruits harder than 30 ShoreA", true, 30.0),
        ] {
            let t = read(prompt);
            assert_eq!(t.harder, harder, "{prompt}");
            let e = shore_a_to_modulus_mpa(shore_a).unwrap();
            assert!((t.modulus_mpa - e).abs() < 1e-12, "{prompt}: {t:?}");
            assert_eq!(t.said, format!("{shore_a:.0} Shore A"), "{prompt}");
        }
        let t = read("Which fruits are softer than 60 Shore 00?");
        assert!(!t.harder && t.said == "60 Shore 00");
    }

    #[test]
    fn a_number_without_a_comparison_or_unit_is_no_threshold() {
        for prompt in [
            "hello \u{1b}[2J there",
            "Which is the 3rd fruit from the left?",
            "Which of the 2 bananas is softer?",
            "Rank the 3 fruits from softest to hardest",
            "Which fruit is the softest?",
            "Is the apple harder than the mango?",
        ] {
            assert_eq!(find(prompt).unwrap(), None, "{prompt}");
        }
    }

    #[test]
    fn a_compared_value_without_a_unit_or_off_its_scale_is_named() {
        for (prompt, value) in [
            ("Which fruits are harder than 2?", "2"),
            ("fruits softer than 150 Shore A", "150"),
            ("harder than 0 MPa", "0"),
            ("harder than -2 MPa", "-2"),
            ("softer than 2,5 MPa", "2,5"),
            ("harder than 300 psi", "300"),
            ("harder than 30 Shore D", "30"),
            ("Is the apple 2 MPa?", "2 MPa"),
            ("harder than 1 MPa and softer than 2 MPa", "2 MPa"),
            ("between 1 and 2 MPa", "2 MPa"),
        ] {
            match find(prompt) {
                Err(QueryError::BadThreshold { value: v, message }) => {
                    assert_eq!(v, value, "{prompt}: {message}");
                }
                other => panic!("{prompt}: {other:?}"),
            }
        }
    }

    #[test]
    fn the_value_is_said_back_on_the_other_scale_and_tested_strictly() {
        let t = read("harder than 2 MPa");
        assert!(t.words().starts_with("2 MPa (") && t.words().ends_with("Shore A)"));
        assert!(t.holds_for(2.5) && !t.holds_for(2.0) && t.holds_for(f64::INFINITY));
        let t = read("softer than 30 Shore A");
        assert!(t.words().starts_with("30 Shore A (") && t.words().ends_with(" MPa)"));
        assert!(t.holds_for(0.1) && !t.holds_for(f64::INFINITY));
    }
}
