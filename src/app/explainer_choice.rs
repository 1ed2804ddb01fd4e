//! The language-model explainer: the facts go to any OpenAI-compatible chat-completions
//! endpoint (Groq, OpenAI, a local llama.cpp or Ollama server), and the reply is the answer
//! only when `grounded::check` finds every label and number in it measured. Anything else
//! (no answer in time, an HTTP error, garbage, an invented or dropped claim) falls back to
//! the template with a notice saying why.

use anyhow::{Context, Result, bail};
use clap::ValueEnum;
use serde::Deserialize;
use std::path::{Path, PathBuf};
use std::time::Duration;
use tactex_core::catalog::FruitCatalog;
use tactex_core::explain::{
    Explainer, Explanation, Facts, TemplateExplainer, grounded, llm_prompt,
};

/// Which explainer writes the answer.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum ExplainerChoice {
    /// Deterministic text from the measurements; offline.
    Template,
    /// A chat-completions endpoint (TACTEX_LLM_BASE_URL / --llm-config), checked for
    /// groundedness, with the template as fallback.
    Llm,
}

/// Where the model is and how long to wait for it.
#[derive(Clone, Debug, PartialEq)]
pub struct LlmConfig {
    /// e.g. https://api.groq.com/openai/v1 or http://127.0.0.1:8080/v1
    pub base_url: String,
    pub model: String,
    pub api_key: Option<String>,
    pub timeout: Duration,
}

/// `--llm-config FILE`: the same settings as the environment, in TOML.
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
struct LlmConfigFile {
    base_url: Option<String>,
    model: Option<String>,
    /// The name of the environment variable that holds the key (keys stay out of files).
    api_key_env: Option<String>,
    timeout_s: Option<f64>,
}

pub const DEFAULT_TIMEOUT_S: f64 = 20.0;

impl LlmConfig {
    /// Settings from `file` (when given), the rest from TACTEX_LLM_BASE_URL,
    /// TACTEX_LLM_MODEL, TACTEX_LLM_API_KEY and TACTEX_LLM_TIMEOUT_S.
    pub fn load(file: Option<&Path>) -> Result<Self> {
        let env = |k: &str| std::env::var(k).ok().filter(|v| !v.trim().is_empty());
        let from_file = match file {
            Some(path) => {
                let text = std::fs::read_to_string(path)
                    .with_context(|| format!("{}: cannot read", path.display()))?;
                toml::from_str::<LlmConfigFile>(&text).map_err(|e| {
                    anyhow::anyhow!(
                        "{}: {}",
                        path.display(),
                        tactex_core::file_failure::toml_failure(&text, &e)
                    )
                })?
            }
            None => LlmConfigFile::default(),
        };
        let named = |field: &str| match file {
            Some(p) => format!(
                "{field} in {} or TACTEX_LLM_{}",
                p.display(),
                field.to_uppercase()
            ),
            None => format!(
                "TACTEX_LLM_{} (or {field} in --llm-config FILE)",
                field.to_uppercase()
            ),
        };
        let Some(base_url) = from_file.base_url.or_else(|| env("TACTEX_LLM_BASE_URL")) else {
            bail!("--explainer llm: no endpoint; set {}", named("base_url"));
        };
        if !(base_url.starts_with("http://") || base_url.starts_with("https://")) {
            bail!("LLM base_url '{base_url}': not an http:// or https:// URL");
        }
        let Some(model) = from_file.model.or_else(|| env("TACTEX_LLM_MODEL")) else {
            bail!("--explainer llm: no model; set {}", named("model"));
        };
        let api_key = match &from_file.api_key_env {
            Some(var) => Some(env(var).with_context(|| {
                format!("LLM api_key_env: environment variable {var} is not set")
            })?),
            None => env("TACTEX_LLM_API_KEY"),
        };
        let timeout_s = match from_file.timeout_s {
            Some(t) => t,
            None => match env("TACTEX_LLM_TIMEOUT_S") {
                Some(t) => t
                    .parse::<f64>()
                    .with_context(|| format!("TACTEX_LLM_TIMEOUT_S '{t}': not a number"))?,
                None => DEFAULT_TIMEOUT_S,
            },
        };
        if !(timeout_s.is_finite() && timeout_s > 0.0 && timeout_s <= 600.0) {
            bail!("LLM timeout_s {timeout_s}: must be in (0, 600] seconds");
        }
        Ok(Self {
            base_url: base_url.trim_end_matches('/').to_string(),
            model,
            api_key,
            timeout: Duration::from_secs_f64(timeout_s),
        })
    }
}

pub struct LlmExplainer {
    config: LlmConfig,
    agent: ureq::Agent,
    catalog: FruitCatalog,
    name: String,
}

#[derive(Deserialize)]
struct Completion {
    choices: Vec<Choice>,
}

#[derive(Deserialize)]
struct Choice {
    message: Message,
}

#[derive(Deserialize)]
struct Message {
    content: Option<String>,
}

impl LlmExplainer {
    pub fn new(config: LlmConfig, catalog: FruitCatalog) -> Self {
        let agent = ureq::Agent::config_builder()
            .timeout_global(Some(config.timeout))
            .http_status_as_error(false)
            .build()
            .into();
        let name = format!("llm:{}", config.model);
        Self {
            config,
            agent,
            catalog,
            name,
        }
    }

