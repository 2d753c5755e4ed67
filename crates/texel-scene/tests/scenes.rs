//! Scene files, mesh files and their errors, end to end.

use std::fs;
use std::path::{Path, PathBuf};

use glam::{Vec2, Vec3};
use texel_scene::{builtin, MeshFilters, Procedural, Scene, SceneError, TextureSource};
use texel_texture::{AddressMode, ColorSpace, FilterMode, Limits, MipmapFilterMode};

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

/// A fresh scratch directory under the system temp dir.
fn scratch(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("texel-scene-{tag}-{}", std::process::id()));
    let _ = fs::remove_dir_all(&d);
    fs::create_dir_all(&d).unwrap();
    d
}

const HEAD: &str = r#"
[output]
width = 64
height = 48

[camera]
eye = [0.0, 0.0, 3.0]
target = [0.0, 0.0, 0.0]
fovy_deg = 45.0
near = 0.1
far = 10.0

[textures.t]
procedural = "uv"
size = 8
"#;

const TRI: &str = r#"
[[meshes]]
texture = "t"
positions = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]
uvs = [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]
triangles = [[0, 1, 2]]
"#;

fn parse(text: &str) -> Result<Scene, SceneError> {
    Scene::from_toml_str(text, Path::new("/virtual/scene.toml"))
}

#[test]
fn shipped_ground_equals_builtin() {
    let file = Scene::from_path(data("ground.toml")).unwrap();
    assert_eq!(file, builtin("ground").unwrap());
    assert_eq!(
        fs::read_to_string(data("ground.toml")).unwrap(),
        texel_scene::GROUND_TOML
    );
    let m = &file.meshes[0];
    assert_eq!(m.positions.len(), 4);
    assert_eq!(m.uvs[2], Vec2::new(250.0, 500.0));
    assert_eq!(m.triangles, vec![[0, 1, 2], [0, 2, 3]]);
    assert_eq!(file.camera.eye, Vec3::new(0.0, 1.0, 0.0));
    assert_eq!(file.output.background, [0, 0, 0, 255]);
    // The checker's texel (0, 0) is black, (128, 0) white.
    let tex = file.load_textures(None, &Limits::default()).unwrap();
    let t = &tex["checker"];
    assert_eq!(t.texel(0, 0, 0), Some([0.0, 0.0, 0.0, 1.0]));
    assert_eq!(t.texel(0, 128, 0), Some([1.0; 4]));
    assert_eq!(t.width(), 1024);
}

#[test]
fn minimal_scene_and_defaults() {
    let s = parse(&format!("{HEAD}{TRI}")).unwrap();
    assert_eq!(s.camera.up, Vec3::Y);
    assert_eq!(s.output.background, [0, 0, 0, 255]);
    assert_eq!(s.meshes[0].address_mode_u, AddressMode::Repeat);
    let spec = &s.textures["t"];
    assert_eq!(spec.color, ColorSpace::Srgb);
    assert_eq!(
        spec.color_space(Some(ColorSpace::Linear)),
        ColorSpace::Linear
    );
    assert_eq!(
        spec.source,
        TextureSource::Procedural(Procedural::Uv {
            width: 8,
            height: 8
        })
    );
}

#[test]
fn every_address_mode_name() {
    for (name, mode) in [
        ("repeat", AddressMode::Repeat),
        ("mirror-repeat", AddressMode::MirrorRepeat),
        ("clamp-to-edge", AddressMode::ClampToEdge),
        ("clamp-to-border", AddressMode::ClampToBorder),
        ("mirror-clamp-to-edge", AddressMode::MirrorClampToEdge),
    ] {
        let t = format!(
            "{HEAD}{}",
            TRI.replace(
                "texture = \"t\"",
                &format!("texture = \"t\"\naddress_mode = \"{name}\"")
            )
        );
        let m = &parse(&t).unwrap().meshes[0];
        assert_eq!((m.address_mode_u, m.address_mode_v), (mode, mode), "{name}");
    }
    let t = format!(
        "{HEAD}{}",
        TRI.replace(
            "texture = \"t\"",
            "texture = \"t\"\naddress_mode = \"repeat\"\naddress_mode_v = \"clamp-to-edge\""
        )
    );
    let m = &parse(&t).unwrap().meshes[0];
    assert_eq!(
        (m.address_mode_u, m.address_mode_v),
        (AddressMode::Repeat, AddressMode::ClampToEdge)
    );
}

/// Line and column of a TOML error, or a panic.
fn toml_pos(e: SceneError) -> (usize, usize, String) {
    match e {
        SceneError::Toml {
            line,
            column,
            message,
            ..
        } => (line, column, message),
        other => panic!("expected a TOML error, got {other}"),
    }
}

#[test]
fn malformed_toml_has_line_and_column() {
    let text = "[output]\nwidth = 64\nheight = = 3\n";
    let (line, column, _) = toml_pos(parse(text).unwrap_err());
    assert_eq!(line, 3);
    assert_eq!(column, 10); // the second `=`
    let e = parse(text).unwrap_err().to_string();
    assert!(e.starts_with("/virtual/scene.toml:3:"), "{e}");
}

