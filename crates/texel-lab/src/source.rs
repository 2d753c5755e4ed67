//! Reading a student's GLSL source: its `#version`, and the lab's rule that texture access uses
//! only `texelFetch` and `textureSize`.
//!
//! The rule check works on the source as the compiler sees it: comments removed (line numbers
//! kept), blocks that the preprocessor drops (`#if 0`, `#ifdef` of a name never defined, their
//! `#else` branches) skipped, and macro bodies read, so `#define SAMPLE texture` is reported on the
//! line of the `#define`. A call is an identifier followed by `(`; one whose name begins with `tex`
//! is a built-in unless the shader defines a function of that name.

use std::collections::BTreeSet;

/// The texture built-ins the lab allows.
pub const ALLOWED: [&str; 2] = ["texelFetch", "textureSize"];

/// One use of a texture built-in the lab forbids.
#[derive(Clone, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct Violation {
    /// 1-based line in the source.
    pub line: usize,
    /// The built-in's name.
    pub call: String,
}

/// A `#version` directive.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct GlslVersion {
    /// The number (110 when the source has no directive).
    pub number: u32,
    /// `es` profile.
    pub es: bool,
    /// `core` or `compatibility`, when given.
    pub profile: Option<String>,
}

impl GlslVersion {
    /// The directive.
    pub fn line(&self) -> String {
        let mut s = format!("#version {}", self.number);
        if self.es {
            s.push_str(" es");
        } else if let Some(p) = &self.profile {
            s.push(' ');
            s.push_str(p);
        }
        s
    }

    /// Whether varyings are `in` / `out` (GLSL 1.30 and later, ES 3.00).
    pub fn has_in_out(&self) -> bool {
        self.es || self.number >= 130
    }
}

/// The source's `#version` (110 when it has none).
pub fn version_of(source: &str) -> GlslVersion {
    let clean = strip_comments(source);
    for line in clean.lines() {
        let t = line.trim();
        if let Some(rest) = t.strip_prefix('#') {
            let mut words = rest.split_whitespace();
            if words.next() == Some("version") {
                let number = words.next().and_then(|n| n.parse().ok()).unwrap_or(110);
                let tail = words.next().map(str::to_string);
                return GlslVersion {
                    number,
                    es: tail.as_deref() == Some("es"),
                    profile: tail.filter(|t| t != "es"),
                };
            }
        }
    }
    GlslVersion {
        number: 110,
        es: false,
        profile: None,
    }
}

/// `source` with its comments and line continuations (`\` before a newline) replaced by spaces
/// (newlines kept, so line numbers hold).
pub fn strip_comments(source: &str) -> String {
    let b = source.as_bytes();
    let mut out = String::with_capacity(source.len());
    let mut i = 0;
    while i < b.len() {
        if b[i] == b'\\' && b.get(i + 1) == Some(&b'\n') {
            out.push_str(" \n");
            i += 2;
        } else if b[i] == b'/' && b.get(i + 1) == Some(&b'/') {
            while i < b.len() && b[i] != b'\n' {
                i += 1;
            }
        } else if b[i] == b'/' && b.get(i + 1) == Some(&b'*') {
            i += 2;
            while i < b.len() && !(b[i] == b'*' && b.get(i + 1) == Some(&b'/')) {
                if b[i] == b'\n' {
                    out.push('\n');
                }
                i += 1;
            }
            i += 2;
            out.push(' ');
        } else {
            // Copy one UTF-8 character.
            let ch = source[i..].chars().next().unwrap_or(' ');
            out.push(ch);
            i += ch.len_utf8();
        }
    }
    out
}

/// Names the compiler defines itself (GLSL 4.60, "Predefined Macros"); the profile macros'
/// values depend on the context, so blocks under them count as kept either way.
const PREDEFINED: [&str; 1] = ["__VERSION__"];

/// Whether `name` is one of GLSL's profile macros (`GL_core_profile`, ...).
fn is_profile(name: &str) -> bool {
    name.starts_with("GL_") && name.ends_with("_profile")
}

/// One open `#if` block: whether its current branch is kept, whether an earlier branch was,
/// whether its parent is kept, and whether its conditions cannot be decided.
#[derive(Clone, Copy)]
struct Block {
    active: bool,
    taken: bool,
    parent: bool,
    unknown: bool,
}

