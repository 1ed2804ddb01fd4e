//! `tactex eval explanations`: the language layer scored on its own. Seeded random scenes of
//! 1 to 6 fruits (distinct kinds) give the facts an explainer gets: every fruit's true label,
//! location words, modulus (with a stated 5% one-standard-error) and ripeness, kept by the
//! query's own kind, colour and position filters as the pipeline keeps detections. Measuring
//! is left out on purpose, so an estimator's error never counts against the words.
//!
//! Prompts rotate through six kinds: locate and measure, pairwise comparison, list-wise
//! comparison (softest / hardest), ranking, filtering by colour and by position; some ask for
//! a fruit that is not there. The expected answer comes from the truth, not from
//! `explain::select`, and each answer is scored for
//!
//! * accuracy: nothing invented (`grounded::check` without its completeness half), every
//!   described fruit with its own modulus and location words, the right extreme, order and
//!   comparison;
//! * completeness: every fruit the answer should describe, with its ripeness where the catalog
//!   has stages, and every asked-for fruit that is not there said to be missing;
//! * clarity: every number carries a unit, at most 40 words per fruit described (plus 20).

use crate::app::explainer_choice::{ExplainerChoice, explainer};
use crate::eval::other_paper_kinds;
use crate::report::output::{OutputDir, write_json_atomic};
use crate::report::plot::{self, BarSeries};
use crate::report::provenance::write_markdown_report;
use crate::report::tail::print_json_or_text;
use anyhow::{Context, Result};
use clap::Args;
use indicatif::{ProgressBar, ProgressStyle};
use rand::seq::IndexedRandom;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::Serialize;
use std::path::PathBuf;
use tactex_core::catalog::FruitCatalog;
use tactex_core::explain::grounded::{self, numbers_with_units};
use tactex_core::explain::{Explainer, Explanation, Facts, Measured, location_words, select};
use tactex_core::ground::colour_name::colour_name;
use tactex_core::hardness::scale::Hardness;
use tactex_core::query;
use tactex_sim::datagen::scene_random::{Variation, random_scene};

/// The standard error every fact carries, relative to its modulus.
pub const FACT_SE: f64 = 0.05;
/// Two moduli closer than this ratio are not judged for order.
const TIE_RATIO: f64 = 1.01;

#[derive(Args)]
pub struct ExplanationEvalArgs {
    /// Prompts to ask (the issue: 100); 1 to 100000.
    #[arg(long, value_parser = crate::app::flag_range::count::<usize>(1, 100_000), default_value_t = 100)]
    pub prompts: usize,
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Who writes the answers: template or llm (see `tactex ask --help`).
    #[arg(long, default_value = "template", value_parser = crate::app::flag_range::choice::<ExplainerChoice>(&ExplainerChoice::NAMES))]
    pub explainer: ExplainerChoice,
    #[arg(long)]
    pub llm_config: Option<PathBuf>,
    /// Print the results as one JSON object.
    #[arg(long)]
    pub json: bool,
    /// Write results.json, cases.json, table.md and scores.png here.
    #[arg(long)]
    pub out: Option<PathBuf>,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Category {
    LocateMeasure,
    Pairwise,
    Listwise,
    Ranking,
    ColourFilter,
    PositionFilter,
}

impl Category {
    fn name(self) -> &'static str {
        match self {
            Category::LocateMeasure => "locate and measure",
            Category::Pairwise => "pairwise",
            Category::Listwise => "list-wise",
            Category::Ranking => "ranking",
            Category::ColourFilter => "by colour",
            Category::PositionFilter => "by position",
        }
    }
}

const CATEGORIES: [Category; 6] = [
    Category::LocateMeasure,
    Category::Pairwise,
    Category::Listwise,
    Category::Ranking,
    Category::ColourFilter,
    Category::PositionFilter,
];

/// One fruit as it truly is.
#[derive(Clone, Debug, Serialize)]
pub struct TrueFruit {
    pub label: String,
    pub location: String,
    pub modulus_mpa: f64,
    pub ripeness: Option<String>,
    pub colour: String,
}

