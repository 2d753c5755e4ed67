//! Nothing lost: outputs behind open descriptors are written through, output directories keep what
//! texel did not write, an image's extension names its format, the default memory budget follows
//! the process's own limits, and work that scene numbers multiply is bounded before it starts.

use std::fs::{File, OpenOptions};
use std::process::{Command, Stdio};

use crate::util::*;

const PNG_MAGIC: &[u8] = b"\x89PNG\r\n\x1a\n";
const EXR_MAGIC: &[u8] = &[0x76, 0x2f, 0x31, 0x01];

fn texel_cmd() -> Command {
    Command::new(env!("CARGO_BIN_EXE_texel"))
}

/// Where `needle` starts in `hay`.
fn find(hay: &[u8], needle: &[u8]) -> Option<usize> {
    hay.windows(needle.len()).position(|w| w == needle)
}

#[test]
fn stdout_redirected_to_a_file_is_appended_to() {
    let d = Dir::new("fd-append");
    let log = d.write("log.txt", "earlier lines\n");
    for path in ["/dev/stdout", "/proc/self/fd/1", "/dev/fd/1"] {
        std::fs::write(&log, "earlier lines\n").unwrap();
        // The shell's `>> log.txt`: standard output opened for appending.
        let out = texel_cmd()
            .args(["render", "--size", "16x9", "-o", path])
            .stdout(OpenOptions::new().append(true).open(&log).unwrap())
            .stderr(Stdio::piped())
            .output()
            .unwrap();
        assert!(out.status.success(), "{path}: {}", stderr(&out));
        let bytes = std::fs::read(&log).unwrap();
        assert!(
            bytes.starts_with(b"earlier lines\n"),
            "{path}: the log lost its lines"
        );
        let png = &bytes[b"earlier lines\n".len()..];
        assert!(png.starts_with(PNG_MAGIC), "{path}");
        let img = image::load_from_memory(png).unwrap();
        assert_eq!((img.width(), img.height()), (16, 9));
        // Still a plain file, no temporary beside it.
        assert!(std::fs::symlink_metadata(&log).unwrap().is_file());
        assert!(temp_files(d.path()).is_empty());
    }
    // Standard error the same way, through its own link.
    let err_log = d.write("err.txt", "kept\n");
    let out = texel_cmd()
        .args(["render", "--size", "16x9", "-o", "/dev/stderr"])
        .stderr(OpenOptions::new().append(true).open(&err_log).unwrap())
        .output()
        .unwrap();
    assert!(out.status.success());
    let bytes = std::fs::read(&err_log).unwrap();
    assert!(bytes.starts_with(b"kept\n"));
    assert!(find(&bytes, PNG_MAGIC).is_some());
}

#[test]
fn a_deleted_file_behind_a_descriptor_is_not_recreated() {
    let d = Dir::new("fd-deleted");
    let f = d.write("gone.png", "");
    let handle = File::options().write(true).open(&f).unwrap();
    std::fs::remove_file(&f).unwrap();
    let out = texel_cmd()
        .args(["render", "--size", "16x9", "-o", "/dev/stdout"])
        .stdout(handle)
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", stderr(&out));
    let names: Vec<_> = std::fs::read_dir(d.path()).unwrap().collect();
    assert!(names.is_empty(), "{names:?}");
}

#[test]
fn mips_never_deletes_its_input() {
    let d = Dir::new("mips-input");
    let out = d.arg("out");
    let src = grey_png(&d, "src.png");
    ok(&["mips", &src.to_string_lossy(), "--out", &out]);
    // The user keeps a texture in texel's output directory and asks for its levels there.
    std::fs::copy(&src, d.join("out/brick.png")).unwrap();
    let brick = d.arg("out/brick.png");
    fails(
        &["mips", &brick, "--out", &out],
        1,
        &["holds the input", "brick.png"],
    );
    assert_eq!(file_bytes(&brick), file_bytes(&src));
    // Texel's own earlier level read as the input: refused the same way, kept.
    let level = d.join("out/level-00-8x8.png");
    let before = file_bytes(&level);
    fails(
        &["mips", &level.to_string_lossy(), "--out", &out],
        1,
        &["holds the input"],
    );
    assert_eq!(file_bytes(&level), before);
    // Elsewhere, the directory is republished and the user's file carried over.
    ok(&["mips", &src.to_string_lossy(), "--out", &out]);
    assert_eq!(file_bytes(&brick), file_bytes(&src));
}

#[test]
fn an_image_is_written_in_the_format_its_name_says() {
    let d = Dir::new("formats");
    let ao = d.arg("ao.exr");
    ok(&[
        "bake-ao",
        "builtin:knot",
        "--size",
        "16",
        "--rays",
        "4",
        "-o",
        &ao,
    ]);
    let bytes = file_bytes(&ao);
    assert!(bytes.starts_with(EXR_MAGIC), "not OpenEXR");
    let img = image::open(&ao).unwrap().to_rgba32f();
    assert_eq!((img.width(), img.height()), (16, 16));
    // The float map and the 8-bit one agree to the 8-bit step.
    let png = d.arg("ao.png");
    ok(&[
        "bake-ao",
        "builtin:knot",
        "--size",
        "16",
        "--rays",
        "4",
        "-o",
        &png,
    ]);
    let grey = load(&png);
    for (f, b) in img.pixels().zip(grey.pixels()) {
        assert!((f.0[0] * 255.0 - f32::from(b[0])).abs() <= 0.5 + 1e-3);
    }
    // A format texel does not write is refused before any work, and nothing is written.
    for (cmd, name) in [
        (vec!["render", "--size", "16x9"], "x.jpg"),
        (vec!["reference", "--size", "16x9", "--spp", "1"], "x.tiff"),
        (vec!["bake-ao", "builtin:knot", "--size", "16"], "x.hdr"),
    ] {
        let path = d.arg(name);
        let mut args = cmd.clone();
        args.extend(["-o", &path]);
        fails(&args, 2, &["texel does not write", ".png", ".exr"]);
        assert!(!d.join(name).exists());
    }
    fails(
        &["view", "--frames", "1", "--screenshot", &d.arg("s.exr")],
        2,
        &["PNG only"],
    );
}

