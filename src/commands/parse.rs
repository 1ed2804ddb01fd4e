//! `tactex parse`: what the prompt parser reads from a question, as text or JSON.

use anyhow::{Context, Result};
use clap::Args;
use tactex_core::catalog::FruitCatalog;
use tactex_core::query::{self, Query};

#[derive(Args)]
pub struct ParseArgs {
    /// The question, e.g. "Which banana is the softest?"
    pub prompt: String,
    /// Print the parsed query as one JSON object.
    #[arg(long)]
    pub json: bool,
}

pub fn run(args: &ParseArgs) -> Result<()> {
    let catalog = FruitCatalog::builtin();
    let query = query::parse(&args.prompt, &catalog)?;
    if args.json {
        println!(
            "{}",
            serde_json::to_string_pretty(&query).context("serialising the query")?
        );
    } else {
        print!("{}", describe(&query));
    }
    Ok(())
}

/// The snake_case name serde gives an enum value.
fn lower<T: serde::Serialize>(v: &T) -> String {
    serde_json::to_value(v)
        .ok()
        .and_then(|v| v.as_str().map(str::to_string))
        .unwrap_or_default()
}

fn describe(q: &Query) -> String {
    let mut s = format!("intent:   {}\n", lower(&q.intent));
    s += &format!("property: {}\n", lower(&q.property));
    if let Some(e) = q.extreme {
        s += &format!("extreme:  {}\n", lower(&e));
    }
    if let Some(g) = &q.goal {
        s += &format!("goal:     {}\n", g.said);
    }
    let over = match (q.all, q.targets.is_empty()) {
        (true, true) => "every fruit".to_string(),
        (true, false) => format!("{} and every other fruit", q.targets.join(", ")),
        (false, true) if !q.categories.is_empty() => "the groups below".to_string(),
        (false, _) => q.targets.join(", "),
    };
    s += &format!("objects:  {over}\n");
    if !q.categories.is_empty() {
        let groups: Vec<String> = q
            .categories
            .iter()
            .map(|c| format!("{} ({})", c.name, c.members.join(", ")))
            .collect();
        s += &format!("groups:   {}\n", groups.join("; "));
    }
    if let Some(t) = &q.threshold {
        s += &format!("value:    {} than {}\n", t.relation(), t.words());
    }
    if let Some(r) = &q.relation {
        s += &format!(
            "value:    {} than the {} (as measured)\n",
            r.relation(),
            r.reference
        );
    }
    if !q.exclude.is_empty() {
        s += &format!("except:   {}\n", q.exclude.join(", "));
    }
    if let Some(c) = &q.filters.color {
        s += &format!("colour:   {c}\n");
    }
    if let Some(p) = &q.filters.position {
        s += &format!("position: {p}\n");
    }
    if let Some(n) = q.filters.count {
        s += &format!("count:    {n}\n");
    }
    if q.ranked {
        s += "ranked:   yes\n";
    }
    if !q.unknown.is_empty() {
        s += &format!("unknown:  {} (not in the catalog)\n", q.unknown.join(", "));
    }
    s
}