/// What a right answer does, in terms of `truth` indices.
#[derive(Clone, Debug, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Expected {
    /// Describe each of these.
    Describe(Vec<usize>),
    /// Name this one first and describe it; any of `tied` may stand in for it.
    Extreme { pick: usize, tied: Vec<usize> },
    /// Describe all of these in this order.
    Ranked(Vec<usize>),
    /// Describe both and say which is harder (None: equally hard, either relation goes).
    Pair {
        a: usize,
        b: usize,
        harder: Option<usize>,
    },
}

#[derive(Clone, Debug, Serialize)]
pub struct Case {
    pub index: usize,
    pub category: Category,
    pub prompt: String,
    pub truth: Vec<TrueFruit>,
    /// Asked-for kinds that are not on the table.
    pub absent: Vec<String>,
    pub expected: Expected,
}

/// The scene and prompt of case `index`.
pub fn case(index: usize, seed: u64, catalog: &FruitCatalog) -> Result<Case> {
    let base = seed.wrapping_mul(7_368_787).wrapping_add(index as u64);
    let mut rng = ChaCha8Rng::seed_from_u64(base);
    let category = CATEGORIES[index % CATEGORIES.len()];
    let n = 1 + (index / CATEGORIES.len()) % 6;
    let kinds = other_paper_kinds(&mut rng, &[], n);
    let scene = random_scene(&kinds, catalog, base, &Variation::default())
        .with_context(|| format!("case {index}: scene"))?;
    let truth: Vec<TrueFruit> = scene
        .objects
        .iter()
        .map(|o| {
            let e = o.hardness.modulus_mpa().unwrap_or(f64::INFINITY);
            let ripeness = catalog
                .get(&o.label)
                .filter(|f| f.has_ripeness())
                .map(|f| f.stage_for_modulus(Some(e)).name.clone());
            TrueFruit {
                label: o.label.clone(),
                location: location_words(o.position_m[0], o.position_m[1]),
                modulus_mpa: e,
                ripeness,
                colour: colour_name(o.color).to_string(),
            }
        })
        .collect();
    let e = |i: usize| truth[i].modulus_mpa;
    let all: Vec<usize> = (0..truth.len()).collect();
    let tied_with = |i: usize, among: &[usize]| -> Vec<usize> {
        among
            .iter()
            .copied()
            .filter(|&j| e(i).max(e(j)) / e(i).min(e(j)) < TIE_RATIO)
            .collect()
    };
    let absent_kind =
        || other_paper_kinds(&mut ChaCha8Rng::seed_from_u64(base ^ 0xab5e), &kinds, 1)[0];
    let (prompt, absent, expected) = match category {
        Category::LocateMeasure => {
            if index.is_multiple_of(5) {
                let k = absent_kind();
                (
                    format!("Where is the {k} and how hard is it?"),
                    vec![k.to_string()],
                    Expected::Describe(Vec::new()),
                )
            } else {
                let i = rng.random_range(0..truth.len());
                (
                    format!("Where is the {} and how hard is it?", truth[i].label),
                    Vec::new(),
                    Expected::Describe(vec![i]),
                )
            }
        }
        Category::Pairwise => {
            let a = rng.random_range(0..truth.len());
            let others_than_a: Vec<usize> = all.iter().copied().filter(|&j| j != a).collect();
            match others_than_a.choose(&mut rng) {
                Some(&b) => {
                    let harder = match e(a).partial_cmp(&e(b)) {
                        _ if e(a).max(e(b)) / e(a).min(e(b)) < TIE_RATIO => None,
                        Some(std::cmp::Ordering::Greater) => Some(a),
                        _ => Some(b),
                    };
                    let prompt = if index.is_multiple_of(2) {
                        format!(
                            "Is the {} harder than the {}?",
                            truth[a].label, truth[b].label
                        )
                    } else {
                        format!(
                            "Which is softer, the {} or the {}?",
                            truth[a].label, truth[b].label
                        )
                    };
                    (prompt, Vec::new(), Expected::Pair { a, b, harder })
                }
                None => {
                    let k = absent_kind();
                    (
                        format!("Is the {} harder than the {k}?", truth[a].label),
                        vec![k.to_string()],
                        Expected::Describe(vec![a]),
                    )
                }
            }
        }
        Category::Listwise => {
            let softest = index % 2 == 1;
            let pick = if softest {
                *all.iter()
                    .min_by(|&&i, &&j| e(i).total_cmp(&e(j)))
                    .expect("one")
            } else {
                *all.iter()
                    .max_by(|&&i, &&j| e(i).total_cmp(&e(j)))
                    .expect("one")
            };
            let word = if softest { "softest" } else { "hardest" };
            (
                format!("Which fruit is the {word}?"),
                Vec::new(),
                Expected::Extreme {
                    pick,
                    tied: tied_with(pick, &all),
                },
            )
        }
        Category::Ranking => {
            let soft_first = index.is_multiple_of(2);
            let mut order = all.clone();
            order.sort_by(|&i, &j| e(i).total_cmp(&e(j)));
            if !soft_first {
                order.reverse();
            }
            let prompt = if soft_first {
                "Rank the fruits from softest to hardest"
            } else {
                "Order the fruit by firmness"
            };
            (prompt.to_string(), Vec::new(), Expected::Ranked(order))
        }
        Category::ColourFilter => {
            let i = rng.random_range(0..truth.len());
            let colour = truth[i].colour.clone();
            let keep = all
                .iter()
                .copied()
                .filter(|&j| truth[j].colour == colour)
                .collect();
            (
                format!("How hard is the {colour} fruit?"),
                Vec::new(),
                Expected::Describe(keep),
            )
        }
        Category::PositionFilter => {
            let i = rng.random_range(0..truth.len());
            let words: Vec<&str> = truth[i].location.split(' ').collect();
            let word = words.choose(&mut rng).expect("one word").to_string();
            let keep = all
                .iter()
                .copied()
                .filter(|&j| query::position_matches(&word, &truth[j].location))
                .collect();
            let phrase = match word.as_str() {
                "left" | "right" => format!("on the {word}"),
                "centre" => "in the centre".to_string(),
                _ => format!("at the {word}"),
            };
            (
                format!("How hard is the fruit {phrase}?"),
                Vec::new(),
                Expected::Describe(keep),
            )
        }
    };
    Ok(Case {
        index,
        category,
        prompt,
        truth,
        absent,
        expected,
    })
}

