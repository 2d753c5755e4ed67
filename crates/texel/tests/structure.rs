//! The workspace's structure, as docs/guide/architecture.md lays it out, read from the library
//! code (comments and `#[cfg(test)]` modules aside: a unit test may use its whole crate):
//! - no crate has top-level modules (a file, or a folder with everything in it) that import each
//!   other through `crate::` paths in a circle;
//! - texel-texture's floors only look down: every `crate::floor::file` path names a file on the
//!   same floor or a lower one, paths name modules rather than the root's re-exports, and its
//!   files import each other in no circle;
//! - texel-raster's and texel-scene's modules stand in layers that only look down (a module
//!   names modules of its own layer or lower ones, directly or through the root's re-exports);
//! - the facade names its surface item by item: no `pub use` of a whole crate, a whole module or
//!   a glob, in any of its files.

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

/// The library code of each top-level module of one crate's `src` (`lib` for the root).
fn module_code(src: &Path) -> BTreeMap<String, String> {
    let mut files = Vec::new();
    rust_files(src, &mut files);
    let mut code: BTreeMap<String, String> = BTreeMap::new();
    for file in &files {
        let text = fs::read_to_string(file).unwrap();
        code.entry(module_of(src, file))
            .or_default()
            .push_str(&library_code(&text));
    }
    code
}

/// The module graph of one crate's `src`.
fn graph(src: &Path) -> BTreeMap<String, BTreeSet<String>> {
    let code = module_code(src);
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

/// Every function with a body in `file` (unit-test modules aside): its name and its length in
/// lines, from the `fn` line to the closing brace.
fn function_lengths(file: &syn::File) -> Vec<(String, usize)> {
    use syn::spanned::Spanned;
    use syn::visit::Visit;
    struct Lengths(Vec<(String, usize)>);
    impl Lengths {
        fn add(&mut self, sig: &syn::Signature, block: &syn::Block) {
            let first = sig.fn_token.span.start().line;
            let last = block.span().end().line;
            self.0.push((sig.ident.to_string(), last + 1 - first));
        }
    }
    impl<'a> Visit<'a> for Lengths {
        fn visit_item_mod(&mut self, m: &'a syn::ItemMod) {
            let test = m.attrs.iter().any(|a| {
                a.path().is_ident("cfg") && a.parse_args::<syn::Ident>().is_ok_and(|i| i == "test")
            });
            if !test {
                syn::visit::visit_item_mod(self, m);
            }
        }
        fn visit_item_fn(&mut self, f: &'a syn::ItemFn) {
            self.add(&f.sig, &f.block);
            syn::visit::visit_item_fn(self, f);
        }
        fn visit_impl_item_fn(&mut self, f: &'a syn::ImplItemFn) {
            self.add(&f.sig, &f.block);
            syn::visit::visit_impl_item_fn(self, f);
        }
        fn visit_trait_item_fn(&mut self, f: &'a syn::TraitItemFn) {
            if let Some(block) = &f.default {
                self.add(&f.sig, block);
            }
            syn::visit::visit_trait_item_fn(self, f);
        }
    }
    let mut lengths = Lengths(Vec::new());
    lengths.visit_file(file);
    lengths.0
}

/// The library functions allowed over 100 lines: (file, name, the reason it stays whole).
const LONG_FUNCTIONS: [(&str, &str, &str); 3] = [
    (
        "crates/texel-texture/src/engine/batch.rs",
        "anisotropic",
        "the anisotropic batch loop, inlined into each kernel's copy; its probe batches and scratch \
         live across the stages, and a split is a frame-time measurement, not a refactor",
    ),
    (
        "crates/texel-texture/src/engine/batch.rs",
        "run_in",
        "the trilinear batch loop, inlined per chunk size; as anisotropic, its stages share \
         chunk-local state on the hottest path",
    ),
    (
        "crates/texel-raster/src/relief.rs",
        "shading_normal",
        "a fragment's normal-map and bump-map branches with their specular antialiasing, which \
         share one tangent frame and roughness rule",
    ),
];

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
    let listed: BTreeSet<(&str, &str)> = LONG_FUNCTIONS.iter().map(|&(f, n, _)| (f, n)).collect();
    let (mut unlisted, mut long) = (Vec::new(), BTreeSet::new());
    let mut counted = 0;
    for file in &files {
        let text = fs::read_to_string(file).unwrap();
        let syntax = syn::parse_file(&text).unwrap_or_else(|e| panic!("{}: {e}", file.display()));
        let rel = file
            .strip_prefix(&root)
            .unwrap()
            .to_string_lossy()
            .into_owned();
        for (name, lines) in function_lengths(&syntax) {
            counted += 1;
            if lines <= 100 {
                continue;
            }
            if !listed.contains(&(rel.as_str(), name.as_str())) {
                unlisted.push(format!("{rel}: {name} has {lines} lines"));
            }
            long.insert((rel.clone(), name));
        }
    }
    assert!(counted > 1000, "found {counted} functions");
    assert!(
        unlisted.is_empty(),
        "split these into named steps:\n{}",
        unlisted.join("\n")
    );
    let stale: Vec<_> = listed
        .iter()
        .filter(|(f, n)| !long.contains(&(f.to_string(), n.to_string())))
        .collect();
    assert!(stale.is_empty(), "listed but at most 100 lines: {stale:?}");
}

