//! The template explainer: deterministic, offline text from the measured result, with each
//! hardness given with its likely range (the calibrated 68% interval).

use super::{Explainer, Explanation, Facts, Measured, stiffness};
use crate::hardness::scale::HardnessReport;
use crate::query::threshold::{Threshold, comparison_word};
use crate::query::{Extreme, Intent, Property, Query};

/// The default explainer: the same facts always give the same words.
#[derive(Clone, Copy, Debug, Default)]
pub struct TemplateExplainer;

impl Explainer for TemplateExplainer {
    fn name(&self) -> &str {
        "template"
    }

    fn explain(&self, facts: &Facts) -> Explanation {
        Explanation {
            text: explain(
                &facts.query,
                &facts.objects,
                &facts.selected,
                &facts.not_found,
            ),
            explainer: "template".into(),
            notice: None,
        }
    }
}

/// The 68% interval (MPa) when it is bounded on both sides.
pub fn likely_range_mpa(m: &Measured) -> Option<[f64; 2]> {
    match m.interval_68_mpa {
        [Some(lo), Some(hi)] if hi >= lo && hi.is_finite() => Some([lo, hi]),
        _ => None,
    }
}

/// A modulus range in words, each number with its unit: "1.21 MPa to 1.72 MPa".
pub fn range_words([lo, hi]: [f64; 2]) -> String {
    format!("{lo:.2} MPa to {hi:.2} MPa")
}

/// The ends of a range around `e` in percent of it, as the answer words them: [-9, 7].
pub fn range_percent(e: f64, [lo, hi]: [f64; 2]) -> [f64; 2] {
    [lo, hi].map(|v| (100.0 * (v / e - 1.0)).round())
}

/// "36 Shore A (1.46 MPa, likely -9% to +7%)", "55 Shore 00 (0.29 MPa)", "rigid". The range
/// is the 68% interval, whose coverage is measured (`eval fruits`), relative to the estimate.
fn describe_hardness(h: &HardnessReport, likely: Option<[f64; 2]>) -> String {
    let Some(e) = h.modulus_mpa else {
        return "rigid".into();
    };
    let modulus = match likely.filter(|_| e > 0.0) {
        Some(r) => {
            let [lo, hi] = range_percent(e, r);
            format!("{e:.2} MPa, likely {lo:+.0}% to {hi:+.0}%")
        }
        None => format!("{e:.2} MPa"),
    };
    format!("{} ({modulus})", h.shore_words())
}

fn hardness_of(m: &Measured) -> Option<String> {
    m.hardness
        .as_ref()
        .map(|h| describe_hardness(h, likely_range_mpa(m)))
}

fn describe(m: &Measured) -> String {
    let mut s = format!("the {} at the {}", m.label, m.location);
    match hardness_of(m) {
        Some(h) => {
            s += &format!(", {h}");
            if let Some(r) = &m.ripeness {
                s += &format!(", {r}");
            }
        }
        None => match &m.not_measured {
            Some(why) => s += &format!(", which I could not measure ({why})"),
            None => s += ", which I could not measure",
        },
    }
    s
}

/// A measured fruit in a list of the others: "mango at 59 Shore A (3.43 MPa)".
fn in_brief(m: &Measured) -> Option<String> {
    let h = m.hardness.as_ref()?;
    Some(format!("{} at {}", m.label, describe_hardness(h, None)))
}

