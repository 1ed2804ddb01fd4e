//! Which parser reads the prompt: the rules (offline, the default) or a language model behind
//! an OpenAI-compatible endpoint, whose reply must be a `QueryDraft` that checks out against
//! the catalog. A model that is slow, down, or writes anything else is replaced by the rules,
//! with a notice saying why.

use crate::app::llm_chat::{LlmChat, LlmConfig};
use anyhow::Result;
use std::path::PathBuf;
use tactex_core::catalog::FruitCatalog;
use tactex_core::printable::printable;
use tactex_core::query::draft::QueryDraft;
use tactex_core::query::reader::{PromptReader, ReadPrompt, RuleReader};
use tactex_core::query::{self, Query, llm_prompt};

/// Which parser reads the prompt.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ParserChoice {
    /// The rule parser; offline.
    #[default]
    Rules,
    /// A chat-completions endpoint (TACTEX_LLM_BASE_URL / --llm-config), its reply checked
    /// against the query's schema and the catalog, with the rules as fallback.
    Llm,
}

impl ParserChoice {
    pub const NAMES: [&'static str; 2] = ["rules", "llm"];
}

impl std::str::FromStr for ParserChoice {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s.trim().to_ascii_lowercase().as_str() {
            "rules" => Ok(Self::Rules),
            "llm" => Ok(Self::Llm),
            _ => Err(format!("unknown parser {s:?} (rules or llm)")),
        }
    }
}

/// The parser that reads prompts.
pub enum PromptParser {
    Rules,
    Llm(LlmChat),
}

impl PromptParser {
    /// The parser `choice` names; `llm_config` is read by `--parser llm` only (the caller
    /// says when no one reads it).
    pub fn new(choice: ParserChoice, llm_config: Option<&PathBuf>) -> Result<Self> {
        Ok(match choice {
            ParserChoice::Rules => Self::Rules,
            ParserChoice::Llm => Self::Llm(LlmChat::new(LlmConfig::load(
                llm_config.map(PathBuf::as_path),
                "--parser llm",
            )?)),
        })
    }
}

impl PromptReader for PromptParser {
    fn read(&self, prompt: &str, catalog: &FruitCatalog) -> ReadPrompt {
        let rules = |notice: Option<String>| ReadPrompt {
            notice,
            ..RuleReader.read(prompt, catalog)
        };
        let chat = match self {
            Self::Rules => return rules(None),
            Self::Llm(chat) => chat,
        };
        // The prompt's limits hold for every parser: an empty or over-long prompt is refused
        // before anything is sent.
        if let Err(e) = query::checked_prompt(prompt) {
            return ReadPrompt {
                query: Err(e),
                ..rules(None)
            };
        }
        let why = match chat.complete(
            llm_prompt::messages(prompt, catalog),
            llm_prompt::TEMPERATURE,
        ) {
            Ok(reply) => match model_reading(&reply, catalog) {
                Ok(query) => {
                    return ReadPrompt {
                        query: Ok(query),
                        parser: chat.name(),
                        notice: None,
                    };
                }
                Err(e) => format!("the model's reading was not a query ({e})"),
            },
            Err(e) => e,
        };
        // What the endpoint or model wrote is outside text: one line, escaped, bounded.
        let why: String = printable(&why).chars().take(MAX_NOTICE_CHARS).collect();
        rules(Some(format!("{why}; read by the rules")))
    }
}

/// The longest reason a notice quotes: a model's 500 kB field name is not a message.
const MAX_NOTICE_CHARS: usize = 240;