#[test]
fn function_lengths_count_from_fn_to_the_closing_brace() {
    let file = syn::parse_file(
        "/// Doc.\n#[inline]\npub fn a() {\n    let s = \"}}{\";\n    // }\n    let c = '}';\n}\n\
         trait T {\n    fn b(&self);\n    fn c(&self) {\n        let r = r#\"}\"#;\n    }\n}\n\
         #[cfg(test)]\nmod tests {\n    fn d() {}\n}\n",
    )
    .unwrap();
    assert_eq!(
        function_lengths(&file),
        vec![("a".to_string(), 5), ("c".to_string(), 3)]
    );
}

/// The `pub use` trees of `items` (modules included) that re-export a whole crate (`pub use
/// texel_x;`, `pub use texel_x as y;`), a glob, a `self` leaf, or a path that `is_module` says
/// names a module, written as `path` strings.
fn wholesale_reexports(items: &[syn::Item], is_module: &dyn Fn(&str) -> bool) -> Vec<String> {
    fn walk(
        tree: &syn::UseTree,
        prefix: &str,
        is_module: &dyn Fn(&str) -> bool,
        out: &mut Vec<String>,
    ) {
        let leaf = |ident: &syn::Ident, out: &mut Vec<String>| {
            let path = format!("{prefix}{ident}");
            if prefix.is_empty() || ident == "self" || is_module(&path) {
                out.push(path);
            }
        };
        match tree {
            syn::UseTree::Path(p) => {
                walk(&p.tree, &format!("{prefix}{}::", p.ident), is_module, out)
            }
            syn::UseTree::Group(g) => g.items.iter().for_each(|t| walk(t, prefix, is_module, out)),
            syn::UseTree::Glob(_) => out.push(format!("{prefix}*")),
            syn::UseTree::Name(n) => leaf(&n.ident, out),
            syn::UseTree::Rename(r) => leaf(&r.ident, out),
        }
    }
    let mut out = Vec::new();
    for item in items {
        match item {
            syn::Item::Use(u) if matches!(u.vis, syn::Visibility::Public(_)) => {
                walk(&u.tree, "", is_module, &mut out)
            }
            syn::Item::Mod(m) => {
                if let Some((_, inner)) = &m.content {
                    out.extend(wholesale_reexports(inner, is_module));
                }
            }
            _ => {}
        }
    }
    out
}