#[test]
fn unknown_key_and_bad_values_are_toml_errors() {
    let text = format!("{HEAD}{TRI}").replace("fovy_deg = 45.0", "fovy_deg = 45.0\nzoom = 2.0");
    let (line, _, msg) = toml_pos(parse(&text).unwrap_err());
    assert_eq!(line, 10); // HEAD starts with an empty line
    assert!(msg.contains("zoom"), "{msg}");
    let text = format!("{HEAD}{TRI}").replace(
        "texture = \"t\"",
        "texture = \"t\"\naddress_mode = \"wrap\"",
    );
    let (_, _, msg) = toml_pos(parse(&text).unwrap_err());
    assert!(
        msg.contains("wrap") && msg.contains("mirror-clamp-to-edge"),
        "{msg}"
    );
    let text = format!("{HEAD}{TRI}").replace("width = 64", "width = -3");
    assert!(matches!(
        parse(&text),
        Err(SceneError::Toml { line: 3, .. })
    ));
    let text =
        format!("{HEAD}{TRI}").replace("[output]\n", "[output]\nbackground = [0, 0, 300, 255]\n");
    assert!(matches!(
        parse(&text),
        Err(SceneError::Toml { line: 3, .. })
    ));
    let text = format!("{HEAD}{TRI}").replace("procedural = \"uv\"", "procedural = \"perlin\"");
    assert!(matches!(parse(&text), Err(SceneError::Toml { .. })));
}

#[test]
fn output_size_limits() {
    for (w, h) in [(0, 48), (64, 0), (16385, 48), (64, 100_000)] {
        let text = format!("{HEAD}{TRI}")
            .replace("width = 64", &format!("width = {w}"))
            .replace("height = 48", &format!("height = {h}"));
        match parse(&text) {
            Err(SceneError::OutputSize { width, height, max }) => {
                assert_eq!((width, height, max), (w, h, 16384));
            }
            other => panic!("{w}x{h}: {other:?}"),
        }
    }
    let text = format!("{HEAD}{TRI}").replace("width = 64", "width = 16384");
    assert!(parse(&text).is_ok());
}

#[test]
fn mesh_errors() {
    let t = format!(
        "{HEAD}{}",
        TRI.replace("[0, 1, 2]]", "[0, 1, 2], [2, 1, 7]]")
    );
    match parse(&t) {
        Err(SceneError::IndexOutOfRange {
            mesh,
            triangle,
            index,
            vertices,
        }) => {
            assert_eq!((mesh, triangle, index, vertices), (0, 1, 7, 3));
        }
        other => panic!("{other:?}"),
    }
    let t = format!(
        "{HEAD}{}",
        TRI.replace("[0.0, 1.0]]", "[0.0, 1.0], [1.0, 1.0]]")
    );
    assert!(matches!(
        parse(&t),
        Err(SceneError::MeshLength {
            attribute: "uvs",
            expected: 3,
            got: 4,
            ..
        })
    ));
    let t = format!(
        "{HEAD}{}",
        TRI.replace("triangles", "normals = [[0.0, 0.0, 1.0]]\ntriangles")
    );
    assert!(matches!(
        parse(&t),
        Err(SceneError::MeshLength {
            attribute: "normals",
            expected: 3,
            got: 1,
            ..
        })
    ));
    for bad in ["nan", "inf", "-inf"] {
        let t = format!(
            "{HEAD}{}",
            TRI.replace("[1.0, 0.0, 0.0]", &format!("[1.0, {bad}, 0.0]"))
        );
        match parse(&t) {
            Err(SceneError::NonFinite { what, .. }) => assert_eq!(what, "meshes[0].positions[1]"),
            other => panic!("{bad}: {other:?}"),
        }
    }
    let t = format!("{HEAD}{}", TRI.replace("[1.0, 0.0]", "[nan, 0.0]"));
    assert!(
        matches!(parse(&t), Err(SceneError::NonFinite { what, .. }) if what == "meshes[0].uvs[1]")
    );
    let t = format!(
        "{HEAD}{}",
        TRI.replace("texture = \"t\"", "texture = \"missing\"")
    );
    assert!(matches!(
        parse(&t),
        Err(SceneError::UnknownTexture { mesh: 0, .. })
    ));
    let t = format!(
        "{HEAD}{}",
        TRI.replace("positions", "obj = \"x.obj\"\npositions")
    );
    assert!(matches!(
        parse(&t),
        Err(SceneError::MeshSource { mesh: 0, .. })
    ));
    let t = format!("{HEAD}{}", TRI.replace("triangles = [[0, 1, 2]]", ""));
    assert!(matches!(
        parse(&t),
        Err(SceneError::MeshSource { mesh: 0, .. })
    ));
}

