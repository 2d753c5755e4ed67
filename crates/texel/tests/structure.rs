//! The workspace's structure, as docs/guide/architecture.md lays it out, read from the library
//! code (comments and `#[cfg(test)]` modules aside: a unit test may use its whole crate):
//! - no crate has top-level modules (a file, or a folder with everything in it) that import each
//!   other through `crate::` paths in a circle;
//! - texel-texture's floors only look down: every `crate::floor::file` path names a file on the
//!   same floor or a lower one, paths name modules rather than the root's re-exports, and its
//!   files import each other in no circle.

use std::collections::{BTreeMap, BTreeSet};
use std::fs;
use std::path::{Path, PathBuf};

/// Every `.rs` file under `dir`.
fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// A file's library code: unit-test modules and comments removed.
fn library_code(text: &str) -> String {
    let library = text.split("#[cfg(test)]\nmod ").next().unwrap();
    library
        .lines()
        .map(|l| match l.find("//") {
            Some(i) => &l[..i],
            None => l,
        })
        .collect::<Vec<_>>()
        .join("\n")
}

/// The top-level module a file of `src` belongs to (`a.rs`, `a/mod.rs` and `a/b.rs` are `a`).
fn module_of(src: &Path, file: &Path) -> String {
    let rel = file.strip_prefix(src).unwrap();
    let first = rel
        .components()
        .next()
        .unwrap()
        .as_os_str()
        .to_string_lossy();
    first.trim_end_matches(".rs").to_string()
}

/// The module graph of one crate's `src`.
fn graph(src: &Path) -> BTreeMap<String, BTreeSet<String>> {
    let mut files = Vec::new();
    rust_files(src, &mut files);
    let mut code: BTreeMap<String, String> = BTreeMap::new();
    for file in &files {
        let text = fs::read_to_string(file).unwrap();
        code.entry(module_of(src, file))
            .or_default()
            .push_str(&library_code(&text));
    }
    let names: BTreeSet<String> = code.keys().cloned().collect();
    code.iter()
        .map(|(module, text)| {
            let refs = text
                .match_indices("crate::")
                .map(|(i, _)| {
                    text[i + "crate::".len()..]
                        .chars()
                        .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
                        .collect::<String>()
                })
                .filter(|r| r != module && names.contains(r))
                .collect();
            (module.clone(), refs)
        })
        .collect()
}

/// A cycle of `g` as a list of nodes, if it has one.
fn cycle(g: &BTreeMap<String, BTreeSet<String>>) -> Option<Vec<String>> {
    fn visit(
        node: &str,
        g: &BTreeMap<String, BTreeSet<String>>,
        state: &mut BTreeMap<String, u8>,
        path: &mut Vec<String>,
    ) -> Option<Vec<String>> {
        state.insert(node.to_string(), 1);
        path.push(node.to_string());
        for next in g.get(node).into_iter().flatten() {
            match state.get(next).copied().unwrap_or(0) {
                0 => {
                    if let Some(c) = visit(next, g, state, path) {
                        return Some(c);
                    }
                }
                1 => {
                    let at = path.iter().position(|n| n == next).unwrap();
                    let mut c = path[at..].to_vec();
                    c.push(next.clone());
                    return Some(c);
                }
                _ => {}
            }
        }
        path.pop();
        state.insert(node.to_string(), 2);
        None
    }
    let mut state = BTreeMap::new();
    for node in g.keys() {
        if !state.contains_key(node) {
            if let Some(c) = visit(node, g, &mut state, &mut Vec::new()) {
                return Some(c);
            }
        }
    }
    None
}

/// texel-texture's floors, lowest first. `mapping` stands beside them and may use only `base`.
const FLOORS: [&str; 5] = ["base", "storage", "kernel", "technique", "engine"];

fn rank(floor: &str) -> Option<usize> {
    if floor == "mapping" {
        return Some(0);
    }
    FLOORS.iter().position(|&f| f == floor)
}