/// Whether `path` (`texel_x::a::b`) names a public module of a workspace crate under `crates`:
/// the parent's file (`crates/texel-x/src/lib.rs` for `texel_x::b`, `src/a.rs` or `src/a/mod.rs`
/// for `texel_x::a::b`) declares `pub mod b`. A private module of the same name as a re-exported
/// item (`mod psnr; pub use psnr::psnr;`) is not one.
fn names_workspace_module(crates: &Path, path: &str) -> bool {
    let parts: Vec<&str> = path.split("::").collect();
    let [krate, parents @ .., leaf] = parts.as_slice() else {
        return false;
    };
    let mut dir = crates.join(krate.replace('_', "-")).join("src");
    let parent = if parents.is_empty() {
        dir.join("lib.rs")
    } else {
        parents.iter().for_each(|p| dir.push(p));
        let file = dir.with_extension("rs");
        if file.is_file() {
            file
        } else {
            dir.join("mod.rs")
        }
    };
    fs::read_to_string(parent).is_ok_and(|text| {
        library_code(&text).lines().any(|l| {
            let l = l.trim();
            l == format!("pub mod {leaf};") || l.starts_with(&format!("pub mod {leaf} {{"))
        })
    })
}

#[test]
fn the_facade_names_its_surface_item_by_item() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let crates = root.parent().unwrap().to_path_buf();
    let is_module = |p: &str| names_workspace_module(&crates, p);
    let mut files = Vec::new();
    rust_files(&root.join("src"), &mut files);
    assert!(files.len() > 1, "{files:?}");
    for file in &files {
        let parsed = syn::parse_file(&fs::read_to_string(file).unwrap()).unwrap();
        let wholesale = wholesale_reexports(&parsed.items, &is_module);
        assert_eq!(wholesale, Vec::<String>::new(), "{}", file.display());
    }
    // The checker sees each wholesale form, in a module too, and passes named items.
    let sample = syn::parse_file(
        "pub use texel_io as io;\npub use texel_raster;\nuse texel_scene as private;\n\
         pub mod m { pub use texel_quality::{psnr, html::*}; }\npub use texel_texture::{Sampler, \
         base::color::displayed as shown};\npub use texel_quality::html;\n\
         pub use texel_scene::{self as scene_crate};\npub use texel_texture::{base::{rng, color::srgb_to_linear}, technique};\n",
    )
    .unwrap();
    assert_eq!(
        wholesale_reexports(&sample.items, &is_module),
        vec![
            "texel_io",
            "texel_raster",
            "texel_quality::html::*",
            "texel_quality::html",
            "texel_scene::self",
            "texel_texture::base::rng",
            "texel_texture::technique",
        ]
    );
}

/// The names the root `lib.rs` re-exports from the crate's own modules, each with its module
/// (`pub use module::{Name, other::Deeper as Alias}` gives `Name` and `Alias`).
fn root_names(lib: &syn::File, modules: &BTreeSet<String>) -> BTreeMap<String, String> {
    fn leaves(tree: &syn::UseTree, out: &mut Vec<String>) {
        match tree {
            syn::UseTree::Path(p) => leaves(&p.tree, out),
            syn::UseTree::Group(g) => g.items.iter().for_each(|t| leaves(t, out)),
            syn::UseTree::Name(n) => out.push(n.ident.to_string()),
            syn::UseTree::Rename(r) => out.push(r.rename.to_string()),
            syn::UseTree::Glob(_) => {}
        }
    }
    let mut names = BTreeMap::new();
    for item in &lib.items {
        let syn::Item::Use(u) = item else { continue };
        let syn::UseTree::Path(p) = &u.tree else {
            continue;
        };
        let module = p.ident.to_string();
        if !modules.contains(&module) {
            continue; // another crate's names
        }
        let mut out = Vec::new();
        leaves(&p.tree, &mut out);
        for name in out {
            names.insert(name, module.clone());
        }
    }
    names
}