#[test]
fn camera_errors() {
    let base = format!("{HEAD}{TRI}");
    let near = |e: &SceneError| matches!(e, SceneError::CameraNearFar { .. });
    let fov = |e: &SceneError| matches!(e, SceneError::CameraFov(_));
    let degenerate = |e: &SceneError| matches!(e, SceneError::CameraDegenerate { .. });
    let non_finite =
        |e: &SceneError| matches!(e, SceneError::NonFinite { what, .. } if what == "camera.eye");
    type Check<'a> = &'a dyn Fn(&SceneError) -> bool;
    let cases: [(&str, &str, Check); 7] = [
        ("near = 0.1", "near = 0.0", &near),
        ("far = 10.0", "far = 0.05", &near),
        ("fovy_deg = 45.0", "fovy_deg = 180.0", &fov),
        ("fovy_deg = 45.0", "fovy_deg = 0.0", &fov),
        (
            "target = [0.0, 0.0, 0.0]",
            "target = [0.0, 0.0, 3.0]",
            &degenerate,
        ),
        // Looking straight down with up = +y.
        (
            "eye = [0.0, 0.0, 3.0]",
            "eye = [0.0, 3.0, 0.0]",
            &degenerate,
        ),
        (
            "eye = [0.0, 0.0, 3.0]",
            "eye = [0.0, nan, 3.0]",
            &non_finite,
        ),
    ];
    for (from, to, want) in cases {
        let e = parse(&base.replace(from, to)).unwrap_err();
        assert!(want(&e), "{to}: {e}");
    }
}

#[test]
fn texture_entry_errors_and_files() {
    let d = scratch("tex");
    let bad_param = HEAD.replace("size = 8", "size = 8\nchecks = 4");
    assert!(matches!(
        parse(&format!("{bad_param}{TRI}")),
        Err(SceneError::InvalidTexture { .. })
    ));
    let both = HEAD.replace("size = 8", "size = 8\npath = \"a.png\"");
    assert!(matches!(
        parse(&format!("{both}{TRI}")),
        Err(SceneError::InvalidTexture { .. })
    ));
    let zero = HEAD.replace(
        "procedural = \"uv\"",
        "procedural = \"checker\"\nchecks = 0",
    );
    assert!(matches!(
        parse(&format!("{zero}{TRI}")),
        Err(SceneError::InvalidTexture { .. })
    ));
    // A file texture is resolved against the scene's directory; missing -> error with the path.
    let file = HEAD.replace(
        "procedural = \"uv\"\nsize = 8",
        "path = \"tex/missing.png\"\ncolor = \"linear\"",
    );
    let scene_path = d.join("s.toml");
    fs::write(&scene_path, format!("{file}{TRI}")).unwrap();
    let s = Scene::from_path(&scene_path).unwrap();
    assert_eq!(
        s.textures["t"].source,
        TextureSource::File(d.join("tex/missing.png"))
    );
    assert_eq!(s.textures["t"].color, ColorSpace::Linear);
    let e = s.load_textures(None, &Limits::default()).unwrap_err();
    assert!(e.to_string().contains("tex/missing.png"), "{e}");
    // A real PNG loads; a texture over the limit is a typed error.
    fs::create_dir_all(d.join("tex")).unwrap();
    let png = image::RgbaImage::from_fn(4, 2, |x, _| image::Rgba([x as u8 * 60, 0, 0, 255]));
    png.save(d.join("tex/missing.png")).unwrap();
    let tex = s.load_textures(None, &Limits::default()).unwrap();
    assert_eq!(
        tex["t"].texel(0, 3, 1),
        Some([180.0 / 255.0, 0.0, 0.0, 1.0])
    );
    let small = Limits {
        max_dimension: 2,
        ..Limits::default()
    };
    assert!(matches!(
        s.load_textures(None, &small),
        Err(SceneError::Texture { .. })
    ));
    // A missing scene file names its path.
    let e = Scene::load(d.join("nope.toml").to_str().unwrap()).unwrap_err();
    assert!(matches!(e, SceneError::Io { .. }) && e.to_string().contains("nope.toml"));
    fs::remove_dir_all(&d).unwrap();
}

const OBJ: &str = "# a unit quad in two groups
mtllib missing.mtl
v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
vt 0 0
vt 1 0
vt 1 1
vt 0 1
vn 0 0 1
o quad
f 1/1/1 2/2/1 3/3/1 4/4/1
";

