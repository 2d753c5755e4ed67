//! Bounds and arithmetic at the edges of f32: work that scene numbers multiply is refused before
//! it starts, with the bound named; lengths whose squares leave f32's range are not mistaken for
//! zero or degenerate; errors say where they are, or nothing when the parser does not know.

use std::path::Path;

use glam::Vec3;
use texel_scene::{Procedural, Scene, SceneLimits, MIN_FOVY_DEG};

/// A scene looking at a triangle from `eye`, with `extra` TOML appended (textures, lights).
fn scene(camera: &str, extra: &str) -> String {
    format!(
        r#"
[output]
width = 64
height = 48

[camera]
{camera}
near = 0.1
far = 10.0

[textures.t]
procedural = "uv"
size = 8

[[meshes]]
texture = "t"
positions = [[-1.0, -1.0, 0.0], [1.0, -1.0, 0.0], [0.0, 1.0, 0.0]]
uvs = [[0.0, 1.0], [1.0, 1.0], [0.5, 0.0]]
triangles = [[0, 1, 2]]
{extra}
"#
    )
}

const CAMERA: &str = "eye = [0.0, 0.0, 3.0]\ntarget = [0.0, 0.0, 0.0]\nfovy_deg = 45.0";

fn load(text: &str) -> Result<Scene, String> {
    Scene::from_toml_str(text, Path::new("t.toml")).map_err(|e| e.to_string())
}

#[test]
fn wave_work_is_bounded_before_it_starts() {
    let waves = |params: &str| {
        load(&scene(
            CAMERA,
            &format!("[textures.w]\nprocedural = \"waves\"\n{params}\n"),
        ))
    };
    waves("").unwrap();
    waves("waves = 4096").unwrap();
    let e = waves("waves = 100000").unwrap_err();
    assert!(e.contains("waves = 100000") && e.contains("4096"), "{e}");
    let e = waves("waves = 4000000000").unwrap_err();
    assert!(e.contains("4096"), "{e}");
    // 8192^2 texels x 64 waves = 2^32 terms, over 2^31.
    let e = waves("size = 8192").unwrap_err();
    assert!(e.contains("wave terms") && e.contains("2147483648"), "{e}");
    waves("size = 4096\nwaves = 128").unwrap();
    // A ring of wave numbers finer than two texels.
    let e = waves("size = 64\ncells = 33").unwrap_err();
    assert!(e.contains("cells = 33"), "{e}");
    waves("size = 64\ncells = 32").unwrap();
    // The bound is the one the procedural type states.
    let p = Procedural::Waves {
        size: 512,
        waves: 64,
        cells: 32,
        slope: 0.3,
        seed: 1,
        heights: false,
    };
    p.check_work().unwrap();
}

#[test]
fn far_cameras_and_tiny_directions_are_not_degenerate() {
    // A camera 3e30 away: |target - eye|^2 overflows f32, the view is still well defined.
    let far = load(&scene(
        "eye = [3e30, 0.0, 3e30]\ntarget = [0.0, 0.0, 0.0]\nfovy_deg = 45.0",
        "",
    ))
    .unwrap();
    let m = far.camera.view_from_world();
    assert!(m.is_finite(), "{m}");
    // The target lies straight ahead: on the view axis, 4.24e30 away.
    let t = m.transform_point3(Vec3::ZERO);
    assert!(t.x.abs() < 1e24 && t.y.abs() < 1e24, "{t}");
    assert!((t.z / -4.2426e30 - 1.0).abs() < 1e-3, "{t}");
    // An eye so far that the view's translation leaves f32: refused, not drawn empty.
    let e = load(&scene(
        "eye = [3e38, 3e38, 0.0]\ntarget = [0.0, 0.0, 0.0]\nfovy_deg = 45.0",
        "",
    ))
    .unwrap_err();
    assert!(e.contains("overflows f32"), "{e}");
    // A view 1e-25 long (its square underflows f32).
    let near = load(&scene(
        "eye = [0.0, 0.0, 1e-25]\ntarget = [0.0, 0.0, 0.0]\nfovy_deg = 45.0",
        "",
    ))
    .unwrap();
    assert!(near.camera.view_from_world().is_finite());
    // A light direction of 1e-30 names a direction; a zero one does not.
    let light = |d: &str| {
        load(&scene(
            CAMERA,
            &format!("[[lights]]\ntype = \"directional\"\ndirection = {d}\nintensity = [1.0, 1.0, 1.0]\n"),
        ))
    };
    light("[0.0, 1e-30, 1e-30]").unwrap();
    light("[3e38, 3e38, 3e38]").unwrap();
    let e = light("[0.0, 0.0, 0.0]").unwrap_err();
    assert!(e.contains("zero"), "{e}");
    // Truly degenerate: eye on the target.
    let e = load(&scene(
        "eye = [1.0, 2.0, 3.0]\ntarget = [1.0, 2.0, 3.0]\nfovy_deg = 45.0",
        "",
    ))
    .unwrap_err();
    assert!(e.contains("eye must differ"), "{e}");
}