/// The facts an explainer gets for `case`: the truth kept by the query's filters, as the
/// pipeline keeps detections.
pub fn facts(case: &Case, catalog: &FruitCatalog) -> Result<Facts> {
    let query = query::parse(&case.prompt, catalog)
        .with_context(|| format!("case {}: {}", case.index, case.prompt))?;
    let objects: Vec<Measured> = case
        .truth
        .iter()
        .filter(|t| {
            query.wants(&t.label)
                && query.filters.colour_matches(&t.colour)
                && query.filters.position_matches(&t.location)
        })
        .map(|t| Measured {
            label: t.label.clone(),
            location: t.location.clone(),
            hardness: Some(Hardness::ModulusMpa(t.modulus_mpa).into()),
            interval_68_mpa: [
                Some(t.modulus_mpa * (1.0 - FACT_SE)),
                Some(t.modulus_mpa * (1.0 + FACT_SE)),
            ],
            interval_95_mpa: [
                Some(t.modulus_mpa * (1.0 - 2.0 * FACT_SE)),
                Some(t.modulus_mpa * (1.0 + 2.0 * FACT_SE)),
            ],
            ripeness: t.ripeness.clone(),
            not_measured: None,
            reference: query.is_reference(&t.label),
        })
        .collect();
    let not_found = query
        .targets
        .iter()
        .filter(|k| !objects.iter().any(|o| &o.label == *k))
        .cloned()
        .collect();
    let selected = select(&query, &objects, catalog);
    Ok(Facts {
        prompt: case.prompt.clone(),
        query,
        objects,
        selected,
        not_found,
    })
}

