//! `texel lab` on Mesa's llvmpipe through EGL (`apt-get install libegl1 libegl-mesa0
//! libgl1-mesa-dri`); without it the tests print why and pass, unless `CI=true`.
//!
//! texel's two GLSL solutions get their convention's verdict in every mode on every lab scene;
//! mutants of them, each with one common mistake, fail exactly the modes the mistake touches,
//! with that mistake named first; a forbidden built-in is reported with its line; a compile error,
//! an endless loop and a shader without `texMode` end cleanly.

use std::path::{Path, PathBuf};

use serde_json::Value;

use crate::util::*;

const GL: &str = include_str!("../../texel-lab/glsl/solution-gl.frag");
const LAB: &str = include_str!("../../texel-lab/glsl/solution-lab.frag");

/// Whether OpenGL through EGL works here; panics under `CI=true` when it does not.
pub(crate) fn have_gl() -> bool {
    match texel::lab::Gl::new() {
        Ok(_) => true,
        Err(e) => {
            assert_ne!(
                std::env::var("CI").as_deref(),
                Ok("true"),
                "CI=true but no OpenGL through EGL: {e}"
            );
            eprintln!("skipped: {e}");
            false
        }
    }
}

/// `texel lab SHADER` at a reduced size and reference; the report.
fn grade(d: &Dir, name: &str, source: &str, extra: &[&str]) -> Value {
    let shader = d.write(&format!("{name}.frag"), source);
    let out = d.join(name);
    let mut args: Vec<String> = vec![
        "lab".into(),
        shader.display().to_string(),
        "--out".into(),
        out.display().to_string(),
        "--size".into(),
        "160x120".into(),
        "--spp".into(),
        "4".into(),
        "--frames".into(),
        "1".into(),
    ];
    args.extend(extra.iter().map(|s| s.to_string()));
    ok(&args);
    report(&out)
}

fn report(dir: &Path) -> Value {
    let text = std::fs::read_to_string(dir.join("report.json")).unwrap();
    serde_json::from_str(&text).unwrap()
}

/// `(scene, mode, verdict, first diagnosis)` of every row.
fn rows(r: &Value) -> Vec<(String, u64, String, String)> {
    r["modes"]
        .as_array()
        .unwrap()
        .iter()
        .map(|m| {
            (
                m["scene"].as_str().unwrap().to_string(),
                m["mode"].as_u64().unwrap(),
                m["verdict"].as_str().unwrap().to_string(),
                m["diagnosis"][0].as_str().unwrap_or("").to_string(),
            )
        })
        .collect()
}

fn sub(s: &str, from: &str, to: &str) -> String {
    assert!(s.contains(from), "{from:?} is not in the solution");
    s.replace(from, to)
}

#[test]
fn solutions_get_their_conventions_verdict_in_every_mode() {
    if !have_gl() {
        return;
    }
    let d = Dir::new("lab-solutions");
    for (name, source, want) in [("gl", GL, "gl"), ("lab", LAB, "lab")] {
        let r = grade(&d, name, source, &[]);
        let rows = rows(&r);
        assert_eq!(rows.len(), 24, "three scenes, eight modes");
        for (scene, mode, verdict, _) in &rows {
            assert_eq!(verdict, want, "{name}: {scene} mode {mode}");
        }
        assert_eq!(r["score"].as_f64(), Some(100.0));
        assert!(r["rule_violations"].as_array().unwrap().is_empty());
        for f in [
            "report.md",
            "report.html",
            "images/1-lab-plane-mode4-shader.png",
        ] {
            assert!(d.join(name).join(f).is_file(), "{f}");
        }
        // The agreement with the other convention is far below the measure's share.
        let other = if want == "gl" {
            "agreement_lab"
        } else {
            "agreement_gl"
        };
        let plane4 = r["modes"]
            .as_array()
            .unwrap()
            .iter()
            .find(|m| m["scene"] == "lab-plane" && m["mode"] == 4)
            .unwrap();
        assert!(plane4[other].as_f64().unwrap() < 0.5, "{plane4}");
    }
}