#[test]
fn a_field_of_view_below_f32_resolution_is_refused_with_the_reason() {
    let fov = |deg: &str| {
        load(&scene(
            &format!("eye = [0.0, 0.0, 3.0]\ntarget = [0.0, 0.0, 0.0]\nfovy_deg = {deg}"),
            "",
        ))
    };
    let e = fov("1e-30").unwrap_err();
    assert!(e.contains("at least 0.01") && e.contains("resolve"), "{e}");
    fov("0.01").unwrap();
    fov("179.9").unwrap();
    assert!(fov("180.0").is_err());
    assert_eq!(MIN_FOVY_DEG, 0.01);
}

#[test]
fn errors_without_a_position_do_not_claim_line_zero() {
    // A light of no known type: the parser's error for the untagged/tagged enum.
    let text = scene(CAMERA, "[[lights]]\ntype = \"laser\"\n");
    let e = load(&text).unwrap_err();
    assert!(!e.contains(":0:0"), "{e}");
    assert!(e.starts_with("t.toml"), "{e}");
    // A malformed line keeps its position.
    let e = load("[output\nwidth = 1").unwrap_err();
    assert!(e.starts_with("t.toml:1:"), "{e}");
    // An error the parser gives no position for names the file alone.
    let e = texel_scene::SceneError::Toml {
        path: "deep.toml".into(),
        line: 0,
        column: 0,
        message: "invalid type".into(),
    };
    assert_eq!(e.to_string(), "deep.toml: invalid type");
}

#[test]
fn meshes_are_bounded_in_number() {
    let mut text = scene(CAMERA, "");
    let tri = "\n[[meshes]]\ntexture = \"t\"\npositions = [[-1.0, -1.0, 0.0], [1.0, -1.0, 0.0], [0.0, 1.0, 0.0]]\nuvs = [[0.0, 1.0], [1.0, 1.0], [0.5, 0.0]]\ntriangles = [[0, 1, 2]]\n";
    for _ in 0..4 {
        text.push_str(tri);
    }
    let limits = SceneLimits {
        max_meshes: 4,
        ..SceneLimits::default()
    };
    let e = Scene::from_toml_str_with(&text, Path::new("t.toml"), &limits)
        .unwrap_err()
        .to_string();
    assert!(e.contains("4 meshes"), "{e}");
    let limits = SceneLimits {
        max_meshes: 5,
        ..limits
    };
    Scene::from_toml_str_with(&text, Path::new("t.toml"), &limits).unwrap();
}

