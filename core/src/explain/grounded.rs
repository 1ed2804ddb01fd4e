//! The groundedness check: a generated reply may only say what was measured. Every fruit it
//! names, every number, every ripeness and location word must come from the facts, and it
//! must not drop an object that answers the question, its hardness, its ripeness or a kind
//! that was not found.

use super::template::{likely_range_mpa, range_percent};
use super::{Facts, Measured};
use crate::catalog::FruitCatalog;

/// What makes a reply ungrounded, in words for the fallback notice.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Ungrounded {
    #[error("it names a {0} that was not measured")]
    InventedFruit(String),
    #[error("{0} is not a measured value")]
    InventedNumber(String),
    #[error("it calls something {0}, which no measured fruit is")]
    InventedRipeness(String),
    #[error("it places something {0}, where no measured fruit is")]
    InventedLocation(String),
    #[error("it leaves out the {0}")]
    DroppedObject(String),
    #[error("it leaves out the hardness of the {0}")]
    DroppedHardness(String),
    #[error("it leaves out that the {0} is {1}")]
    DroppedRipeness(String, String),
    #[error("it does not say that no {0} was found")]
    DroppedNotFound(String),
    #[error("it is empty")]
    Empty,
}

/// Units after which a number must be a hardness value (lower case, first word).
const HARDNESS_UNITS: &[&str] = &["mpa", "kpa", "shore", "pa"];
/// Numbers before "%" are read with it as their unit.
const PERCENT: &str = "%";
const RIPENESS_WORDS: &[&str] = &["unripe", "ripe", "overripe"];
const LOCATION_WORDS: &[&str] = &["left", "right", "front", "back"];

/// A number as written: its value and how many decimals it was given with.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Written {
    pub value: f64,
    pub decimals: i32,
}

impl Written {
    /// Whether `v` rounds to what was written (half a unit of the last digit, and 1% slack
    /// for a model that rounds 0.295 to 0.3 or converts units).
    pub fn matches(&self, v: f64) -> bool {
        let half = 0.5 * 10f64.powi(-self.decimals);
        (self.value - v).abs() <= half + 1e-9 || (self.value - v).abs() <= 0.01 * v.abs()
    }
}

/// Numbers in `text` with the word that follows each (lower case), e.g. (1.46, "mpa"), or
/// "%". "Shore 00" is a scale name, not a number.
pub fn numbers_with_units(text: &str) -> Vec<(Written, String)> {
    let chars: Vec<char> = text.chars().collect();
    let mut out = Vec::new();
    let mut i = 0;
    while i < chars.len() {
        let starts = chars[i].is_ascii_digit()
            && (i == 0 || !(chars[i - 1].is_alphanumeric() || chars[i - 1] == '.'));
        if !starts {
            i += 1;
            continue;
        }
        let begin = i;
        while i < chars.len() && chars[i].is_ascii_digit() {
            i += 1;
        }
        let mut decimals = 0;
        if i + 1 < chars.len() && chars[i] == '.' && chars[i + 1].is_ascii_digit() {
            i += 1;
            while i < chars.len() && chars[i].is_ascii_digit() {
                i += 1;
                decimals += 1;
            }
        }
        let literal: String = chars[begin..i].iter().collect();
        // "Shore 00" names a scale, not a value.
        let before: String = chars[..begin].iter().collect::<String>().to_lowercase();
        if literal == "00" && before.trim_end().ends_with("shore") {
            continue;
        }
        let rest: String = chars[i..].iter().collect();
        let rest = rest.trim_start();
        let unit = if rest.starts_with('%') {
            PERCENT.to_string()
        } else {
            rest.split(|c: char| !c.is_alphanumeric())
                .next()
                .unwrap_or("")
                .to_lowercase()
        };
        if let Ok(value) = literal.parse::<f64>() {
            out.push((Written { value, decimals }, unit));
        }
    }
    out
}

fn words(text: &str) -> Vec<String> {
    // "least ripe" / "most ripe" rank, they do not call anything ripe.
    text.to_lowercase()
        .replace("least ripe", "least")
        .replace("most ripe", "most")
        .split(|c: char| !c.is_alphanumeric())
        .filter(|w| !w.is_empty())
        .map(str::to_string)
        .collect()
}

/// The hardness values a reply may quote for one object: modulus (MPa, and kPa / Pa), Shore
/// A and 00, and the ends of its intervals.
fn hardness_values(m: &Measured) -> Vec<f64> {
    let Some(h) = m.hardness else {
        return Vec::new();
    };
    let mut v = vec![h.shore_a, h.shore_00];
    if let Some(e) = h.modulus_mpa {
        v.extend([e, e * 1e3, e * 1e6]);
    }
    v.extend(m.interval_68_mpa.iter().chain(&m.interval_95_mpa).flatten());
    v
}