/// One mistake each: the modes it must fail (on at least one scene), the diagnosis key the
/// first diagnosis of each failing mode carries, and the modes it must leave passing.
#[test]
fn mutants_fail_the_modes_their_mistake_touches() {
    if !have_gl() {
        return;
    }
    let d = Dir::new("lab-mutants");
    let wrap = "return i - n * int(floor(float(i) / float(n)));";
    let mutants: Vec<(&str, String, &[u64], &str)> = vec![
        (
            "half-texel",
            sub(GL, "vec2(levelSize(level)) - 0.5;", "vec2(levelSize(level)) + 0.5;"),
            &[2, 3, 4, 5, 6, 7, 8],
            "half-texel",
        ),
        (
            "nearest-half",
            sub(GL, "return fetch(ivec2(floor(x)), 0);", "return fetch(ivec2(floor(x - 0.5)), 0);"),
            &[1],
            "half-texel",
        ),
        (
            "shorter",
            sub(GL, "float lod = log2(max(lx, ly));", "float lod = log2(min(lx, ly));"),
            &[3, 4],
            "shorter-derivative",
        ),
        (
            "blend",
            sub(
                LAB,
                "return a + (bilinear(p, int(hi)) - a) * t;",
                "return a + (bilinear(p, int(hi)) - a) * (1.0 - t);",
            ),
            &[4, 5, 6, 7, 8],
            "blend-reversed",
        ),
        (
            "span",
            sub(
                GL,
                "sum += trilinear(texCoord + t * axis, probeLod);",
                "sum += trilinear(texCoord + 2.0 * t * axis, probeLod);",
            ),
            &[5, 6, 7, 8],
            "probe-span-double",
        ),
        ("no-wrap", sub(LAB, wrap, "return i;"), &[1, 2, 3, 4, 5, 6, 7, 8], "no-wrap"),
        (
            "level-floor",
            sub(
                LAB,
                "int level = int(clamp(ceil(N), 0.0, float(lastLevel())));",
                "int level = int(clamp(floor(N), 0.0, float(lastLevel())));",
            ),
            &[3],
            "level-floor",
        ),
        (
            "aniso-major",
            sub(
                LAB,
                "float level = ratio > lambdaMax ? M + log2(lmax / lambdaMax) : M + log2(lmin);",
                "float level = M + log2(lmax);",
            ),
            &[5, 6, 7, 8],
            "aniso-level-major",
        ),
        (
            "aniso-one",
            sub(
                LAB,
                "        if (n == 1) {\n            // Anisotropy 1: one probe at P.\n            fragColor = trilinear(texCoord, level);\n            return;\n        }\n",
                "",
            ),
            &[5, 6, 7, 8],
            "anisotropy 1 not handled",
        ),
    ];
    for (name, source, failing, key) in &mutants {
        let r = grade(&d, name, source, &[]);
        for mode in 1..=8u64 {
            let of_mode: Vec<_> = rows(&r).into_iter().filter(|row| row.1 == mode).collect();
            let bad: Vec<_> = of_mode.iter().filter(|row| row.2 == "neither").collect();
            if failing.contains(&mode) {
                assert!(
                    !bad.is_empty(),
                    "{name}: mode {mode} passes everywhere: {of_mode:?}"
                );
                for row in &bad {
                    assert!(
                        row.3.contains(key),
                        "{name}: {} mode {mode}: {}",
                        row.0,
                        row.3
                    );
                }
            } else {
                assert!(bad.is_empty(), "{name}: mode {mode} fails: {bad:?}");
            }
        }
    }
}

