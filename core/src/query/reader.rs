//! Who reads a prompt into a `Query`: the rules here, or a front end's reader (a language
//! model behind an endpoint, in the `tactex` binary), each saying who read it and, where a
//! reader stood in for another, why.

use super::{Query, QueryError, parse};
use crate::catalog::FruitCatalog;

/// A prompt as read, by whom, and why the reader asked for did not read it.
#[derive(Debug)]
pub struct ReadPrompt {
    pub query: Result<Query, QueryError>,
    /// "rules", or e.g. "llm:<model>" when a model's reading is the query.
    pub parser: String,
    pub notice: Option<String>,
}

/// Reads prompts. Infallible as a reader: one that cannot read falls back to the rules and
/// says why in `notice`; the rules' refusal is then the answer.
pub trait PromptReader: Send + Sync {
    fn read(&self, prompt: &str, catalog: &FruitCatalog) -> ReadPrompt;
}

/// The rule parser, offline.
pub struct RuleReader;

impl PromptReader for RuleReader {
    fn read(&self, prompt: &str, catalog: &FruitCatalog) -> ReadPrompt {
        ReadPrompt {
            query: parse(prompt, catalog),
            parser: "rules".into(),
            notice: None,
        }
    }
}
