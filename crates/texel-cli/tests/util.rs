//! Helpers shared by the integration tests, in the style of ripgrep's `tests/util.rs`: [`texel`]
//! runs the binary, [`ok`] and [`fails`] check its exit, [`Dir`] is a scratch directory per test.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use texel::quality::Image8;

// ---------------------------------------------------------------------------------------------
// Helpers
// ---------------------------------------------------------------------------------------------

/// Every filter name, in the CLI's order (the library's one list).
pub(crate) const FILTERS: [&str; 13] = texel::Filter::NAMES;

/// The built-in scenes the demo covers.
pub(crate) const BUILTINS: [&str; 14] = [
    "ground",
    "ground-rotated",
    "zoneplate",
    "cube",
    "sphere",
    "globe",
    "globe-equirect",
    "triangle",
    "glossy",
    "bricks",
    "terrain",
    "knot",
    "mirror-spheres",
    "mirror-plane",
];

/// Run `texel` with `args`.
pub(crate) fn texel<S: AsRef<std::ffi::OsStr>>(args: &[S]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_texel"))
        .args(args)
        .output()
        .expect("cannot start the texel binary")
}

pub(crate) fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

pub(crate) fn stdout(out: &Output) -> String {
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// Run `texel` and require success without a panic; returns the output.
pub(crate) fn ok<S: AsRef<std::ffi::OsStr>>(args: &[S]) -> Output {
    let out = texel(args);
    let err = stderr(&out);
    assert!(
        out.status.success(),
        "texel {:?} failed ({:?}): {err}",
        args.iter()
            .map(|a| a.as_ref().to_string_lossy().into_owned())
            .collect::<Vec<_>>(),
        out.status.code()
    );
    assert!(!err.contains("panicked"), "{err}");
    out
}

/// Run `texel`, require exit code `code` (1: texel's own errors, 2: clap's usage errors), no panic,
/// and every one of `needles` in stderr. Texel's own errors must be exactly one line
/// `texel: error: ...`. Returns stderr.
pub(crate) fn fails<S: AsRef<std::ffi::OsStr>>(args: &[S], code: i32, needles: &[&str]) -> String {
    let out = texel(args);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(code), "stderr: {err}");
    assert!(!err.contains("panicked"), "{err}");
    if code == 1 {
        assert_eq!(err.lines().count(), 1, "one error line expected: {err}");
        assert!(err.starts_with("texel: error: "), "{err}");
    }
    for n in needles {
        assert!(err.contains(n), "stderr lacks {n:?}: {err}");
    }
    err
}

/// A scratch directory under the system temp dir, unique per test (and process); removed when the
/// test passes, kept for inspection when it fails.
pub(crate) struct Dir(pub(crate) PathBuf);

impl Dir {
    pub(crate) fn new(name: &str) -> Dir {
        let d = std::env::temp_dir().join(format!("texel-cli-test-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        Dir(d)
    }

    pub(crate) fn path(&self) -> &Path {
        &self.0
    }

    pub(crate) fn join(&self, p: &str) -> PathBuf {
        self.0.join(p)
    }

    /// `join` as a `String`, for argument lists.
    pub(crate) fn arg(&self, p: &str) -> String {
        self.join(p).to_string_lossy().into_owned()
    }

    pub(crate) fn write(&self, name: &str, bytes: impl AsRef<[u8]>) -> PathBuf {
        let p = self.join(name);
        std::fs::write(&p, bytes).unwrap();
        p
    }
}

impl Drop for Dir {
    fn drop(&mut self) {
        if !std::thread::panicking() {
            let _ = std::fs::remove_dir_all(&self.0);
        }
    }
}

pub(crate) fn load(path: impl AsRef<Path>) -> Image8 {
    let path = path.as_ref();
    Image8::load(path).unwrap_or_else(|e| panic!("cannot load {}: {e}", path.display()))
}

pub(crate) fn file_bytes(path: impl AsRef<Path>) -> Vec<u8> {
    let path = path.as_ref();
    std::fs::read(path).unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()))
}

/// Every file under `dir` (recursively) whose name looks like a temporary of an atomic write:
/// `.NAME.tmpPID` (texel-cli) or `.NAME.PID.N.tmp` (texel-quality).
pub(crate) fn temp_files(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            out.extend(temp_files(&p));
        }
        let name = p.file_name().unwrap().to_string_lossy().into_owned();
        if name.starts_with('.') && name.contains(".tmp") {
            out.push(p);
        }
    }
    out
}

/// The shipped ground scene (identical to `scenes/ground.toml`).
pub(crate) fn ground_toml() -> String {
    concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../texel-scene/tests/data/ground.toml"
    )
    .to_string()
}

/// Output, camera and a small checker texture `t` of a scene looking at the z = 0 plane from z = 3;
/// append `[[meshes]]`. Background blue.
pub(crate) const HEAD: &str = r#"[output]
width = 64
height = 48
background = [0, 0, 255, 255]