/// The interface's names, another GLSL version and the student's own vertex shader.
#[test]
fn names_versions_and_vertex_shaders() {
    if !have_gl() {
        return;
    }
    let d = Dir::new("lab-interface");
    let fast = ["--scene", "lab-wall", "--modes", "1,4,8"];
    let verdicts = |r: &Value| -> Vec<String> { rows(r).into_iter().map(|row| row.2).collect() };
    // Renamed: the sampler, the mode uniform and the varying.
    let renamed = GL
        .replace("texSlot", "image")
        .replace("texMode", "filterMode")
        .replace("texCoord", "uv");
    let mut extra = fast.to_vec();
    extra.extend([
        "--sampler",
        "image",
        "--mode-uniform",
        "filterMode",
        "--varying",
        "uv",
    ]);
    let r = grade(&d, "renamed", &renamed, &extra);
    assert_eq!(verdicts(&r), ["gl"; 3]);
    // GLSL 1.30: `in`/`out` but no layouts.
    let old = sub(LAB, "#version 330 core", "#version 130");
    let r = grade(&d, "v130", &old, &fast);
    assert_eq!(verdicts(&r), ["lab"; 3]);
    // The student's vertex shader (the attributes and uniform texel documents), which mirrors u.
    let vertex = "#version 330 core\nin vec3 position;\nin vec2 texCoordIn;\nuniform mat4 clipFromWorld;\nout vec2 texCoord;\nvoid main() {\n    texCoord = vec2(1.0 - texCoordIn.x, texCoordIn.y);\n    gl_Position = clipFromWorld * vec4(position, 1.0);\n}\n";
    let v = d.write("mirror.vert", vertex);
    let mut extra = fast.to_vec();
    let v = v.display().to_string();
    extra.extend(["--vertex", &v]);
    let r = grade(&d, "vertex", GL, &extra);
    // texel grades on the coordinates the shader received, so the mirrored ones agree too.
    assert_eq!(verdicts(&r), ["gl"; 3]);
}

#[test]
fn forbidden_builtins_are_reported_and_still_graded() {
    if !have_gl() {
        return;
    }
    let d = Dir::new("lab-rule");
    let source = sub(
        GL,
        "void main() {\n",
        "void main() {\n    if (texMode == 9) { fragColor = texture(texSlot, texCoord); return; }\n",
    );
    let line = source
        .lines()
        .position(|l| l.contains("texture(texSlot"))
        .unwrap()
        + 1;
    let r = grade(
        &d,
        "rule",
        &source,
        &["--scene", "lab-wall", "--modes", "1,4"],
    );
    assert_eq!(
        r["rule_violations"],
        serde_json::json!([{"line": line, "call": "texture"}])
    );
    assert_eq!(r["modes"].as_array().unwrap().len(), 2);
    assert!(std::fs::read_to_string(d.join("rule/report.md"))
        .unwrap()
        .contains("breaks the rule"));
}

fn lab_fails(d: &Dir, name: &str, source: &str, extra: &[&str], needles: &[&str]) -> PathBuf {
    let shader = d.write(&format!("{name}.frag"), source);
    let out = d.join(name);
    let mut args = vec![
        "lab".to_string(),
        shader.display().to_string(),
        "--out".into(),
        out.display().to_string(),
        "--size".into(),
        "64x48".into(),
    ];
    args.extend(extra.iter().map(|s| s.to_string()));
    fails(&args, 1, needles);
    assert!(!out.exists(), "{name}: a failed run leaves no report");
    out
}

#[test]
fn broken_shaders_end_cleanly() {
    if !have_gl() {
        return;
    }
    let d = Dir::new("lab-broken");
    lab_fails(
        &d,
        "compile",
        "#version 330 core\nout vec4 c;\nvoid main() { c = vec4(1.0) }\n",
        &[],
        &["does not compile"],
    );
    lab_fails(
        &d,
        "no-mode",
        "#version 330 core\nin vec2 texCoord;\nuniform sampler2D texSlot;\nout vec4 c;\nvoid main() { c = texelFetch(texSlot, ivec2(texCoord), 0); }\n",
        &[],
        &["no active mode uniform `texMode`"],
    );
    // Alpha is never negative, which the compiler cannot know. llvmpipe ends a loop after 65535
    // iterations, so each one does enough work (16 fetches 64 times) that a frame takes hours.
    let fetches: String = (0..16)
        .map(|k| format!("            s += texelFetch(texSlot, ivec2((i + {k}) & 63, {k}), 0);\n"))
        .collect();
    let endless = format!(
        "#version 330 core\nin vec2 texCoord;\nuniform sampler2D texSlot;\nuniform int texMode;\nout vec4 c;\n\
         void main() {{\n    vec4 s = vec4(0.0);\n    for (int i = 0; texMode > 0 && s.a >= 0.0; i++) {{\n        \
         for (int j = 0; j < 64 && s.a >= 0.0; j++) {{\n{fetches}            s = sin(s) + 1.5;\n        }}\n    }}\n    c = s;\n}}\n"
    );
    lab_fails(
        &d,
        "endless",
        &endless,
        &["--timeout", "5", "--scene", "lab-wall", "--modes", "1"],
        &["did not finish within 5 s"],
    );
}