#[test]
fn obj_mesh() {
    let d = scratch("obj");
    fs::write(d.join("quad.obj"), OBJ).unwrap();
    let text = format!(
        "{HEAD}[[meshes]]\ntexture = \"t\"\naddress_mode = \"mirror-repeat\"\nobj = \"quad.obj\"\n"
    );
    fs::write(d.join("s.toml"), &text).unwrap();
    let s = Scene::from_path(d.join("s.toml")).unwrap();
    let m = &s.meshes[0];
    assert_eq!(m.triangles.len(), 2); // the quad is triangulated
    assert_eq!(m.positions.len(), 4);
    assert_eq!(m.address_mode_u, AddressMode::MirrorRepeat);
    // v is flipped: vertex (1, 1, 0) had vt (1, 1) -> uv (1, 0).
    let i = m
        .positions
        .iter()
        .position(|p| *p == Vec3::new(1.0, 1.0, 0.0))
        .unwrap();
    assert_eq!(m.uvs[i], Vec2::new(1.0, 0.0));
    assert_eq!(m.normals.as_ref().unwrap()[i], Vec3::Z);
    // Every triangle covers the quad with positive area (counter-clockwise kept).
    for t in &m.triangles {
        let [a, b, c] = t.map(|k| m.positions[k as usize]);
        assert!((b - a).cross(c - a).z > 0.0);
    }
    // No uvs -> error naming the file; corrupt -> error naming the file; missing -> Io.
    fs::write(d.join("nouv.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    let e = texel_scene::load_obj(&d.join("nouv.obj"), "t").unwrap_err();
    assert!(
        matches!(e, SceneError::MeshFile { .. }) && e.to_string().contains("nouv.obj"),
        "{e}"
    );
    fs::write(d.join("bad.obj"), "v 0 0 0\nvt 0 0\nf 1/1 9/1 3/1\n").unwrap();
    let e = texel_scene::load_obj(&d.join("bad.obj"), "t").unwrap_err();
    assert!(
        matches!(e, SceneError::Obj { .. })
            && e.to_string().contains("bad.obj")
            && e.to_string().contains("line 3 (\"f 1/1 9/1 3/1\")"),
        "{e}"
    );
    let e = texel_scene::load_obj(&d.join("none.obj"), "t").unwrap_err();
    assert!(
        matches!(e, SceneError::Io { .. }) && e.to_string().contains("none.obj"),
        "{e}"
    );
    fs::remove_dir_all(&d).unwrap();
}

/// A little-endian buffer: 3 positions (36 bytes), 3 uvs (24), 3 u16 indices (6), 2 bytes padding.
fn triangle_buffer() -> Vec<u8> {
    let mut b = Vec::new();
    for v in [0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0] {
        b.extend(v.to_le_bytes());
    }
    for v in [0.0f32, 0.0, 1.0, 0.0, 0.0, 1.0] {
        b.extend(v.to_le_bytes());
    }
    for i in [0u16, 1, 2] {
        b.extend(i.to_le_bytes());
    }
    b.extend([0, 0]);
    b
}

/// glTF JSON for the triangle, translated by (10, 0, 0) under a parent scaled by 2, with a sampler.
fn triangle_json(buffer_uri: Option<&str>) -> String {
    let uri = buffer_uri.map_or(String::new(), |u| format!("\"uri\": \"{u}\", "));
    format!(
        r#"{{
  "asset": {{"version": "2.0"}},
  "scene": 0,
  "scenes": [{{"nodes": [0]}}],
  "nodes": [{{"scale": [2.0, 2.0, 2.0], "children": [1]}}, {{"translation": [10.0, 0.0, 0.0], "mesh": 0}}],
  "meshes": [{{"primitives": [{{"attributes": {{"POSITION": 0, "TEXCOORD_0": 1}}, "indices": 2, "material": 0}}]}}],
  "materials": [{{"pbrMetallicRoughness": {{"baseColorTexture": {{"index": 0}}}}}}],
  "textures": [{{"sampler": 0, "source": 0}}],
  "images": [{{"uri": "not-loaded.png"}}],
  "samplers": [{{"magFilter": 9728, "minFilter": 9987, "wrapS": 33648, "wrapT": 33071}}],
  "buffers": [{{{uri}"byteLength": 66}}],
  "bufferViews": [
    {{"buffer": 0, "byteOffset": 0, "byteLength": 36}},
    {{"buffer": 0, "byteOffset": 36, "byteLength": 24}},
    {{"buffer": 0, "byteOffset": 60, "byteLength": 6}}
  ],
  "accessors": [
    {{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]}},
    {{"bufferView": 1, "componentType": 5126, "count": 3, "type": "VEC2"}},
    {{"bufferView": 2, "componentType": 5123, "count": 3, "type": "SCALAR"}}
  ]
}}"#
    )
}

fn check_gltf_mesh(m: &texel_scene::Mesh) {
    // world = scale 2 * translate (10, 0, 0): (0,0,0) -> (20,0,0), (1,0,0) -> (22,0,0).
    assert_eq!(
        m.positions,
        vec![
            Vec3::new(20.0, 0.0, 0.0),
            Vec3::new(22.0, 0.0, 0.0),
            Vec3::new(20.0, 2.0, 0.0)
        ]
    );
    assert_eq!(m.uvs, vec![Vec2::ZERO, Vec2::X, Vec2::Y]);
    assert_eq!(m.triangles, vec![[0, 1, 2]]);
    assert_eq!(m.address_mode_u, AddressMode::MirrorRepeat);
    assert_eq!(m.address_mode_v, AddressMode::ClampToEdge);
    assert_eq!(
        m.filters,
        Some(MeshFilters {
            mag_filter: Some(FilterMode::Nearest),
            min_filter: Some(FilterMode::Linear),
            mipmap_filter: Some(MipmapFilterMode::Linear),
        })
    );
}

