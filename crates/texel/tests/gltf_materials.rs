//! glTF files with their own `pbrMetallicRoughness` materials: what is imported (textures with
//! their samplers, channels and factors, images from files, data URIs and buffer views), and that
//! the imported material renders exactly as the same material written in a scene file.

use std::fs;
use std::path::{Path, PathBuf};

use base64::Engine;
use texel::scene::{ColorInput, ScalarInput, SceneError, TextureSource};
use texel::texture::{AddressMode, ColorSpace};
use texel::{Filter, MemoryBudget, PreparedScene, Scene, SceneOptions};

/// A fresh scratch directory.
fn scratch(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("texel-gltf-{tag}-{}", std::process::id()));
    let _ = fs::remove_dir_all(&d);
    fs::create_dir_all(&d).unwrap();
    d
}

/// A `side` x `side` PNG of one colour.
fn png(rgba: [u8; 4], side: u32) -> Vec<u8> {
    let img = image::RgbaImage::from_pixel(side, side, image::Rgba(rgba));
    let mut out = std::io::Cursor::new(Vec::new());
    img.write_to(&mut out, image::ImageFormat::Png).unwrap();
    out.into_inner()
}

fn data_uri(bytes: &[u8], mime: &str) -> String {
    let b64 = base64::engine::general_purpose::STANDARD.encode(bytes);
    format!("data:{mime};base64,{b64}")
}

const BASE_RGBA: [u8; 4] = [200, 100, 50, 255];
/// Occlusion (red) 64, roughness (green) 153, metalness (blue) 51.
const ORM_RGBA: [u8; 4] = [64, 153, 51, 255];
const NORMAL_RGBA: [u8; 4] = [160, 100, 230, 255];

