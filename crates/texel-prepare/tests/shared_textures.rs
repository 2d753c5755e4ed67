//! Textures that load to the same texels are loaded once, shared, and charged once: the glTF
//! textures of one image, and scene-file textures naming one file in one colour space.

use std::fs;
use std::path::PathBuf;
use std::sync::Arc;

use texel_prepare::memory::{raster_bytes, FRAME_BYTES_PER_PIXEL, TRIANGLE_BYTES, VERTEX_BYTES};
use texel_prepare::{ColorHandling, MemoryBudget, PreparedScene, SceneOptions};
use texel_raster::SpecularAa;
use texel_scene::Scene;
use texel_texture::{Filter, Limits, Texture};

/// A fresh scratch directory.
fn scratch(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("texel-prepare-{tag}-{}", std::process::id()));
    let _ = fs::remove_dir_all(&d);
    fs::create_dir_all(&d).unwrap();
    d
}

/// A `side` x `side` PNG with texels that vary (so its pyramid is not trivial).
fn png(side: u32) -> Vec<u8> {
    let img = image::RgbaImage::from_fn(side, side, |x, y| {
        image::Rgba([(x * 7 + y) as u8, (y * 3) as u8, (x ^ y) as u8, 255])
    });
    let mut out = std::io::Cursor::new(Vec::new());
    img.write_to(&mut out, image::ImageFormat::Png).unwrap();
    out.into_inner()
}

/// The head of a scene file: a small frame looking at the unit quad.
const HEAD: &str = r#"
[output]
width = 64
height = 48
[camera]
eye = [0.0, 0.0, 3.0]
target = [0.0, 0.0, 0.0]
fovy_deg = 60.0
near = 0.1
far = 100.0
[[lights]]
type = "directional"
direction = [0.3, 0.5, 1.0]
intensity = [3.0, 3.0, 3.0]
"#;