/// The lines the preprocessor keeps (true) or drops, by evaluating `#if`, `#ifdef`, `#ifndef`,
/// `#elif`, `#else`, `#endif` over the names `#define`d so far and the predefined ones. Where a
/// condition cannot be decided (operators, macros with values, the profile macros) every branch
/// counts as kept, so nothing the compiler might see escapes the check.
fn active_lines(clean: &str) -> Vec<bool> {
    let mut defined: BTreeSet<String> = PREDEFINED.iter().map(|s| s.to_string()).collect();
    let mut stack: Vec<Block> = Vec::new();
    let mut out = Vec::new();
    for line in clean.lines() {
        let active = stack.last().is_none_or(|b| b.active);
        let t = line.trim();
        let Some(rest) = t.strip_prefix('#') else {
            out.push(active);
            continue;
        };
        let rest = rest.trim_start();
        let (word, arg) = rest
            .split_once(char::is_whitespace)
            .map_or((rest, ""), |(w, a)| (w, a.trim()));
        let decide = |word: &str, arg: &str, defined: &BTreeSet<String>| -> Option<bool> {
            match word {
                _ if is_profile(arg) && word != "if" && word != "elif" => None,
                "ifdef" => Some(defined.contains(arg)),
                "ifndef" => Some(!defined.contains(arg)),
                _ => evaluate(arg, defined),
            }
        };
        match word {
            "define" if active => {
                if let Some(name) = arg.split(|c: char| !c.is_alphanumeric() && c != '_').next() {
                    defined.insert(name.to_string());
                }
                out.push(true);
                continue;
            }
            "undef" if active => {
                defined.remove(arg);
            }
            "if" | "ifdef" | "ifndef" => {
                let c = decide(word, arg, &defined);
                stack.push(Block {
                    active: active && c.unwrap_or(true),
                    taken: c.unwrap_or(true),
                    parent: active,
                    unknown: c.is_none(),
                });
            }
            "elif" => {
                if let Some(top) = stack.last_mut() {
                    let c = decide(word, arg, &defined);
                    let unknown = top.unknown || c.is_none();
                    let keep = unknown || !top.taken && c.unwrap_or(true);
                    *top = Block {
                        active: top.parent && keep,
                        taken: top.taken || keep,
                        parent: top.parent,
                        unknown,
                    };
                }
            }
            "else" => {
                if let Some(top) = stack.last_mut() {
                    let keep = top.unknown || !top.taken;
                    top.active = top.parent && keep;
                    top.taken = true;
                }
            }
            "endif" => {
                stack.pop();
            }
            _ => {}
        }
        // Directives themselves hold no calls (a #define body is checked where it stands).
        out.push(false);
    }
    out
}

/// A preprocessor condition: an integer, `defined(X)` or `defined X`, after any number of `!`;
/// `None` for anything else (operators, macros with values, the profile macros).
fn evaluate(arg: &str, defined: &BTreeSet<String>) -> Option<bool> {
    let a = arg.trim();
    let rest = a.trim_start_matches(|c: char| c == '!' || c.is_whitespace());
    let negations = a[..a.len() - rest.len()].matches('!').count();
    let value = if let Ok(n) = rest.parse::<i64>() {
        n != 0
    } else if let Some(r) = rest.strip_prefix("defined") {
        let name = r
            .trim()
            .trim_start_matches('(')
            .trim_end_matches(')')
            .trim();
        let plain = !name.is_empty() && name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_');
        if !plain || is_profile(name) {
            return None;
        }
        defined.contains(name)
    } else {
        return None;
    };
    Some(value ^ (negations % 2 == 1))
}

/// Identifiers of `line` with their byte offsets.
fn identifiers(line: &str) -> Vec<(usize, &str)> {
    let b = line.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    while i < b.len() {
        if b[i].is_ascii_alphabetic() || b[i] == b'_' {
            let start = i;
            while i < b.len() && (b[i].is_ascii_alphanumeric() || b[i] == b'_') {
                i += 1;
            }
            out.push((start, &line[start..i]));
        } else if b[i].is_ascii_digit() {
            while i < b.len() && (b[i].is_ascii_alphanumeric() || b[i] == b'_' || b[i] == b'.') {
                i += 1;
            }
        } else {
            i += 1;
        }
    }
    out
}

/// Words that may precede a function's name where it is defined or declared.
fn is_type(word: &str) -> bool {
    matches!(word, "void" | "float" | "int" | "uint" | "bool" | "double")
        || ["vec", "ivec", "uvec", "bvec", "dvec", "mat", "dmat"]
            .iter()
            .any(|p| {
                word.strip_prefix(p)
                    .is_some_and(|r| r.chars().all(|c| c.is_ascii_digit() || c == 'x'))
            })
}

/// The longest level argument [`level_size_queries`] reads: a line of many unclosed calls costs
/// its length, not its square.
const MAX_ARGUMENT: usize = 256;