/// Where each fruit of `truth` is first named in `text` (byte offset), if it is.
fn first_mentions(text: &str, truth: &[TrueFruit], catalog: &FruitCatalog) -> Vec<Option<usize>> {
    let lower = text.to_lowercase();
    let mut words = Vec::new();
    let mut start = None;
    for (i, c) in lower
        .char_indices()
        .chain(std::iter::once((lower.len(), ' ')))
    {
        match (c.is_alphanumeric(), start) {
            (true, None) => start = Some(i),
            (false, Some(s)) => {
                words.push((s, &lower[s..i]));
                start = None;
            }
            _ => {}
        }
    }
    truth
        .iter()
        .map(|t| {
            words
                .iter()
                .find(|(_, w)| catalog.find_word(w).is_some_and(|f| f.name == t.label))
                .map(|(at, _)| *at)
        })
        .collect()
}

/// One answer's scores and what cost them.
#[derive(Clone, Debug, Serialize)]
pub struct CaseScore {
    pub index: usize,
    pub category: Category,
    pub prompt: String,
    pub answer: String,
    pub explainer: String,
    pub notice: Option<String>,
    pub accurate: bool,
    pub complete: bool,
    pub clear: bool,
    pub words: usize,
    pub problems: Vec<String>,
}

/// Scores the explanation given for `case`.
pub fn score(
    case: &Case,
    explanation: &Explanation,
    facts: &Facts,
    catalog: &FruitCatalog,
) -> CaseScore {
    let answer = explanation.text.as_str();
    let mut accuracy = Vec::new();
    let mut completeness = Vec::new();
    let mut clarity = Vec::new();
    // Invented claims: the groundedness check's first half.
    if let Err(e) = grounded::check_invented(answer, facts, catalog) {
        accuracy.push(format!("invented: {e}"));
    }
    let mentions = first_mentions(answer, &case.truth, catalog);
    let lower = answer.to_lowercase();
    // The stretch of text about fruit i: from its first mention to the next fruit's.
    let segment = |i: usize| -> Option<&str> {
        let at = mentions[i]?;
        let end = mentions
            .iter()
            .flatten()
            .filter(|&&m| m > at)
            .min()
            .copied()
            .unwrap_or(lower.len());
        Some(&lower[at..end])
    };
    let described: Vec<usize> = match &case.expected {
        Expected::Describe(v) | Expected::Ranked(v) => v.clone(),
        Expected::Extreme { pick, .. } => vec![*pick],
        Expected::Pair { a, b, .. } => vec![*a, *b],
    };
    for &i in &described {
        let t = &case.truth[i];
        let Some(seg) = segment(i) else {
            completeness.push(format!("the {} is not described", t.label));
            continue;
        };
        let has_value = numbers_with_units(seg)
            .iter()
            .any(|(n, unit)| unit == "mpa" && n.matches(t.modulus_mpa));
        if !has_value {
            accuracy.push(format!(
                "the {} is not given its {:.2} MPa",
                t.label, t.modulus_mpa
            ));
        }
        if !seg.contains(&t.location) {
            accuracy.push(format!(
                "the {} is not placed at the {}",
                t.label, t.location
            ));
        }
        if let Some(r) = &t.ripeness {
            let said = seg
                .split(|c: char| !c.is_alphanumeric())
                .any(|w| w == r.as_str());
            if !said {
                completeness.push(format!("the {} is not called {r}", t.label));
            }
        }
    }
    match &case.expected {
        Expected::Extreme { tied, .. } => {
            let first = (0..case.truth.len())
                .filter(|&i| mentions[i].is_some())
                .min_by_key(|&i| mentions[i]);
            if !first.is_some_and(|f| tied.contains(&f)) {
                accuracy.push(format!(
                    "names {} first",
                    first.map_or("nothing".to_string(), |f| case.truth[f].label.clone())
                ));
            }
        }
        Expected::Ranked(order) => {
            let named: Vec<usize> = order
                .iter()
                .copied()
                .filter(|&i| mentions[i].is_some())
                .collect();
            for w in named.windows(2) {
                let (i, j) = (w[0], w[1]);
                let (ei, ej) = (case.truth[i].modulus_mpa, case.truth[j].modulus_mpa);
                let tie = ei.max(ej) / ei.min(ej) < TIE_RATIO;
                if mentions[i] > mentions[j] && !tie {
                    accuracy.push(format!(
                        "ranks the {} before the {}",
                        case.truth[j].label, case.truth[i].label
                    ));
                }
            }
        }
        Expected::Pair { a, b, harder } => {
            if let Some(h) = harder {
                let s = if h == a { *b } else { *a };
                let (hl, sl) = (&case.truth[*h].label, &case.truth[s].label);
                // "X ... harder than ... Y" or "X ... softer than ... Y".
                let right = [(hl, "harder", sl), (sl, "softer", hl)]
                    .iter()
                    .any(|(x, rel, y)| {
                        lower
                            .split(". ")
                            .any(|sentence| relation(sentence, x, rel, y, catalog))
                    });
                if !right {
                    accuracy.push(format!("does not say the {hl} is harder than the {sl}"));
                }
            }
        }
        Expected::Describe(_) => {}
    }
    for k in &case.absent {
        let said = lower.contains(k.as_str())
            && [
                "could not find",
                "not found",
                "no ",
                "not on the table",
                "cannot find",
            ]
            .iter()
            .any(|p| lower.contains(p));
        if !said {
            completeness.push(format!("does not say the {k} is not there"));
        }
    }
    let words = answer.split_whitespace().count();
    let limit = 20 + 40 * described.len().max(1);
    if words > limit {
        clarity.push(format!("{words} words for {} fruit", described.len()));
    }
    for (n, unit) in numbers_with_units(answer) {
        if !["mpa", "shore", "%", "kpa"].contains(&unit.as_str()) {
            clarity.push(format!("{} has no unit", n.value));
        }
    }
    CaseScore {
        index: case.index,
        category: case.category,
        prompt: case.prompt.clone(),
        answer: answer.to_string(),
        explainer: explanation.explainer.clone(),
        notice: explanation.notice.clone(),
        accurate: accuracy.is_empty(),
        complete: completeness.is_empty(),
        clear: clarity.is_empty(),
        words,
        problems: accuracy
            .into_iter()
            .chain(completeness)
            .chain(clarity)
            .collect(),
    }
}