/// The modules of `code` names through `crate::x` and `crate::{x, y}`, where `x` is one of
/// `modules` or a root re-export of one (`names`).
fn named_modules(
    code: &str,
    modules: &BTreeSet<String>,
    names: &BTreeMap<String, String>,
) -> BTreeSet<String> {
    let ident = |s: &str| -> String {
        s.chars()
            .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
            .collect()
    };
    let mut out = BTreeSet::new();
    let mut add = |x: String| {
        if modules.contains(&x) {
            out.insert(x);
        } else if let Some(m) = names.get(&x) {
            out.insert(m.clone());
        }
    };
    for (i, _) in code.match_indices("crate::") {
        let rest = &code[i + "crate::".len()..];
        if let Some(group) = rest.strip_prefix('{') {
            // The group's top-level paths: commas inside nested braces belong to one path.
            let mut depth = 0usize;
            let mut start = 0;
            for (j, c) in group.char_indices() {
                match c {
                    '{' => depth += 1,
                    '}' if depth == 0 => {
                        add(ident(group[start..j].trim()));
                        break;
                    }
                    '}' => depth -= 1,
                    ',' if depth == 0 => {
                        add(ident(group[start..j].trim()));
                        start = j + 1;
                    }
                    _ => {}
                }
            }
        } else {
            add(ident(rest));
        }
    }
    out
}

/// Every module of the crate at `src` in one of `layers` (lowest first), and each naming only
/// modules of its layer or lower ones: the breaches, as messages.
fn layer_breaches(src: &Path, layers: &[&[&str]]) -> Vec<String> {
    let code = module_code(src);
    let lib = syn::parse_file(&fs::read_to_string(src.join("lib.rs")).unwrap()).unwrap();
    let modules: BTreeSet<String> = code.keys().filter(|m| *m != "lib").cloned().collect();
    let names = root_names(&lib, &modules);
    let layer_of = |m: &str| layers.iter().position(|l| l.contains(&m));
    let mut wrong = Vec::new();
    for (module, text) in code.iter().filter(|(m, _)| *m != "lib") {
        let Some(own) = layer_of(module) else {
            wrong.push(format!("{module} is in no layer"));
            continue;
        };
        for to in named_modules(text, &modules, &names) {
            match layer_of(&to) {
                Some(l) if l > own => wrong.push(format!("{module} looks up at {to}")),
                _ => {}
            }
        }
    }
    wrong
}

/// texel-raster's layers, lowest first: the frame's vocabulary; a triangle's set-up and its
/// attributes; shading; the tile loop; the jobs built on it.
const RASTER_LAYERS: &[&[&str]] = &[
    &[
        "error", "camera", "clip", "stream", "views", "settings", "draw", "frame",
    ],
    &["setup", "interp", "point"],
    &["relief", "shade"],
    &["tile"],
    &["reference", "exact", "adaptive", "warp"],
];

/// texel-scene's layers, lowest first: the vocabulary of a scene; the scene model and what is
/// read off it; the loaders; the scene file.
const SCENE_LAYERS: &[&[&str]] = &[
    &["error", "camera", "limits", "procedural", "environment"],
    &["model", "tangents", "texture", "validate"],
    &["obj", "gltf_import", "builtin"],
    &["file"],
];

#[test]
fn raster_and_scene_modules_stand_in_layers_that_only_look_down() {
    let crates = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let mut wrong = layer_breaches(&crates.join("texel-raster/src"), RASTER_LAYERS);
    wrong.extend(layer_breaches(
        &crates.join("texel-scene/src"),
        SCENE_LAYERS,
    ));
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
}

#[test]
fn layer_reads_see_modules_groups_and_root_names() {
    let modules: BTreeSet<String> = ["draw", "frame", "setup"].map(String::from).into();
    let lib =
        syn::parse_file("pub use frame::{Frame, Clear as Cleared};\npub use glam::Vec3;").unwrap();
    let names = root_names(&lib, &modules);
    assert_eq!(names.get("Cleared").map(String::as_str), Some("frame"));
    assert!(!names.contains_key("Vec3"));
    let code =
        "use crate::{setup, Frame};\nlet d = crate::draw::DrawCall::new();\ncrate::Vec3::ZERO";
    let want: BTreeSet<String> = ["draw", "frame", "setup"].map(String::from).into();
    assert_eq!(named_modules(code, &modules, &names), want);
    // A nested group does not end the outer one: `frame` after `draw::{..}` is seen.
    let nested = "use crate::{draw::{DrawCall, Mesh}, frame::Frame};";
    let want: BTreeSet<String> = ["draw", "frame"].map(String::from).into();
    assert_eq!(named_modules(nested, &modules, &names), want);
}