/// The percentages a reply may quote for one object: the ends of its likely range relative to
/// the estimate, as the template words them.
fn percent_values(m: &Measured) -> Vec<f64> {
    match (m.hardness.and_then(|h| h.modulus_mpa), likely_range_mpa(m)) {
        (Some(e), Some(r)) if e > 0.0 => range_percent(e, r).map(f64::abs).to_vec(),
        _ => Vec::new(),
    }
}

/// Checks `reply` against `facts`: nothing invented, nothing dropped; the first problem
/// found is the error.
pub fn check(reply: &str, facts: &Facts, catalog: &FruitCatalog) -> Result<(), Ungrounded> {
    check_invented(reply, facts, catalog)?;
    check_dropped(reply, facts, catalog)
}

/// The first half of `check`: every fruit, number, ripeness and location word of `reply`
/// comes from `facts`.
pub fn check_invented(
    reply: &str,
    facts: &Facts,
    catalog: &FruitCatalog,
) -> Result<(), Ungrounded> {
    if reply.trim().is_empty() {
        return Err(Ungrounded::Empty);
    }
    let said = words(reply);
    let says = |w: &str| said.iter().any(|s| s == w);
    for w in &said {
        if let Some(f) = catalog.find_word(w) {
            let known = facts.objects.iter().any(|o| o.label == f.name)
                || facts.not_found.contains(&f.name)
                || facts.query.targets.contains(&f.name);
            if !known {
                return Err(Ungrounded::InventedFruit(f.name.clone()));
            }
        }
    }
    // The value a threshold question holds the fruit against may be said back.
    let hardness: Vec<f64> = facts
        .objects
        .iter()
        .flat_map(hardness_values)
        .chain(
            super::held_against(&facts.query, &facts.objects)
                .iter()
                .flat_map(|t| t.values()),
        )
        .collect();
    let percents: Vec<f64> = facts.objects.iter().flat_map(percent_values).collect();
    let counts: Vec<f64> = [
        Some(facts.objects.len()),
        Some(facts.selected.len()),
        facts.query.filters.count,
    ]
    .into_iter()
    .flatten()
    .chain(1..=facts.objects.len())
    .map(|n| n as f64)
    .collect();
    for (n, unit) in numbers_with_units(reply) {
        let grounded = if unit == PERCENT {
            percents.iter().any(|&v| n.matches(v))
        } else if HARDNESS_UNITS.contains(&unit.as_str()) {
            hardness.iter().any(|&v| n.matches(v))
        } else {
            hardness.iter().chain(&counts).any(|&v| n.matches(v))
        };
        if !grounded {
            let shown = format!("{:.*}", n.decimals as usize, n.value);
            let unit = if unit.is_empty() {
                String::new()
            } else {
                format!(" {unit}")
            };
            return Err(Ungrounded::InventedNumber(format!("{shown}{unit}")));
        }
    }
    for &r in RIPENESS_WORDS {
        if says(r)
            && !facts
                .objects
                .iter()
                .any(|o| o.ripeness.as_deref() == Some(r))
        {
            return Err(Ungrounded::InventedRipeness(r.into()));
        }
    }
    for &l in LOCATION_WORDS {
        if says(l)
            && !facts
                .objects
                .iter()
                .any(|o| o.location.split(' ').any(|w| w == l))
        {
            return Err(Ungrounded::InventedLocation(l.into()));
        }
    }

    Ok(())
}