#[test]
fn a_procedural_sky_is_bounded_in_texels() {
    use texel_scene::{max_sky_width, Mapping, MAX_SKY_TEXELS};
    let sky = |params: &str| {
        load(&scene(
            CAMERA,
            &format!("[environment]\nprocedural = \"sky\"\n{params}\n"),
        ))
    };
    sky("size = 2048").unwrap();
    let e = sky("size = 8192").unwrap_err();
    assert!(
        e.contains("2097152") && e.contains("use size 2048 or less"),
        "{e}"
    );
    // Each mapping's largest size is the last within the bound (brute force over the sizes).
    for (mapping, layers) in [
        (Mapping::Equirect, 1u64),
        (Mapping::Cube, 6),
        (Mapping::Octahedral, 1),
    ] {
        let texels = |w: u64| match mapping {
            Mapping::Equirect => w * (w / 2).max(1) * layers,
            _ => w * w * layers,
        };
        let max = u64::from(max_sky_width(mapping));
        assert!(
            texels(max) <= MAX_SKY_TEXELS && texels(max + 1) > MAX_SKY_TEXELS,
            "{mapping:?}"
        );
    }
    let e = sky("mapping = \"cube\"\nsize = 600").unwrap_err();
    assert!(e.contains("591"), "{e}");
}

/// A glTF document with `nodes` instances of one quad, its buffer embedded.
fn instanced_quad(nodes: usize) -> String {
    let mut buf = Vec::new();
    for v in [
        -1.0f32, -1.0, 0.0, 1.0, -1.0, 0.0, 1.0, 1.0, 0.0, -1.0, 1.0, 0.0,
    ] {
        buf.extend(v.to_le_bytes());
    }
    for v in [0.0f32, 1.0, 1.0, 1.0, 1.0, 0.0, 0.0, 0.0] {
        buf.extend(v.to_le_bytes());
    }
    for i in [0u16, 1, 2, 0, 2, 3] {
        buf.extend(i.to_le_bytes());
    }
    const A: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut b64 = String::new();
    for c in buf.chunks(3) {
        let n = (u32::from(c[0]) << 16)
            | (u32::from(*c.get(1).unwrap_or(&0)) << 8)
            | u32::from(*c.get(2).unwrap_or(&0));
        for k in 0..4 {
            b64.push(if k <= c.len() {
                A[(n >> (18 - 6 * k) & 63) as usize] as char
            } else {
                '='
            });
        }
    }
    let list: Vec<String> = (0..nodes).map(|k| k.to_string()).collect();
    let node_objs: Vec<&str> = (0..nodes).map(|_| r#"{"mesh": 0}"#).collect();
    format!(
        r#"{{"asset": {{"version": "2.0"}}, "scene": 0, "scenes": [{{"nodes": [{}]}}],
  "nodes": [{}],
  "meshes": [{{"primitives": [{{"attributes": {{"POSITION": 0, "TEXCOORD_0": 1}}, "indices": 2}}]}}],
  "buffers": [{{"uri": "data:application/octet-stream;base64,{b64}", "byteLength": 92}}],
  "bufferViews": [{{"buffer": 0, "byteOffset": 0, "byteLength": 48}}, {{"buffer": 0, "byteOffset": 48, "byteLength": 32}}, {{"buffer": 0, "byteOffset": 80, "byteLength": 12}}],
  "accessors": [{{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [-1, -1, 0], "max": [1, 1, 0]}}, {{"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC2"}}, {{"bufferView": 2, "componentType": 5123, "count": 6, "type": "SCALAR"}}]}}"#,
        list.join(","),
        node_objs.join(",")
    )
}

#[test]
fn gltf_instances_are_counted_before_any_buffer_is_read() {
    let limits = SceneLimits {
        max_meshes: 100,
        ..SceneLimits::default()
    };
    let load = |nodes| {
        texel_scene::load_gltf_slice(
            instanced_quad(nodes).as_bytes(),
            None,
            Path::new("q.gltf"),
            "t",
            &limits,
        )
    };
    assert_eq!(load(100).unwrap().len(), 100);
    let e = load(101).unwrap_err().to_string();
    assert!(e.contains("the limit of 100 meshes"), "{e}");
}