/// Whether `sentence` names `x`, then `rel` ("harder"), "than", then `y`.
fn relation(sentence: &str, x: &str, rel: &str, y: &str, catalog: &FruitCatalog) -> bool {
    let words: Vec<&str> = sentence
        .split(|c: char| !c.is_alphanumeric())
        .filter(|w| !w.is_empty())
        .collect();
    let is = |w: &str, name: &str| catalog.find_word(w).is_some_and(|f| f.name == name);
    let Some(px) = words.iter().position(|w| is(w, x)) else {
        return false;
    };
    let Some(pr) = words.iter().position(|w| *w == rel) else {
        return false;
    };
    let Some(py) = words.iter().rposition(|w| is(w, y)) else {
        return false;
    };
    px < pr && words.get(pr + 1) == Some(&"than") && pr < py
}

#[derive(Serialize)]
struct CategoryScore {
    category: Category,
    prompts: usize,
    accuracy: f64,
    completeness: f64,
    clarity: f64,
    mean_words: f64,
}

#[derive(Serialize)]
struct Report {
    protocol: String,
    explainer: String,
    seed: u64,
    prompts: usize,
    accuracy: f64,
    completeness: f64,
    clarity: f64,
    fallbacks: usize,
    categories: Vec<CategoryScore>,
}

fn share(scores: &[&CaseScore], f: impl Fn(&CaseScore) -> bool) -> f64 {
    if scores.is_empty() {
        return f64::NAN;
    }
    scores.iter().filter(|s| f(s)).count() as f64 / scores.len() as f64
}