/// The second half of `check`: every answering object with its hardness and ripeness, and
/// every kind not found, is in `reply`.
fn check_dropped(reply: &str, facts: &Facts, catalog: &FruitCatalog) -> Result<(), Ungrounded> {
    let said = words(reply);
    let says = |w: &str| said.iter().any(|s| s == w);
    let mentions_fruit = |name: &str| {
        said.iter()
            .any(|w| catalog.find_word(w).is_some_and(|f| f.name == name))
    };
    for &i in &facts.selected {
        let Some(m) = facts.objects.get(i) else {
            continue;
        };
        if !mentions_fruit(&m.label) {
            return Err(Ungrounded::DroppedObject(m.label.clone()));
        }
        let values = hardness_values(m);
        if !values.is_empty()
            && !numbers_with_units(reply)
                .iter()
                .any(|(n, _)| values.iter().any(|&v| n.matches(v)))
        {
            return Err(Ungrounded::DroppedHardness(m.label.clone()));
        }
        if let Some(r) = &m.ripeness
            && !says(r)
        {
            return Err(Ungrounded::DroppedRipeness(m.label.clone(), r.clone()));
        }
    }
    for kind in &facts.not_found {
        if !mentions_fruit(kind) {
            return Err(Ungrounded::DroppedNotFound(kind.clone()));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::explain::{Explainer, TemplateExplainer, location_words, select};
    use crate::hardness::scale::Hardness;

    fn facts(prompt: &str) -> (Facts, FruitCatalog) {
        let catalog = FruitCatalog::builtin();
        let query = crate::query::parse(prompt, &catalog).unwrap();
        let m = |label: &str, e: f64, x: f64, y: f64, r: &str| Measured {
            label: label.into(),
            location: location_words(x, y),
            hardness: Some(Hardness::ModulusMpa(e).into()),
            interval_68_mpa: [Some(e * 0.9), Some(e * 1.1)],
            interval_95_mpa: [Some(e * 0.8), Some(e * 1.2)],
            ripeness: Some(r.into()),
            not_measured: None,
            reference: false,
        };
        let objects = vec![
            m("banana", 0.80, -0.15, -0.1, "ripe"),
            m("lime", 4.0, 0.0, 0.0, "unripe"),
        ];
        let selected = select(&query, &objects, &catalog);
        let facts = Facts {
            prompt: prompt.into(),
            query,
            objects,
            selected,
            not_found: Vec::new(),
        };
        (facts, catalog)
    }

    #[test]
    fn a_threshold_may_be_said_back_but_not_another_value() {
        let (f, c) = facts("Which fruits are harder than 2 MPa?");
        let reply = "One fruit is harder than 2 MPa (44 Shore A): the lime at the centre, \
                     4.00 MPa, unripe. The banana at the left front is 0.80 MPa, ripe.";
        assert_eq!(check(reply, &f, &c), Ok(()), "{reply}");
        let reply = reply.replace("2 MPa", "2.5 MPa");
        assert!(matches!(
            check(&reply, &f, &c),
            Err(Ungrounded::InventedNumber(_))
        ));
    }

    #[test]
    fn numbers_are_read_with_their_decimals_and_units() {
        let n = numbers_with_units("It is 0.80 MPa ± 10 % (21 Shore 00), 3rd of 2.");
        let got: Vec<(f64, i32, &str)> = n
            .iter()
            .map(|(w, u)| (w.value, w.decimals, u.as_str()))
            .collect();
        assert_eq!(
            got,
            vec![
                (0.80, 2, "mpa"),
                (10.0, 0, "%"),
                (21.0, 0, "shore"),
                (3.0, 0, "rd"),
                (2.0, 0, "")
            ]
        );
    }

    #[test]
    fn the_template_is_grounded() {
        for prompt in [
            "Which fruit is the softest?",
            "Rank the fruits from softest to hardest",
            "How hard is the banana?",
            "Is the lime harder than the banana?",
            "Which fruits are harder than 2 MPa?",
            "Which fruits are softer than 30 Shore A?",
            "Is anything harder than 10 MPa?",
            "Which fruit is softer than 0.85 MPa?",
        ] {
            let (f, c) = facts(prompt);
            let text = TemplateExplainer.explain(&f).text;
            assert_eq!(check(&text, &f, &c), Ok(()), "{prompt}: {text}");
        }
    }

    #[test]
    fn a_paraphrase_with_the_measured_values_is_grounded() {
        let (f, c) = facts("Which fruit is the softest?");
        let reply = "The banana on the left front is the softest: about 0.8 MPa, and it is ripe.";
        assert_eq!(check(reply, &f, &c), Ok(()));
    }

    #[test]
    fn invented_and_dropped_claims_are_caught() {
        let (f, c) = facts("Which fruit is the softest?");
        let cases = [
            (
                "The banana at the left front is 0.35 MPa and ripe.",
                Ungrounded::InventedNumber("0.35 mpa".into()),
            ),
            (
                "The mango at the left front is 0.80 MPa and ripe.",
                Ungrounded::InventedFruit("mango".into()),
            ),
            (
                "The banana at the left front is 0.80 MPa and overripe.",
                Ungrounded::InventedRipeness("overripe".into()),
            ),
            (
                "The banana at the right is 0.80 MPa and ripe.",
                Ungrounded::InventedLocation("right".into()),
            ),
            (
                "The softest is at the left front, 0.80 MPa, ripe.",
                Ungrounded::DroppedObject("banana".into()),
            ),
            (
                "The banana at the left front is the softest and ripe.",
                Ungrounded::DroppedHardness("banana".into()),
            ),
            (
                "The banana at the left front is the softest at 0.80 MPa.",
                Ungrounded::DroppedRipeness("banana".into(), "ripe".into()),
            ),
            ("  ", Ungrounded::Empty),
        ];
        for (reply, want) in cases {
            assert_eq!(check(reply, &f, &c), Err(want), "{reply}");
        }
    }

    #[test]
    fn kinds_not_found_must_be_said() {
        let (mut f, c) = facts("How hard are the banana and the kiwi?");
        // Only the banana was asked for and found.
        f.objects.truncate(1);
        f.selected = vec![0];
        f.not_found = vec!["kiwi".into()];
        let reply = "The banana at the left front is 0.80 MPa and ripe.";
        assert_eq!(
            check(reply, &f, &c),
            Err(Ungrounded::DroppedNotFound("kiwi".into()))
        );
        let reply = "The banana at the left front is 0.80 MPa and ripe. I found no kiwi.";
        assert_eq!(check(reply, &f, &c), Ok(()));
    }
}
