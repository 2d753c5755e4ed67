//! Every command the README and the guide show runs here, so the documents cannot drift from the
//! tool. The commands are read from the documents' `sh` code blocks (and `texel` lines in plain
//! blocks) exactly as written; the test only makes the work small (image size, reference samples,
//! frames, rays), runs each document's commands in order in a scratch directory of its own (a
//! later command may read what an earlier one wrote), and checks that each exits 0 and writes
//! what it names (`-o`, `--out`, `--screenshot`, `--error-map`).
//!
//! - `--gpu` commands need a Vulkan adapter, `view` an X server, `lab` OpenGL through EGL: without
//!   them they are skipped with the reason, unless `CI=true`.
//! - `cargo run -p texel --example NAME` runs the example binary that `cargo test --workspace`
//!   builds.
//! - Peer scripts (`scripts/peers/`, `scripts/vs_llvmpipe.py`) need a Python environment made
//!   from PyPI and Mesa's GL drivers; the test checks that every script a command names exists
//!   (and that `.sh` scripts are executable).
//! - A block whose info string says `no-run` (the recipe for a remote GPU machine) is not run.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use crate::gpu::have_adapter;
use crate::util::*;
use crate::view::Xvfb;

/// The repository's root.
fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .canonicalize()
        .expect("the repository root")
}

/// The README and every page of the guide.
fn documents() -> Vec<PathBuf> {
    let root = repo();
    let mut docs: Vec<PathBuf> = std::fs::read_dir(root.join("docs/guide"))
        .expect("docs/guide")
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "md"))
        .collect();
    docs.sort();
    docs.insert(0, root.join("README.md"));
    docs
}

/// One command line of a document.
#[derive(Debug)]
struct DocCommand {
    /// `FILE:LINE`, for messages.
    at: String,
    /// The words of the command, its comment removed.
    words: Vec<String>,
    /// Whether it stands in an `sh` block (where every line must be a command the test knows).
    in_sh: bool,
}

/// The command lines of `text`'s code blocks.
fn commands(name: &str, text: &str) -> Vec<DocCommand> {
    let mut out = Vec::new();
    let mut fence: Option<String> = None;
    for (i, line) in text.lines().enumerate() {
        let t = line.trim();
        if let Some(info) = t.strip_prefix("```") {
            fence = match fence {
                None => Some(info.trim().to_string()),
                Some(_) => None,
            };
            continue;
        }
        let Some(info) = &fence else { continue };
        let lang = info.split_whitespace().next().unwrap_or("");
        if info.split_whitespace().any(|w| w == "no-run") || !(lang.is_empty() || lang == "sh") {
            continue;
        }
        let command = match t.find(" #") {
            Some(at) => t[..at].trim_end(),
            None => t,
        };
        let in_sh = lang == "sh";
        if command.is_empty()
            || command.starts_with('#')
            || !(in_sh || command.starts_with("texel ") || command.starts_with("cargo run "))
        {
            continue;
        }
        assert!(
            !command.contains(['"', '\'', '\\', '|', '>', '<', '$', '`']),
            "{name}:{}: quoting, pipes and variables are outside what this test runs: {command}",
            i + 1
        );
        out.push(DocCommand {
            at: format!("{name}:{}", i + 1),
            words: command.split_whitespace().map(str::to_string).collect(),
            in_sh,
        });
    }
    out
}

/// Set `flag` to `value`: replace its value where the command gives one, add it otherwise.
fn set(args: &mut Vec<String>, flag: &str, value: &str) {
    match args.iter().position(|a| a == flag) {
        Some(i) if i + 1 < args.len() => args[i + 1] = value.to_string(),
        _ => {
            args.push(flag.to_string());
            args.push(value.to_string());
        }
    }
}

/// The value of `flag` in `args`.
fn value<'a>(args: &'a [String], flag: &str) -> Option<&'a str> {
    let i = args.iter().position(|a| a == flag)?;
    args.get(i + 1).map(String::as_str)
}

/// The flags whose value is a path the command writes.
const OUTPUT_FLAGS: [&str; 4] = ["-o", "--out", "--screenshot", "--error-map"];