/// Run `texel args` under `ulimit -v kib` (through `sh`), returning its exit code and stderr.
fn under_ulimit(kib: u64, args: &[&str]) -> (Option<i32>, String) {
    let quoted: Vec<String> = args.iter().map(|a| format!("'{a}'")).collect();
    let out = Command::new("sh")
        .arg("-c")
        .arg(format!(
            "ulimit -v {kib} && exec '{}' {}",
            env!("CARGO_BIN_EXE_texel"),
            quoted.join(" ")
        ))
        .output()
        .unwrap();
    (out.status.code(), stderr(&out))
}

/// A scene of four 8192 x 8192 procedural textures: 358 MiB each with their pyramids.
fn four_big_textures(d: &Dir) -> String {
    let mut toml = String::from(HEAD);
    for k in 0..4 {
        toml.push_str(&format!(
            "[textures.t{k}]\nprocedural = \"checker\"\nsize = 8192\n\n"
        ));
    }
    for k in 0..4 {
        toml.push_str(&TRIANGLE.replace("texture = \"t\"", &format!("texture = \"t{k}\"")));
    }
    d.write("big.toml", &toml).to_string_lossy().into_owned()
}

#[test]
fn the_default_budget_follows_ulimit() {
    let d = Dir::new("ulimit");
    let scene = four_big_textures(&d);
    let (code, err) = under_ulimit(
        1_000_000,
        &["render", &scene, "--size", "16x9", "-o", &d.arg("x.png")],
    );
    assert_eq!(code, Some(1), "{err}");
    assert!(err.contains("ulimit -v"), "{err}");
    assert!(!d.join("x.png").exists());
}

#[test]
fn an_explicit_budget_is_held_to_the_process_limits() {
    // Asking for more than the process may map (64 GiB under about 1 GiB of address space) is
    // held to what it may: the same refusal as the default's, naming the request and the cap,
    // rather than an allocation that aborts.
    let d = Dir::new("ulimit-explicit");
    let scene = four_big_textures(&d);
    let out = d.arg("x.png");
    let args = [
        "render",
        &scene,
        "--size",
        "16x9",
        "--max-memory",
        "64G",
        "-o",
        &out,
    ];
    let (code, err) = under_ulimit(1_000_000, &args);
    assert_eq!(code, Some(1), "{err}");
    assert!(
        err.contains("--max-memory 65536.0 MiB, capped at") && err.contains("ulimit -v"),
        "{err}"
    );
    assert!(!d.join("x.png").exists());
}

#[test]
fn gltf_strides_are_checked_before_the_reader_runs() {
    let d = Dir::new("gltf-stride");
    d.write("quad.bin", quad_buffer());
    // POSITION (VEC3 of f32, 12 bytes) read with a stride of 4 bytes.
    let doc = quad_gltf("quad.bin").replace(
        r#"{"buffer": 0, "byteOffset": 0, "byteLength": 48}"#,
        r#"{"buffer": 0, "byteOffset": 0, "byteLength": 48, "byteStride": 4}"#,
    );
    assert!(doc.contains("byteStride"));
    d.write("quad.gltf", doc);
    fails(
        &[
            "bake-ao",
            &d.arg("quad.gltf"),
            "--size",
            "16",
            "-o",
            &d.arg("ao.png"),
        ],
        1,
        &["byteStride 4", "at least 12"],
    );
    let scene = format!("{HEAD}[[meshes]]\ntexture = \"t\"\ngltf = \"quad.gltf\"\n");
    d.write("s.toml", scene);
    fails(
        &[
            "render",
            &d.arg("s.toml"),
            "--size",
            "16x9",
            "-o",
            &d.arg("x.png"),
        ],
        1,
        &["byteStride"],
    );
    // Elements reaching past their view, and a view past its buffer.
    for (from, to, needle) in [
        (
            r#""count": 4, "type": "VEC3""#,
            r#""count": 5, "type": "VEC3""#,
            "reach past",
        ),
        (
            r#""byteOffset": 80, "byteLength": 12"#,
            r#""byteOffset": 84, "byteLength": 12"#,
            "past the end of buffer 0",
        ),
    ] {
        let doc = quad_gltf("quad.bin").replace(from, to);
        assert!(doc.contains(to));
        d.write("bad.gltf", doc);
        fails(
            &[
                "bake-ao",
                &d.arg("bad.gltf"),
                "--size",
                "16",
                "-o",
                &d.arg("ao.png"),
            ],
            1,
            &[needle],
        );
    }
}
