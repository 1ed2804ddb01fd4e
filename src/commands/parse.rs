//! `tactex parse`: what the prompt parser reads from a question, as text or JSON.

use crate::app::parser_choice::{ParserChoice, PromptParser};
use crate::report::tail::print_json_or_text;
use anyhow::{Context, Result, bail};
use clap::Args;
use std::path::PathBuf;
use tactex_core::catalog::FruitCatalog;
use tactex_core::query::Query;
use tactex_core::query::reader::PromptReader;

#[derive(Args)]
pub struct ParseArgs {
    /// The question, e.g. "Which banana is the softest?"
    pub prompt: String,
    /// Print the parsed query as one JSON object.
    #[arg(long)]
    pub json: bool,
    /// Who reads the question: rules (offline) or llm (an OpenAI-compatible endpoint from
    /// TACTEX_LLM_* or --llm-config; a reading that does not check out falls back to the
    /// rules with a notice).
    #[arg(long, default_value = "rules", value_parser = crate::app::flag_range::choice::<ParserChoice>(&ParserChoice::NAMES))]
    pub parser: ParserChoice,
    /// TOML with base_url, model, api_key_env and timeout_s for --parser llm.
    #[arg(long)]
    pub llm_config: Option<PathBuf>,
}

pub(crate) fn run(args: &ParseArgs) -> Result<()> {
    let catalog = FruitCatalog::builtin();
    if let (Some(path), ParserChoice::Rules) = (&args.llm_config, args.parser) {
        bail!("--llm-config {}: read only by --parser llm", path.display());
    }
    let parser = PromptParser::new(args.parser, args.llm_config.as_ref())?;
    let read = parser.read(&args.prompt, &catalog);
    if let Some(notice) = &read.notice {
        eprintln!("note: {notice}");
    }
    let query = read.query?;
    // The query's fields, and who read it ("rules" or "llm:<model>").
    let mut json = serde_json::to_value(&query).context("serialising the query")?;
    json["parser"] = read.parser.clone().into();
    json["parse_notice"] = read.notice.clone().into();
    print_json_or_text(&json, args.json, || {
        print!("{}", describe(&query));
        println!("parser:   {}", read.parser);
        Ok(())
    })
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
            r.named()
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
    if let Some(size) = q.filters.size {
        s += &format!("size:     {}\n", size.name());
    }
    if q.ranked {
        s += "ranked:   yes\n";
    }
    if !q.unknown.is_empty() {
        s += &format!("unknown:  {} (not in the catalog)\n", q.unknown.join(", "));
    }
    if let Some(c) = &q.candidate {
        s += &format!("held up:  the {c}, against every fruit (yes or no)\n");
    }
    for c in &q.corrected {
        s += &format!("read:     '{}' as {}\n", c.said, c.read);
    }
    s
}
