//! The terminal: paths and names in messages show control and bidirectional characters as
//! escapes, so an error is one line that reads as it prints, and a full standard output or
//! standard error never makes texel panic (a result it cannot write is an error).

use std::fs::{File, OpenOptions};
use std::process::{Command, Output, Stdio};

use crate::util::*;

/// Whether `c` may drive the terminal or fake a line: a control character other than a line
/// feed, a line or paragraph separator, or a bidirectional formatting character.
fn raw(c: char) -> bool {
    (c.is_control() && c != '\n')
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

/// Render a scene at `name` in a scratch directory: one error line, `shown` in it, nothing raw.
fn one_honest_line(test: &str, name: &str, shown: &str) {
    let d = Dir::new(test);
    let scene = d.arg(name);
    let err = fails(
        &["render", "--size", "16x9", &scene, "-o", &d.arg("x.png")],
        1,
        &[shown],
    );
    assert!(!err.chars().any(raw), "raw character in {err:?}");
}

#[test]
fn a_path_cannot_clear_the_screen() {
    one_honest_line("term-esc", "x\u{1b}[2J.toml", "x\\u{1b}[2J.toml");
}

#[test]
fn a_path_cannot_forge_an_error_line() {
    one_honest_line(
        "term-newline",
        "x\ntexel: error: forged",
        "x\\ntexel: error: forged",
    );
}

#[test]
fn a_path_cannot_print_reversed() {
    one_honest_line(
        "term-rlo",
        "gnp.\u{202e}lmot.toml",
        "gnp.\\u{202e}lmot.toml",
    );
}

#[test]
fn a_name_inside_a_scene_is_escaped() {
    // The texture's path comes from the file, not the command line.
    let d = Dir::new("term-texture");
    let body = HEAD.replace(
        "procedural = \"checker\"\nsize = 64\nchecks = 4",
        "path = \"a\\u001b]0;owned\\u0007\\r\\u2067.png\"",
    );
    let scene = d.write("s.toml", format!("{body}{TRIANGLE}"));
    let err = fails(
        &["render", &scene.to_string_lossy(), "-o", &d.arg("x.png")],
        1,
        &["a\\u{1b}]0;owned\\u{7}\\r\\u{2067}.png"],
    );
    assert!(!err.chars().any(raw), "raw character in {err:?}");
}

#[test]
fn a_usage_error_cannot_forge_a_line() {
    let out = texel(&["render", "--a\u{1b}[2J\ntexel: error: forged"]);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(!err.chars().any(raw), "raw character in {err:?}");
    assert!(
        err.lines().all(|l| !l.starts_with("texel: error: forged")),
        "{err}"
    );
    assert!(
        err.contains("--a\\u{1b}[2J\\ntexel: error: forged"),
        "{err}"
    );
}

// ---------------------------------------------------------------------------------------------
// Full streams
// ---------------------------------------------------------------------------------------------

/// `/dev/full`, opened for writing: every write fails with ENOSPC.
fn full() -> File {
    OpenOptions::new().write(true).open("/dev/full").unwrap()
}

/// Which of texel's streams are opened on `/dev/full`.
#[derive(Clone, Copy, Debug)]
enum Full {
    Stdout,
    Stderr,
    Both,
}

/// Run `texel args` with the streams of `which` on `/dev/full` (the others piped); require no
/// panic.
fn run_full(args: &[&str], which: Full) -> Output {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_texel"));
    cmd.args(args);
    match which {
        Full::Stdout => cmd.stdout(full()).stderr(Stdio::piped()),
        Full::Stderr => cmd.stdout(Stdio::piped()).stderr(full()),
        Full::Both => cmd.stdout(full()).stderr(full()),
    };
    let out = cmd.output().unwrap();
    let err = stderr(&out);
    assert_ne!(out.status.code(), Some(101), "{args:?}, {which:?}: {err}");
    assert!(!err.contains("panicked"), "{args:?}, {which:?}: {err}");
    out
}

#[test]
fn render_with_full_streams() {
    let d = Dir::new("term-full-render");
    let png = d.arg("x.png");
    for which in [Full::Stdout, Full::Stderr, Full::Both] {
        let out = run_full(&["render", "--size", "16x9", "-o", &png], which);
        assert!(out.status.success(), "{which:?}: {}", stderr(&out));
        // An error that cannot be shown still fails.
        let out = run_full(&["render", &d.arg("missing.toml"), "-o", &png], which);
        assert_eq!(out.status.code(), Some(1), "{which:?}");
    }
    // The image itself on a full standard output is an error, said on standard error.
    let out = run_full(&["render", "--size", "16x9", "-o", "-"], Full::Stdout);
    assert_eq!(out.status.code(), Some(1));
    assert_eq!(stderr(&out).lines().count(), 1, "{}", stderr(&out));
}

#[test]
fn reference_with_full_streams() {
    let d = Dir::new("term-full-reference");
    let png = d.arg("r.png");
    let args = [
        "reference",
        "--size",
        "16x9",
        "--spp",
        "1",
        "--max-spp",
        "1",
        "-o",
        &png,
    ];
    for which in [Full::Stdout, Full::Stderr, Full::Both] {
        let _ = std::fs::remove_file(&png);
        // The summary line on standard error is a diagnostic: the reference is written.
        let out = run_full(&args, which);
        assert!(out.status.success(), "{which:?}: {}", stderr(&out));
        assert_eq!(load(&png).width(), 16);
    }
}

#[test]
fn compare_with_full_streams() {
    let d = Dir::new("term-full-compare");
    let report = d.arg("report");
    let args = [
        "compare",
        "--size",
        "32x18",
        "--spp",
        "1",
        "--filters",
        "nearest",
        "--out",
        &report,
    ];
    // The report's table goes to standard output: a full one is an error.
    let out = run_full(&args, Full::Stdout);
    assert_eq!(out.status.code(), Some(1));
    let err = stderr(&out);
    assert!(
        err.contains("texel: error: cannot write to standard output"),
        "{err}"
    );
    assert!(err.contains("No space left on device"), "{err}");
    let out = run_full(&args, Full::Both);
    assert_eq!(out.status.code(), Some(1));
    // Standard error is for diagnostics only.
    let out = run_full(&args, Full::Stderr);
    assert!(out.status.success());
    assert!(stdout(&out).contains("nearest"), "{}", stdout(&out));
    assert!(d.join("report/index.html").is_file());
}

#[test]
fn results_on_a_full_stdout_are_errors() {
    // With an adapter the list cannot be written; without one there is none to write.
    let out = run_full(&["gpu-info"], Full::Stdout);
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    for args in [&["--help"][..], &["--version"], &["render", "--help"]] {
        let out = run_full(args, Full::Stdout);
        assert_eq!(out.status.code(), Some(1), "{args:?}");
        assert!(stderr(&out).contains("No space left on device"), "{args:?}");
        let out = run_full(args, Full::Stderr);
        assert!(out.status.success(), "{args:?}");
    }
    // A usage error with nowhere to say it still exits 2.
    let out = run_full(&["render", "--bogus"], Full::Stderr);
    assert_eq!(out.status.code(), Some(2));
}