#[test]
fn gltf_with_external_buffer_and_glb() {
    let d = scratch("gltf");
    let buf = triangle_buffer();
    assert_eq!(buf.len(), 68);
    fs::write(d.join("tri.bin"), &buf).unwrap();
    fs::write(d.join("tri.gltf"), triangle_json(Some("tri.bin"))).unwrap();
    let text = format!("{HEAD}[[meshes]]\ntexture = \"t\"\ngltf = \"tri.gltf\"\n");
    fs::write(d.join("s.toml"), &text).unwrap();
    let s = Scene::from_path(d.join("s.toml")).unwrap();
    check_gltf_mesh(&s.meshes[0]);

    // The same as GLB: header, JSON chunk (space-padded), BIN chunk.
    let mut json = triangle_json(None).into_bytes();
    while !json.len().is_multiple_of(4) {
        json.push(b' ');
    }
    let total = 12 + 8 + json.len() + 8 + buf.len();
    let mut glb = Vec::new();
    glb.extend(b"glTF");
    glb.extend(2u32.to_le_bytes());
    glb.extend((total as u32).to_le_bytes());
    glb.extend((json.len() as u32).to_le_bytes());
    glb.extend(b"JSON");
    glb.extend(&json);
    glb.extend((buf.len() as u32).to_le_bytes());
    glb.extend(b"BIN\0");
    glb.extend(&buf);
    fs::write(d.join("tri.glb"), &glb).unwrap();
    let meshes = texel_scene::load_gltf(&d.join("tri.glb"), "t").unwrap();
    check_gltf_mesh(&meshes[0]);
    // A TOML address mode overrides the glTF sampler's.
    let text = format!(
        "{HEAD}[[meshes]]\ntexture = \"t\"\naddress_mode_v = \"repeat\"\ngltf = \"tri.glb\"\n"
    );
    fs::write(d.join("s2.toml"), &text).unwrap();
    let m = &Scene::from_path(d.join("s2.toml")).unwrap().meshes[0];
    assert_eq!(
        (m.address_mode_u, m.address_mode_v),
        (AddressMode::MirrorRepeat, AddressMode::Repeat)
    );

    // Corrupt: truncated GLB, JSON garbage, missing buffer file -> errors naming the file.
    fs::write(d.join("cut.glb"), &glb[..40]).unwrap();
    fs::write(d.join("junk.gltf"), "{ not json").unwrap();
    fs::write(d.join("nobuf.gltf"), triangle_json(Some("gone.bin"))).unwrap();
    for f in ["cut.glb", "junk.gltf"] {
        let e = texel_scene::load_gltf(&d.join(f), "t").unwrap_err();
        assert!(matches!(e, SceneError::Gltf { .. }), "{f}: {e}");
        assert!(e.to_string().contains(f), "{e}");
    }
    let e = texel_scene::load_gltf(&d.join("nobuf.gltf"), "t").unwrap_err();
    assert!(matches!(e, SceneError::MeshFile { .. }), "{e}");
    assert!(
        e.to_string().contains("nobuf.gltf") && e.to_string().contains("gone.bin"),
        "{e}"
    );
    // A mesh without TEXCOORD_0.
    let no_uv = triangle_json(Some("tri.bin")).replace(", \"TEXCOORD_0\": 1", "");
    fs::write(d.join("nouv.gltf"), no_uv).unwrap();
    let e = texel_scene::load_gltf(&d.join("nouv.gltf"), "t").unwrap_err();
    assert!(
        matches!(e, SceneError::MeshFile { .. }) && e.to_string().contains("TEXCOORD_0"),
        "{e}"
    );
    fs::remove_dir_all(&d).unwrap();
}

/// Regressions found by the `obj` and `gltf` fuzz targets: inputs that panicked inside `tobj`
/// (a relative face index past the first `vt`: `vt * 2 + 1` overflowed) and `gltf-json` (a
/// POSITION accessor index with no accessors) are errors naming the problem.
#[test]
fn fuzz_regressions_are_errors() {
    use texel_scene::{load_gltf_slice, load_obj_bytes, SceneLimits};
    let limits = SceneLimits::default();
    let obj = b"v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf -1/-1 -2/-2 -3/-3\n";
    let e = load_obj_bytes(obj, Path::new("f.obj"), "t", &limits).unwrap_err();
    assert!(matches!(e, SceneError::Obj { .. }), "{e}");
    assert!(e.to_string().contains("line 5"), "{e}");
    // The same relative index with enough vt lines later in the file: still out of range there.
    let later = b"v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf -1/-1 -2/-2 -3/-3\nvt 1 0\nvt 0 1\n";
    let e = load_obj_bytes(later, Path::new("f.obj"), "t", &limits).unwrap_err();
    assert!(e.to_string().contains("line 5"), "{e}");
    // An `l` line of several corners is triangulated by tobj too: its indices are checked.
    let line = b"v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nl 1 -2/-2 -3/-3 0 0\nvt 1 0\nvt 0 1\n";
    let e = load_obj_bytes(line, Path::new("f.obj"), "t", &limits).unwrap_err();
    assert!(e.to_string().contains("line 5"), "{e}");
    let gltf = br#"{"asset": {"version": "2.0"}, "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 1}}]}]}"#;
    let e = load_gltf_slice(gltf, None, Path::new("f.gltf"), "t", &limits).unwrap_err();
    assert!(
        e.to_string()
            .contains("refers to accessor 0, but the file has 0"),
        "{e}"
    );
}