/// `args` (a `texel` command line without the program) made small; also the outputs it names.
fn shrink(args: &[String]) -> (Vec<String>, Vec<String>) {
    let mut a = args.to_vec();
    let sub = a.first().cloned().unwrap_or_default();
    match sub.as_str() {
        "render" => set(&mut a, "--size", "160x90"),
        "reference" => {
            set(&mut a, "--size", "80x45");
            set(&mut a, "--spp", "8");
            set(&mut a, "--max-spp", "16");
        }
        "compare" => {
            set(&mut a, "--size", "160x90");
            set(&mut a, "--spp", "4");
            if value(&a, "--max-spp").is_some() {
                set(&mut a, "--max-spp", "16");
            }
            if value(&a, "--orbit").is_some() {
                set(&mut a, "--orbit", "2");
            }
        }
        "bench" => {
            set(&mut a, "--size", "160x90");
            set(&mut a, "--frames", "1");
            set(&mut a, "--warmup", "0");
        }
        "warp" => set(&mut a, "--size", "96x54"),
        "bake-ao" => {
            set(&mut a, "--size", "64");
            set(&mut a, "--rays", "4");
        }
        "view" => {
            set(&mut a, "--size", "160x90");
            set(&mut a, "--frames", "2");
            set(&mut a, "--screenshot", "view-shot.png");
            a.push("--no-hud".to_string());
        }
        "demo" => {
            set(&mut a, "--size", "48x27");
            set(&mut a, "--spp", "1");
        }
        "lab" => {
            set(&mut a, "--size", "80x60");
            set(&mut a, "--spp", "1");
            set(&mut a, "--frames", "1");
        }
        _ => {}
    }
    let mut outputs: Vec<String> = OUTPUT_FLAGS
        .iter()
        .filter_map(|f| value(&a, f).map(str::to_string))
        .collect();
    if sub == "demo" && value(&a, "--out").is_none() {
        outputs.push("texel-demo/index.html".to_string());
    }
    (a, outputs)
}

/// `args` with every input word that names a file of the repository made absolute, so the command
/// runs in a scratch directory and still finds `scenes/` and `docs/images/`. The values of output
/// flags stay relative: a command never writes into the repository.
fn rooted(args: &[String]) -> Vec<String> {
    let root = repo();
    args.iter()
        .enumerate()
        .map(|(i, a)| {
            let p = root.join(a);
            let output = i > 0 && OUTPUT_FLAGS.contains(&args[i - 1].as_str());
            if !output && !a.starts_with('-') && a.contains('/') && p.exists() {
                p.to_string_lossy().into_owned()
            } else {
                a.clone()
            }
        })
        .collect()
}

/// Whether a `--gpu` or `view` command can run here; prints why not (and fails under `CI=true`,
/// inside the helpers).
fn can_run(args: &[String], x: &mut Option<Option<Xvfb>>) -> bool {
    if args.iter().any(|a| a == "--gpu") && !have_adapter() {
        return false;
    }
    if args.first().is_some_and(|s| s == "view") {
        return x.get_or_insert_with(Xvfb::start).is_some();
    }
    if args.first().is_some_and(|s| s == "lab") && !crate::lab::have_gl() {
        return false;
    }
    true
}

fn check(at: &str, what: &[String], out: &Output, dir: &Dir, outputs: &[String]) {
    let err = stderr(out);
    assert!(
        out.status.success() && !err.contains("panicked"),
        "{at}: {what:?} failed ({:?}): {err}",
        out.status.code()
    );
    assert!(
        !err.lines().any(|l| l.starts_with("error:")),
        "{at}: {what:?} succeeded with an error line: {err}"
    );
    for o in outputs {
        let p = dir.join(o.trim_end_matches('/'));
        let written = if p.is_dir() {
            std::fs::read_dir(&p).unwrap().next().is_some()
        } else {
            p.metadata().is_ok_and(|m| m.len() > 0)
        };
        assert!(written, "{at}: {what:?} did not write {o}");
    }
}

/// The example binaries `cargo test --workspace` builds beside the `texel` binary.
fn example(name: &str) -> Option<PathBuf> {
    let exe = Path::new(env!("CARGO_BIN_EXE_texel"))
        .parent()?
        .join("examples")
        .join(name);
    if exe.is_file() {
        return Some(exe);
    }
    assert_ne!(
        std::env::var("CI").as_deref(),
        Ok("true"),
        "CI=true but the example {name} is not built (cargo test --workspace builds it)"
    );
    eprintln!("skipped: the example {name} is not built (run cargo test --workspace)");
    None
}

