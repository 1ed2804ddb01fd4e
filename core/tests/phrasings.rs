//! The prompt parser against how people ask: `fixtures/phrasings.tsv` holds over 200
//! phrasings written from the paper's four tiers and from everyday speech, each with what it
//! means. Every one that reads wrong is listed, not only the first.

use tactex_core::catalog::FruitCatalog;
use tactex_core::hardness::scale::Hardness;
use tactex_core::query::{Extreme, Intent, Property, Query, parse};

const PHRASINGS: &str = include_str!("fixtures/phrasings.tsv");

fn intent(name: &str) -> Intent {
    match name {
        "identify" => Intent::Identify,
        "extreme" => Intent::Extreme,
        "compare" => Intent::Compare,
        "summarize" => Intent::Summarize,
        "threshold" => Intent::Threshold,
        other => panic!("phrasings.tsv: intent {other:?}"),
    }
}

fn property(name: &str) -> Property {
    match name {
        "hardness" => Property::Hardness,
        "softness" => Property::Softness,
        "ripeness" => Property::Ripeness,
        other => panic!("phrasings.tsv: property {other:?}"),
    }
}

/// What is wrong with `query` against the expected columns, if anything.
fn mismatch(query: &Query, cols: &[&str]) -> Option<String> {
    let mut wrong = Vec::new();
    if query.intent != intent(cols[1]) {
        wrong.push(format!("intent {:?}, expected {}", query.intent, cols[1]));
    }
    if query.property != property(cols[2]) {
        wrong.push(format!(
            "property {:?}, expected {}",
            query.property, cols[2]
        ));
    }
    let extreme = match cols[3] {
        "most" => Some(Extreme::Most),
        "least" => Some(Extreme::Least),
        _ => None,
    };
    if query.extreme != extreme {
        wrong.push(format!("extreme {:?}, expected {}", query.extreme, cols[3]));
    }
    let (names, all) = match cols[4] {
        "all" => ("", true),
        t => match t.strip_suffix("+all") {
            Some(names) => (names, true),
            None => (t, false),
        },
    };
    let mut expected: Vec<&str> = names.split(',').filter(|n| !n.is_empty()).collect();
    let mut got: Vec<&str> = query.targets.iter().map(String::as_str).collect();
    expected.sort_unstable();
    got.sort_unstable();
    if got != expected || query.all != all {
        wrong.push(format!(
            "targets {:?} all={}, expected {}",
            query.targets, query.all, cols[4]
        ));
    }
    let extras = cols.get(5).copied().unwrap_or("");
    let mut colour = None;
    let mut position = None;
    let mut exclude = Vec::new();
    let mut count = None;
    let mut size: Option<String> = None;
    let mut ranked = false;
    let mut unknown = Vec::new();
    let mut categories: Vec<String> = Vec::new();
    let mut threshold = None;
    let mut relation = None;
    let mut goal: Option<String> = None;
    let mut candidate: Option<String> = None;
    let mut read: Vec<String> = Vec::new();
    for pair in extras.split(' ').filter(|p| !p.is_empty()) {
        // A word without '=' continues a two-word position.
        let Some((key, value)) = pair.split_once('=') else {
            continue;
        };
        match key {
            "colour" => colour = Some(value.to_string()),
            "exclude" => exclude.push(value.to_string()),
            "count" => count = Some(value.parse().unwrap()),
            "size" => size = Some(value.to_string()),
            "ranked" => ranked = value == "true",
            "unknown" => unknown.push(value.to_string()),
            "position" => position = Some(value.to_string()),
            // A group's name may take two words ("stone fruit"), written with '_'.
            "category" => categories.push(value.replace('_', " ")),
            // harder:2MPa, softer:30A: the direction, and the value as `Hardness` reads it.
            "threshold" => {
                let (dir, v) = value.split_once(':').unwrap();
                let e = Hardness::parse(v).unwrap().modulus_mpa().unwrap();
                threshold = Some((dir == "harder", e));
            }
            // softer:apple: the direction and the fruit held against; softer:banana@left
            // with the reference's place ('_' for a space); softer:apple+mango: several;
            // riper:banana@right, less_ripe:banana: by ripeness, two of one kind.
            "relation" => {
                let (dir, name) = value.split_once(':').unwrap();
                let (name, place) = match name.split_once('@') {
                    Some((n, p)) => (n, Some(p.replace('_', " "))),
                    None => (name, None),
                };
                let harder = matches!(dir, "harder" | "less_ripe");
                let ripeness = matches!(dir, "riper" | "less_ripe");
                relation = Some((harder, ripeness, name.to_string(), place));
            }
            // goal=for_a_smoothie: the use as the answer says it back, '_' for spaces.
            "goal" => goal = Some(value.replace('_', " ")),
            "candidate" => candidate = Some(value.to_string()),
            // A typing slip and the catalog word it reads as: "read=bananna:banana".
            "read" => read.push(value.to_string()),
            other => panic!("phrasings.tsv: extra {other:?}"),
        }
    }
    // Positions may take two words ("right front"), which the column's spaces split.
    if let Some(p) = extras.split("position=").nth(1) {
        let words: Vec<&str> = p.split(' ').take_while(|w| !w.contains('=')).collect();
        position = Some(words.join(" "));
    }
    if query.filters.color != colour {
        wrong.push(format!(
            "colour {:?}, expected {colour:?}",
            query.filters.color
        ));
    }
    if query.filters.position != position {
        wrong.push(format!(
            "position {:?}, expected {position:?}",
            query.filters.position
        ));
    }
    if query.exclude != exclude {
        wrong.push(format!("exclude {:?}, expected {exclude:?}", query.exclude));
    }
    let got_size = query.filters.size.map(|s| s.name().to_string());
    if got_size != size {
        wrong.push(format!("size {got_size:?}, expected {size:?}"));
    }
    if count.is_some() && query.filters.count != count {
        wrong.push(format!(
            "count {:?}, expected {count:?}",
            query.filters.count
        ));
    }
    if query.ranked != ranked {
        wrong.push(format!("ranked {}, expected {ranked}", query.ranked));
    }
    let got_categories: Vec<&str> = query.categories.iter().map(|c| c.name.as_str()).collect();
    if got_categories != categories {
        wrong.push(format!(
            "categories {got_categories:?}, expected {categories:?}"
        ));
    }
    let got_threshold = query.threshold.as_ref().map(|t| (t.harder, t.modulus_mpa));
    let same = match (got_threshold, threshold) {
        (Some((a, e)), Some((b, f))) => a == b && (e - f).abs() <= 1e-9 * f,
        (g, t) => g.is_none() && t.is_none(),
    };
    if !same {
        wrong.push(format!(
            "threshold {got_threshold:?}, expected {threshold:?}"
        ));
    }
    let got_relation = query.relation.as_ref().map(|r| {
        (
            r.harder,
            r.ripeness,
            r.kinds().collect::<Vec<_>>().join("+"),
            r.position.clone(),
        )
    });
    if got_relation != relation {
        wrong.push(format!("relation {got_relation:?}, expected {relation:?}"));
    }
    let got_goal = query.goal.as_ref().map(|g| g.said.clone());
    if got_goal != goal {
        wrong.push(format!("goal {got_goal:?}, expected {goal:?}"));
    }
    if query.unknown != unknown {
        wrong.push(format!("unknown {:?}, expected {unknown:?}", query.unknown));
    }
    if query.candidate != candidate {
        wrong.push(format!(
            "candidate {:?}, expected {candidate:?}",
            query.candidate
        ));
    }
    let got_read: Vec<String> = query
        .corrected
        .iter()
        .map(|c| format!("{}:{}", c.said, c.read))
        .collect();
    if got_read != read {
        wrong.push(format!("read {got_read:?}, expected {read:?}"));
    }
    (!wrong.is_empty()).then(|| wrong.join("; "))
}