/// The `floor/file` names that `code` names through `crate::floor::file` (or
/// `crate::floor::{file, ..}`), and every root re-export it names (`crate::Name`).
fn floor_imports(code: &str) -> (BTreeSet<String>, BTreeSet<String>) {
    let ident = |s: &str| -> String {
        s.chars()
            .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
            .collect()
    };
    let (mut files, mut root) = (BTreeSet::new(), BTreeSet::new());
    for (i, _) in code.match_indices("crate::") {
        let rest = &code[i + "crate::".len()..];
        let floor = ident(rest);
        if rank(&floor).is_none() {
            root.insert(floor);
            continue;
        }
        let Some(after) = rest[floor.len()..].strip_prefix("::") else {
            continue;
        };
        if let Some(group) = after.strip_prefix('{') {
            let group = &group[..group.find('}').unwrap_or(group.len())];
            for name in group.split(',').map(|p| ident(p.trim())) {
                if !name.is_empty() {
                    files.insert(format!("{floor}/{name}"));
                }
            }
        } else {
            files.insert(format!("{floor}/{}", ident(after)));
        }
    }
    (files, root)
}

#[test]
fn texture_floors_only_look_down_and_no_file_imports_in_a_circle() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("../texel-texture/src");
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    let mut graph = BTreeMap::new();
    let mut wrong = Vec::new();
    for file in &files {
        let rel = file.strip_prefix(&src).unwrap().with_extension("");
        let Some(floor) = rel
            .parent()
            .and_then(|p| p.to_str())
            .filter(|p| !p.is_empty())
        else {
            continue; // lib.rs: the root re-exports
        };
        let node = rel.to_string_lossy().into_owned();
        let own = rank(floor).unwrap_or_else(|| panic!("src/{floor} is not a floor"));
        let (imports, root) = floor_imports(&library_code(&fs::read_to_string(file).unwrap()));
        wrong.extend(
            root.iter()
                .map(|r| format!("src/{node}.rs names crate::{r} (name the module)")),
        );
        let mut edges = BTreeSet::new();
        for to in imports {
            let to_floor = to.split('/').next().unwrap();
            if to.ends_with("/mod") || to == node {
                continue;
            }
            if rank(to_floor).unwrap() > own
                || (floor == "mapping" && !matches!(to_floor, "base" | "mapping"))
            {
                wrong.push(format!("src/{node}.rs looks up at src/{to}.rs"));
            }
            edges.insert(to);
        }
        graph.insert(node, edges);
    }
    assert!(graph.len() >= 25, "found {} files on floors", graph.len());
    if let Some(c) = cycle(&graph) {
        wrong.push(format!("circle: {}", c.join(" -> ")));
    }
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
}

#[test]
fn floor_paths_are_read_in_groups_paths_and_root_names() {
    let (files, root) = floor_imports(
        "use crate::base::{floor, rng::Mix};\nlet x = crate::kernel::bilinear::blend;\nuse crate::Lanes;",
    );
    let want = ["base/floor", "base/rng", "kernel/bilinear"].map(String::from);
    assert_eq!(files, BTreeSet::from(want));
    assert_eq!(root, BTreeSet::from(["Lanes".to_string()]));
}

#[test]
fn no_crate_has_modules_in_a_circle() {
    let crates = Path::new(env!("CARGO_MANIFEST_DIR")).parent().unwrap();
    let mut checked = 0;
    let mut circles = Vec::new();
    for entry in fs::read_dir(crates).unwrap() {
        let src = entry.unwrap().path().join("src");
        if !src.is_dir() {
            continue;
        }
        checked += 1;
        if let Some(c) = cycle(&graph(&src)) {
            circles.push(format!("{}: {}", src.display(), c.join(" -> ")));
        }
    }
    assert!(checked >= 8, "found {checked} crates");
    assert!(circles.is_empty(), "{}", circles.join("\n"));
}