/// Calls of `textureSize` whose level is not the literal `0`, by line: Mesa's llvmpipe answers one
/// size for every pixel of a 2x2 quad (and more) whatever their levels, so a shader that asks a
/// per-pixel level's size reads wrong texels along level boundaries there. Level 0's size halved
/// (`max(textureSize(s, 0) >> level, ivec2(1))`) is the same on every driver.
pub fn level_size_queries(source: &str) -> Vec<usize> {
    let clean = strip_comments(source);
    let active = active_lines(&clean);
    let mut out = Vec::new();
    for (k, line) in clean.lines().enumerate() {
        if !active.get(k).copied().unwrap_or(true) {
            continue;
        }
        for (at, id) in identifiers(line) {
            if id != "textureSize" {
                continue;
            }
            let Some(args) = line[at + id.len()..].trim_start().strip_prefix('(') else {
                continue;
            };
            // The second argument: after the first top-level comma, up to the closing paren.
            let (mut depth, mut comma, mut end) = (0i32, None, None);
            for (i, c) in args.char_indices().take_while(|(i, _)| *i < MAX_ARGUMENT) {
                match c {
                    '(' => depth += 1,
                    ')' if depth == 0 => {
                        end = Some(i);
                        break;
                    }
                    ')' => depth -= 1,
                    ',' if depth == 0 && comma.is_none() => comma = Some(i),
                    _ => {}
                }
            }
            let level = match (comma, end) {
                (Some(c), Some(e)) => args[c + 1..e].trim(),
                _ => "",
            };
            if !level.is_empty() && level != "0" && out.last() != Some(&(k + 1)) {
                out.push(k + 1);
            }
        }
    }
    out
}

/// Lines holding a comment, and lines holding code (the lab asks for comments).
pub fn comment_lines(source: &str) -> (usize, usize) {
    let clean = strip_comments(source);
    let (mut comments, mut code) = (0, 0);
    for (raw, c) in source.lines().zip(clean.lines()) {
        if raw.trim() != c.trim() {
            comments += 1;
        }
        if !c.trim().is_empty() {
            code += 1;
        }
    }
    (comments, code)
}

/// Every use of a texture built-in other than [`ALLOWED`], with its line, in source order: a
/// call (`name` then `(`, on a later line too) of a name beginning with `tex` that the shader
/// does not define, and any mention of one of GLSL's texture built-ins by name (a macro may call
/// it: `#define SAMPLE texture`, `ID(texture)(...)`).
pub fn violations(source: &str) -> Vec<Violation> {
    let clean = strip_comments(source);
    let active = active_lines(&clean);
    let lines: Vec<&str> = clean.lines().collect();
    let kept = |k: usize| active.get(k).copied().unwrap_or(true);
    // The next non-blank text after byte `at` of line `k`, on a later line if this one ends.
    let next = |k: usize, at: usize| -> &str {
        let after = lines[k][at..].trim_start();
        if !after.is_empty() {
            return after;
        }
        lines[k + 1..]
            .iter()
            .map(|l| l.trim_start())
            .find(|l| !l.is_empty())
            .unwrap_or("")
    };
    // Functions the shader defines: `type name (` on a kept line.
    let mut own: BTreeSet<&str> = BTreeSet::new();
    for (k, line) in lines.iter().enumerate().filter(|(k, _)| kept(*k)) {
        let ids = identifiers(line);
        for w in ids.windows(2) {
            if is_type(w[0].1) && next(k, w[1].0 + w[1].1.len()).starts_with('(') {
                own.insert(w[1].1);
            }
        }
    }
    let mut out = Vec::new();
    for (k, line) in lines.iter().enumerate().filter(|(k, _)| kept(*k)) {
        for (at, id) in identifiers(line) {
            if !id.starts_with("tex") || ALLOWED.contains(&id) || own.contains(id) {
                continue;
            }
            if BUILTINS.contains(&id) || next(k, at + id.len()).starts_with('(') {
                out.push(Violation {
                    line: k + 1,
                    call: id.to_string(),
                });
            }
        }
    }
    out
}

/// GLSL's texture built-ins (core and compatibility, 1.10 to 4.60, and the common extensions).
const BUILTINS: &[&str] = &[
    "texture",
    "textureProj",
    "textureLod",
    "textureOffset",
    "texelFetchOffset",
    "textureProjOffset",
    "textureLodOffset",
    "textureProjLod",
    "textureProjLodOffset",
    "textureGrad",
    "textureGradOffset",
    "textureProjGrad",
    "textureProjGradOffset",
    "textureGather",
    "textureGatherOffset",
    "textureGatherOffsets",
    "textureQueryLod",
    "textureQueryLevels",
    "textureSamples",
    "texture1D",
    "texture1DProj",
    "texture1DLod",
    "texture1DProjLod",
    "texture2D",
    "texture2DProj",
    "texture2DLod",
    "texture2DProjLod",
    "texture3D",
    "texture3DProj",
    "texture3DLod",
    "texture3DProjLod",
    "textureCube",
    "textureCubeLod",
    "texture2DRect",
    "texture2DRectProj",
    "texture2DLodEXT",
    "texture2DProjLodEXT",
    "textureCubeLodEXT",
    "texture2DGradEXT",
    "texture2DProjGradEXT",
    "textureCubeGradEXT",
    "textureClampARB",
    "textureGradClampARB",
    "textureOffsetClampARB",
];