#[test]
fn over_200_everyday_phrasings_read_as_people_mean_them() {
    let catalog = FruitCatalog::builtin();
    let mut wrong = Vec::new();
    let mut n = 0;
    for line in PHRASINGS.lines() {
        if line.starts_with('#') || line.is_empty() {
            continue;
        }
        n += 1;
        let cols: Vec<&str> = line.split('\t').collect();
        assert!(
            cols.len() >= 5,
            "phrasings.tsv: {line:?} has {} columns",
            cols.len()
        );
        let prompt = cols[0];
        match (parse(prompt, &catalog), cols[1]) {
            (Err(e), "error") => {
                let needle = cols.get(5).copied().unwrap_or("");
                if !e.to_string().contains(needle) {
                    wrong.push(format!(
                        "{prompt:?}: error {e}, expected one naming {needle:?}"
                    ));
                }
            }
            (Ok(q), "error") => wrong.push(format!("{prompt:?}: read as {q:?}, expected refused")),
            (Err(e), _) => wrong.push(format!("{prompt:?}: refused ({e})")),
            (Ok(q), _) => {
                if let Some(why) = mismatch(&q, &cols) {
                    wrong.push(format!("{prompt:?}: {why}"));
                }
            }
        }
    }
    assert!(n >= 200, "only {n} phrasings");
    assert!(
        wrong.is_empty(),
        "{} of {n} phrasings read wrong:\n{}",
        wrong.len(),
        wrong.join("\n")
    );
}
