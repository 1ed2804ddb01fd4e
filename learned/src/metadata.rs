//! The metadata an ONNX file carries (`ModelProto.metadata_props`, field 14), read from the
//! file itself so that it works on every backend (tract does not expose it through ort).
//! Ultralytics' exports keep the class names there.

use prost::Message;

#[derive(Clone, PartialEq, Message)]
struct ModelProps {
    /// Every ONNX model states its IR version; bytes without one (an empty file, most other
    /// files that happen to decode as protobuf) are not a model.
    #[prost(int64, tag = "1")]
    ir_version: i64,
    #[prost(message, repeated, tag = "14")]
    metadata_props: Vec<Entry>,
}

#[derive(Clone, PartialEq, Message)]
struct Entry {
    #[prost(string, tag = "1")]
    key: String,
    #[prost(string, tag = "2")]
    value: String,
}

/// The key-value metadata of an ONNX model, in file order; an error for bytes that are not
/// a protobuf message.
pub fn metadata_props(onnx: &[u8]) -> Result<Vec<(String, String)>, String> {
    let props = ModelProps::decode(onnx).map_err(|e| format!("not an ONNX model: {e}"))?;
    if props.ir_version <= 0 {
        return Err(if onnx.is_empty() {
            "not an ONNX model: the file is empty".into()
        } else {
            "not an ONNX model: it states no IR version".into()
        });
    }
    Ok(props
        .metadata_props
        .into_iter()
        .map(|e| (e.key, e.value))
        .collect())
}

/// Class names from Ultralytics' `names` metadata, a Python dict literal such as
/// `{0: 'apple', 1: "kiwi's"}`, in class order; None unless the keys are exactly 0..n.
pub fn ultralytics_names(literal: &str) -> Option<Vec<String>> {
    let body = literal.trim().strip_prefix('{')?.strip_suffix('}')?;
    let mut names = Vec::new();
    let mut rest = body.trim_start();
    while !rest.is_empty() {
        let (key, after) = rest.split_once(':')?;
        if key.trim().parse::<usize>().ok()? != names.len() {
            return None;
        }
        let after = after.trim_start();
        let quote = after.chars().next().filter(|c| *c == '\'' || *c == '"')?;
        let mut name = String::new();
        let mut chars = after[1..].char_indices();
        let end = loop {
            let (i, c) = chars.next()?;
            match c {
                '\\' => name.push(chars.next()?.1),
                c if c == quote => break i + 2,
                c => name.push(c),
            }
        };
        names.push(name);
        rest = after[end..].trim_start();
        rest = rest.strip_prefix(',').unwrap_or(rest).trim_start();
    }
    (!names.is_empty()).then_some(names)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ultralytics_class_names_parse_with_quotes_and_escapes() {
        assert_eq!(
            ultralytics_names("{0: 'mango', 1: \"kiwi's\", 2: 'a\\'b'}").unwrap(),
            vec!["mango", "kiwi's", "a'b"]
        );
        assert_eq!(ultralytics_names("{}"), None);
        assert_eq!(ultralytics_names("{1: 'x'}"), None, "keys must start at 0");
        assert_eq!(ultralytics_names("[0, 1]"), None);
        assert_eq!(ultralytics_names("{0: 'x', 1: 'y"), None, "unterminated");
    }

    #[test]
    fn metadata_is_read_from_the_model_proto_and_garbage_is_refused() {
        // ModelProto { metadata_props: [{key: "names", value: "{0: 'a'}"}] } by hand.
        let entry = Entry {
            key: "names".into(),
            value: "{0: 'a'}".into(),
        };
        let bytes = ModelProps {
            ir_version: 8,
            metadata_props: vec![entry],
        }
        .encode_to_vec();
        assert_eq!(
            metadata_props(&bytes).unwrap(),
            vec![("names".to_string(), "{0: 'a'}".to_string())]
        );
        assert!(metadata_props(b"\xff\xff\xff garbage").is_err());
        assert!(metadata_props(b"").unwrap_err().contains("empty"));
    }
}