#[cfg(test)]
mod tests {
    use super::*;

    fn calls(src: &str) -> Vec<(usize, String)> {
        violations(src)
            .into_iter()
            .map(|v| (v.line, v.call))
            .collect()
    }

    #[test]
    fn texel_fetch_and_texture_size_are_allowed() {
        let src = "#version 330\nuniform sampler2D s;\nvoid main() {\n ivec2 n = textureSize(s, 0);\n vec4 c = texelFetch(s, ivec2(0), 0);\n}\n";
        assert!(calls(src).is_empty());
    }

    #[test]
    fn other_builtins_are_reported_with_their_lines() {
        let src = "#version 330\nvoid main() {\n  vec4 a = texture(s, uv);\n  vec4 b = textureLod (s, uv, 2.0); vec4 c = texture2D(s, uv);\n}\n";
        assert_eq!(
            calls(src),
            vec![
                (3, "texture".into()),
                (4, "textureLod".into()),
                (4, "texture2D".into())
            ]
        );
    }

    #[test]
    fn comments_and_dropped_blocks_do_not_count() {
        let src = "// texture(s, uv)\n/* textureLod(s, uv, 0.0)\n texture(s, uv) */\n#if 0\nvec4 a = texture(s, uv);\n#else\nvec4 b = texelFetch(s, ivec2(0), 0);\n#endif\n#ifdef NEVER\n texture(s, uv);\n#endif\nvec4 c = textureGrad(s, uv, dx, dy);\n";
        assert_eq!(calls(src), vec![(12, "textureGrad".into())]);
    }

    #[test]
    fn macros_are_read_where_they_stand() {
        let src = "#define SAMPLE texture\n#define LOOK(p) textureLod(s, p, 0.0)\nvoid main() { vec4 c = SAMPLE(s, uv); }\n";
        assert_eq!(
            calls(src),
            vec![(1, "texture".into()), (2, "textureLod".into())]
        );
    }

    #[test]
    fn the_shaders_own_functions_are_not_builtins() {
        let src = "vec4 texBilinear(int level, vec2 p) { return vec4(0.0); }\nvoid main() { vec4 c = texBilinear(0, uv); vec2 texCoord2 = texCoord; }\n";
        assert!(calls(src).is_empty());
    }

    #[test]
    fn conditions_it_cannot_decide_keep_every_branch() {
        let src = "#ifdef GL_core_profile\nvec4 a = texture(s, uv);\n#else\nvec4 b = texture2D(s, uv);\n#endif\n#if defined(A) && 1\nvec4 c = textureLod(s, uv, 0.0);\n#endif\n#if !!0\nvec4 d = textureGrad(s, uv, x, y);\n#endif\n#ifdef __VERSION__\nvec4 e = textureProj(s, p);\n#endif\n";
        assert_eq!(
            calls(src),
            vec![
                (2, "texture".into()),
                (4, "texture2D".into()),
                (7, "textureLod".into()),
                (13, "textureProj".into())
            ]
        );
    }

    #[test]
    fn calls_across_lines_and_through_macros_count() {
        let src = "vec4 a = texture\n    (s, uv);\n#define ID(x) x\nvec4 b = ID(textureLod)(s, uv, 0.0);\n#if 0\nvec4 texture(sampler2D s, vec2 p);\n#endif\n";
        assert_eq!(
            calls(src),
            vec![(1, "texture".into()), (4, "textureLod".into())]
        );
    }

    #[test]
    fn deep_negations_and_long_lines_are_cheap() {
        let src = format!(
            "#if {}0\nvec4 a = texture(s, uv);\n#endif\n",
            "!".repeat(200_001)
        );
        assert_eq!(calls(&src), vec![(2, "texture".into())]);
        let line = "textureSize(s, ".repeat(50_000);
        assert!(level_size_queries(&line).is_empty());
    }

    #[test]
    fn per_pixel_level_sizes_are_found() {
        let src = "ivec2 a = textureSize(s, 0);\nivec2 b = textureSize(s, level);\nivec2 c = textureSize(s, int(floor(n)));\n";
        assert_eq!(level_size_queries(src), vec![2, 3]);
    }

    #[test]
    fn versions() {
        assert_eq!(
            version_of("// x\n#version 330 core\n").line(),
            "#version 330 core"
        );
        assert_eq!(version_of("#version 300 es\n").line(), "#version 300 es");
        assert!(!version_of("void main(){}").has_in_out());
        assert!(version_of("#version 130\n").has_in_out());
    }
}
