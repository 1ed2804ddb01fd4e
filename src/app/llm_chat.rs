//! A client for any OpenAI-compatible chat-completions endpoint (Groq, OpenAI, a local
//! llama.cpp or Ollama server), configured by TACTEX_LLM_* or `--llm-config FILE`: the one
//! way the explainer and the prompt parser reach a language model.

use anyhow::{Context, Result, bail};
use serde::Deserialize;
use std::path::Path;
use std::time::Duration;

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
    /// TACTEX_LLM_MODEL, TACTEX_LLM_API_KEY and TACTEX_LLM_TIMEOUT_S; `who` (the flag that
    /// asked for a model) names what is missing.
    pub fn load(file: Option<&Path>, who: &str) -> Result<Self> {
        let env = |k: &str| std::env::var(k).ok().filter(|v| !v.trim().is_empty());
        let from_file = match file {
            Some(path) => {
                let text = read_small(path)?;
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
            bail!("{who}: no endpoint; set {}", named("base_url"));
        };
        if !(base_url.starts_with("http://") || base_url.starts_with("https://")) {
            bail!("LLM base_url '{base_url}': not an http:// or https:// URL");
        }
        let Some(model) = from_file.model.or_else(|| env("TACTEX_LLM_MODEL")) else {
            bail!("{who}: no model; set {}", named("model"));
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

#[cfg(feature = "llm")]
#[derive(Deserialize)]
struct Completion {
    choices: Vec<Choice>,
}

#[cfg(feature = "llm")]
#[derive(Deserialize)]
struct Choice {
    message: Message,
}

#[cfg(feature = "llm")]
#[derive(Deserialize)]
struct Message {
    content: Option<String>,
}

/// The largest configuration file read: a few settings, not a stream (`/dev/urandom`).
const MAX_CONFIG_BYTES: u64 = 64 * 1024;

/// A configuration file's text, refused when it is not a regular file of a few kB.
fn read_small(path: &Path) -> Result<String> {
    use std::io::Read;
    let shown = path.display();
    let meta = std::fs::metadata(path).with_context(|| format!("{shown}: cannot read"))?;
    if !meta.is_file() {
        bail!("{shown}: not a regular file");
    }
    let mut text = String::new();
    std::fs::File::open(path)
        .and_then(|f| f.take(MAX_CONFIG_BYTES + 1).read_to_string(&mut text))
        .with_context(|| format!("{shown}: cannot read"))?;
    if text.len() as u64 > MAX_CONFIG_BYTES {
        bail!("{shown}: over {MAX_CONFIG_BYTES} bytes; an LLM configuration is a few lines");
    }
    Ok(text)
}

/// A chat-completions endpoint, and a client that waits no longer than the configuration
/// says.
pub struct LlmChat {
    pub config: LlmConfig,
    #[cfg(feature = "llm")]
    agent: ureq::Agent,
}

impl LlmChat {
    pub fn new(config: LlmConfig) -> Self {
        #[cfg(feature = "llm")]
        let agent = ureq::Agent::config_builder()
            .timeout_global(Some(config.timeout))
            .http_status_as_error(false)
            .build()
            .into();
        Self {
            config,
            #[cfg(feature = "llm")]
            agent,
        }
    }

    /// "llm:<model>": who wrote a reply.
    pub fn name(&self) -> String {
        format!("llm:{}", self.config.model)
    }

    /// Built without the client (the Python extension), there is never a reply: callers
    /// fall back to the template and the rules with a notice, as for an endpoint that is down.
    #[cfg(not(feature = "llm"))]
    pub fn complete(
        &self,
        _messages: serde_json::Value,
        _temperature: f64,
    ) -> Result<String, String> {
        Err(format!(
            "{}: this build has no LLM client (the `llm` feature of the tactex library)",
            self.config.base_url
        ))
    }

    /// The model's reply text to `messages`, or why there is none.
    #[cfg(feature = "llm")]
    pub fn complete(
        &self,
        messages: serde_json::Value,
        temperature: f64,
    ) -> Result<String, String> {
        let url = format!("{}/chat/completions", self.config.base_url);
        let body = serde_json::json!({
            "model": self.config.model,
            "temperature": temperature,
            "messages": messages,
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
            // The body is the endpoint's text: escaped, so a terminal never acts on it.
            let first = tactex_core::printable::printable(&first);
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

#[cfg(test)]
pub(crate) mod fake {
    //! A one-thread chat-completions server on 127.0.0.1 for tests.
    use std::io::{BufRead, BufReader, Read, Write};
    use std::net::TcpListener;
    use std::sync::{Arc, Mutex};
    use std::time::Duration;

    /// How the fake endpoint behaves.
    #[derive(Clone)]
    pub(crate) enum Behaviour {
        Reply(String),
        Slow(Duration),
        Garbage,
        Status(u16),
    }

    /// A one-thread chat-completions server on 127.0.0.1 that records each request body.
    pub(crate) fn fake_server(
        behaviour: Behaviour,
    ) -> (String, Arc<Mutex<Vec<serde_json::Value>>>) {
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
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn no_endpoint_is_a_one_line_error_naming_the_variable() {
        // Only this test touches the LLM variables, so it cannot race another test.
        let err = LlmConfig::load(Some(Path::new("/nonexistent/llm.toml")), "--explainer llm")
            .unwrap_err();
        assert!(
            format!("{err:#}").contains("/nonexistent/llm.toml"),
            "{err:#}"
        );
        let dir = tempfile::tempdir().unwrap();
        let file = dir.path().join("llm.toml");
        std::fs::write(&file, "model = \"m\"\nbase_url = \"ftp://x\"\n").unwrap();
        let err = LlmConfig::load(Some(&file), "--explainer llm").unwrap_err();
        assert!(format!("{err:#}").contains("ftp://x"), "{err:#}");
        std::fs::write(
            &file,
            "model = \"m\"\nbase_url = \"http://127.0.0.1:1/v1\"\nsecret = 1\n",
        )
        .unwrap();
        let err = LlmConfig::load(Some(&file), "--explainer llm").unwrap_err();
        assert!(format!("{err:#}").contains("secret"), "{err:#}");
        std::fs::write(
            &file,
            "model = \"m\"\nbase_url = \"http://127.0.0.1:1/v1/\"\ntimeout_s = 3\n",
        )
        .unwrap();
        let c = LlmConfig::load(Some(&file), "--explainer llm").unwrap();
        assert_eq!(c.base_url, "http://127.0.0.1:1/v1");
        assert_eq!(c.timeout, Duration::from_secs(3));
    }
}