/// Review findings: accessor types the gltf crate's readers do not handle (they hit
/// `unreachable!`), an attribute with more elements than POSITION (a sparse accessor can claim
/// billions for a few bytes), and a long node chain (the ancestor walk is linear, not quadratic)
/// are errors, not crashes, out-of-memory aborts or hangs.
#[test]
fn gltf_accessors_and_chains_are_checked_before_reading() {
    use texel_scene::{load_gltf_slice, SceneLimits};
    let limits = SceneLimits::default();
    let doc = |accessors: &str, nodes: &str| {
        format!(
            r#"{{"asset": {{"version": "2.0"}}, "scene": 0, "scenes": [{{"nodes": [0]}}], "nodes": [{nodes}],
            "meshes": [{{"primitives": [{{"attributes": {{"POSITION": 0, "TEXCOORD_0": 1}}}}]}}],
            "buffers": [{{"byteLength": 80, "uri": "data:application/octet-stream;base64,{}"}}],
            "bufferViews": [{{"buffer": 0, "byteOffset": 0, "byteLength": 48}}, {{"buffer": 0, "byteOffset": 48, "byteLength": 32}}],
            "accessors": [{{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]}}, {accessors}]}}"#,
            "A".repeat(108)
        )
    };
    let load =
        |text: String| load_gltf_slice(text.as_bytes(), None, Path::new("f.gltf"), "t", &limits);
    // The well-formed document loads (the buffer is zeros: a degenerate but valid triangle).
    let uv = r#"{"bufferView": 1, "componentType": 5126, "count": 3, "type": "VEC2"}"#;
    assert!(load(doc(uv, r#"{"mesh": 0}"#)).is_ok());
    // TEXCOORD_0 as u32: the gltf crate would reach unreachable!().
    let e = load(doc(&uv.replace("5126", "5125"), r#"{"mesh": 0}"#)).unwrap_err();
    assert!(e.to_string().contains("TexCoords(0)"), "{e}");
    // A sparse TEXCOORD_0 claiming four billion elements.
    let sparse = r#"{"componentType": 5126, "count": 4000000000, "type": "VEC2",
        "sparse": {"count": 1, "indices": {"bufferView": 0, "componentType": 5125}, "values": {"bufferView": 1}}}"#;
    let e = load(doc(sparse, r#"{"mesh": 0}"#)).unwrap_err();
    assert!(
        e.to_string()
            .contains("4000000000 elements but POSITION has 3"),
        "{e}"
    );
    // A chain of 200 000 nodes: refused for its depth or its instances, after a linear check.
    let chain: Vec<String> = (0..200_000)
        .map(|k| {
            if k + 1 < 200_000 {
                format!(r#"{{"mesh": 0, "children": [{}]}}"#, k + 1)
            } else {
                r#"{"mesh": 0}"#.to_string()
            }
        })
        .collect();
    let e = load(doc(uv, &chain.join(","))).unwrap_err();
    assert!(
        e.to_string().contains("deeper than 256")
            || e.to_string().contains("triangles")
            || e.to_string().contains("limit of 65536 meshes"),
        "{e}"
    );
}

#[test]
fn the_environment_table_parses_and_loads() {
    use texel_scene::{EnvironmentSource, Sky};
    // The procedural sky with its parameters.
    let text = format!(
        "{HEAD}{TRI}\n[environment]\nprocedural = \"sky\"\nsize = 64\nsun = [0.0, 1.0, 0.0]\n\
         intensity = [1.0, 0.5, 0.25]\nbackground = false\nmapping = \"equirect\"\n"
    );
    let s = parse(&text).unwrap();
    let e = s.environment.as_ref().unwrap();
    assert_eq!(
        e.source,
        EnvironmentSource::Sky(Sky {
            width: 64,
            sun: Vec3::Y,
            seed: 0
        })
    );
    assert_eq!(e.intensity, Vec3::new(1.0, 0.5, 0.25));
    assert!(!e.background);
    let t = e.load(&Limits::default()).unwrap();
    assert_eq!(t.len(), 1);
    assert_eq!((t[0].width(), t[0].height()), (64, 32));
    // A file map, relative to the scene, in Radiance HDR (float, linear).
    let dir = scratch("env");
    let mut hdr = Vec::new();
    let pixels = vec![image::Rgb([2.5f32, 0.5, 0.125]); 8 * 4];
    image::codecs::hdr::HdrEncoder::new(&mut hdr)
        .encode(&pixels, 8, 4)
        .unwrap();
    fs::write(dir.join("sky.hdr"), &hdr).unwrap();
    let scene_path = dir.join("scene.toml");
    let text = format!("{HEAD}{TRI}\n[environment]\npath = \"sky.hdr\"\nintensity = 2.0\n");
    fs::write(&scene_path, &text).unwrap();
    let s = Scene::from_path(&scene_path).unwrap();
    let e = s.environment.as_ref().unwrap();
    assert_eq!(e.source, EnvironmentSource::File(dir.join("sky.hdr")));
    assert_eq!(e.intensity, Vec3::splat(2.0));
    assert!(e.background);
    let t = e.load(&Limits::default()).unwrap();
    let c = t[0].texel(0, 3, 2).unwrap();
    assert!(
        (c[0] - 2.5).abs() < 0.05 && (c[2] - 0.125).abs() < 0.01,
        "{c:?}"
    );
    // A missing file is named when the map is loaded.
    fs::remove_file(dir.join("sky.hdr")).unwrap();
    let err = e.load(&Limits::default()).unwrap_err().to_string();
    assert!(
        err.contains("environment") && err.contains("sky.hdr"),
        "{err}"
    );
    let _ = fs::remove_dir_all(&dir);
}

#[test]
fn cube_and_octahedral_maps_load_from_crosses_faces_and_the_sky() {
    use texel_scene::{EnvironmentSource, Mapping, Sky};
    let dir = scratch("env-cube");
    // A horizontal cross of 4x3 faces of 4 texels: each face a grey of its own.
    let grey = |face: usize| (face as u8 + 1) * 40;
    let cell = |x: u32, y: u32| match (x / 4, y / 4) {
        (2, 1) => Some(0),
        (0, 1) => Some(1),
        (1, 0) => Some(2),
        (1, 2) => Some(3),
        (1, 1) => Some(4),
        (3, 1) => Some(5),
        _ => None,
    };
    let cross =
        image::RgbImage::from_fn(16, 12, |x, y| image::Rgb([cell(x, y).map_or(0, grey); 3]));
    cross.save(dir.join("cross.png")).unwrap();
    image::RgbImage::new(16, 13)
        .save(dir.join("odd.png"))
        .unwrap();
    for (f, size) in ["px", "nx", "py", "ny", "pz", "nz"]
        .iter()
        .zip([4, 4, 4, 4, 4, 5])
    {
        image::RgbImage::new(size, size)
            .save(dir.join(format!("{f}.png")))
            .unwrap();
    }
    let load = |table: &str| {
        let path = dir.join("scene.toml");
        fs::write(&path, format!("{HEAD}{TRI}\n[environment]\n{table}\n")).unwrap();
        let s = Scene::from_path(&path)?;
        let e = s.environment.clone().unwrap();
        e.load(&Limits::default()).map(|t| (e, t))
    };
    let (e, faces) = load("path = \"cross.png\"\nmapping = \"cube\"").unwrap();
    assert_eq!(e.mapping, Mapping::Cube);
    assert_eq!(faces.len(), 6);
    for (face, t) in faces.iter().enumerate() {
        assert_eq!((t.width(), t.height()), (4, 4));
        let want = texel_texture::base::color::srgb_to_linear(f32::from(grey(face)) / 255.0);
        assert!(
            (t.texel(0, 1, 2).unwrap()[0] - want).abs() < 1e-4,
            "face {face}"
        );
    }
    let err = load("path = \"odd.png\"\nmapping = \"cube\"")
        .unwrap_err()
        .to_string();
    assert!(err.contains("cross") && err.contains("16x13"), "{err}");
    let err = load("path = \"odd.png\"\nmapping = \"octahedral\"")
        .unwrap_err()
        .to_string();
    assert!(err.contains("square"), "{err}");
    // Six files, one of the wrong size: named.
    let (e, _) =
        load("faces = [\"px.png\", \"nx.png\", \"py.png\", \"ny.png\", \"pz.png\", \"px.png\"]")
            .unwrap();
    assert_eq!(e.mapping, Mapping::Cube);
    assert!(matches!(e.source, EnvironmentSource::Faces(_)));
    let err =
        load("faces = [\"px.png\", \"nx.png\", \"py.png\", \"ny.png\", \"pz.png\", \"nz.png\"]")
            .unwrap_err()
            .to_string();
    assert!(err.contains("nz.png") && err.contains("5x5"), "{err}");
    // The sky in each mapping, at its default size.
    for (mapping, layers, size) in [("cube", 6, 256), ("octahedral", 1, 512)] {
        let text =
            format!("{HEAD}{TRI}\n[environment]\nprocedural = \"sky\"\nmapping = \"{mapping}\"\n");
        let s = parse(&text).unwrap();
        let e = s.environment.as_ref().unwrap();
        assert!(matches!(e.source, EnvironmentSource::Sky(Sky { width, .. }) if width == size));
        let t = e.load(&Limits::default()).unwrap();
        assert_eq!(t.len(), layers);
        assert_eq!((t[0].width(), t[0].height()), (size, size));
    }
    let _ = fs::remove_dir_all(&dir);
}

#[test]
fn bad_environment_tables_are_refused() {
    for (table, expect) in [
        ("procedural = \"sky\"\npath = \"a.hdr\"", "exactly one"),
        ("intensity = 1.0", "exactly one"),
        (
            "faces = [\"a\", \"b\", \"c\", \"d\", \"e\", \"f\"]\nmapping = \"octahedral\"",
            "cube map's",
        ),
        (
            "faces = [\"a\", \"b\", \"c\", \"d\", \"e\"]",
            "invalid length",
        ),
        (
            "faces = [\"a\", \"b\", \"c\", \"d\", \"e\", \"f\"]\npath = \"a.hdr\"",
            "exactly one",
        ),
        (
            "faces = [\"a\", \"b\", \"c\", \"d\", \"e\", \"f\"]\nsize = 4",
            "procedural sky",
        ),
        (
            "procedural = \"sky\"\nmapping = \"sphere\"",
            "unknown variant",
        ),
        ("procedural = \"sky\"\nintensity = -1.0", "negative"),
        (
            "procedural = \"sky\"\nintensity = [1.0, nan, 1.0]",
            "finite",
        ),
        ("procedural = \"sky\"\nsize = 0", "size"),
        ("procedural = \"sky\"\nsize = 100000", "size"),
        ("procedural = \"sky\"\nsun = [0.0, 0.0, 0.0]", "sun"),
        ("path = \"a.hdr\"\nsun = [0.0, 1.0, 0.0]", "procedural sky"),
        ("procedural = \"sky\"\nbrightness = 2.0", "unknown field"),
    ] {
        let text = format!("{HEAD}{TRI}\n[environment]\n{table}\n");
        let err = parse(&text).unwrap_err().to_string();
        assert!(err.contains(expect), "{table}: {err}");
    }
}

#[test]
fn sphere_uv_keys_parse_and_bad_ones_are_refused() {
    use texel_texture::mapping::sphere::SurfaceProjection;
    let with = |keys: &str| parse(&format!("{HEAD}{TRI}{keys}\n"));
    let m = with("sphere_uv = \"mercator\"\nsphere_centre = [1.0, 2.0, 3.0]").unwrap();
    let u = m.meshes[0].uv_mapping.unwrap();
    assert_eq!(u.projection, SurfaceProjection::MERCATOR);
    assert_eq!(u.centre, Vec3::new(1.0, 2.0, 3.0));
    let m = with("sphere_uv = \"mercator\"\nmercator_cut_deg = 60.0").unwrap();
    match m.meshes[0].uv_mapping.unwrap().projection {
        SurfaceProjection::Mercator { cut } => assert!((cut - 60f64.to_radians()).abs() < 1e-12),
        other => panic!("{other:?}"),
    }
    let m = with("sphere_uv = \"equirect\"").unwrap();
    assert_eq!(
        m.meshes[0].uv_mapping.unwrap().projection,
        SurfaceProjection::Equirect
    );
    assert_eq!(
        parse(&format!("{HEAD}{TRI}")).unwrap().meshes[0].uv_mapping,
        None
    );
    for (keys, needle) in [
        (
            "sphere_uv = \"equirect\"\nmercator_cut_deg = 80.0",
            "mercator_cut_deg is for",
        ),
        (
            "sphere_uv = \"mercator\"\nmercator_cut_deg = 90.0",
            "outside (0, 89.9]",
        ),
        (
            "sphere_uv = \"mercator\"\nmercator_cut_deg = -5.0",
            "outside (0, 89.9]",
        ),
        (
            "sphere_uv = \"mercator\"\nmercator_cut_deg = nan",
            "outside (0, 89.9]",
        ),
        ("sphere_centre = [0.0, 0.0, 0.0]", "need sphere_uv"),
        (
            "sphere_uv = \"mercator\"\nsphere_centre = [inf, 0.0, 0.0]",
            "not finite",
        ),
        ("sphere_uv = \"sinusoidal\"", "unknown variant"),
    ] {
        let e = with(keys).unwrap_err().to_string();
        assert!(e.contains(needle), "{keys}: {e}");
    }
}

#[test]
fn the_globes_carry_their_projection_at_every_vertex() {
    use texel_texture::mapping::sphere::SurfaceProjection;
    for (name, want) in [
        ("sphere", SurfaceProjection::Equirect),
        ("globe-equirect", SurfaceProjection::Equirect),
        ("globe", SurfaceProjection::MERCATOR),
    ] {
        let s = builtin(name).unwrap();
        let m = &s.meshes[0];
        let u = m.uv_mapping.unwrap();
        assert_eq!(u.projection, want, "{name}");
        // Each vertex's uv is the projection of its direction (u = 1 on the duplicated seam
        // column, and at the poles any u: the column's).
        for (p, uv) in m.positions.iter().zip(&m.uvs) {
            let d = (*p - u.centre).as_dvec3();
            let want = u.projection.uv(d);
            assert!(
                (f64::from(uv.y) - want.y).abs() < 1e-6,
                "{name} {p}: {uv} {want}"
            );
            let pole = d.normalize().y.abs() > 1.0 - 1e-6;
            let du = (f64::from(uv.x) - want.x).rem_euclid(1.0);
            assert!(pole || du.min(1.0 - du) < 1e-6, "{name} {p}: {uv} {want}");
        }
    }
}

#[test]
fn both_globe_maps_draw_the_same_globe() {
    // Sample each map at the texel a sphere point lands in: away from edges (where the texels'
    // different sizes antialias differently) the two maps agree, and the discs are where
    // Tissot's indicatrix puts them.
    use glam::DVec3;
    let maps = [false, true].map(|mercator| Procedural::Globe {
        width: 2048,
        height: if mercator { 2048 } else { 1024 },
        mercator,
    });
    let colour_at = |p: &Procedural, d: DVec3| {
        let uv = p.globe_projection().unwrap().uv(d);
        let (w, h) = p.size();
        let i = ((uv.x * f64::from(w)) as u32).min(w - 1);
        let j = ((uv.y * f64::from(h)) as u32).min(h - 1);
        p.code(i, j)
    };
    let at = |lat: f64, lon: f64| {
        let (lat, lon) = (lat.to_radians(), lon.to_radians());
        DVec3::new(lat.cos() * lon.sin(), lat.sin(), lat.cos() * lon.cos())
    };
    let (ocean, disc, line) = (
        [28, 64, 128, 255],
        [240, 150, 40, 255],
        [255, 255, 255, 255],
    );
    for (lat, lon, want) in [
        (3.0, 33.0, disc),
        (58.0, 93.0, disc),
        (-33.0, 207.0, disc),
        (62.0, 92.0, disc),
        (7.5, 22.5, ocean),
        (80.0, 7.0, ocean),
        (45.0, 37.5, line),
        (-22.5, 75.0, line),
    ] {
        for p in &maps {
            assert_eq!(colour_at(p, at(lat, lon)), want, "{p:?} at ({lat}, {lon})");
        }
    }
    // The prime meridian (the seam) is red in both.
    for p in &maps {
        let c = colour_at(p, at(20.0, 359.99));
        assert!(c[0] > 150 && c[1] < 100, "{c:?}");
    }
}