/// The sentences of a threshold's answer: the fruit past the value (or that none is, and
/// the nearest), the others asked about, and any whose likely range holds the value.
fn past_threshold(
    query: &Query,
    t: &Threshold,
    objects: &[Measured],
    selected: &[usize],
) -> Vec<String> {
    // Against another of the same kind by ripeness ("riper than the one on the left").
    let by_ripeness = query.relation.as_ref().is_some_and(|r| r.ripeness);
    let rel = comparison_word(t.harder, by_ripeness);
    let value = t.words();
    // How far past the value a fruit lies: the hardest first after "harder than".
    let past = |i: usize| {
        let e = stiffness(&objects[i]);
        if t.harder { e } else { -e }
    };
    let kind = query.asked_kind();
    let asked: Vec<usize> = (0..objects.len())
        .filter(|&i| {
            query.asks_about(&objects[i].label, objects[i].reference)
                && objects[i].hardness.is_some()
        })
        .collect();
    let mut parts = Vec::new();
    if selected.is_empty() {
        if asked.is_empty() {
            // The reference alone was on the table (or none of the group asked about).
            match &query.relation {
                // "Is the banana on the left riper than the one on the right?" with one banana.
                Some(r)
                    if query.targets == [r.reference.as_str()]
                        && objects.iter().filter(|m| m.label == r.reference).count() == 1 =>
                {
                    parts.push(format!(
                        "I found one {kind} only, so there is no other {kind} to hold it against."
                    ))
                }
                Some(_) => parts.push(format!("I found no {kind} to hold against {value}.")),
                None => {}
            }
            return parts;
        }
        if let [only] = asked[..] {
            // "Is the apple softer than 2 MPa?": answered about the apple.
            parts.push(capitalise(&format!(
                "{}, is not {rel} than {value}.",
                describe(&objects[only])
            )));
            return parts;
        }
        parts.push(format!("No {kind} I measured is {rel} than {value}."));
        let nearest = asked
            .iter()
            .copied()
            .max_by(|&a, &b| past(a).total_cmp(&past(b)));
        if let Some(i) = nearest {
            let word = match (by_ripeness, t.harder) {
                (false, true) => "hardest",
                (false, false) => "softest",
                (true, true) => "least ripe",
                (true, false) => "ripest",
            };
            // Against another fruit, that fruit is past every other: the nearest is of them.
            let of = if query.relation.is_some() {
                " of the others"
            } else {
                ""
            };
            parts.push(format!("The {word}{of} is {}.", describe(&objects[i])));
        }
    } else {
        let all_past: Vec<usize> = asked
            .iter()
            .copied()
            .filter(|&i| t.holds_for(stiffness(&objects[i])))
            .collect();
        match query.extreme {
            // "the softest fruit harder than 2 MPa": the one picked, then the rest past it.
            Some(extreme) => {
                let word = superlative(query.property, Some(extreme));
                parts.push(format!(
                    "Of the {} {} {rel} than {value}, the {word} is {}.",
                    count_words(all_past.len()).to_lowercase(),
                    counted(&kind, all_past.len()),
                    describe(&objects[selected[0]])
                ));
                let rest: Vec<String> = all_past
                    .iter()
                    .filter(|i| !selected.contains(i))
                    .filter_map(|&i| in_brief(&objects[i]))
                    .collect();
                if !rest.is_empty() {
                    parts.push(format!("Also {rel}: {}.", rest.join(", ")));
                }
            }
            None => {
                let list: Vec<String> = selected.iter().map(|&i| describe(&objects[i])).collect();
                let verb = if selected.len() == 1 { "is" } else { "are" };
                parts.push(format!(
                    "{} {} {verb} {rel} than {value}: {}.",
                    count_words(selected.len()),
                    counted(&kind, selected.len()),
                    list.join("; ")
                ));
            }
        }
        // The others nearest the value first.
        let mut others: Vec<usize> = asked
            .iter()
            .copied()
            .filter(|i| !all_past.contains(i))
            .collect();
        others.sort_by(|&a, &b| past(b).total_cmp(&past(a)));
        let others: Vec<String> = others
            .iter()
            .filter_map(|&i| in_brief(&objects[i]))
            .collect();
        if !others.is_empty() {
            parts.push(format!("Not {rel}: {}.", others.join(", ")));
        }
    }
    for &i in &asked {
        let m = &objects[i];
        if let Some([lo, hi]) = likely_range_mpa(m)
            && lo <= t.modulus_mpa
            && t.modulus_mpa <= hi
        {
            parts.push(format!(
                "The {}'s likely range holds {}, so it may be on either side.",
                m.label, t.said
            ));
        }
    }
    parts
}

