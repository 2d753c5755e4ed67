//! The crate's floors only look down (ARCHITECTURE.md): every `crate::` path in the library code
//! of `src/` (comments, doc links and `#[cfg(test)]` modules aside: a unit test may use the whole
//! crate) names a module on the same floor or a lower one, paths name modules, not the root's
//! re-exports, and the files' imports form no circle.

use std::collections::{BTreeMap, BTreeSet};
use std::fs;
use std::path::Path;

/// The floors, lowest first. `mapping` stands beside them and may use only the ground floor.
const FLOORS: [&str; 5] = ["base", "storage", "kernel", "technique", "engine"];

fn rank(floor: &str) -> Option<usize> {
    if floor == "mapping" {
        return Some(0);
    }
    FLOORS.iter().position(|&f| f == floor)
}

/// Every `src/<floor>/<file>.rs` as `("floor", "file")` with its code (comments removed).
fn sources() -> Vec<((String, String), String)> {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut out = Vec::new();
    for floor in fs::read_dir(&src).unwrap() {
        let floor = floor.unwrap().path();
        if !floor.is_dir() {
            continue;
        }
        let floor_name = floor.file_name().unwrap().to_string_lossy().into_owned();
        for file in fs::read_dir(&floor).unwrap() {
            let file = file.unwrap().path();
            let stem = file.file_stem().unwrap().to_string_lossy().into_owned();
            let text = fs::read_to_string(&file).unwrap();
            let library = text.split("#[cfg(test)]\nmod ").next().unwrap();
            let code: String = library
                .lines()
                .map(|l| match l.find("//") {
                    Some(i) => &l[..i],
                    None => l,
                })
                .collect::<Vec<_>>()
                .join("\n");
            out.push(((floor_name.clone(), stem), code));
        }
    }
    out.sort();
    out
}

/// The `(floor, file)` pairs that `code` names through `crate::floor::file` (or
/// `crate::floor::{file, ..}`), and every root re-export it names (`crate::Name`).
fn imports(code: &str) -> (BTreeSet<(String, String)>, BTreeSet<String>) {
    let mut files = BTreeSet::new();
    let mut root = BTreeSet::new();
    let ident = |s: &str| -> String {
        s.chars()
            .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
            .collect()
    };
    for (i, _) in code.match_indices("crate::") {
        let rest = &code[i + "crate::".len()..];
        let first = ident(rest);
        if rank(&first).is_none() {
            root.insert(first);
            continue;
        }
        let after = &rest[first.len()..];
        let Some(after) = after.strip_prefix("::") else {
            continue;
        };
        if let Some(group) = after.strip_prefix('{') {
            let group = &group[..group.find('}').unwrap_or(group.len())];
            for part in group.split(',') {
                let name = ident(part.trim());
                if !name.is_empty() {
                    files.insert((first.clone(), name));
                }
            }
        } else {
            files.insert((first.clone(), ident(after)));
        }
    }
    (files, root)
}

#[test]
fn floors_only_look_down_and_no_file_imports_in_a_circle() {
    let sources = sources();
    assert!(sources.len() >= 25, "found {} source files", sources.len());
    let mut graph: BTreeMap<(String, String), BTreeSet<(String, String)>> = BTreeMap::new();
    let mut wrong = Vec::new();
    for ((floor, file), code) in &sources {
        let own = rank(floor).unwrap_or_else(|| panic!("src/{floor} is not a floor"));
        let (files, root) = imports(code);
        for name in root {
            wrong.push(format!(
                "src/{floor}/{file}.rs names crate::{name} (name the module)"
            ));
        }
        let mut edges = BTreeSet::new();
        for (to_floor, to_file) in files {
            if to_file == "mod" || (&to_floor, &to_file) == (floor, file) {
                continue;
            }
            let up = rank(&to_floor).unwrap() > own
                || (floor == "mapping" && to_floor != "base" && to_floor != "mapping");
            if up {
                wrong.push(format!(
                    "src/{floor}/{file}.rs looks up at src/{to_floor}/{to_file}.rs"
                ));
            }
            edges.insert((to_floor, to_file));
        }
        graph.insert((floor.clone(), file.clone()), edges);
    }
    // Depth-first search for a back edge.
    fn visit(
        node: &(String, String),
        graph: &BTreeMap<(String, String), BTreeSet<(String, String)>>,
        state: &mut BTreeMap<(String, String), u8>,
        path: &mut Vec<(String, String)>,
        circles: &mut Vec<String>,
    ) {
        state.insert(node.clone(), 1);
        path.push(node.clone());
        for next in graph.get(node).into_iter().flatten() {
            match state.get(next).copied().unwrap_or(0) {
                0 => visit(next, graph, state, path, circles),
                1 => {
                    let at = path.iter().position(|n| n == next).unwrap();
                    let names: Vec<String> = path[at..]
                        .iter()
                        .chain([next])
                        .map(|(f, m)| format!("{f}/{m}"))
                        .collect();
                    circles.push(names.join(" -> "));
                }
                _ => {}
            }
        }
        path.pop();
        state.insert(node.clone(), 2);
    }
    let (mut state, mut circles) = (BTreeMap::new(), Vec::new());
    for node in graph.keys() {
        if !state.contains_key(node) {
            visit(node, &graph, &mut state, &mut Vec::new(), &mut circles);
        }
    }
    wrong.extend(circles.into_iter().map(|c| format!("circle: {c}")));
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
}

#[test]
fn the_parser_sees_groups_paths_and_root_names() {
    let (files, root) =
        imports("use crate::base::{floor, rng::Mix};\nlet x = crate::kernel::bilinear::blend;\nuse crate::Lanes;");
    let want: BTreeSet<(String, String)> =
        [("base", "floor"), ("base", "rng"), ("kernel", "bilinear")]
            .iter()
            .map(|(a, b)| (a.to_string(), b.to_string()))
            .collect();
    assert_eq!(files, want);
    assert_eq!(root, BTreeSet::from(["Lanes".to_string()]));
}
