//! `--max-memory` refusals state the whole need of the step they refuse: given as the next
//! `--max-memory`, the figure a refusal prints gets past that step.

use crate::util::*;

/// The figure a refusal asks for, in whole MiB as a user types it: its "in all" sum, or with
/// nothing held its "needs about" figure, rounded up.
fn asked_mib(message: &str) -> u64 {
    let figure = match message.find(" MiB in all") {
        Some(end) => message[..end].rsplit(' ').next(),
        None => message
            .split("needs about ")
            .nth(1)
            .and_then(|rest| rest.split(' ').next()),
    };
    let figure: f64 = figure
        .and_then(|f| f.parse().ok())
        .unwrap_or_else(|| panic!("no figure in {message:?}"));
    figure.ceil() as u64
}

/// What a refusal refuses: the text between `texel: error: ` and ` needs about`.
fn step(message: &str) -> String {
    let rest = message.split("texel: error: ").nth(1).unwrap_or(message);
    rest.split(" needs about")
        .next()
        .unwrap_or(rest)
        .trim()
        .to_string()
}

/// Render `scene` with `extra` arguments from `--max-memory` of `start` MiB, raising it to what
/// each refusal asks for until the render succeeds; the steps refused. Every refusal must state
/// a larger figure, and refuse another step than the one before it.
fn follow(d: &Dir, scene: &str, extra: &[&str], start: u64) -> Vec<String> {
    let mut limit = start;
    let mut steps: Vec<String> = Vec::new();
    let out = d.arg("x.png");
    for _ in 0..12 {
        let max = format!("{limit}M");
        let mut args = vec!["render", scene, "--max-memory", &max, "-o", &out];
        args.extend(extra);
        let run = texel(&args);
        if run.status.success() {
            return steps;
        }
        let err = stderr(&run);
        assert_eq!(run.status.code(), Some(1), "{err}");
        assert!(err.contains("needs about"), "--max-memory {max}: {err}");
        let next = asked_mib(&err);
        assert!(next > limit, "--max-memory {max}: {err}");
        let what = step(&err);
        if let Some(last) = steps.last() {
            assert_ne!(
                *last, what,
                "refused again at the --max-memory its message asked for: {err}"
            );
        }
        steps.push(what);
        limit = next;
    }
    panic!("no end to the refusals: {steps:?}");
}

#[test]
fn a_refusal_s_figure_as_the_next_limit_gets_past_it() {
    let d = Dir::new("budget-messages");
    let scene = d.write("big.toml", HEAD.replace("size = 64", "size = 2048") + QUAD);
    let scene = scene.to_string_lossy().to_string();
    let size = ["--size", "640x360"];
    let steps = follow(&d, &scene, &size, 1);
    assert!(
        steps.iter().any(|s| s.starts_with("loading texture \"t\"")),
        "{steps:?}"
    );
    let ripmap = ["--size", "640x360", "--filter", "ripmap"];
    let steps = follow(&d, &scene, &ripmap, 1);
    assert!(steps.iter().any(|s| s.contains("ripmap")), "{steps:?}");
}