/// The superlative an answer names its pick with: "softest", "least hard", "ripest".
fn superlative(property: Property, extreme: Option<Extreme>) -> &'static str {
    match (property, extreme) {
        (Property::Softness, Some(Extreme::Least)) => "least soft",
        (Property::Softness, _) => "softest",
        (Property::Hardness, Some(Extreme::Least)) => "least hard",
        (Property::Hardness, _) => "hardest",
        (Property::Ripeness, Some(Extreme::Least)) => "least ripe",
        (Property::Ripeness, _) => "ripest",
    }
}

/// The indefinite article before a kind: "an apple", "a banana".
fn article(kind: &str) -> &'static str {
    if kind.starts_with(['a', 'e', 'i', 'o', 'u']) {
        "an"
    } else {
        "a"
    }
}

/// A property as a noun: "hardness", "softness", "ripeness".
fn property_noun(property: Property) -> &'static str {
    match property {
        Property::Hardness => "hardness",
        Property::Softness => "softness",
        Property::Ripeness => "ripeness",
    }
}

/// A kind as a count of it reads: "one banana", "two bananas", "three citrus fruit", "two
/// berries"; several kinds together are "fruit".
fn counted(kind: &str, n: usize) -> String {
    if n == 1 {
        return kind.to_string();
    }
    // "Two bananas or tomatoes are ..." reads as a choice: several kinds are fruit.
    if kind.contains(" or ") {
        return "fruit".into();
    }
    if kind.ends_with("fruit") {
        kind.to_string()
    } else if let Some(stem) = kind.strip_suffix('y') {
        format!("{stem}ies")
    } else if kind.ends_with("ch") || kind.ends_with("tomato") || kind.ends_with("mango") {
        format!("{kind}es")
    } else {
        format!("{kind}s")
    }
}

/// A count as an answer opens a sentence with it: "One", ..., "Ten", "12".
fn count_words(n: usize) -> String {
    const WORDS: [&str; 11] = [
        "No", "One", "Two", "Three", "Four", "Five", "Six", "Seven", "Eight", "Nine", "Ten",
    ];
    WORDS
        .get(n)
        .map_or_else(|| n.to_string(), |w| w.to_string())
}

/// Whether two measured moduli may be equal: their 68% intervals overlap.
fn within_uncertainty(a: &Measured, b: &Measured) -> bool {
    match (likely_range_mpa(a), likely_range_mpa(b)) {
        (Some([a0, a1]), Some([b0, b1])) => a0 <= b1 && b0 <= a1,
        _ => false,
    }
}

fn capitalise(s: &str) -> String {
    let mut c = s.chars();
    c.next().map_or(String::new(), |f| {
        f.to_uppercase().collect::<String>() + c.as_str()
    })
}

