//! The template explainer: deterministic, offline text from the measured result, with the
//! rule-based location words (left/centre/right, front/centre/back) of the TactEx paper.

use crate::catalog::FruitCatalog;
use crate::hardness::HardnessReport;
use crate::query::{Extreme, Intent, Property, Query};
use serde::Serialize;

/// Objects this far (m) from the table centre line are "left"/"right" or "front"/"back".
pub const LOCATION_BAND_M: f64 = 0.06;

/// "left front", "centre back", "centre", ... from table coordinates (x right, y back).
pub fn location_words(x: f64, y: f64) -> String {
    let lr = if x < -LOCATION_BAND_M {
        "left"
    } else if x > LOCATION_BAND_M {
        "right"
    } else {
        "centre"
    };
    let fb = if y < -LOCATION_BAND_M {
        "front"
    } else if y > LOCATION_BAND_M {
        "back"
    } else {
        "centre"
    };
    match (lr, fb) {
        ("centre", "centre") => "centre".into(),
        (lr, fb) => format!("{lr} {fb}"),
    }
}

/// One measured object as the explainer sees it.
#[derive(Clone, Debug, Serialize)]
pub struct Measured {
    pub label: String,
    pub location: String,
    pub hardness: Option<HardnessReport>,
    /// One-standard-error modulus interval (MPa).
    pub modulus_interval_mpa: [Option<f64>; 2],
    pub ripeness: Option<String>,
}

fn describe_hardness(h: &HardnessReport) -> String {
    match h.modulus_mpa {
        None => "rigid".into(),
        Some(e) if h.shore_a < 10.0 => format!("{:.0} Shore 00 ({e:.2} MPa)", h.shore_00),
        Some(e) => format!("{:.0} Shore A ({e:.2} MPa)", h.shore_a),
    }
}

fn describe(m: &Measured) -> String {
    let mut s = format!("the {} at the {}", m.label, m.location);
    match &m.hardness {
        Some(h) => {
            s += &format!(", {}", describe_hardness(h));
            if let Some(r) = &m.ripeness {
                s += &format!(", {r}");
            }
        }
        None => s += ", which I could not measure",
    }
    s
}

fn stiffness(m: &Measured) -> f64 {
    m.hardness
        .map_or(f64::NAN, |h| h.modulus_mpa.unwrap_or(f64::INFINITY))
}

fn capitalise(s: &str) -> String {
    let mut c = s.chars();
    c.next().map_or(String::new(), |f| {
        f.to_uppercase().collect::<String>() + c.as_str()
    })
}

/// Indices of `objects` that answer the query, in answer order.
pub fn select(query: &Query, objects: &[Measured], catalog: &FruitCatalog) -> Vec<usize> {
    let mut measured: Vec<usize> = (0..objects.len())
        .filter(|&i| objects[i].hardness.is_some())
        .collect();
    // How much of the asked property an object has.
    let key = |i: &usize| -> f64 {
        let m = &objects[*i];
        let e = stiffness(m);
        match query.property {
            Property::Hardness => e,
            Property::Softness => -e,
            // Ripeness: stiffness relative to the fruit's unripe stage, lower is riper.
            Property::Ripeness => -catalog
                .get(&m.label)
                .map_or(e, |f| e / f.stages[0].modulus_mpa),
        }
    };
    match query.intent {
        Intent::Summarize if query.ranked => {
            measured.sort_by(|a, b| key(b).total_cmp(&key(a)));
            measured
        }
        Intent::Extreme => {
            let pick = match query.extreme {
                Some(Extreme::Least) => measured.iter().min_by(|a, b| key(a).total_cmp(&key(b))),
                _ => measured.iter().max_by(|a, b| key(a).total_cmp(&key(b))),
            };
            pick.copied().into_iter().collect()
        }
        _ => measured,
    }
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
    if objects.is_empty() {
        parts.push("I found no fruit to touch on the table.".to_string());
    }
    match query.intent {
        Intent::Extreme if !selected.is_empty() => {
            let word = match (query.property, query.extreme) {
                (Property::Softness, Some(Extreme::Least)) => "least soft",
                (Property::Softness, _) => "softest",
                (Property::Hardness, Some(Extreme::Least)) => "least hard",
                (Property::Hardness, _) => "hardest",
                (Property::Ripeness, Some(Extreme::Least)) => "least ripe",
                (Property::Ripeness, _) => "ripest",
            };
            let kind = if query.all || query.targets.is_empty() {
                "fruit".to_string()
            } else {
                query.targets.join(" or ")
            };
            parts.push(format!(
                "The {word} {kind} is {}.",
                describe(&objects[selected[0]])
            ));
            let mut ranked: Vec<&Measured> =
                objects.iter().filter(|m| m.hardness.is_some()).collect();
            if ranked.len() > 1 {
                ranked.sort_by(|a, b| stiffness(a).total_cmp(&stiffness(b)));
                let list: Vec<String> = ranked
                    .iter()
                    .map(|m| {
                        format!(
                            "{} ({})",
                            m.label,
                            describe_hardness(m.hardness.as_ref().unwrap())
                        )
                    })
                    .collect();
                parts.push(format!("From softest to hardest: {}.", list.join(", ")));
            }
        }
        Intent::Compare if selected.len() >= 2 => {
            let (a, b) = (&objects[selected[0]], &objects[selected[1]]);
            let rel = if stiffness(a) > stiffness(b) {
                "harder"
            } else {
                "softer"
            };
            parts.push(capitalise(&format!(
                "{} is {rel} than {}.",
                describe(a),
                describe(b)
            )));
        }
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
    if let Some(n) = query.filters.count
        && !objects.is_empty()
        && objects.len() != n
    {
        parts.push(format!(
            "You mentioned {n}; I found {} on the table.",
            objects.len()
        ));
    }
    for kind in missing {
        parts.push(format!("I could not find a {kind} on the table."));
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
    use crate::hardness::Hardness;

    fn m(label: &str, e: f64, x: f64, y: f64) -> Measured {
        Measured {
            label: label.into(),
            location: location_words(x, y),
            hardness: Some(Hardness::ModulusMpa(e).into()),
            modulus_interval_mpa: [None, None],
            ripeness: Some("ripe".into()),
        }
    }

    #[test]
    fn locations_follow_the_table_frame() {
        assert_eq!(location_words(-0.2, -0.1), "left front");
        assert_eq!(location_words(0.2, 0.1), "right back");
        assert_eq!(location_words(0.0, 0.0), "centre");
        assert_eq!(location_words(0.0, 0.2), "centre back");
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
    }
}
