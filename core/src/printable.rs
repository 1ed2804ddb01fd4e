//! Text from outside (prompts, file contents, a model's or a peer's reply) made safe to
//! print: control characters, terminal escape sequences among them, shown as escapes rather
//! than acted on by the terminal; and numbers from outside shown short.

/// Characters that reorder or hide text on a terminal without being control characters:
/// bidirectional overrides and isolates, zero-width spaces and joiners, the byte-order mark.
pub fn is_hidden(c: char) -> bool {
    matches!(c, '\u{200B}'..='\u{200F}' | '\u{202A}'..='\u{202E}' | '\u{2060}'..='\u{2064}' | '\u{2066}'..='\u{2069}' | '\u{FEFF}')
}

/// A name (a sensor profile's, a scene's, an object's label) is shown in every report: one
/// short line.
pub const MAX_NAME_CHARS: usize = 100;

/// Whether `name` can name a profile, a scene or an object: one line of at most
/// `MAX_NAME_CHARS` characters with no control characters and none that reorder or hide text
/// on a terminal (bidirectional overrides, zero-width characters); Err says what is wrong,
/// the name shown escaped.
pub fn check_name(name: &str) -> Result<(), String> {
    if name.trim().is_empty() {
        return Err("empty; a name says which sensor or scene this is".into());
    }
    if name.chars().count() > MAX_NAME_CHARS || name.chars().any(|c| c.is_control() || is_hidden(c))
    {
        return Err(format!(
            "'{}', expected one line of at most {MAX_NAME_CHARS} characters without control, bidirectional or zero-width characters",
            printable(&name.chars().take(40).collect::<String>())
        ));
    }
    Ok(())
}

/// `text` with every control character but tab, and every hidden one (`is_hidden`), written
/// as its Rust escape (`\u{1b}`); line breaks too, so that an error stays one line.
pub fn printable(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        if (c.is_control() && c != '\t') || is_hidden(c) {
            out.extend(c.escape_default());
        } else {
            out.push(c);
        }
    }
    out
}

/// At most `max_chars` of `text` from outside, `printable`, with " ..." where it was cut:
/// an excerpt that keeps an error to one short line.
pub fn excerpt(text: &str, max_chars: usize) -> String {
    let kept: String = text.chars().take(max_chars).collect();
    let cut = if kept.len() < text.len() { " ..." } else { "" };
    format!("{}{cut}", printable(&kept))
}

/// A number shown short: 1e308 as "1e308", not 309 digits; everyday values as written.
pub fn short_number(v: f64) -> String {
    if v.is_finite() && v != 0.0 && !(1e-4..1e6).contains(&v.abs()) {
        format!("{v:e}")
    } else {
        format!("{v}")
    }
}

/// A list of numbers from outside as `[a, b, c]`, each `short_number`.
pub fn short_numbers(v: &[f64]) -> String {
    let items: Vec<String> = v.iter().map(|x| short_number(*x)).collect();
    format!("[{}]", items.join(", "))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_excerpt_is_short_printable_and_says_where_it_was_cut() {
        assert_eq!(excerpt("f 1 2", 60), "f 1 2");
        assert_eq!(excerpt("a\u{1b}[2Jbcdef", 4), "a\\u{1b}[2 ...");
        assert_eq!(excerpt("ééé", 3), "ééé");
    }

    #[test]
    fn escape_sequences_and_line_breaks_are_shown_not_acted_on() {
        let shown = printable("soft \u{1b}[31mred\u{1b}[0m\r\nnext\u{7}");
        assert_eq!(shown, "soft \\u{1b}[31mred\\u{1b}[0m\\r\\nnext\\u{7}");
        assert!(!shown.chars().any(char::is_control));
        assert_eq!(
            printable("lime\u{202E}emil\u{200B}"),
            "lime\\u{202e}emil\\u{200b}"
        );
        assert_eq!(
            printable("Which kiwi is softest?\tné"),
            "Which kiwi is softest?\tné"
        );
    }
}