/// The answer text for a query over measured objects; `missing` lists asked-for kinds the
/// camera did not find.
pub fn explain(
    query: &Query,
    objects: &[Measured],
    selected: &[usize],
    missing: &[String],
) -> String {
    let mut parts = Vec::new();
    // A fruit name read through a typing slip is said first: the rest of the answer rests
    // on that reading.
    if !query.corrected.is_empty() {
        let read: Vec<String> = query
            .corrected
            .iter()
            .map(|c| format!("'{}' as {}", c.said, c.read))
            .collect();
        let said = match read.split_last() {
            Some((last, rest)) if !rest.is_empty() => format!("{} and {last}", rest.join(", ")),
            _ => read.join(""),
        };
        parts.push(format!("I read {said}."));
    }
    // The use the question named, and how it was read: "You asked for a fruit for a
    // smoothie: I read that as the ripest fruit."
    if let Some(goal) = &query.goal {
        let kind = query.asked_kind();
        let reading = match query.extreme {
            Some(_) => format!("the {} {kind}", superlative(query.property, query.extreme)),
            None => format!("the {kind} ordered by {}", property_noun(query.property)),
        };
        parts.push(format!(
            "You asked for {} {kind} {}: I read that as {reading}.",
            article(&kind),
            goal.said
        ));
    }
    // Named kinds that are missing get their own sentence below; only a question about every
    // fruit (perhaps of a colour or place) is answered with "none".
    if objects.is_empty() && missing.is_empty() {
        let mut which = query.asked_kind();
        if let Some(c) = &query.filters.color {
            which = format!("{c} {which}");
        }
        if let Some(p) = &query.filters.position {
            which = format!("{which} at the {p}");
        }
        parts.push(format!("I found no {which} to touch on the table."));
    }
    match query.intent {
        Intent::Extreme if !selected.is_empty() => {
            let word = superlative(query.property, query.extreme);
            let kind = query.asked_kind();
            let best = &objects[selected[selected.len() - 1]];
            match &query.candidate {
                // "Is the banana the softest?": yes or no first, then the fruit that is.
                Some(c) if &best.label == c => {
                    parts.push(format!("Yes: the {word} {kind} is {}.", describe(best)))
                }
                // A banana not found or not measured is said so below, with why.
                Some(_) => {
                    parts.push(format!("No: the {word} {kind} is {}.", describe(best)));
                    if let [held_up, _] = selected {
                        let m = &objects[*held_up];
                        // "the banana at the left front, 24 Shore A ..." as a sentence of its own.
                        let rest = describe(m);
                        let rest = rest.trim_start_matches(&format!("the {} at the ", m.label));
                        parts.push(format!("The {} is at the {rest}.", m.label));
                    }
                }
                None => parts.push(format!("The {word} {kind} is {}.", describe(best))),
            }
            let mut ranked: Vec<&Measured> =
                objects.iter().filter(|m| m.hardness.is_some()).collect();
            if ranked.len() > 1 {
                ranked.sort_by(|a, b| stiffness(a).total_cmp(&stiffness(b)));
                let list: Vec<String> = ranked
                    .iter()
                    // The list stays short: uncertainties are in the sentence before.
                    .filter_map(|m| {
                        let h = describe_hardness(m.hardness.as_ref()?, None);
                        Some(format!("{} ({h})", m.label))
                    })
                    .collect();
                parts.push(format!("From softest to hardest: {}.", list.join(", ")));
            }
        }
        Intent::Compare if selected.len() >= 2 => {
            let (a, b) = (&objects[selected[0]], &objects[selected[1]]);
            // Two of one kind asked by ripeness: within a kind the softer is the riper.
            let by_ripeness = query.property == Property::Ripeness && a.label == b.label;
            let rel = comparison_word(stiffness(a) > stiffness(b), by_ripeness);
            parts.push(capitalise(&format!(
                "{}, is {rel} than {}.",
                describe(a),
                describe(b)
            )));
            if within_uncertainty(a, b) {
                let alike = if by_ripeness { "ripe" } else { "hard" };
                parts.push(format!(
                    "The difference is within the measurement uncertainty, so they may be \
                     equally {alike}."
                ));
            }
        }
        Intent::Threshold => match (super::held_against(query, objects), &query.relation) {
            (Some(t), _) => parts.extend(past_threshold(query, &t, objects, selected)),
            (None, Some(r)) => {
                // Every reference not found, else the first not measured.
                let of_kind = |k: &str| -> Vec<&Measured> {
                    objects
                        .iter()
                        .filter(|m| m.reference && m.label == k)
                        .collect()
                };
                let named = |k: &str| {
                    if r.also.is_empty() {
                        r.named()
                    } else {
                        k.to_string()
                    }
                };
                let missing: Vec<String> = r
                    .kinds()
                    .filter(|k| of_kind(k).is_empty())
                    .map(named)
                    .collect();
                let why = match missing.as_slice() {
                    [_, ..] => format!("I found no {} on the table", missing.join(" or ")),
                    [] => {
                        let k = r
                            .kinds()
                            .find(|k| of_kind(k).iter().all(|m| m.hardness.is_none()))
                            .unwrap_or(&r.reference);
                        format!("I could not measure the {}", named(k))
                    }
                };
                parts.push(format!(
                    "{why}, so I cannot say which {} is {} than {}.",
                    query.asked_kind(),
                    r.relation(),
                    if r.also.is_empty() { "it" } else { "them" }
                ))
            }
            (None, None) => {}
        },
        Intent::Summarize if query.ranked && !selected.is_empty() => {
            let (most, least) = match query.property {
                Property::Hardness => ("hardest", "softest"),
                Property::Softness => ("softest", "hardest"),
                Property::Ripeness => ("ripest", "least ripe"),
            };
            let list: Vec<String> = selected.iter().map(|&i| describe(&objects[i])).collect();
            parts.push(format!("From {most} to {least}: {}.", list.join("; ")));
        }
        _ => {
            for &i in selected {
                parts.push(capitalise(&format!("{}.", describe(&objects[i]))));
            }
        }
    }
    // "the larger of the two limes" counts the limes it picks from, not the one picked.
    if let Some(n) = query.filters.count
        && query.filters.size.is_none()
        && !objects.is_empty()
        && objects.len() != n
    {
        parts.push(format!(
            "You mentioned {n}; I found {} on the table.",
            objects.len()
        ));
    }
    // A fruit that was found but could not be pressed is said so, with why, once.
    for (i, m) in objects.iter().enumerate() {
        let asked = query.asks_about(&m.label, m.reference);
        if m.hardness.is_none() && asked && !selected.contains(&i) {
            parts.push(capitalise(&format!("{}.", describe(m))));
        }
    }
    for kind in missing {
        parts.push(format!(
            "I could not find {} {kind} on the table.",
            article(kind)
        ));
    }
    for name in &query.unknown {
        parts.push(format!(
            "I do not know the {name}: it is not in my fruit catalog, so I did not look for it."
        ));
    }
    parts.join(" ")
}