/// Run one document's commands in order; returns how many ran.
fn run_document(doc: &Path) -> usize {
    let text = std::fs::read_to_string(doc).unwrap();
    let name = doc.strip_prefix(repo()).unwrap().display().to_string();
    let dir = Dir::new(&format!("docs-{}", name.replace(['/', '.'], "-")));
    let mut x: Option<Option<Xvfb>> = None;
    let mut ran = 0;
    for c in commands(&name, &text) {
        let w = &c.words;
        let texel_args: Option<&[String]> = match w.iter().map(String::as_str).collect::<Vec<_>>()[..]
        {
            ["texel", ..] => Some(&w[1..]),
            ["cargo", "run", "--release", "--", ..] => Some(&w[4..]),
            _ => None,
        };
        if let Some(args) = texel_args {
            let (args, outputs) = shrink(args);
            if !can_run(&args, &mut x) {
                continue;
            }
            let args = rooted(&args);
            let mut cmd = Command::new(env!("CARGO_BIN_EXE_texel"));
            cmd.args(&args).current_dir(dir.path());
            if let Some(Some(x)) = &x {
                cmd.env("DISPLAY", x.display())
                    .env_remove("WAYLAND_DISPLAY");
            }
            let started = std::time::Instant::now();
            let out = cmd.output().expect("cannot start texel");
            eprintln!("{}: {:.1} s", c.at, started.elapsed().as_secs_f64());
            check(&c.at, &args, &out, &dir, &outputs);
            ran += 1;
            continue;
        }
        match w.iter().map(String::as_str).collect::<Vec<_>>()[..] {
            ["cargo", "run", "--release", "-p", "texel", "--example", ex, "--", ..] => {
                let Some(exe) = example(ex) else { continue };
                let args = rooted(&w[8..]);
                let out = Command::new(exe)
                    .args(&args)
                    .current_dir(dir.path())
                    .output()
                    .expect("cannot start the example");
                let outputs: Vec<String> = match args.iter().position(|a| a == "-o") {
                    Some(i) => args[i + 1..].iter().take(1).cloned().collect(),
                    None => args.last().into_iter().cloned().collect(),
                };
                check(&c.at, &args, &out, &dir, &outputs);
                ran += 1;
            }
            // The suite itself, and building the binary the tour uses.
            ["cargo", "test" | "build" | "install", ..] => {}
            // Installing the Python package: `python::python_package_tests_pass` installs it from
            // this checkout and runs its tests, the README's example among them.
            ["pip", "install", "./python" | "./python[ray]"] => {}
            _ => {
                let scripts: Vec<&String> = w.iter().filter(|a| a.contains("scripts/")).collect();
                assert!(
                    !c.in_sh || !scripts.is_empty(),
                    "{}: a command this test does not know how to run: {}",
                    c.at,
                    w.join(" ")
                );
                for s in scripts {
                    let p = repo().join(s);
                    assert!(p.is_file(), "{}: {s} does not exist", c.at);
                    if s.ends_with(".sh") {
                        use std::os::unix::fs::PermissionsExt;
                        let mode = p.metadata().unwrap().permissions().mode();
                        assert!(mode & 0o111 != 0, "{}: {s} is not executable", c.at);
                    }
                }
            }
        }
    }
    ran
}

#[test]
fn every_command_in_the_readme_and_the_guide_runs() {
    let docs = documents();
    assert!(docs.len() > 5, "{docs:?}");
    let mut ran = 0;
    for doc in &docs {
        ran += run_document(doc);
    }
    // The README's tour alone shows eight commands; a parser that finds none must not pass.
    assert!(ran >= 8, "only {ran} commands ran");
}

#[test]
fn the_command_reader_takes_blocks_as_written() {
    let text = "x\n```sh\ntexel render -o a.png   # one\n# a comment\n```\n```toml\ntexel = 1\n```\n```sh no-run\ncp a b\n```\n```\ntexel mips t.png --out m/\nnot a command\n```\n";
    let cs = commands("t.md", text);
    let words: Vec<String> = cs.iter().map(|c| c.words.join(" ")).collect();
    assert_eq!(
        words,
        ["texel render -o a.png", "texel mips t.png --out m/"]
    );
    assert_eq!(cs[0].at, "t.md:3");
    assert!(cs[0].in_sh && !cs[1].in_sh);
    let (a, outs) = shrink(&["compare".into(), "--spp".into(), "256".into()]);
    assert_eq!(a, ["compare", "--spp", "4", "--size", "160x90"]);
    assert!(outs.is_empty());
}

/// The README's filter table and docs/benchmarks.md are what `scripts/bench.py render` makes of
/// the records in docs/benchmarks/ (Python's standard library only; without `python3` the test
/// says so and passes, unless `CI=true`).
#[test]
fn the_benchmark_tables_are_generated_from_their_records() {
    let out = match Command::new("python3")
        .args(["scripts/bench.py", "render", "--check"])
        .current_dir(repo())
        .output()
    {
        Ok(out) => out,
        Err(e) => {
            assert_ne!(
                std::env::var("CI").as_deref(),
                Ok("true"),
                "CI=true but no python3 ({e}): apt-get install python3"
            );
            eprintln!("skipped: no python3 ({e})");
            return;
        }
    };
    assert!(out.status.success(), "{}", stderr(&out));
    let records = std::fs::read_dir(repo().join("docs/benchmarks"))
        .unwrap()
        .filter(|e| {
            e.as_ref()
                .unwrap()
                .path()
                .extension()
                .is_some_and(|x| x == "json")
        })
        .count();
    assert!(records >= 1, "no benchmark records");
}
