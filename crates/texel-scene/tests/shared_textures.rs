//! What "the same texture" means ([`TextureKey`], [`Scene::texture_groups`]): one glTF image
//! read once and shared by every texture that names it, one file under any spelling of its path,
//! in one colour space; and [`Scene::load_textures`] loads each once.

use std::fs;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use base64::Engine;
use texel_scene::{EncodedImage, Procedural, Scene, TextureSource, TextureSpec};
use texel_texture::{ColorSpace, Limits};

/// A fresh scratch directory.
fn scratch(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("texel-scene-shared-{tag}-{}", std::process::id()));
    let _ = fs::remove_dir_all(&d);
    fs::create_dir_all(&d).unwrap();
    d
}

/// A 16 x 16 PNG.
fn png() -> Vec<u8> {
    let img =
        image::RgbaImage::from_fn(16, 16, |x, y| image::Rgba([x as u8 * 16, y as u8, 7, 255]));
    let mut out = std::io::Cursor::new(Vec::new());
    img.write_to(&mut out, image::ImageFormat::Png).unwrap();
    out.into_inner()
}

const HEAD: &str = r#"
[output]
width = 32
height = 32
[camera]
eye = [0.0, 0.0, 3.0]
target = [0.0, 0.0, 0.0]
fovy_deg = 60.0
near = 0.1
far = 100.0
"#;

const TRI: &str = "positions = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]\n\
                   uvs = [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]\ntriangles = [[0, 1, 2]]\n";

#[test]
fn keys_compare_what_is_loaded() {
    let d = scratch("keys");
    fs::create_dir_all(d.join("sub")).unwrap();
    fs::write(d.join("a.png"), png()).unwrap();
    let file = |p: &Path, color| TextureSpec::new(TextureSource::File(p.to_path_buf()), color);
    let a = file(&d.join("a.png"), ColorSpace::Srgb);
    let a2 = file(&d.join("sub/../a.png"), ColorSpace::Srgb);
    let a_linear = file(&d.join("a.png"), ColorSpace::Linear);
    assert_eq!(a.key(None), a2.key(None));
    assert_ne!(a.key(None), a_linear.key(None));
    // The override decides the colour space: raw reads both as linear.
    assert_eq!(
        a.key(Some(ColorSpace::Linear)),
        a_linear.key(Some(ColorSpace::Linear))
    );
    // Encoded bytes: one allocation, or equal contents; the sampler plays no part.
    let bytes: Arc<[u8]> = png().into();
    let encoded = |bytes: Arc<[u8]>| {
        TextureSpec::new(
            TextureSource::Encoded(EncodedImage {
                bytes,
                origin: "test".into(),
            }),
            ColorSpace::Srgb,
        )
    };
    let e1 = encoded(Arc::clone(&bytes));
    let mut e2 = encoded(Arc::clone(&bytes));
    e2.sampler = Some(texel_scene::TextureSampler {
        address_mode_u: texel_texture::AddressMode::ClampToEdge,
        address_mode_v: texel_texture::AddressMode::Repeat,
        filters: Default::default(),
    });
    assert_eq!(e1.key(None), e2.key(None));
    assert_eq!(e1.key(None), encoded(png().into()).key(None));
    let mut other = png();
    *other.last_mut().unwrap() ^= 1;
    assert_ne!(e1.key(None), encoded(other.into()).key(None));
    // A file and its bytes in memory are read apart.
    assert_ne!(a.key(None), e1.key(None));
    let checker = |checks| {
        TextureSpec::new(
            TextureSource::Procedural(Procedural::Checker {
                width: 8,
                height: 8,
                checks,
            }),
            ColorSpace::Srgb,
        )
    };
    assert_eq!(checker(2).key(None), checker(2).key(None));
    assert_ne!(checker(2).key(None), checker(4).key(None));
    let _ = fs::remove_dir_all(&d);
}

