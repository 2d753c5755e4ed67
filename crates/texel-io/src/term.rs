//! Text for the terminal: messages that hold paths and names a user (or a file) chose, written
//! so that they can neither drive the terminal nor fake a line, and writes to standard output
//! and standard error that never panic.
//!
//! - [`escape`] shows control characters (C0, DEL, C1), the Unicode line and paragraph
//!   separators and the bidirectional formatting characters as escapes (`\n`, `\u{1b}`,
//!   `\u{202e}`): an escaped message is one line that reads as it prints.
//! - [`escape_text`] does the same but keeps line feeds, for texel's own multi-line text (a
//!   report) that holds user-derived parts.
//! - [`stderr_line`] writes one escaped line to standard error and ignores a failed write: a
//!   diagnostic that cannot be shown changes nothing else ([`stderr_text`] keeps line feeds).
//!   [`stdout_line`] and [`stdout_text`] write results to standard output and return the error
//!   of a failed write, for the caller to report.

use std::borrow::Cow;
use std::fmt::Display;
use std::io::{self, Write};

/// Whether `c` is shown as an escape: a control character (C0, DEL, C1), a Unicode line or
/// paragraph separator, or a bidirectional formatting character (the marks, embeddings,
/// overrides and isolates).
pub fn needs_escape(c: char) -> bool {
    c.is_control()
        || matches!(
            c,
            '\u{061c}'
                | '\u{200e}'
                | '\u{200f}'
                | '\u{2028}'
                | '\u{2029}'
                | '\u{202a}'..='\u{202e}'
                | '\u{2066}'..='\u{2069}'
        )
}

/// `s` with every character of [`needs_escape`] shown as an escape: `\n`, `\r` and `\t` by
/// name, every other one as `\u{HEX}`. Borrowed when nothing needs escaping.
pub fn escape(s: &str) -> Cow<'_, str> {
    escape_except(s, None)
}

/// [`escape`], keeping line feeds: for multi-line text whose lines are texel's own.
pub fn escape_text(s: &str) -> Cow<'_, str> {
    escape_except(s, Some('\n'))
}

fn escape_except(s: &str, keep: Option<char>) -> Cow<'_, str> {
    let escaped = |c: char| needs_escape(c) && Some(c) != keep;
    let Some(first) = s.find(escaped) else {
        return Cow::Borrowed(s);
    };
    let mut out = String::with_capacity(s.len() + 8);
    out.push_str(&s[..first]);
    for c in s[first..].chars() {
        if !escaped(c) {
            out.push(c);
            continue;
        }
        match c {
            '\n' => out.push_str("\\n"),
            '\r' => out.push_str("\\r"),
            '\t' => out.push_str("\\t"),
            _ => out.push_str(&format!("\\u{{{:x}}}", u32::from(c))),
        }
    }
    Cow::Owned(out)
}

/// `line` escaped ([`escape`]) with its line feed.
fn one_line(line: impl Display) -> String {
    let mut s = escape(&line.to_string()).into_owned();
    s.push('\n');
    s
}

