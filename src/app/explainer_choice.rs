//! The language-model explainer: the facts go to any OpenAI-compatible chat-completions
//! endpoint (Groq, OpenAI, a local llama.cpp or Ollama server), and the reply is the answer
//! only when `grounded::check` finds every label and number in it measured. Anything else
//! (no answer in time, an HTTP error, garbage, an invented or dropped claim) falls back to
//! the template with a notice saying why.

use crate::app::llm_chat::LlmChat;
pub use crate::app::llm_chat::LlmConfig;
use anyhow::{Result, bail};
use std::path::PathBuf;
use tactex_core::catalog::FruitCatalog;
use tactex_core::explain::{
    Explainer, Explanation, Facts, TemplateExplainer, grounded, llm_prompt,
};

/// Which explainer writes the answer.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ExplainerChoice {
    /// Deterministic text from the measurements; offline.
    #[default]
    Template,
    /// A chat-completions endpoint (TACTEX_LLM_BASE_URL / --llm-config), checked for
    /// groundedness, with the template as fallback.
    Llm,
}

impl ExplainerChoice {
    pub const NAMES: [&'static str; 2] = ["template", "llm"];
}

impl std::str::FromStr for ExplainerChoice {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s.trim().to_ascii_lowercase().as_str() {
            "template" => Ok(Self::Template),
            "llm" => Ok(Self::Llm),
            _ => Err(format!("unknown explainer {s:?} (template or llm)")),
        }
    }
}

pub struct LlmExplainer {
    chat: LlmChat,
    catalog: FruitCatalog,
    name: String,
}

impl LlmExplainer {
    pub fn new(config: LlmConfig, catalog: FruitCatalog) -> Self {
        let chat = LlmChat::new(config);
        let name = chat.name();
        Self {
            chat,
            catalog,
            name,
        }
    }

    /// The model's reply text, or why there is none.
    fn ask(&self, facts: &Facts) -> Result<String, String> {
        self.chat
            .complete(llm_prompt::messages(facts), llm_prompt::TEMPERATURE)
    }
}

impl Explainer for LlmExplainer {
    fn name(&self) -> &str {
        &self.name
    }

    fn explain(&self, facts: &Facts) -> Explanation {
        let why = match self.ask(facts) {
            Ok(reply) => match grounded::check(&reply, facts, &self.catalog) {
                Ok(()) => {
                    return Explanation {
                        text: reply,
                        explainer: self.name.clone(),
                        notice: None,
                    };
                }
                Err(e) => format!("the model's reply was not grounded ({e})"),
            },
            Err(e) => e,
        };
        let mut fallback = TemplateExplainer.explain(facts);
        fallback.notice = Some(format!("{why}; answered with the template"));
        fallback
    }
}

/// The explainer `choice` names; `llm_config` is the optional `--llm-config FILE`.
pub fn explainer(
    choice: ExplainerChoice,
    llm_config: Option<&PathBuf>,
) -> Result<Box<dyn Explainer>> {
    Ok(match choice {
        ExplainerChoice::Template => {
            if let Some(path) = llm_config {
                bail!(
                    "--llm-config {}: read only by --explainer llm; the explainer here is the template",
                    path.display()
                );
            }
            Box::new(TemplateExplainer)
        }
        ExplainerChoice::Llm => Box::new(LlmExplainer::new(
            LlmConfig::load(llm_config.map(PathBuf::as_path), "--explainer llm")?,
            FruitCatalog::builtin(),
        )),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::app::llm_chat::fake::{Behaviour, fake_server};
    use std::time::Duration;
    use tactex_core::explain::{Measured, location_words, select};
    use tactex_core::hardness::scale::Hardness;

    fn facts() -> Facts {
        let catalog = FruitCatalog::builtin();
        let prompt = "Which fruit is the softest?";
        let query = tactex_core::query::parse(prompt, &catalog).unwrap();
        let m = |label: &str, e: f64, x: f64, y: f64, r: &str| Measured {
            label: label.into(),
            location: location_words(x, y),
            hardness: Some(Hardness::ModulusMpa(e).into()),
            interval_68_mpa: [Some(e - 0.05), Some(e + 0.05)],
            interval_95_mpa: [Some(e - 0.1), Some(e + 0.1)],
            ripeness: Some(r.into()),
            not_measured: None,
            reference: false,
        };
        let objects = vec![
            m("banana", 0.80, -0.15, -0.1, "ripe"),
            m("lime", 4.0, 0.0, 0.0, "unripe"),
        ];
        let selected = select(&query, &objects, &catalog);
        Facts {
            prompt: prompt.into(),
            query,
            objects,
            selected,
            not_found: Vec::new(),
        }
    }

    fn explainer_at(url: &str, timeout_s: f64) -> LlmExplainer {
        LlmExplainer::new(
            LlmConfig {
                base_url: url.into(),
                model: "fake-model".into(),
                api_key: Some("k-test".into()),
                timeout: Duration::from_secs_f64(timeout_s),
            },
            FruitCatalog::builtin(),
        )
    }

    #[test]
    fn a_grounded_reply_is_the_answer_and_the_request_follows_the_paper() {
        let good = "The softest fruit is the ripe banana at the left front, 0.80 MPa.";
        let (url, seen) = fake_server(Behaviour::Reply(good.into()));
        let e = explainer_at(&url, 5.0).explain(&facts());
        assert_eq!(e.text, good);
        assert_eq!(e.explainer, "llm:fake-model");
        assert_eq!(e.notice, None);
        let request = seen.lock().unwrap()[0].clone();
        assert_eq!(request["model"], "fake-model");
        assert_eq!(request["temperature"], 0.1);
        assert_eq!(request["messages"][0]["content"], llm_prompt::SYSTEM_ROLE);
        assert!(
            request["messages"][1]["content"]
                .as_str()
                .unwrap()
                .contains("0.80 MPa")
        );
    }

    /// Each failure falls back to the template's words with a notice naming the cause.
    fn falls_back(behaviour: Behaviour, timeout_s: f64, cause: &str) {
        let (url, _) = fake_server(behaviour);
        let f = facts();
        let e = explainer_at(&url, timeout_s).explain(&f);
        assert_eq!(e.text, TemplateExplainer.explain(&f).text);
        assert_eq!(e.explainer, "template");
        let notice = e.notice.expect("a notice");
        assert!(notice.contains(cause), "{notice}");
        assert!(notice.ends_with("answered with the template"), "{notice}");
    }

    #[test]
    fn a_slow_endpoint_times_out_to_the_template() {
        falls_back(Behaviour::Slow(Duration::from_secs(3)), 0.5, "within 0.5 s");
    }

    #[test]
    fn garbage_falls_back_to_the_template() {
        falls_back(Behaviour::Garbage, 5.0, "not a chat completion");
    }

    #[test]
    fn an_http_500_falls_back_to_the_template() {
        falls_back(Behaviour::Status(500), 5.0, "HTTP 500");
    }

    #[test]
    fn a_hallucinated_number_falls_back_to_the_template() {
        falls_back(
            Behaviour::Reply("The softest is the ripe banana at the left front, 0.35 MPa.".into()),
            5.0,
            "0.35 mpa is not a measured value",
        );
    }

    #[test]
    fn a_dropped_object_falls_back_to_the_template() {
        falls_back(
            Behaviour::Reply("The softest fruit is at the left front, 0.80 MPa, ripe.".into()),
            5.0,
            "leaves out the banana",
        );
    }
}