#[cfg(test)]
mod tests {
    use super::*;

    use crate::catalog::FruitCatalog;
    use crate::explain::{location_words, select};
    use crate::hardness::scale::Hardness;

    fn m(label: &str, e: f64, x: f64, y: f64) -> Measured {
        Measured {
            label: label.into(),
            location: location_words(x, y),
            hardness: Some(Hardness::ModulusMpa(e).into()),
            interval_68_mpa: [None, None],
            interval_95_mpa: [None, None],
            ripeness: Some("ripe".into()),
            not_measured: None,
            reference: false,
        }
    }

    fn with_range(mut m: Measured, lo: f64, hi: f64) -> Measured {
        m.interval_68_mpa = [Some(lo), Some(hi)];
        m
    }

    #[test]
    fn a_threshold_selects_the_fruit_past_it_in_order_and_says_the_rest() {
        let c = FruitCatalog::builtin();
        let objs = [
            m("apple", 3.25, 0.1, 0.1),
            m("banana", 0.8, -0.15, -0.1),
            with_range(m("lime", 1.9, 0.0, 0.0), 1.7, 2.2),
            m("avocado", 5.0, 0.2, 0.1),
        ];
        let q = crate::query::parse("Which fruits are harder than 2 MPa?", &c).unwrap();
        let sel = select(&q, &objs, &c);
        assert_eq!(sel, vec![3, 0], "hardest first");
        let text = explain(&q, &objs, &sel, &[]);
        assert!(
            text.starts_with("Two fruit are harder than 2 MPa ("),
            "{text}"
        );
        assert!(
            text.contains("Not harder: lime at 43 Shore A (1.90 MPa)"),
            "{text}"
        );
        assert!(
            text.contains("The lime's likely range holds 2 MPa"),
            "{text}"
        );

        let q = crate::query::parse("Which fruits are softer than 30 Shore A?", &c).unwrap();
        let sel = select(&q, &objs, &c);
        assert_eq!(sel, vec![1], "{q:?}");
        let text = explain(&q, &objs, &sel, &[]);
        assert!(
            text.starts_with("One fruit is softer than 30 Shore A ("),
            "{text}"
        );

        // None past it: said, with the nearest.
        let q = crate::query::parse("Is anything harder than 10 MPa?", &c).unwrap();
        let sel = select(&q, &objs, &c);
        assert!(sel.is_empty());
        let text = explain(&q, &objs, &sel, &[]);
        assert!(
            text.starts_with("No fruit I measured is harder than 10 MPa"),
            "{text}"
        );
        assert!(text.contains("The hardest is the avocado"), "{text}");
        // One fruit asked about: answered about it.
        let q = crate::query::parse("Is the apple softer than 2 MPa?", &c).unwrap();
        let sel = select(&q, &objs, &c);
        let text = explain(&q, &objs, &sel, &[]);
        assert!(
            text.starts_with("The apple at the right back, 57 Shore A (3.25 MPa), ripe, is not softer than 2 MPa ("),
            "{text}"
        );
    }