/// A quad in the z = 0 plane facing +z, side 2, with normals and uvs over [0, 1]; material 0 has
/// a base colour texture (image 0, a data URI), a metallic-roughness texture that is also the
/// occlusion texture (image 1, a file beside the glTF, clamped), and a normal texture (image 2,
/// in the buffer after the geometry, mirrored). `patch` edits the JSON text.
fn quad_gltf(dir: &Path, patch: impl Fn(String) -> String) -> PathBuf {
    let mut buf = Vec::new();
    for p in [
        [-1.0f32, -1.0, 0.0],
        [1.0, -1.0, 0.0],
        [1.0, 1.0, 0.0],
        [-1.0, 1.0, 0.0],
    ] {
        p.iter().for_each(|x| buf.extend(x.to_le_bytes()));
    }
    for _ in 0..4 {
        [0.0f32, 0.0, 1.0]
            .iter()
            .for_each(|x| buf.extend(x.to_le_bytes()));
    }
    for uv in [[0.0f32, 1.0], [1.0, 1.0], [1.0, 0.0], [0.0, 0.0]] {
        uv.iter().for_each(|x| buf.extend(x.to_le_bytes()));
    }
    for i in [0u16, 1, 2, 0, 2, 3] {
        buf.extend(i.to_le_bytes());
    }
    assert_eq!(buf.len(), 140);
    let normal_png = png(NORMAL_RGBA, 4);
    buf.extend(&normal_png);
    let image_len = normal_png.len();
    fs::write(dir.join("orm.png"), png(ORM_RGBA, 4)).unwrap();
    let json = format!(
        r#"{{
  "asset": {{"version": "2.0"}},
  "scene": 0,
  "scenes": [{{"nodes": [0]}}],
  "nodes": [{{"mesh": 0}}],
  "meshes": [{{"primitives": [{{"attributes": {{"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2}}, "indices": 3, "material": 0}}]}}],
  "materials": [{{
    "pbrMetallicRoughness": {{
      "baseColorFactor": [0.5, 1.0, 0.25, 1.0],
      "baseColorTexture": {{"index": 0}},
      "metallicFactor": 0.5,
      "roughnessFactor": 0.8,
      "metallicRoughnessTexture": {{"index": 1}}
    }},
    "normalTexture": {{"index": 2, "scale": 0.5}},
    "occlusionTexture": {{"index": 1, "strength": 0.5}}
  }}],
  "textures": [{{"source": 0}}, {{"sampler": 0, "source": 1}}, {{"sampler": 1, "source": 2}}],
  "samplers": [{{"wrapS": 33071, "wrapT": 33071}}, {{"wrapS": 33648, "wrapT": 33648}}],
  "images": [{{"uri": "{base}"}}, {{"uri": "orm.png"}}, {{"bufferView": 4, "mimeType": "image/png"}}],
  "buffers": [{{"uri": "{buffer}", "byteLength": {len}}}],
  "bufferViews": [
    {{"buffer": 0, "byteOffset": 0, "byteLength": 48}},
    {{"buffer": 0, "byteOffset": 48, "byteLength": 48}},
    {{"buffer": 0, "byteOffset": 96, "byteLength": 32}},
    {{"buffer": 0, "byteOffset": 128, "byteLength": 12}},
    {{"buffer": 0, "byteOffset": 140, "byteLength": {image_len}}}
  ],
  "accessors": [
    {{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [-1, -1, 0], "max": [1, 1, 0]}},
    {{"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC3"}},
    {{"bufferView": 2, "componentType": 5126, "count": 4, "type": "VEC2"}},
    {{"bufferView": 3, "componentType": 5123, "count": 6, "type": "SCALAR"}}
  ]
}}"#,
        base = data_uri(&png(BASE_RGBA, 4), "image/png"),
        buffer = data_uri(&buf, "application/octet-stream"),
        len = buf.len(),
    );
    let path = dir.join("quad.gltf");
    fs::write(&path, patch(json)).unwrap();
    path
}

const HEAD: &str = r#"
[output]
width = 48
height = 40
[camera]
eye = [0.4, 0.3, 2.5]
target = [0.0, 0.0, 0.0]
fovy_deg = 60.0
near = 0.05
far = 100.0
[[lights]]
type = "directional"
direction = [0.3, 0.5, 1.0]
intensity = [3.0, 3.0, 3.0]
[[lights]]
type = "ambient"
intensity = [0.4, 0.4, 0.4]
"#;

fn load(dir: &Path, text: &str) -> Result<Scene, SceneError> {
    let path = dir.join("scene.toml");
    fs::write(&path, format!("{HEAD}{text}")).unwrap();
    Scene::from_path(&path)
}

fn render(scene: Scene) -> Vec<[f32; 4]> {
    let mut budget = MemoryBudget::new(1 << 30, "test");
    let prepared = PreparedScene::new(scene, &SceneOptions::default(), &mut budget).unwrap();
    let samplers = prepared.samplers(Filter::Trilinear).unwrap();
    let mut settings = prepared.settings();
    settings.target = texel::ColorTarget::Float;
    texel::render(&settings, &prepared.draws(&samplers))
        .unwrap()
        .color
}

#[test]
fn a_gltf_material_is_imported_with_its_textures_channels_and_samplers() {
    let d = scratch("import");
    quad_gltf(&d, |j| j);
    let scene = load(&d, "[[meshes]]\ngltf = \"quad.gltf\"\n").unwrap();
    let mesh = &scene.meshes[0];
    assert_eq!(mesh.texture, "quad.gltf#texture0.srgb");
    assert_eq!(mesh.material.as_deref(), Some("quad.gltf#material0"));
    // Texture 0 has no sampler: glTF's default repeats.
    assert_eq!(
        (mesh.address_mode_u, mesh.address_mode_v),
        (AddressMode::Repeat, AddressMode::Repeat)
    );
    let m = &scene.materials["quad.gltf#material0"];
    assert_eq!(
        m.base_color,
        ColorInput::Rgb(glam::Vec3::new(0.5, 1.0, 0.25))
    );
    let orm = "quad.gltf#texture1.linear".to_string();
    assert_eq!(
        m.roughness,
        ScalarInput::Channel {
            texture: orm.clone(),
            channel: 1,
            factor: 0.8
        }
    );
    assert_eq!(
        m.metallic,
        ScalarInput::Channel {
            texture: orm.clone(),
            channel: 2,
            factor: 0.5
        }
    );
    assert_eq!(m.normal.as_deref(), Some("quad.gltf#texture2.linear"));
    assert_eq!(m.normal_scale, 0.5);
    assert_eq!(m.occlusion.as_ref(), Some(&orm));
    assert_eq!(m.occlusion_strength, 0.5);
    let t = &scene.textures;
    assert_eq!(t.len(), 3, "{:?}", t.keys().collect::<Vec<_>>());
    let base = &t["quad.gltf#texture0.srgb"];
    assert_eq!(base.color, ColorSpace::Srgb);
    assert!(matches!(base.source, TextureSource::Encoded(_)));
    let orm_spec = &t[&orm];
    assert_eq!(orm_spec.color, ColorSpace::Linear);
    assert_eq!(orm_spec.source, TextureSource::File(d.join("orm.png")));
    let own = orm_spec.sampler.unwrap();
    assert_eq!(
        (own.address_mode_u, own.address_mode_v),
        (AddressMode::ClampToEdge, AddressMode::ClampToEdge)
    );
    let normal = &t["quad.gltf#texture2.linear"];
    assert!(matches!(&normal.source, TextureSource::Encoded(e) if e.bytes.starts_with(b"\x89PNG")));
    assert_eq!(
        normal.sampler.unwrap().address_mode_u,
        AddressMode::MirrorRepeat
    );

    // Each map is read through its own texture's sampler, and the channels glTF names.
    let mut budget = MemoryBudget::new(1 << 30, "test");
    let prepared = PreparedScene::new(scene, &SceneOptions::default(), &mut budget).unwrap();
    let samplers = prepared.samplers(Filter::Aniso16).unwrap();
    assert_eq!(
        samplers.len(),
        1 + 3,
        "the mesh's, then repeat, clamp, mirror"
    );
    let draws = prepared.draws(&samplers);
    let mat = draws[0].material.unwrap();
    let modes = |s: &texel::Sampler| (s.descriptor().address_mode_u, s.descriptor().min_filter);
    let rough = mat.roughness_map.unwrap();
    assert_eq!(rough.channel, 1);
    assert_eq!(mat.metallic_map.unwrap().channel, 2);
    assert_eq!(mat.occlusion_map.unwrap().channel, 0);
    assert_eq!(
        modes(rough.input.sampler),
        (
            AddressMode::ClampToEdge,
            samplers[0].descriptor().min_filter
        ),
        "the named filter, the texture's address modes"
    );
    assert_eq!(
        modes(mat.normal_map.unwrap().sampler).0,
        AddressMode::MirrorRepeat
    );
    assert_eq!((mat.roughness, mat.metallic), (0.8, 0.5));
    fs::remove_dir_all(&d).unwrap();
}

#[test]
fn an_imported_material_renders_as_the_same_material_in_a_scene_file() {
    let d = scratch("render");
    quad_gltf(&d, |j| j);
    fs::write(d.join("base.png"), png(BASE_RGBA, 4)).unwrap();
    fs::write(d.join("normal.png"), png(NORMAL_RGBA, 4)).unwrap();
    let imported = render(load(&d, "[[meshes]]\ngltf = \"quad.gltf\"\n").unwrap());
    // The same, by hand: roughness and metalness are the constant channels times the factors.
    let by_hand = format!(
        r#"
[textures.base]
path = "base.png"
[textures.orm]
path = "orm.png"
color = "linear"
[textures.normal]
path = "normal.png"
color = "linear"
[materials.m]
base_color = [0.5, 1.0, 0.25]
roughness = {r}
metallic = {m}
normal = "normal"
normal_scale = 0.5
occlusion = "orm"
occlusion_strength = 0.5
[[meshes]]
texture = "base"
material = "m"
gltf = "quad.gltf"
"#,
        r = 0.8 * 153.0 / 255.0,
        m = 0.5 * 51.0 / 255.0,
    );
    let written = render(load(&d, &by_hand).unwrap());
    let covered = imported.iter().filter(|p| p[3] > 0.0).count();
    assert!(covered > 48 * 40 / 4, "{covered} pixels covered");
    let worst = imported
        .iter()
        .zip(&written)
        .flat_map(|(a, b)| (0..4).map(move |c| (a[c] - b[c]).abs()))
        .fold(0.0f32, f32::max);
    assert!(worst < 1e-5, "largest difference {worst}");

    // Occlusion dims the ambient light only: without it the image is brighter, by exactly the
    // ambient part that 1 + 0.5 (64/255 - 1) removed.
    let no_ao = render(load(&d, &by_hand.replace("occlusion = \"orm\"\n", "")).unwrap());
    let ambient_only = |text: &str| {
        let text = text.replace(
            "direction = [0.3, 0.5, 1.0]",
            "direction = [0.0, 0.0, -1.0]",
        );
        let path = d.join("amb.toml");
        fs::write(
            &path,
            format!("{HEAD}{text}").replace("[3.0, 3.0, 3.0]", "[0.0, 0.0, 0.0]"),
        )
        .unwrap();
        render(Scene::from_path(&path).unwrap())
    };
    let dim = ambient_only(&by_hand);
    let full = ambient_only(&by_hand.replace("occlusion = \"orm\"\n", ""));
    let k = 1.0 + 0.5 * (64.0 / 255.0 - 1.0);
    let mut checked = 0;
    for (a, b) in dim.iter().zip(&full) {
        if b[3] > 0.0 && b[0] > 0.01 {
            assert!(
                (a[0] - k * b[0]).abs() < 1e-5 * b[0].max(1.0),
                "{a:?} vs {k} * {b:?}"
            );
            checked += 1;
        }
    }
    assert!(checked > 100, "{checked}");
    let brighter = no_ao
        .iter()
        .zip(&written)
        .filter(|(a, b)| a[0] > b[0] + 1e-4)
        .count();
    assert!(brighter > 100, "{brighter}");
    fs::remove_dir_all(&d).unwrap();
}

#[test]
fn a_named_material_or_texture_wins_over_the_gltf_and_bad_maps_are_refused() {
    let d = scratch("override");
    quad_gltf(&d, |j| j);
    // A named material: the glTF's is not imported.
    let s = load(
        &d,
        "[textures.t]\nprocedural = \"checker\"\n[materials.x]\nbase_color = \"t\"\n\
         [[meshes]]\nmaterial = \"x\"\ngltf = \"quad.gltf\"\n",
    )
    .unwrap();
    assert_eq!(s.meshes[0].material.as_deref(), Some("x"));
    assert!(s.materials.keys().all(|k| !k.contains('#')));
    assert!(s.textures.keys().all(|k| !k.contains('#')));
    // A named texture replaces the base colour texture; the other maps are still imported.
    let s = load(
        &d,
        "[textures.t]\nprocedural = \"checker\"\n[[meshes]]\ntexture = \"t\"\ngltf = \"quad.gltf\"\n",
    )
    .unwrap();
    assert_eq!(s.meshes[0].texture, "t");
    assert!(!s.textures.contains_key("quad.gltf#texture0.srgb"));
    assert!(s.materials["quad.gltf#material0"].normal.is_some());
    // No material at all: white, and texel's own Lambertian default.
    quad_gltf(&d, |j| j.replace(", \"material\": 0", ""));
    let s = load(&d, "[[meshes]]\ngltf = \"quad.gltf\"\n").unwrap();
    assert_eq!(s.meshes[0].texture, "quad.gltf#white");
    assert_eq!(s.meshes[0].material, None);
    let white = render(s);
    assert!(white.iter().any(|p| p[3] > 0.0));

    // A map on another uv set, an image outside its buffer, a corrupt image.
    quad_gltf(&d, |j| {
        j.replace(
            "\"normalTexture\": {\"index\": 2,",
            "\"normalTexture\": {\"index\": 2, \"texCoord\": 1,",
        )
    });
    let e = load(&d, "[[meshes]]\ngltf = \"quad.gltf\"\n").unwrap_err();
    assert!(e.to_string().contains("TEXCOORD_1"), "{e}");
    quad_gltf(&d, |j| {
        j.replace("\"byteOffset\": 140", "\"byteOffset\": 150")
    });
    let e = load(&d, "[[meshes]]\ngltf = \"quad.gltf\"\n").unwrap_err();
    assert!(e.to_string().contains("image 2"), "{e}");
    quad_gltf(&d, |j| j);
    fs::write(d.join("orm.png"), b"\x89PNG not really").unwrap();
    let s = load(&d, "[[meshes]]\ngltf = \"quad.gltf\"\n").unwrap();
    let mut budget = MemoryBudget::new(1 << 30, "test");
    let e = PreparedScene::new(s, &SceneOptions::default(), &mut budget).unwrap_err();
    assert!(e.to_string().contains("orm.png"), "{e}");
    fs::remove_dir_all(&d).unwrap();
}

/// `TANGENT` is kept, its direction through the node's transform; a mirroring transform flips
/// its handedness `w` (the bitangent `w cross(n, t)` must follow the mirrored surface).
#[test]
fn tangents_are_read_and_mirroring_flips_their_handedness() {
    let d = scratch("tangents");
    let with_tangents = |j: String| {
        j.replace(
            "\"NORMAL\": 1, \"TEXCOORD_0\": 2",
            "\"NORMAL\": 1, \"TEXCOORD_0\": 2, \"TANGENT\": 4",
        )
        .replace(
            "\"count\": 6, \"type\": \"SCALAR\"}",
            "\"count\": 6, \"type\": \"SCALAR\"}, \
             {\"bufferView\": 5, \"componentType\": 5126, \"count\": 4, \"type\": \"VEC4\"}",
        )
        .replace(
            "}\n  ],\n  \"accessors\"",
            "}, {\"buffer\": 0, \"byteOffset\": 0, \"byteLength\": 64}\n  ],\n  \"accessors\"",
        )
    };
    // The tangents are the position floats read four at a time: (-1, -1, 0, 1), (-1, 0, 1, 1),
    // (0, -1, 1, 0), (0, 0, 1, 0).
    let raw = [
        glam::Vec4::new(-1.0, -1.0, 0.0, 1.0),
        glam::Vec4::new(-1.0, 0.0, 1.0, 1.0),
        glam::Vec4::new(0.0, -1.0, 1.0, 0.0),
        glam::Vec4::new(0.0, 0.0, 1.0, 0.0),
    ];
    for (node, mirror) in [
        ("{\"mesh\": 0}", 1.0),
        ("{\"mesh\": 0, \"scale\": [-1, 1, 1]}", -1.0),
    ] {
        quad_gltf(&d, |j| with_tangents(j).replace("{\"mesh\": 0}", node));
        let s = load(&d, "[[meshes]]\ngltf = \"quad.gltf\"\n").unwrap();
        let t = s.meshes[0].tangents.as_ref().expect("TANGENT read");
        for (got, raw) in t.iter().zip(&raw) {
            let xyz = (raw.truncate() * glam::Vec3::new(mirror, 1.0, 1.0)).normalize();
            assert!((got.truncate() - xyz).length() < 1e-6, "{got} vs {xyz}");
            let w = if raw.w < 0.0 { -mirror } else { mirror };
            assert_eq!(got.w, w);
        }
    }
    fs::remove_dir_all(&d).unwrap();
}