pub(crate) fn run(args: &ExplanationEvalArgs) -> Result<()> {
    let catalog = FruitCatalog::builtin();
    let explainer: Box<dyn Explainer> = explainer(args.explainer, args.llm_config.as_ref())?;
    let cases = (0..args.prompts)
        .map(|i| case(i, args.seed, &catalog))
        .collect::<Result<Vec<_>>>()?;
    let bar = ProgressBar::new(cases.len() as u64).with_style(
        ProgressStyle::with_template("eval explanations [{bar:30}] {pos}/{len} prompts, eta {eta}")
            .expect("a valid template"),
    );
    let mut scores = Vec::new();
    for c in &cases {
        let f = facts(c, &catalog)?;
        scores.push(score(c, &explainer.explain(&f), &f, &catalog));
        bar.inc(1);
    }
    bar.finish_and_clear();
    let all: Vec<&CaseScore> = scores.iter().collect();
    let categories: Vec<CategoryScore> = CATEGORIES
        .iter()
        .map(|&cat| {
            let these: Vec<&CaseScore> = scores.iter().filter(|s| s.category == cat).collect();
            CategoryScore {
                category: cat,
                prompts: these.len(),
                accuracy: share(&these, |s| s.accurate),
                completeness: share(&these, |s| s.complete),
                clarity: share(&these, |s| s.clear),
                mean_words: these.iter().map(|s| s.words as f64).sum::<f64>()
                    / these.len().max(1) as f64,
            }
        })
        .collect();
    let report = Report {
        protocol: format!(
            "{} prompts over seeded random scenes of 1-6 fruits (distinct kinds); facts are the truth with a {:.0}% standard error, kept by the query's filters; scored against the truth",
            args.prompts,
            FACT_SE * 100.0
        ),
        explainer: explainer.name().to_string(),
        seed: args.seed,
        prompts: scores.len(),
        accuracy: share(&all, |s| s.accurate),
        completeness: share(&all, |s| s.complete),
        clarity: share(&all, |s| s.clear),
        fallbacks: scores.iter().filter(|s| s.notice.is_some()).count(),
        categories,
    };
    let table = table(&report);
    if let Some(out) = &args.out {
        let out = OutputDir::create("--out", out)?;
        let dir = out.path();
        write_json_atomic(&dir.join("results.json"), &report)?;
        write_json_atomic(&dir.join("cases.json"), &scores)?;
        write_markdown_report(&dir.join("table.md"), &table)?;
        let names: Vec<String> = report
            .categories
            .iter()
            .map(|c| c.category.name().to_string())
            .collect();
        let series = [
            (
                "accuracy",
                report.categories.iter().map(|c| c.accuracy).collect(),
            ),
            (
                "completeness",
                report.categories.iter().map(|c| c.completeness).collect(),
            ),
            (
                "clarity",
                report.categories.iter().map(|c| c.clarity).collect(),
            ),
        ]
        .map(|(name, values): (&str, Vec<f64>)| BarSeries {
            name: name.into(),
            values,
        });
        plot::bars(
            &dir.join("scores.png"),
            &format!("eval explanations: {}", report.explainer),
            "share of prompts",
            &names,
            &series,
            false,
        )?;
        out.finish()?;
    }
    print_json_or_text(&report, args.json, || {
        print!("{table}");
        for s in scores.iter().filter(|s| !s.problems.is_empty()).take(10) {
            println!(
                "\n#{} {}\n  {}\n  {}",
                s.index,
                s.prompt,
                s.answer,
                s.problems.join("; ")
            );
        }
        Ok(())
    })?;
    Ok(())
}

fn table(r: &Report) -> String {
    let mut t = format!(
        "{}; explainer {}\n\n| prompts | kind | accuracy | completeness | clarity | words |\n|---:|---|---:|---:|---:|---:|\n",
        r.protocol, r.explainer
    );
    for c in &r.categories {
        t += &format!(
            "| {} | {} | {:.2} | {:.2} | {:.2} | {:.1} |\n",
            c.prompts,
            c.category.name(),
            c.accuracy,
            c.completeness,
            c.clarity,
            c.mean_words
        );
    }
    t += &format!(
        "| {} | all | {:.2} | {:.2} | {:.2} | |\n",
        r.prompts, r.accuracy, r.completeness, r.clarity
    );
    t
}

#[cfg(test)]
mod tests {
    use super::*;
    use tactex_core::explain::TemplateExplainer;

    /// The template's words, or any other text, as an explanation to score.
    fn said(text: &str) -> Explanation {
        Explanation {
            text: text.into(),
            explainer: "test".into(),
            notice: None,
        }
    }