#[test]
fn the_graph_sees_paths_in_code_and_a_cycle() {
    let dir = std::env::temp_dir().join(format!("texel-structure-{}", std::process::id()));
    let src = dir.join("src");
    fs::create_dir_all(src.join("b")).unwrap();
    fs::write(
        src.join("a.rs"),
        "use crate::b::x;\n// crate::c in a comment\n",
    )
    .unwrap();
    fs::write(src.join("b/mod.rs"), "mod y;\n").unwrap();
    fs::write(src.join("b/y.rs"), "fn f() { crate::c::g() }\n").unwrap();
    fs::write(
        src.join("c.rs"),
        "pub fn g() {}\n#[cfg(test)]\nmod tests { use crate::a; }\n",
    )
    .unwrap();
    let g = graph(&src);
    assert_eq!(g["a"], BTreeSet::from(["b".to_string()]));
    assert_eq!(g["b"], BTreeSet::from(["c".to_string()]));
    assert!(g["c"].is_empty());
    assert_eq!(cycle(&g), None);
    fs::write(src.join("c.rs"), "use crate::a;\n").unwrap();
    let c = cycle(&graph(&src)).unwrap();
    assert_eq!(c.first(), c.last());
    assert_eq!(c.len(), 4);
    fs::remove_dir_all(&dir).unwrap();
}

/// `text` with comments, string literals and character literals blanked to spaces (newlines
/// kept), so that the braces left are the code's own.
fn code_only(text: &str) -> String {
    let c: Vec<char> = text.chars().collect();
    let mut out = String::with_capacity(text.len());
    let blank = |ch: char| if ch == '\n' { '\n' } else { ' ' };
    let mut i = 0;
    while i < c.len() {
        let next = c.get(i + 1).copied();
        if c[i] == '/' && next == Some('/') {
            while i < c.len() && c[i] != '\n' {
                out.push(' ');
                i += 1;
            }
        } else if c[i] == '/' && next == Some('*') {
            let mut depth = 0;
            loop {
                if i >= c.len() {
                    break;
                }
                if c[i] == '/' && c.get(i + 1) == Some(&'*') {
                    depth += 1;
                    out.push_str("  ");
                    i += 2;
                } else if c[i] == '*' && c.get(i + 1) == Some(&'/') {
                    depth -= 1;
                    out.push_str("  ");
                    i += 2;
                    if depth == 0 {
                        break;
                    }
                } else {
                    out.push(blank(c[i]));
                    i += 1;
                }
            }
        } else if c[i] == 'r'
            && matches!(next, Some('"') | Some('#'))
            && (i == 0 || !(c[i - 1].is_alphanumeric() || c[i - 1] == '_'))
        {
            // A raw string: r"..." or r#"..."#.
            let mut j = i + 1;
            while c.get(j) == Some(&'#') {
                j += 1;
            }
            if c.get(j) != Some(&'"') {
                out.push(c[i]);
                i += 1;
                continue;
            }
            let hashes = j - i - 1;
            let close: Vec<char> = std::iter::once('"')
                .chain(std::iter::repeat_n('#', hashes))
                .collect();
            let mut k = j + 1;
            while k < c.len() && !c[k..].starts_with(&close) {
                k += 1;
            }
            let end = (k + close.len()).min(c.len());
            out.extend(c[i..end].iter().map(|&ch| blank(ch)));
            i = end;
        } else if c[i] == '"' {
            out.push(' ');
            i += 1;
            while i < c.len() && c[i] != '"' {
                if c[i] == '\\' {
                    out.push(' ');
                    i += 1;
                }
                if i < c.len() {
                    out.push(blank(c[i]));
                    i += 1;
                }
            }
            out.push(' ');
            i += 1;
        } else if c[i] == '\'' {
            // A character literal ('x', '\n', '\u{..}'), or a lifetime, which stays.
            let end = if next == Some('\\') {
                (i + 2..c.len()).find(|&k| c[k] == '\'')
            } else if c.get(i + 2) == Some(&'\'') {
                Some(i + 2)
            } else {
                None
            };
            match end {
                Some(e) => {
                    out.extend(c[i..=e].iter().map(|&ch| blank(ch)));
                    i = e + 1;
                }
                None => {
                    out.push('\'');
                    i += 1;
                }
            }
        } else {
            out.push(c[i]);
            i += 1;
        }
    }
    out
}

