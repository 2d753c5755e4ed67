//! No crate of the workspace has modules that import each other in a circle: for every crate's
//! `src/`, the graph whose nodes are its top-level modules (a file, or a folder with everything in
//! it) and whose edges are the `crate::module` paths of the library code (comments and
//! `#[cfg(test)]` modules aside) has no cycle. So each crate reads bottom up, as
//! docs/guide/architecture.md lays it out. (texel-texture's own floors, file by file, are checked
//! by its `tests/floors.rs`.)

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