#[test]
fn one_file_under_several_names_is_loaded_once_per_colour_space() {
    let d = scratch("files");
    fs::create_dir_all(d.join("tex")).unwrap();
    fs::write(d.join("tex/a.png"), png()).unwrap();
    let text = format!(
        "{HEAD}[textures.a]\npath = \"tex/a.png\"\n[textures.b]\npath = \"./tex/../tex/a.png\"\n\
         [textures.c]\npath = \"tex/a.png\"\ncolor = \"linear\"\n\
         [[meshes]]\ntexture = \"a\"\n{TRI}[[meshes]]\ntexture = \"b\"\n{TRI}\
         [[meshes]]\ntexture = \"c\"\n{TRI}"
    );
    let path = d.join("s.toml");
    fs::write(&path, text).unwrap();
    let scene = Scene::from_path(&path).unwrap();
    let groups = scene.texture_groups(None).unwrap();
    let names: Vec<Vec<&str>> = groups
        .iter()
        .map(|g| g.uses.iter().map(|u| u.name).collect())
        .collect();
    assert_eq!(names, [vec!["a", "b"], vec!["c"]]);
    assert_eq!(
        (groups[0].color, groups[1].color),
        (ColorSpace::Srgb, ColorSpace::Linear)
    );
    let t = scene.load_textures(None, &Limits::default()).unwrap();
    assert!(Arc::ptr_eq(&t["a"], &t["b"]) && !Arc::ptr_eq(&t["a"], &t["c"]));
    let raw = scene
        .load_textures(Some(ColorSpace::Linear), &Limits::default())
        .unwrap();
    assert!(Arc::ptr_eq(&raw["a"], &raw["c"]));
    let _ = fs::remove_dir_all(&d);
}

#[test]
fn gltf_textures_of_one_image_share_its_bytes() {
    const N: usize = 50;
    let d = scratch("gltf");
    let mut buf = Vec::new();
    for p in [[-1.0f32, -1.0, 0.0], [1.0, -1.0, 0.0], [1.0, 1.0, 0.0]] {
        p.iter().for_each(|x| buf.extend(x.to_le_bytes()));
    }
    for uv in [[0.0f32, 1.0], [1.0, 1.0], [1.0, 0.0]] {
        uv.iter().for_each(|x| buf.extend(x.to_le_bytes()));
    }
    let b64 = |b: &[u8]| base64::engine::general_purpose::STANDARD.encode(b);
    let prims: Vec<String> = (0..N)
        .map(|i| {
            format!(r#"{{"attributes": {{"POSITION": 0, "TEXCOORD_0": 1}}, "material": {i}}}"#)
        })
        .collect();
    let materials: Vec<String> = (0..N)
        .map(|i| {
            format!(
                r#"{{"pbrMetallicRoughness": {{"baseColorTexture": {{"index": {i}}}, "metallicRoughnessTexture": {{"index": {i}}}}}}}"#
            )
        })
        .collect();
    let textures: Vec<String> = (0..N).map(|_| r#"{"source": 0}"#.to_string()).collect();
    let json = format!(
        r#"{{"asset": {{"version": "2.0"}}, "scene": 0, "scenes": [{{"nodes": [0]}}],
  "nodes": [{{"mesh": 0}}], "meshes": [{{"primitives": [{prims}]}}],
  "materials": [{materials}], "textures": [{textures}],
  "images": [{{"uri": "data:image/png;base64,{image}"}}],
  "buffers": [{{"uri": "data:application/octet-stream;base64,{buffer}", "byteLength": {len}}}],
  "bufferViews": [{{"buffer": 0, "byteOffset": 0, "byteLength": 36}},
                  {{"buffer": 0, "byteOffset": 36, "byteLength": 24}}],
  "accessors": [
    {{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [-1, -1, 0], "max": [1, 1, 0]}},
    {{"bufferView": 1, "componentType": 5126, "count": 3, "type": "VEC2"}}]}}"#,
        prims = prims.join(", "),
        materials = materials.join(", "),
        textures = textures.join(", "),
        image = b64(&png()),
        buffer = b64(&buf),
        len = buf.len(),
    );
    fs::write(d.join("many.gltf"), json).unwrap();
    let path = d.join("s.toml");
    fs::write(&path, format!("{HEAD}[[meshes]]\ngltf = \"many.gltf\"\n")).unwrap();
    let scene = Scene::from_path(&path).unwrap();
    let bytes: Vec<&Arc<[u8]>> = scene
        .textures
        .values()
        .filter_map(|t| match &t.source {
            TextureSource::Encoded(e) => Some(&e.bytes),
            _ => None,
        })
        .collect();
    assert_eq!(
        bytes.len(),
        2 * N,
        "texture i as sRGB colour and as linear data"
    );
    assert!(bytes.iter().all(|b| Arc::ptr_eq(b, bytes[0])));
    let groups = scene.texture_groups(None).unwrap();
    assert_eq!(groups.len(), 2);
    assert!(groups.iter().all(|g| g.uses.len() == N));
    let t = scene.load_textures(None, &Limits::default()).unwrap();
    for i in 1..N {
        let srgb = format!("many.gltf#texture{i}.srgb");
        let linear = format!("many.gltf#texture{i}.linear");
        assert!(Arc::ptr_eq(&t[&srgb], &t["many.gltf#texture0.srgb"]));
        assert!(Arc::ptr_eq(&t[&linear], &t["many.gltf#texture0.linear"]));
    }
    let _ = fs::remove_dir_all(&d);
}