    #[test]
    fn softest_is_selected_and_explained() {
        let c = FruitCatalog::builtin();
        let q = crate::query::parse("Which fruit is the softest?", &c).unwrap();
        let objs = [
            m("apple", 3.25, 0.1, 0.1),
            m("banana", 0.8, -0.15, -0.1),
            m("lime", 1.5, 0.0, 0.0),
        ];
        let sel = select(&q, &objs, &c);
        assert_eq!(sel, vec![1]);
        let text = explain(&q, &objs, &sel, &[]);
        assert!(
            text.starts_with("The softest fruit is the banana at the left front"),
            "{text}"
        );
        assert!(text.contains("From softest to hardest: banana"), "{text}");
        let q = crate::query::parse("Which fruit is the hardest?", &c).unwrap();
        assert_eq!(select(&q, &objs, &c), vec![0]);
    }

    #[test]
    fn rankings_list_every_object_in_order() {
        let c = FruitCatalog::builtin();
        let objs = [
            m("apple", 3.25, 0.1, 0.1),
            m("banana", 0.8, -0.15, -0.1),
            m("lime", 1.5, 0.0, 0.0),
        ];
        let q = crate::query::parse("Rank the fruits from softest to hardest", &c).unwrap();
        let sel = select(&q, &objs, &c);
        assert_eq!(sel, vec![1, 2, 0]);
        let text = explain(&q, &objs, &sel, &[]);
        assert!(
            text.starts_with("From softest to hardest: the banana"),
            "{text}"
        );
        let q = crate::query::parse("Order the fruit by firmness", &c).unwrap();
        assert_eq!(select(&q, &objs, &c), vec![0, 2, 1]);
    }

    #[test]
    fn a_fruit_held_up_to_every_other_is_answered_yes_or_no() {
        let c = FruitCatalog::builtin();
        let objs = [
            m("apple", 3.25, 0.1, 0.1),
            m("banana", 0.8, -0.15, -0.1),
            m("tomato", 0.45, 0.0, 0.0),
        ];
        let q = crate::query::parse("Is the banana softer than the others?", &c).unwrap();
        let sel = select(&q, &objs, &c);
        // The banana asked about, then the fruit that beats it.
        assert_eq!(sel, vec![1, 2]);
        let text = explain(&q, &objs, &sel, &[]);
        assert!(
            text.starts_with("No: the softest fruit is the tomato")
                && text.contains("The banana is at the"),
            "{text}"
        );
        let q = crate::query::parse("Is the tomato the softest fruit?", &c).unwrap();
        let sel = select(&q, &objs, &c);
        assert_eq!(sel, vec![2]);
        let text = explain(&q, &objs, &sel, &[]);
        assert!(
            text.starts_with("Yes: the softest fruit is the tomato"),
            "{text}"
        );
    }

    #[test]
    fn a_misspelt_fruit_is_said_back_as_read() {
        let c = FruitCatalog::builtin();
        let q = crate::query::parse("Is the bananna softer than the aple?", &c).unwrap();
        let objs = [m("apple", 3.25, 0.1, 0.1), m("banana", 0.8, -0.15, -0.1)];
        let text = explain(&q, &objs, &select(&q, &objs, &c), &[]);
        assert!(
            text.starts_with("I read 'bananna' as banana and 'aple' as apple."),
            "{text}"
        );
    }

