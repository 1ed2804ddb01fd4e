//! What is wrong in a TOML or JSON file, said on one line with where: the line and the key,
//! so that a value of the wrong type names its field (the parsers' own messages name only
//! the type).

/// "line 3 (`timeout_s = "abc"`): invalid type: string \"abc\", expected f64".
pub fn toml_failure(text: &str, e: &toml::de::Error) -> String {
    let message = e.message().lines().next().unwrap_or("invalid TOML").trim();
    let Some(span) = e.span() else {
        return message.to_string();
    };
    let start = span.start.min(text.len());
    let line = text[..start].matches('\n').count() + 1;
    let shown: String = text
        .lines()
        .nth(line - 1)
        .unwrap_or("")
        .trim()
        .chars()
        .take(80)
        .collect();
    if shown.is_empty() {
        format!("line {line}: {message}")
    } else {
        format!("line {line} (`{shown}`): {message}")
    }
}

/// "field `height` (line 1, column 249): invalid type: string \"abc\", expected u32".
pub fn json_failure(text: &str, e: &serde_json::Error) -> String {
    let message = e.to_string();
    // serde_json appends " at line L column C"; the place is said up front instead.
    let message = message
        .rsplit_once(" at line ")
        .map_or(message.as_str(), |(m, _)| m);
    let (line, column) = (e.line(), e.column());
    let offset: usize = text
        .split_inclusive('\n')
        .take(line.saturating_sub(1))
        .map(str::len)
        .sum::<usize>()
        + column;
    // serde's column counts bytes: it can fall inside a character.
    let mut end = offset.min(text.len());
    while !text.is_char_boundary(end) {
        end -= 1;
    }
    match last_key(&text[..end]) {
        Some(key) => format!("field `{key}` (line {line}, column {column}): {message}"),
        None => format!("line {line}, column {column}: {message}"),
    }
}

/// The last `"key":` before the end of `text`: the field whose value the parser was reading.
fn last_key(text: &str) -> Option<&str> {
    let mut end = text.len();
    while let Some(colon) = text[..end].rfind(':') {
        let before = text[..colon].trim_end();
        if let Some(quoted) = before.strip_suffix('"')
            && let Some(open) = quoted.rfind('"')
        {
            return Some(&quoted[open + 1..]);
        }
        end = colon;
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Debug, serde::Deserialize)]
    #[allow(dead_code)]
    struct Config {
        model: String,
        timeout_s: f64,
    }

    #[test]
    fn a_value_of_the_wrong_type_is_named_by_its_line() {
        let text = "model = \"m\"\ntimeout_s = \"abc\"\n";
        let e = toml::from_str::<Config>(text).unwrap_err();
        let said = toml_failure(text, &e);
        assert!(
            said.starts_with("line 2 (`timeout_s = \"abc\"`): "),
            "{said}"
        );
        assert!(!said.contains('\n'));
    }

    #[test]
    fn a_json_value_of_the_wrong_type_is_named_by_its_key() {
        let text = "{\n  \"model\": \"m\",\n  \"timeout_s\": \"abc\"\n}";
        let e = serde_json::from_str::<Config>(text).unwrap_err();
        let said = json_failure(text, &e);
        assert!(
            said.starts_with("field `timeout_s` (line 3, column "),
            "{said}"
        );
        assert!(said.contains("expected f64"), "{said}");
        let compact = r#"{"model":"m","timeout_s":"abc"}"#;
        let e = serde_json::from_str::<Config>(compact).unwrap_err();
        assert!(json_failure(compact, &e).starts_with("field `timeout_s`"));
    }

    /// serde's column counts bytes: a column inside a character panicked on the slice.
    #[test]
    fn an_error_at_a_character_of_several_bytes_is_named_not_a_panic() {
        for text in [
            "\u{feff}{\"model\": \"m\"}",
            "{\"model\": \"m\", \"timeout_s\": é}",
        ] {
            let e = serde_json::from_str::<Config>(text).unwrap_err();
            let said = json_failure(text, &e);
            assert!(said.contains("line 1, column"), "{said}");
        }
    }
}