[camera]
eye = [0.0, 0.0, 3.0]
target = [0.0, 0.0, 0.0]
fovy_deg = 45.0
near = 0.1
far = 10.0

[textures.t]
procedural = "checker"
size = 64
checks = 4
"#;

/// A valid inline triangle using texture `t`.
pub(crate) const TRIANGLE: &str = r#"
[[meshes]]
texture = "t"
positions = [[-1.0, -1.0, 0.0], [1.0, -1.0, 0.0], [0.0, 1.0, 0.0]]
uvs = [[0.0, 1.0], [1.0, 1.0], [0.5, 0.0]]
triangles = [[0, 1, 2]]
"#;

/// The unit quad `[-1, 1]^2` at z = 0 with uv (0, 0) at its top-left, as inline TOML.
pub(crate) const QUAD: &str = r#"
[[meshes]]
texture = "t"
positions = [[-1.0, -1.0, 0.0], [1.0, -1.0, 0.0], [1.0, 1.0, 0.0], [-1.0, 1.0, 0.0]]
uvs = [[0.0, 1.0], [1.0, 1.0], [1.0, 0.0], [0.0, 0.0]]
triangles = [[0, 1, 2], [0, 2, 3]]
"#;

// ---------------------------------------------------------------------------------------------
// Mesh fixtures: the unit quad as OBJ, glTF buffer and glTF JSON
// ---------------------------------------------------------------------------------------------

/// The quad as OBJ: the same vertices in the same order; OBJ's v axis points up, so vt = 1 - v.
pub(crate) const QUAD_OBJ: &str = "# unit quad\n\
v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\n\
vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n\
f 1/1 2/2 3/3\nf 1/1 3/3 4/4\n";

/// The quad's glTF buffer: 4 positions (48 bytes), 4 uvs (32), 6 u16 indices (12).
pub(crate) fn quad_buffer() -> Vec<u8> {
    let mut b = Vec::new();
    for v in [
        -1.0f32, -1.0, 0.0, 1.0, -1.0, 0.0, 1.0, 1.0, 0.0, -1.0, 1.0, 0.0,
    ] {
        b.extend(v.to_le_bytes());
    }
    for v in [0.0f32, 1.0, 1.0, 1.0, 1.0, 0.0, 0.0, 0.0] {
        b.extend(v.to_le_bytes());
    }
    for i in [0u16, 1, 2, 0, 2, 3] {
        b.extend(i.to_le_bytes());
    }
    b
}

/// A glTF document drawing the quad from the buffer at `uri` (a file name or a data URI).
pub(crate) fn quad_gltf(uri: &str) -> String {
    format!(
        r#"{{
  "asset": {{"version": "2.0"}},
  "scene": 0,
  "scenes": [{{"nodes": [0]}}],
  "nodes": [{{"mesh": 0}}],
  "meshes": [{{"primitives": [{{"attributes": {{"POSITION": 0, "TEXCOORD_0": 1}}, "indices": 2}}]}}],
  "buffers": [{{"uri": "{uri}", "byteLength": 92}}],
  "bufferViews": [
    {{"buffer": 0, "byteOffset": 0, "byteLength": 48}},
    {{"buffer": 0, "byteOffset": 48, "byteLength": 32}},
    {{"buffer": 0, "byteOffset": 80, "byteLength": 12}}
  ],
  "accessors": [
    {{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [-1, -1, 0], "max": [1, 1, 0]}},
    {{"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC2"}},
    {{"bufferView": 2, "componentType": 5123, "count": 6, "type": "SCALAR"}}
  ]
}}"#
    )
}

/// Standard base64 with padding (RFC 4648), for a glTF data URI.
pub(crate) fn base64(bytes: &[u8]) -> String {
    const A: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut s = String::new();
    for c in bytes.chunks(3) {
        let n = (u32::from(c[0]) << 16)
            | (u32::from(*c.get(1).unwrap_or(&0)) << 8)
            | u32::from(*c.get(2).unwrap_or(&0));
        for k in 0..4 {
            if k <= c.len() {
                s.push(A[(n >> (18 - 6 * k) & 63) as usize] as char);
            } else {
                s.push('=');
            }
        }
    }
    s
}

/// An 8x8 opaque grey PNG at `d/name`: a small valid source image.
pub(crate) fn grey_png(d: &Dir, name: &str) -> PathBuf {
    let path = d.join(name);
    Image8::filled(8, 8, [9, 9, 9, 255])
        .unwrap()
        .write_png(&path)
        .unwrap();
    path
}

/// The smallest comparison that scores an `--extra` image (`extra` is `LABEL=PATH`): nearest on
/// the default scene at 32x18 with one reference sample, written to `out`.
pub(crate) fn compare_extra(extra: &str, out: &str) -> Vec<String> {
    [
        "compare",
        "--size",
        "32x18",
        "--spp",
        "1",
        "--filters",
        "nearest",
        "--extra",
        extra,
        "--out",
        out,
    ]
    .map(String::from)
    .to_vec()
}