    #[test]
    fn counts_and_unknown_fruits_are_answered() {
        let c = FruitCatalog::builtin();
        let q = crate::query::parse("How hard are the two bananas and the grapes?", &c).unwrap();
        let objs = [m("banana", 0.8, -0.15, -0.1)];
        let text = explain(&q, &objs, &[0], &[]);
        assert!(
            text.contains("You mentioned 2; I found 1 on the table."),
            "{text}"
        );
        assert!(text.contains("I do not know the grape"), "{text}");
    }

    #[test]
    fn missing_objects_are_said_plainly() {
        let c = FruitCatalog::builtin();
        let q = crate::query::parse("Identify the hardness of the kiwi", &c).unwrap();
        let text = explain(&q, &[], &[], &["kiwi".into()]);
        assert!(
            text.contains("I could not find a kiwi on the table."),
            "{text}"
        );
        let q = crate::query::parse("Identify the hardness of the orange", &c).unwrap();
        let text = explain(&q, &[], &[], &["orange".into()]);
        assert!(
            text.contains("I could not find an orange on the table."),
            "{text}"
        );
    }

    #[test]
    fn a_use_is_said_back_with_the_property_it_was_read_as() {
        let c = FruitCatalog::builtin();
        let objs = [m("banana", 0.8, -0.15, -0.1), m("avocado", 5.0, 0.1, 0.1)];
        let q = crate::query::parse("What should I keep for next week?", &c).unwrap();
        let text = explain(&q, &objs, &select(&q, &objs, &c), &[]);
        assert!(
            text.starts_with(
                "You asked for a fruit to keep for next week: I read that as the least ripe \
                 fruit. The least ripe fruit is the avocado"
            ),
            "{text}"
        );
        let q = crate::query::parse("Which banana is best for a smoothie?", &c).unwrap();
        let text = explain(&q, &objs, &select(&q, &objs, &c), &[]);
        assert!(
            text.starts_with("You asked for a banana for a smoothie: I read that as the ripest"),
            "{text}"
        );
    }

    #[test]
    fn hardness_is_given_with_its_uncertainty() {
        let mut lime = m("lime", 1.46, 0.0, 0.0);
        lime.interval_68_mpa = [Some(1.34), Some(1.58)];
        let c = FruitCatalog::builtin();
        let q = crate::query::parse("How hard is the lime?", &c).unwrap();
        let text = explain(&q, std::slice::from_ref(&lime), &[0], &[]);
        assert!(
            text.contains("36 Shore A (1.46 MPa, likely -8% to +8%)"),
            "{text}"
        );
    }

    #[test]
    fn comparisons_inside_the_uncertainty_say_so() {
        let c = FruitCatalog::builtin();
        let q = crate::query::parse("Is the lime harder than the lemon?", &c).unwrap();
        let mut lime = m("lime", 1.50, 0.1, 0.0);
        let mut lemon = m("lemon", 1.40, -0.1, 0.0);
        lime.interval_68_mpa = [Some(1.40), Some(1.60)];
        lemon.interval_68_mpa = [Some(1.30), Some(1.50)];
        let objs = [lime.clone(), lemon.clone()];
        let text = explain(&q, &objs, &[0, 1], &[]);
        assert!(text.contains("is harder than the lemon"), "{text}");
        assert!(
            text.contains("within the measurement uncertainty"),
            "{text}"
        );
        // Far apart: no hedge.
        lemon.hardness = Some(Hardness::ModulusMpa(0.5).into());
        lemon.interval_68_mpa = [Some(0.45), Some(0.55)];
        let text = explain(&q, &[lime, lemon], &[0, 1], &[]);
        assert!(!text.contains("uncertainty"), "{text}");
    }

    #[test]
    fn a_counted_kind_takes_its_plural() {
        assert_eq!(counted("banana", 1), "banana");
        assert_eq!(counted("banana or tomato", 2), "fruit");
        assert_eq!(counted("citrus fruit", 3), "citrus fruit");
        assert_eq!(counted("berry", 2), "berries");
        assert_eq!(counted("peach", 2), "peaches");
        assert_eq!(counted("avocado", 2), "avocados");
        assert_eq!(counted("fruit", 0), "fruit");
    }
}
