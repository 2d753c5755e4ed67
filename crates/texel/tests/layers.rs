//! Layered materials through the whole path: scene file, preparation (baking), rasterizer.

use std::path::Path;

use texel::raster::SpecularAa;
use texel::scene::LayerOrder;
use texel::{Filter, MemoryBudget, PreparedScene, Scene, SceneOptions};

const BASE: &str = r#"
[output]
width = 96
height = 64
[camera]
eye = [0.0, 1.2, 2.5]
target = [0.0, 0.0, -2.0]
fovy_deg = 55.0
near = 0.05
far = 100.0
[textures.checks]
procedural = "checker"
size = 64
checks = 8
[textures.bumps]
procedural = "bumps"
size = 64
cells = 4
slope = 0.8
color = "linear"
[textures.rough]
procedural = "noise-heights"
size = 64
cells = 4
color = "linear"
[textures.first]
procedural = "solid"
rgba = [255, 0, 0, 0]
color = "linear"
[[lights]]
type = "directional"
direction = [0.3, 0.6, -1.0]
intensity = [3.0, 3.0, 3.0]
[[lights]]
type = "ambient"
intensity = [0.1, 0.1, 0.1]
[[meshes]]
material = "m"
positions = [[-3.0, 0.0, 1.0], [3.0, 0.0, 1.0], [3.0, 0.0, -12.0], [-3.0, 0.0, -12.0]]
normals = [[0.0, 1.0, 0.0], [0.0, 1.0, 0.0], [0.0, 1.0, 0.0], [0.0, 1.0, 0.0]]
uvs = [[0.0, 0.0], [4.0, 0.0], [4.0, 9.0], [0.0, 9.0]]
triangles = [[0, 1, 2], [0, 2, 3]]
"#;

fn render(material: &str, options: &SceneOptions, filter: Filter) -> Vec<[f32; 4]> {
    let scene = Scene::from_toml_str(&format!("{BASE}{material}"), Path::new("t.toml")).unwrap();
    let mut budget = MemoryBudget::new(1 << 30, "test");
    let prepared = PreparedScene::new(scene, options, &mut budget).unwrap();
    let samplers = prepared.samplers(filter).unwrap();
    let mut settings = prepared.settings();
    settings.target = texel::ColorTarget::Float;
    let frame = texel::render(&settings, &prepared.draws(&samplers)).unwrap();
    frame.color
}

const PLAIN: &str = r#"
[materials.m]
base_color = "checks"
roughness = "rough"
normal = "bumps"
"#;

/// Layer 0 holds the plain material's maps, layer 1 something else; the mask gives layer 0
/// everything.
const LAYERED: &str = r#"
[materials.m]
mask = "first"
[[materials.m.layers]]
base_color = "checks"
roughness = "rough"
normal = "bumps"
[[materials.m.layers]]
base_color = [0.2, 0.9, 0.1]
roughness = 0.1
"#;

/// Mean absolute difference per colour channel, and the largest.
fn differences(a: &[[f32; 4]], b: &[[f32; 4]]) -> (f32, f32) {
    let d: Vec<f32> = a
        .iter()
        .zip(b)
        .flat_map(|(a, b)| (0..3).map(move |c| (a[c] - b[c]).abs()))
        .collect();
    (
        d.iter().sum::<f32>() / d.len() as f32,
        d.iter().copied().fold(0.0, f32::max),
    )
}

/// A layer that the mask weighs alone renders as the same maps in a plain material, under every
/// specular antialiasing method, filtered then blended; blended then filtered, the baked maps are
/// float copies of the layer's taken at level 0, so that order agrees to their resampling.
#[test]
fn a_layer_weighed_alone_renders_as_the_plain_material() {
    for aa in [
        SpecularAa::None,
        SpecularAa::Toksvig,
        SpecularAa::Lean,
        SpecularAa::Projected,
    ] {
        for filter in [Filter::Trilinear, Filter::Aniso16] {
            let options = SceneOptions {
                specular_aa: Some(aa),
                ..SceneOptions::default()
            };
            let plain = render(PLAIN, &options, filter);
            let layered = render(LAYERED, &options, filter);
            let (_, worst) = differences(&plain, &layered);
            assert!(worst < 1e-5, "{aa:?} {filter:?}: {worst}");
            let baked = SceneOptions {
                layer_order: Some(LayerOrder::BlendThenFilter),
                ..options
            };
            let baked = render(LAYERED, &baked, filter);
            let (mean, _) = differences(&plain, &baked);
            assert!(
                mean < 0.01,
                "{aa:?} {filter:?} baked: mean difference {mean}"
            );
        }
    }
}

/// Two layers half and half: the image lies between the two layers' own images (colour is
/// blended linearly), and differs from both.
#[test]
fn an_even_mask_blends_between_the_layers() {
    let half = r#"
[textures.half]
procedural = "solid"
rgba = [128, 128, 0, 0]
color = "linear"
"#;
    let layer = |c: &str| format!("[[materials.m.layers]]\nbase_color = {c}\nroughness = 1.0\n");
    let (r, b) = (layer("[0.9, 0.1, 0.1]"), layer("[0.1, 0.1, 0.9]"));
    let options = SceneOptions::default();
    let draw = |layers: &str| {
        let text = format!("{half}[materials.m]\nmask = \"half\"\n{layers}");
        render(&text, &options, Filter::Trilinear)
    };
    // (One layer ignores the mask, which only names the mesh's texture slot.)
    let (mixed, red, blue) = (draw(&format!("{r}{b}")), draw(&r), draw(&b));
    let mut lit = 0;
    for ((m, r), b) in mixed.iter().zip(&red).zip(&blue) {
        if m[3] == 0.0 {
            continue;
        }
        lit += 1;
        for c in 0..3 {
            let want = 0.5 * (r[c] + b[c]);
            assert!(
                (m[c] - want).abs() < 1e-4 * (1.0 + want),
                "{m:?} {r:?} {b:?}"
            );
        }
    }
    assert!(lit > 1000, "the plane covers the frame: {lit}");
}