/// The name of the function a line of code starts, if it starts one.
fn fn_name(line: &str) -> Option<&str> {
    let mut rest = line.trim_start();
    for word in [
        "pub(crate) ",
        "pub(super) ",
        "pub ",
        "const ",
        "async ",
        "unsafe ",
    ] {
        rest = rest.strip_prefix(word).unwrap_or(rest);
    }
    let rest = rest.strip_prefix("fn ")?;
    let end = rest
        .find(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
        .unwrap_or(rest.len());
    (end > 0).then(|| &rest[..end])
}

/// Every function with a body in `code` (as [`code_only`] leaves it): its name and its length in
/// lines, from the `fn` line to the closing brace.
fn function_lengths(code: &str) -> Vec<(String, usize)> {
    let lines: Vec<&str> = code.lines().collect();
    let mut out = Vec::new();
    for (start, line) in lines.iter().enumerate() {
        let Some(name) = fn_name(line) else { continue };
        let mut depth = 0usize;
        let mut opened = false;
        'scan: for (k, l) in lines[start..].iter().enumerate() {
            for ch in l.chars() {
                match ch {
                    ';' if !opened => break 'scan,
                    '{' => {
                        depth += 1;
                        opened = true;
                    }
                    '}' => {
                        depth = depth.saturating_sub(1);
                        if opened && depth == 0 {
                            out.push((name.to_string(), k + 1));
                            break 'scan;
                        }
                    }
                    _ => {}
                }
            }
        }
    }
    out
}

/// The library functions allowed over 100 lines, each as (file, name, the reason it stays whole).
/// None is: every long job reads as named steps.
const LONG_FUNCTIONS: &[(&str, &str, &str)] = &[];

#[test]
fn library_functions_are_at_most_100_lines() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let mut files = Vec::new();
    for entry in fs::read_dir(root.join("crates")).unwrap() {
        let src = entry.unwrap().path().join("src");
        if src.is_dir() {
            rust_files(&src, &mut files);
        }
    }
    rust_files(&root.join("python/src"), &mut files);
    let mut long = BTreeSet::new();
    let mut counted = 0;
    for file in &files {
        let text = fs::read_to_string(file).unwrap();
        let library = text.split("#[cfg(test)]\nmod ").next().unwrap();
        let rel = file
            .strip_prefix(&root)
            .unwrap()
            .to_string_lossy()
            .into_owned();
        for (name, lines) in function_lengths(&code_only(library)) {
            counted += 1;
            if lines > 100 {
                long.insert((rel.clone(), name, lines));
            }
        }
    }
    assert!(counted > 1000, "found {counted} functions");
    let listed: BTreeSet<(&str, &str)> = LONG_FUNCTIONS.iter().map(|&(f, n, _)| (f, n)).collect();
    let unlisted: Vec<String> = long
        .iter()
        .filter(|(f, n, _)| !listed.contains(&(f.as_str(), n.as_str())))
        .map(|(f, n, l)| format!("{f}: {n} has {l} lines"))
        .collect();
    assert!(unlisted.is_empty(), "split these:\n{}", unlisted.join("\n"));
    let found: BTreeSet<(&str, &str)> = long
        .iter()
        .map(|(f, n, _)| (f.as_str(), n.as_str()))
        .collect();
    let stale: Vec<_> = listed.difference(&found).collect();
    assert!(
        stale.is_empty(),
        "listed but at most 100 lines now: {stale:?}"
    );
}

#[test]
fn function_lengths_see_code_not_strings_or_comments() {
    let code = code_only(
        "pub fn a() {\n    let s = \"}}{\";\n    // }\n    let c = '}';\n}\nfn b<'x>(v: &'x str);\nfn c() {\n    /* { */\n    let r = r#\"}\"#;\n}\n",
    );
    assert_eq!(
        function_lengths(&code),
        vec![("a".to_string(), 5), ("c".to_string(), 4)]
    );
}