/// A GLB of `n` quads (one mesh, `n` primitives), primitive `i` with material `i`, whose base
/// colour and normal textures are both glTF texture `i`; every texture reads image 0 (a PNG in
/// the binary chunk) through one of two samplers.
fn many_textures_glb(n: usize, image: &[u8]) -> Vec<u8> {
    let mut bin = Vec::new();
    for p in [
        [-1.0f32, -1.0, 0.0],
        [1.0, -1.0, 0.0],
        [1.0, 1.0, 0.0],
        [-1.0, 1.0, 0.0],
    ] {
        p.iter().for_each(|x| bin.extend(x.to_le_bytes()));
    }
    for _ in 0..4 {
        [0.0f32, 0.0, 1.0]
            .iter()
            .for_each(|x| bin.extend(x.to_le_bytes()));
    }
    for uv in [[0.0f32, 1.0], [1.0, 1.0], [1.0, 0.0], [0.0, 0.0]] {
        uv.iter().for_each(|x| bin.extend(x.to_le_bytes()));
    }
    for i in [0u16, 1, 2, 0, 2, 3] {
        bin.extend(i.to_le_bytes());
    }
    assert_eq!(bin.len(), 140);
    bin.extend(image);
    let buffer_len = bin.len();
    bin.resize(bin.len().next_multiple_of(4), 0);
    let primitives: Vec<String> = (0..n)
        .map(|i| {
            format!(
                r#"{{"attributes": {{"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2}}, "indices": 3, "material": {i}}}"#
            )
        })
        .collect();
    let materials: Vec<String> = (0..n)
        .map(|i| {
            format!(
                r#"{{"pbrMetallicRoughness": {{"baseColorTexture": {{"index": {i}}}}}, "normalTexture": {{"index": {i}}}}}"#
            )
        })
        .collect();
    let textures: Vec<String> = (0..n)
        .map(|i| format!(r#"{{"source": 0, "sampler": {}}}"#, i % 2))
        .collect();
    let json = format!(
        r#"{{
  "asset": {{"version": "2.0"}},
  "scene": 0,
  "scenes": [{{"nodes": [0]}}],
  "nodes": [{{"mesh": 0}}],
  "meshes": [{{"primitives": [{primitives}]}}],
  "materials": [{materials}],
  "textures": [{textures}],
  "samplers": [{{"wrapS": 33071, "wrapT": 33071}}, {{"wrapS": 10497, "wrapT": 33648}}],
  "images": [{{"bufferView": 4, "mimeType": "image/png"}}],
  "buffers": [{{"byteLength": {buffer_len}}}],
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
        primitives = primitives.join(", "),
        materials = materials.join(", "),
        textures = textures.join(", "),
        image_len = image.len(),
    );
    let mut json = json.into_bytes();
    json.resize(json.len().next_multiple_of(4), b' ');
    let mut glb = Vec::new();
    glb.extend(b"glTF");
    glb.extend(2u32.to_le_bytes());
    glb.extend(((12 + 8 + json.len() + 8 + bin.len()) as u32).to_le_bytes());
    glb.extend((json.len() as u32).to_le_bytes());
    glb.extend(0x4E4F_534Au32.to_le_bytes());
    glb.extend(&json);
    glb.extend((bin.len() as u32).to_le_bytes());
    glb.extend(0x004E_4942u32.to_le_bytes());
    glb.extend(&bin);
    glb
}

/// What [`PreparedScene::new`] charges before the textures: the meshes, rasterizing them and
/// one frame.
fn geometry_bytes(scene: &Scene) -> u64 {
    let (w, h) = (scene.output.width, scene.output.height);
    let verts: u64 = scene.meshes.iter().map(|m| m.positions.len() as u64).sum();
    let tris: u64 = scene.meshes.iter().map(|m| m.triangles.len() as u64).sum();
    verts * VERTEX_BYTES
        + tris * TRIANGLE_BYTES
        + raster_bytes(scene, w, h)
        + u64::from(w) * u64::from(h) * FRAME_BYTES_PER_PIXEL
}

/// The distinct textures of `prepared`, by address.
fn distinct(prepared: &PreparedScene) -> Vec<&Arc<Texture>> {
    let mut out: Vec<&Arc<Texture>> = Vec::new();
    for t in prepared.textures.values() {
        if !out.iter().any(|o| Arc::ptr_eq(o, t)) {
            out.push(t);
        }
    }
    out
}

/// Textures `name` and `other` of `prepared` are one texture.
fn shared(prepared: &PreparedScene, name: &str, other: &str) -> bool {
    Arc::ptr_eq(&prepared.textures[name], &prepared.textures[other])
}

#[test]
fn gltf_textures_of_one_image_are_decoded_and_charged_once() {
    const N: usize = 400;
    let d = scratch("glb");
    let image = png(256);
    fs::write(d.join("many.glb"), many_textures_glb(N, &image)).unwrap();
    let path = d.join("scene.toml");
    fs::write(&path, format!("{HEAD}[[meshes]]\ngltf = \"many.glb\"\n")).unwrap();
    let scene = Scene::from_path(&path).unwrap();
    assert_eq!(scene.meshes.len(), N);
    let geometry = geometry_bytes(&scene);
    // One decode of the image as sRGB and one as linear, with their pyramids and the normal
    // map's LEAN moments, all well within the limit; a decode per texture would take more
    // than the limit holds.
    let one = Texture::decode(&image, texel_texture::ColorSpace::Srgb, &Limits::default())
        .unwrap()
        .pyramid_bytes();
    let limit = geometry + 16 * one;
    assert!(2 * N as u64 * one > limit);
    let mut budget = MemoryBudget::new(limit, "the test's limit");
    let options = SceneOptions {
        specular_aa: Some(SpecularAa::Lean),
        ..SceneOptions::default()
    };
    let prepared = PreparedScene::new(scene, &options, &mut budget).unwrap();
    assert_eq!(prepared.textures.len(), 2 * N);
    let textures = distinct(&prepared);
    assert_eq!(
        textures.len(),
        2,
        "the sRGB and the linear texture of image 0"
    );
    let srgb = "many.glb#texture0.srgb";
    let linear = "many.glb#texture0.linear";
    for i in 1..N {
        assert!(shared(
            &prepared,
            srgb,
            &format!("many.glb#texture{i}.srgb")
        ));
        assert!(shared(
            &prepared,
            linear,
            &format!("many.glb#texture{i}.linear")
        ));
    }
    assert!(!shared(&prepared, srgb, linear));
    let lean = texel_raster::material::lean_map(&prepared.textures[linear], &Limits::default())
        .unwrap()
        .pyramid_bytes();
    let pyramids: u64 = textures.iter().map(|t| t.pyramid_bytes()).sum();
    assert_eq!(pyramids, 2 * one);
    assert_eq!(budget.used(), geometry + pyramids + lean);
    // The textures' own samplers stay theirs: the two of the file.
    let plan = prepared.plan(Some(Filter::Trilinear), &mut budget).unwrap();
    assert_eq!(plan.samplers().len(), N + 2);
    let _ = fs::remove_dir_all(&d);
}

#[test]
fn scene_textures_naming_one_file_are_loaded_once_per_colour_space() {
    const N: usize = 200;
    let d = scratch("files");
    fs::create_dir_all(d.join("tex")).unwrap();
    fs::write(d.join("tex/a.png"), png(256)).unwrap();
    let mut text = HEAD.to_string();
    // The same file under three spellings, as colour; once more as data.
    let spellings = ["tex/a.png", "./tex/a.png", "tex/../tex/a.png"];
    for k in 0..N {
        let p = spellings[k % spellings.len()];
        text += &format!("[textures.t{k}]\npath = \"{p}\"\n");
    }
    text += "[textures.data]\npath = \"tex/a.png\"\ncolor = \"linear\"\n";
    let quad = "positions = [[-1.0, -1.0, 0.0], [1.0, -1.0, 0.0], [1.0, 1.0, 0.0]]\n\
                uvs = [[0.0, 1.0], [1.0, 1.0], [1.0, 0.0]]\ntriangles = [[0, 1, 2]]\n";
    for k in 0..N {
        text += &format!("[[meshes]]\ntexture = \"t{k}\"\n{quad}");
    }
    text += &format!("[[meshes]]\ntexture = \"data\"\n{quad}");
    let path = d.join("scene.toml");
    fs::write(&path, text).unwrap();
    let scene = Scene::from_path(&path).unwrap();
    let geometry = geometry_bytes(&scene);
    let one = Texture::load(
        d.join("tex/a.png"),
        texel_texture::ColorSpace::Srgb,
        &Limits::default(),
    )
    .unwrap()
    .pyramid_bytes();
    let limit = geometry + 16 * one;
    assert!(N as u64 * one > limit);

    let mut budget = MemoryBudget::new(limit, "the test's limit");
    let prepared =
        PreparedScene::new(scene.clone(), &SceneOptions::default(), &mut budget).unwrap();
    assert_eq!(distinct(&prepared).len(), 2);
    for k in 1..N {
        assert!(shared(&prepared, "t0", &format!("t{k}")));
    }
    assert!(!shared(&prepared, "t0", "data"));
    assert_eq!(budget.used(), geometry + 2 * one);

    // `--color raw` reads every colour texture as linear: one texture then.
    let mut budget = MemoryBudget::new(limit, "the test's limit");
    let raw = SceneOptions {
        color: ColorHandling::Raw,
        ..SceneOptions::default()
    };
    let prepared = PreparedScene::new(scene, &raw, &mut budget).unwrap();
    assert_eq!(distinct(&prepared).len(), 1);
    assert!(shared(&prepared, "t1", "data"));
    assert_eq!(budget.used(), geometry + one);
    let _ = fs::remove_dir_all(&d);
}

#[test]
fn ripmaps_of_a_shared_texture_are_charged_once() {
    let d = scratch("ripmap");
    fs::write(d.join("a.png"), png(64)).unwrap();
    let quad = "positions = [[-1.0, -1.0, 0.0], [1.0, -1.0, 0.0], [1.0, 1.0, 0.0]]\n\
                uvs = [[0.0, 1.0], [1.0, 1.0], [1.0, 0.0]]\ntriangles = [[0, 1, 2]]\n";
    let text = format!(
        "{HEAD}[textures.a]\npath = \"a.png\"\n[textures.b]\npath = \"a.png\"\n\
         [[meshes]]\ntexture = \"a\"\n{quad}[[meshes]]\ntexture = \"b\"\n{quad}"
    );
    let path = d.join("scene.toml");
    fs::write(&path, text).unwrap();
    let scene = Scene::from_path(&path).unwrap();
    let mut budget = MemoryBudget::new(1 << 30, "the test's limit");
    let prepared = PreparedScene::new(scene, &SceneOptions::default(), &mut budget).unwrap();
    let before = budget.used();
    let plan = prepared.plan(Some(Filter::Ripmap), &mut budget).unwrap();
    let a = &prepared.textures["a"];
    let ripmap = a.structure_bytes(plan.samplers()[0].descriptor()) - a.pyramid_bytes();
    assert_eq!(budget.used() - before, ripmap);
    assert_eq!(plan.structure_bytes(), ripmap + a.pyramid_bytes());
    let _ = fs::remove_dir_all(&d);
}