/// An error and its causes on one line, `outer: cause: root cause`, a cause left out where the
/// text before it already holds it (an error that prints its source).
pub fn chain_line(err: &(dyn std::error::Error + 'static)) -> String {
    let mut parts: Vec<String> = Vec::new();
    let mut next = Some(err);
    while let Some(e) = next {
        let s = e.to_string();
        if !parts.last().is_some_and(|p| p.contains(&s)) {
            parts.push(s);
        }
        next = e.source();
    }
    parts.join(": ")
}

/// Write `line` ([`escape`]d, so one line whatever it holds) and a line feed to standard error
/// in one write; a failed write is ignored.
pub fn stderr_line(line: impl Display) {
    let s = one_line(line);
    let mut err = io::stderr().lock();
    let _ = err.write_all(s.as_bytes()).and_then(|()| err.flush());
}

/// Write `text` ([`escape_text`]d: its line feeds kept) to standard error in one write; a failed
/// write is ignored.
pub fn stderr_text(text: &str) {
    let mut err = io::stderr().lock();
    let _ = err
        .write_all(escape_text(text).as_bytes())
        .and_then(|()| err.flush());
}

/// Write `line` ([`escape`]d) and a line feed to standard output and flush it.
pub fn stdout_line(line: impl Display) -> io::Result<()> {
    write_stdout(&one_line(line))
}

/// Write `text` ([`escape_text`]d: its line feeds kept) to standard output and flush it.
pub fn stdout_text(text: &str) -> io::Result<()> {
    write_stdout(&escape_text(text))
}

fn write_stdout(s: &str) -> io::Result<()> {
    let mut out = io::stdout().lock();
    out.write_all(s.as_bytes())?;
    out.flush()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An error with a message and an optional source.
    #[derive(Debug, thiserror::Error)]
    #[error("{0}")]
    struct Layer(String, #[source] Option<Box<Layer>>);

    fn chain(texts: &[&str]) -> Layer {
        texts
            .iter()
            .rev()
            .fold(None, |source, t| {
                Some(Layer(t.to_string(), source.map(Box::new)))
            })
            .unwrap()
    }

    #[test]
    fn a_chain_is_one_line_with_repeated_causes_left_out() {
        assert_eq!(chain_line(&chain(&["outer"])), "outer");
        assert_eq!(
            chain_line(&chain(&[
                "cannot load scene a.toml",
                "bad file",
                "no such file"
            ])),
            "cannot load scene a.toml: bad file: no such file"
        );
        // A cause whose text the error before it already printed is not said twice.
        assert_eq!(
            chain_line(&chain(&["the texture t: no such file", "no such file"])),
            "the texture t: no such file"
        );
    }

    #[test]
    fn plain_text_is_borrowed_unchanged() {
        for s in [
            "",
            "scenes/ground.toml",
            "été – 地面 ✓ \\u{1b}",
            "a \"quoted\" name",
        ] {
            assert!(matches!(escape(s), Cow::Borrowed(b) if b == s), "{s}");
            assert!(matches!(escape_text(s), Cow::Borrowed(b) if b == s), "{s}");
        }
        assert!(matches!(escape_text("two\nlines\n"), Cow::Borrowed(_)));
    }

    #[test]
    fn named_controls() {
        assert_eq!(escape("a\nb\rc\td"), "a\\nb\\rc\\td");
        assert_eq!(
            escape("x\ntexel: error: forged"),
            "x\\ntexel: error: forged"
        );
    }

    #[test]
    fn other_controls() {
        assert_eq!(escape("\u{1b}[2J"), "\\u{1b}[2J");
        assert_eq!(escape("\0\u{7}\u{8}\u{7f}"), "\\u{0}\\u{7}\\u{8}\\u{7f}");
        // C1: CSI and NEL.
        assert_eq!(escape("\u{9b}2J\u{85}"), "\\u{9b}2J\\u{85}");
    }

    #[test]
    fn bidirectional_formatting() {
        for c in [
            '\u{061c}', '\u{200e}', '\u{200f}', '\u{202a}', '\u{202b}', '\u{202c}', '\u{202d}',
            '\u{202e}', '\u{2066}', '\u{2067}', '\u{2068}', '\u{2069}',
        ] {
            let s = format!("a{c}b");
            assert_eq!(escape(&s), format!("a\\u{{{:x}}}b", u32::from(c)));
        }
        assert_eq!(escape("gnp.\u{202e}exe"), "gnp.\\u{202e}exe");
    }

    #[test]
    fn line_separators() {
        assert_eq!(escape("a\u{2028}b\u{2029}"), "a\\u{2028}b\\u{2029}");
    }

    #[test]
    fn text_keeps_line_feeds_only() {
        assert_eq!(
            escape_text("| a\u{1b}[2J |\n| b\r |\n"),
            "| a\\u{1b}[2J |\n| b\\r |\n"
        );
    }

    #[test]
    fn one_line_is_one_line() {
        assert_eq!(one_line(format_args!("p: {}", "a\nb")), "p: a\\nb\n");
    }
}