/// The query in a model's reply, or why there is none.
fn model_reading(reply: &str, catalog: &FruitCatalog) -> Result<Query, String> {
    let object = llm_prompt::reply_object(reply).ok_or("no JSON object in the reply")?;
    let draft: QueryDraft = serde_json::from_str(object).map_err(|e| e.to_string())?;
    draft.checked(catalog)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::app::llm_chat::fake::{Behaviour, fake_server};
    use std::time::Duration;

    fn parser_at(url: &str, timeout_s: f64) -> PromptParser {
        PromptParser::Llm(LlmChat::new(LlmConfig {
            base_url: url.into(),
            model: "fake-model".into(),
            api_key: None,
            timeout: Duration::from_secs_f64(timeout_s),
        }))
    }

    #[test]
    fn a_checked_reading_is_the_query_and_the_request_carries_the_examples() {
        // A phrasing the rules cannot read, read by the model.
        let prompt = "Out of everything here, what's the squishiest thing I could blend?";
        let reply = r#"```json
{"intent": "extreme", "property": "ripeness", "extreme": "most", "all": true, "goal": "for a smoothie"}
```"#;
        let (url, seen) = fake_server(Behaviour::Reply(reply.into()));
        let catalog = FruitCatalog::builtin();
        let read = parser_at(&url, 5.0).read(prompt, &catalog);
        let q = read.query.unwrap();
        assert_eq!(read.parser, "llm:fake-model");
        assert_eq!(read.notice, None);
        assert_eq!(q.goal.unwrap().said, "for a smoothie");
        let request = seen.lock().unwrap()[0].clone();
        assert_eq!(request["temperature"], 0.0);
        let turns = request["messages"].as_array().unwrap();
        assert_eq!(turns.last().unwrap()["content"], prompt);
        assert_eq!(turns[1]["content"], "Which fruit is the softest?");
    }

    /// Each failure falls back to the rules' reading with a notice naming the cause.
    fn falls_back(behaviour: Behaviour, timeout_s: f64, cause: &str) {
        let (url, _) = fake_server(behaviour);
        let catalog = FruitCatalog::builtin();
        let prompt = "Which banana is the ripest?";
        let read = parser_at(&url, timeout_s).read(prompt, &catalog);
        assert_eq!(read.query, query::parse(prompt, &catalog));
        assert_eq!(read.parser, "rules");
        let notice = read.notice.expect("a notice");
        assert!(notice.contains(cause), "{notice}");
        assert!(notice.ends_with("read by the rules"), "{notice}");
    }

    #[test]
    fn a_slow_endpoint_times_out_to_the_rules() {
        falls_back(Behaviour::Slow(Duration::from_secs(3)), 0.5, "within 0.5 s");
    }

    #[test]
    fn garbage_falls_back_to_the_rules() {
        falls_back(Behaviour::Garbage, 5.0, "not a chat completion");
    }

    #[test]
    fn an_http_500_falls_back_to_the_rules() {
        falls_back(Behaviour::Status(500), 5.0, "HTTP 500");
    }

    #[test]
    fn prose_instead_of_a_query_falls_back_to_the_rules() {
        falls_back(
            Behaviour::Reply("The ripest banana is probably the yellow one.".into()),
            5.0,
            "no JSON object in the reply",
        );
    }

    #[test]
    fn a_reading_outside_the_catalog_falls_back_to_the_rules() {
        falls_back(
            Behaviour::Reply(
                r#"{"intent": "extreme", "property": "ripeness", "extreme": "most", "targets": ["plantain"]}"#
                    .into(),
            ),
            5.0,
            "targets: 'plantain' is not in the fruit catalog",
        );
    }

    #[test]
    fn a_notice_quoting_the_reply_is_one_escaped_bounded_line() {
        let key = format!("\u{1b}[2J{}\nerror: forged", "k".repeat(500_000));
        let mut fields = serde_json::Map::new();
        fields.insert("intent".into(), "identify".into());
        fields.insert(key, 1.into());
        let reply = serde_json::Value::Object(fields).to_string();
        let (url, _) = fake_server(Behaviour::Reply(reply));
        let read = parser_at(&url, 5.0).read("How hard is the kiwi?", &FruitCatalog::builtin());
        let notice = read.notice.unwrap();
        assert!(notice.len() < 400, "{} bytes", notice.len());
        assert!(!notice.chars().any(char::is_control), "{notice:?}");
        assert!(notice.contains("\\u{1b}[2J"), "{notice}");
        assert!(read.query.is_ok());
    }

    #[test]
    fn a_closed_port_falls_back_to_the_rules() {
        // A port bound and released: nothing listens there.
        let port = std::net::TcpListener::bind("127.0.0.1:0")
            .unwrap()
            .local_addr()
            .unwrap()
            .port();
        let parser = parser_at(&format!("http://127.0.0.1:{port}/v1"), 2.0);
        let read = parser.read("Which banana is the ripest?", &FruitCatalog::builtin());
        assert_eq!(read.parser, "rules");
        assert!(read.query.is_ok());
        assert!(read.notice.unwrap().ends_with("read by the rules"));
    }
}
