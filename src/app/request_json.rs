//! Requests handed over as JSON text (the Python package sends its keywords so): every field
//! by name, each choice read by its own `FromStr` (the parse the CLI's flags use), and a
//! mistake a `FieldError` naming the field as the caller named it.

use crate::app::flag_range::FieldError;
use serde::de::{DeserializeOwned, Error};
use serde::{Deserialize, Deserializer};
use std::str::FromStr;

/// A choice given as its name ("layer", "cpu", "indentation"), read by its `FromStr`.
pub fn parsed<'de, D, T>(d: D) -> Result<T, D::Error>
where
    D: Deserializer<'de>,
    T: FromStr<Err = String>,
{
    let text = String::deserialize(d)?;
    text.parse().map_err(D::Error::custom)
}

/// The request `text` holds; an error names the field it is about (the innermost key).
pub fn from_json<T: DeserializeOwned>(text: &str) -> Result<T, FieldError> {
    let mut de = serde_json::Deserializer::from_str(text);
    serde_path_to_error::deserialize(&mut de).map_err(|e| {
        let path = e.path().to_string();
        let field = path.rsplit('.').next().unwrap_or("request").to_string();
        let message = e.into_inner().to_string();
        // serde_json says where in the text; the caller never saw the text.
        let message = match message.find(" at line ") {
            Some(at) => message[..at].to_string(),
            None => message,
        };
        // A missing or unknown key is about that key, whatever the path says.
        let named = |what: &str| {
            let rest = message.strip_prefix(what)?.strip_prefix(" `")?;
            Some(rest[..rest.find('`')?].to_string())
        };
        if let Some(key) = named("missing field") {
            return FieldError::new(&key, "needed, and not given");
        }
        if let Some(key) = named("unknown field") {
            return FieldError::new(&key, "not a field of this request");
        }
        let field = if field.is_empty() || field == "?" || field == "." {
            "request"
        } else {
            &field
        };
        FieldError::new(field, message)
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use tactex_sim::contact::Fidelity;

    #[derive(Debug, Deserialize)]
    #[serde(deny_unknown_fields)]
    struct Request {
        #[serde(deserialize_with = "parsed")]
        fidelity: Fidelity,
        depth_mm: f64,
    }

    #[test]
    fn a_bad_field_is_named_and_its_place_in_the_text_is_not() {
        let ok: Request = from_json(r#"{"fidelity": "rigid", "depth_mm": 1}"#).unwrap();
        assert_eq!((ok.fidelity, ok.depth_mm), (Fidelity::Rigid, 1.0));
        let e = from_json::<Request>(r#"{"fidelity": "fem", "depth_mm": 1}"#).unwrap_err();
        assert_eq!(e.field, "fidelity");
        assert!(e.problem.starts_with("unknown fidelity"), "{e}");
        assert!(!e.problem.contains("line"), "{e}");
        let e = from_json::<Request>(r#"{"fidelity": "layer", "depth_mm": "x"}"#).unwrap_err();
        assert_eq!(e.field, "depth_mm");
        let e = from_json::<Request>(r#"{"fidelity": "layer"}"#).unwrap_err();
        assert_eq!(
            (e.field.as_str(), e.problem.as_str()),
            ("depth_mm", "needed, and not given")
        );
        let e =
            from_json::<Request>(r#"{"fidelity": "layer", "depth_mm": 1, "x": 2}"#).unwrap_err();
        assert_eq!(e.field, "x");
    }
}