    fn answered(index: usize) -> (Case, Facts, String) {
        let catalog = FruitCatalog::builtin();
        let c = case(index, 1, &catalog).unwrap();
        let f = facts(&c, &catalog).unwrap();
        let text = TemplateExplainer.explain(&f).text;
        (c, f, text)
    }

    fn first(pred: impl Fn(&Case) -> bool) -> (Case, Facts, String) {
        (0..200)
            .map(answered)
            .find(|(c, _, _)| pred(c))
            .expect("a case of that kind")
    }

    #[test]
    fn the_template_scores_full_marks_on_every_kind_and_size() {
        let catalog = FruitCatalog::builtin();
        for i in 0..36 {
            let (c, f, text) = answered(i);
            let s = score(&c, &said(&text), &f, &catalog);
            assert!(
                s.accurate && s.complete && s.clear,
                "#{i} {}: {text}: {:?}",
                c.prompt,
                s.problems
            );
        }
    }

    #[test]
    fn wrong_answers_lose_the_score_they_should() {
        let catalog = FruitCatalog::builtin();
        // A wrong value.
        let (c, f, text) = first(|c| matches!(&c.expected, Expected::Describe(v) if v.len() == 1));
        let e = c.truth[match &c.expected {
            Expected::Describe(v) => v[0],
            _ => unreachable!(),
        }]
        .modulus_mpa;
        let wrong = text.replace(&format!("{e:.2} MPa"), &format!("{:.2} MPa", e * 1.5));
        let s = score(&c, &said(&wrong), &f, &catalog);
        assert!(!s.accurate, "{wrong}");
        // Ripeness left out.
        let (c, f, text) = first(
            |c| matches!(&c.expected, Expected::Describe(v) if v.len() == 1 && c.truth[v[0]].ripeness.is_some()),
        );
        let i = match &c.expected {
            Expected::Describe(v) => v[0],
            _ => unreachable!(),
        };
        let r = c.truth[i].ripeness.clone().unwrap();
        let dropped = text.replace(&format!(", {r}"), "");
        let s = score(&c, &said(&dropped), &f, &catalog);
        assert!(s.accurate && !s.complete, "{dropped}: {:?}", s.problems);
        // The wrong extreme named first.
        let (c, f, text) = first(|c| {
            matches!(&c.expected, Expected::Extreme { tied, .. } if tied.len() == 1)
                && c.truth.len() >= 3
        });
        let Expected::Extreme { pick, .. } = c.expected else {
            unreachable!()
        };
        let other = (0..c.truth.len()).find(|&j| j != pick).unwrap();
        let swapped = format!("The {} is the one. {text}", c.truth[other].label);
        let s = score(&c, &said(&swapped), &f, &catalog);
        assert!(!s.accurate, "{swapped}");
        // A ranking out of order.
        let (c, f, text) = first(|c| matches!(&c.expected, Expected::Ranked(v) if v.len() >= 3));
        let parts: Vec<&str> = text.splitn(2, ": ").collect();
        let mut items: Vec<&str> = parts[1].trim_end_matches('.').split("; ").collect();
        let last = items.len() - 1;
        items.swap(0, last);
        let reordered = format!("{}: {}.", parts[0], items.join("; "));
        let s = score(&c, &said(&reordered), &f, &catalog);
        assert!(!s.accurate, "{reordered}");
        // An absent fruit not reported.
        let (c, f, text) = first(|c| !c.absent.is_empty());
        let silent = text
            .split(". ")
            .filter(|s| !s.contains("could not find"))
            .collect::<Vec<_>>()
            .join(". ");
        let s = score(&c, &said(&silent), &f, &catalog);
        assert!(!s.complete, "{silent}");
        // A number without a unit, and an invented fruit.
        let (c, f, text) = answered(6);
        let s = score(&c, &said(&format!("{text} It weighs 120.")), &f, &catalog);
        assert!(!s.clear && !s.accurate, "{:?}", s.problems);
        let s = score(
            &c,
            &said(&format!("{text} The pineapple is a mango.")),
            &f,
            &catalog,
        );
        assert!(!s.accurate, "{:?}", s.problems);
    }
}