    /// The model's reply text, or why there is none.
    fn ask(&self, facts: &Facts) -> Result<String, String> {
        let url = format!("{}/chat/completions", self.config.base_url);
        let body = serde_json::json!({
            "model": self.config.model,
            "temperature": llm_prompt::TEMPERATURE,
            "messages": llm_prompt::messages(facts),
        });
        let mut request = self.agent.post(&url);
        if let Some(key) = &self.config.api_key {
            request = request.header("Authorization", &format!("Bearer {key}"));
        }
        // One wording for a transport failure, whether sending or reading timed out.
        let failed = |e: ureq::Error| match e {
            ureq::Error::Timeout(_) => format!(
                "no reply from {url} within {:.1} s",
                self.config.timeout.as_secs_f64()
            ),
            e => format!("{url}: {e}"),
        };
        let mut response = request.send_json(&body).map_err(failed)?;
        let status = response.status();
        let text = response
            .body_mut()
            .with_config()
            .limit(1 << 20)
            .read_to_string()
            .map_err(failed)?;
        if !status.is_success() {
            let first = text
                .lines()
                .next()
                .unwrap_or("")
                .chars()
                .take(120)
                .collect::<String>();
            return Err(format!("{url}: HTTP {} {first}", status.as_u16()));
        }
        let completion: Completion = serde_json::from_str(&text)
            .map_err(|e| format!("{url}: not a chat completion ({e})"))?;
        completion
            .choices
            .into_iter()
            .next()
            .and_then(|c| c.message.content)
            .map(|s| s.trim().to_string())
            .ok_or_else(|| format!("{url}: the completion has no message"))
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
            LlmConfig::load(llm_config.map(PathBuf::as_path))?,
            FruitCatalog::builtin(),
        )),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::{BufRead, BufReader, Read, Write};
    use std::net::TcpListener;
    use std::sync::{Arc, Mutex};
    use tactex_core::explain::{Measured, location_words, select};
    use tactex_core::hardness::scale::Hardness;

    /// How the fake endpoint behaves.
    #[derive(Clone)]
    enum Behaviour {
        Reply(String),
        Slow(Duration),
        Garbage,
        Status(u16),
    }

    /// A one-thread chat-completions server on 127.0.0.1 that records each request body.
    fn fake_server(behaviour: Behaviour) -> (String, Arc<Mutex<Vec<serde_json::Value>>>) {
        let listener = TcpListener::bind("127.0.0.1:0").unwrap();
        let url = format!("http://{}/v1", listener.local_addr().unwrap());
        let seen = Arc::new(Mutex::new(Vec::new()));
        let log = seen.clone();
        std::thread::spawn(move || {
            for stream in listener.incoming() {
                let Ok(mut stream) = stream else { continue };
                let mut reader = BufReader::new(stream.try_clone().unwrap());
                let mut length = 0usize;
                loop {
                    let mut line = String::new();
                    if reader.read_line(&mut line).unwrap_or(0) == 0 || line == "\r\n" {
                        break;
                    }
                    if let Some(v) = line.to_lowercase().strip_prefix("content-length:") {
                        length = v.trim().parse().unwrap_or(0);
                    }
                }
                let mut body = vec![0; length];
                reader.read_exact(&mut body).ok();
                if let Ok(v) = serde_json::from_slice(&body) {
                    log.lock().unwrap().push(v);
                }
                let (status, payload) = match &behaviour {
                    Behaviour::Reply(text) => (
                        200,
                        serde_json::json!({"choices": [{"message": {"role": "assistant", "content": text}}]})
                            .to_string(),
                    ),
                    Behaviour::Slow(d) => {
                        std::thread::sleep(*d);
                        (200, "{}".to_string())
                    }
                    Behaviour::Garbage => (200, "<html>gateway says hello</html>".to_string()),
                    Behaviour::Status(s) => (*s, "{\"error\": \"internal\"}".to_string()),
                };
                let _ = write!(
                    stream,
                    "HTTP/1.1 {status} X\r\ncontent-type: application/json\r\ncontent-length: {}\r\nconnection: close\r\n\r\n{payload}",
                    payload.len()
                );
            }
        });
        (url, seen)
    }

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

    #[test]
    fn no_endpoint_is_a_one_line_error_naming_the_variable() {
        // Only this test touches the LLM variables, so it cannot race another test.
        let err = LlmConfig::load(Some(Path::new("/nonexistent/llm.toml"))).unwrap_err();
        assert!(
            format!("{err:#}").contains("/nonexistent/llm.toml"),
            "{err:#}"
        );
        let dir = tempfile::tempdir().unwrap();
        let file = dir.path().join("llm.toml");
        std::fs::write(&file, "model = \"m\"\nbase_url = \"ftp://x\"\n").unwrap();
        let err = LlmConfig::load(Some(&file)).unwrap_err();
        assert!(format!("{err:#}").contains("ftp://x"), "{err:#}");
        std::fs::write(
            &file,
            "model = \"m\"\nbase_url = \"http://127.0.0.1:1/v1\"\nsecret = 1\n",
        )
        .unwrap();
        let err = LlmConfig::load(Some(&file)).unwrap_err();
        assert!(format!("{err:#}").contains("secret"), "{err:#}");
        std::fs::write(
            &file,
            "model = \"m\"\nbase_url = \"http://127.0.0.1:1/v1/\"\ntimeout_s = 3\n",
        )
        .unwrap();
        let c = LlmConfig::load(Some(&file)).unwrap();
        assert_eq!(c.base_url, "http://127.0.0.1:1/v1");
        assert_eq!(c.timeout, Duration::from_secs(3));
    }
}
