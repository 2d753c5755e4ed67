//! A refusal of the memory budget states the whole need of the step it refuses: a limit of the
//! figure it prints gets past that step, whichever account (the budget's, or a texture's own
//! limit set from what the budget had left) refused it.

use std::fs;
use std::path::PathBuf;

use texel_prepare::{Error, MemoryBudget, PreparedScene, SceneOptions};
use texel_raster::SpecularAa;
use texel_scene::Scene;
use texel_texture::Filter;

/// A fresh scratch directory.
fn scratch(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("texel-budget-{tag}-{}", std::process::id()));
    let _ = fs::remove_dir_all(&d);
    fs::create_dir_all(&d).unwrap();
    d
}

/// The limit, in bytes, that a refusal's message asks for: its "in all" figure, or with
/// nothing held its "needs about" figure (MiB with one decimal).
fn asked(message: &str) -> u64 {
    let figure = match message.find(" MiB in all") {
        Some(end) => message[..end].rsplit(' ').next(),
        None => message
            .split("needs about ")
            .nth(1)
            .and_then(|rest| rest.split(' ').next()),
    };
    let figure = figure.unwrap_or_else(|| panic!("no figure in {message:?}"));
    let (whole, tenth) = figure
        .split_once('.')
        .unwrap_or_else(|| panic!("{figure:?} in {message:?}"));
    let tenths: u64 = whole.parse::<u64>().unwrap() * 10 + tenth.parse::<u64>().unwrap();
    (tenths << 20).div_ceil(10)
}

/// Prepare `scene` and plan `filter` from a limit of `start` bytes, raising the limit to what
/// each refusal asks for, until it succeeds; what each refusal refused, in order.
/// Each refusal must be the budget's, state a larger limit, and refuse another step than the
/// one before it.
fn follow(scene: &Scene, options: &SceneOptions, filter: Filter, start: u64) -> Vec<String> {
    let mut limit = start;
    let mut steps: Vec<String> = Vec::new();
    for _ in 0..16 {
        let mut budget = MemoryBudget::new(limit, "the test's limit");
        let result = PreparedScene::new(scene.clone(), options, &mut budget)
            .and_then(|p| p.plan(Some(filter), &mut budget).map(|_| ()));
        let e = match result {
            Ok(()) => return steps,
            Err(e) => e,
        };
        let message = e.to_string();
        let Error::OverBudget { what, .. } = e else {
            panic!("at a limit of {limit} bytes, a refusal that states no whole need: {message}");
        };
        let next = asked(&message);
        assert!(next > limit, "{message}");
        if let Some(last) = steps.last() {
            assert_ne!(
                *last, what,
                "refused again at the limit its message asked for: {message}"
            );
        }
        steps.push(what);
        limit = next;
    }
    panic!("no end to the refusals: {steps:?}");
}

const HEAD: &str = r#"
[output]
width = 256
height = 192
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

const QUAD: &str = "positions = [[-1.0, -1.0, 0.0], [1.0, -1.0, 0.0], [1.0, 1.0, 0.0], \
                    [-1.0, 1.0, 0.0]]\nuvs = [[0.0, 1.0], [1.0, 1.0], [1.0, 0.0], [0.0, 0.0]]\n\
                    normals = [[0.0, 0.0, 1.0], [0.0, 0.0, 1.0], [0.0, 0.0, 1.0], [0.0, 0.0, 1.0]]\n\
                    triangles = [[0, 1, 2], [0, 2, 3]]\n";

#[test]
fn the_figure_of_a_texture_or_ripmap_refusal_gets_past_it() {
    let text = format!(
        "{HEAD}[textures.big]\nprocedural = \"checker\"\nsize = 1024\n[[meshes]]\ntexture = \"big\"\n{QUAD}"
    );
    let scene = Scene::from_toml_str(&text, std::path::Path::new("/virtual/s.toml")).unwrap();
    let steps = follow(&scene, &SceneOptions::default(), Filter::Ripmap, 1 << 20);
    let refused = |s: &str| steps.iter().any(|w| w.contains(s));
    assert!(refused("frame"), "{steps:?}");
    assert!(refused("loading texture \"big\""), "{steps:?}");
    assert!(refused("ripmap"), "{steps:?}");
}

#[test]
fn the_figure_of_an_image_file_or_moment_map_refusal_gets_past_it() {
    let d = scratch("file");
    let img = image::RgbaImage::from_fn(512, 512, |x, y| {
        image::Rgba([(x * 5 + y) as u8, (y * 3) as u8, (x ^ y) as u8, 255])
    });
    img.save(d.join("base.png")).unwrap();
    let text = format!(
        "{HEAD}[textures.base]\npath = \"base.png\"\n\
         [textures.bumps]\nprocedural = \"bumps\"\nsize = 512\ncolor = \"linear\"\n\
         [materials.m]\nbase_color = \"base\"\nnormal = \"bumps\"\n\
         [[meshes]]\ntexture = \"base\"\nmaterial = \"m\"\n{QUAD}"
    );
    let path = d.join("s.toml");
    fs::write(&path, text).unwrap();
    let scene = Scene::from_path(&path).unwrap();
    let options = SceneOptions {
        specular_aa: Some(SpecularAa::Lean),
        ..SceneOptions::default()
    };
    let steps = follow(&scene, &options, Filter::Trilinear, 1 << 20);
    let refused = |s: &str| steps.iter().any(|w| w.contains(s));
    assert!(refused("loading texture \"base\""), "{steps:?}");
    assert!(refused("LEAN"), "{steps:?}");
    let _ = fs::remove_dir_all(&d);
}
