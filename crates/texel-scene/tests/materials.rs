//! Lights, materials and tangents in scene files.

use std::path::Path;

use glam::{Vec2, Vec3};
use texel_scene::{
    ColorInput, Displacement, LayerBlendSpec, LayerOrder, LayerSpec, LightSpec, MaterialSpec, Mesh,
    Procedural, ScalarInput, Scene, SceneError, SpecularAaSpec, MAX_SHADING_SAMPLES,
};

const BASE: &str = r#"
[output]
width = 64
height = 32
[camera]
eye = [0.0, 1.0, 3.0]
target = [0.0, 0.0, 0.0]
fovy_deg = 50.0
near = 0.1
far = 100.0
[textures.grey]
procedural = "solid"
[textures.bumps]
procedural = "bumps"
size = 64
cells = 4
color = "linear"
[textures.rough]
procedural = "checker"
size = 8
color = "linear"
"#;

const MESH: &str = r#"
[[meshes]]
material = "m"
positions = [[-1.0, 0.0, 1.0], [1.0, 0.0, 1.0], [1.0, 0.0, -1.0], [-1.0, 0.0, -1.0]]
uvs = [[0.0, 1.0], [1.0, 1.0], [1.0, 0.0], [0.0, 0.0]]
triangles = [[0, 1, 2], [0, 2, 3]]
"#;

fn parse(extra: &str) -> Result<Scene, SceneError> {
    Scene::from_toml_str(&format!("{BASE}{extra}{MESH}"), Path::new("test.toml"))
}

#[test]
fn lights_and_materials_parse_with_their_defaults() {
    let s = parse(
        r#"
[[lights]]
type = "directional"
direction = [0.0, 1.0, 0.5]
intensity = [3.0, 3.0, 3.0]
[[lights]]
type = "point"
position = [0.0, 2.0, 0.0]
intensity = [10.0, 9.0, 8.0]
[[lights]]
type = "ambient"
intensity = [0.1, 0.1, 0.1]
[materials.m]
base_color = "grey"
roughness = "rough"
metallic = 0.25
normal = "bumps"
normal_scale = 0.5
specular_aa = "toksvig"
"#,
    )
    .unwrap();
    assert_eq!(s.lights.len(), 3);
    assert_eq!(
        s.lights[1],
        LightSpec::Point {
            position: Vec3::new(0.0, 2.0, 0.0),
            intensity: Vec3::new(10.0, 9.0, 8.0)
        }
    );
    let m = &s.materials["m"];
    assert_eq!(m.base_color, ColorInput::Texture("grey".into()));
    assert_eq!(m.roughness, ScalarInput::Texture("rough".into()));
    assert_eq!(m.metallic, ScalarInput::Value(0.25));
    assert_eq!(m.normal.as_deref(), Some("bumps"));
    assert_eq!(m.specular_aa, SpecularAaSpec::Toksvig);
    // The mesh takes its texture from the material's base colour.
    assert_eq!(s.meshes[0].texture, "grey");
    assert_eq!(s.meshes[0].material.as_deref(), Some("m"));
    // Defaults: white, roughness 0.5, metallic 0, no maps, no antialiasing.
    let with_texture = |material: &str| {
        Scene::from_toml_str(
            &format!(
                "{BASE}{material}{}",
                MESH.replace("material = \"m\"", "material = \"m\"\ntexture = \"grey\"")
            ),
            Path::new("test.toml"),
        )
    };
    let s = with_texture("[materials.m]\n").unwrap();
    assert_eq!(s.materials["m"], MaterialSpec::default());
    let d = MaterialSpec::default();
    assert_eq!(d.base_color, ColorInput::Rgb(Vec3::ONE));
    assert_eq!(d.roughness, ScalarInput::Value(0.5));
    assert_eq!(d.metallic, ScalarInput::Value(0.0));
    assert_eq!(
        (d.normal.as_deref(), d.specular_aa, d.shading_samples),
        (None, SpecularAaSpec::None, 1)
    );
    // A constant base colour multiplies the mesh's texture, which must then be given.
    let s = with_texture("[materials.m]\nbase_color = [0.5, 0.25, 1.0]\n").unwrap();
    assert_eq!(
        s.materials["m"].base_color,
        ColorInput::Rgb(Vec3::new(0.5, 0.25, 1.0))
    );
    for material in [
        "[materials.m]\n",
        "[materials.m]\nbase_color = [0.5, 0.25, 1.0]\n",
    ] {
        let e = parse(material).unwrap_err().to_string();
        assert!(e.contains("give texture = NAME"), "{e}");
    }
}

#[test]
fn every_specular_aa_method_and_height_maps_parse() {
    for (name, want) in [
        ("none", SpecularAaSpec::None),
        ("toksvig", SpecularAaSpec::Toksvig),
        ("lean", SpecularAaSpec::Lean),
        ("projected", SpecularAaSpec::Projected),
    ] {
        let s = parse(&format!(
            "[materials.m]\nbase_color = \"grey\"\nnormal = \"bumps\"\nspecular_aa = \"{name}\"\n"
        ))
        .unwrap();
        assert_eq!(s.materials["m"].specular_aa, want);
    }
    for n in [1, 4, MAX_SHADING_SAMPLES] {
        let s = parse(&format!(
            "[materials.m]\nbase_color = \"grey\"\nnormal = \"bumps\"\nshading_samples = {n}\n"
        ))
        .unwrap();
        assert_eq!(s.materials["m"].shading_samples, n);
    }
    for (name, want) in [
        ("none", Displacement::None),
        ("bump", Displacement::Bump),
        ("pom", Displacement::Pom),
        ("tessellate", Displacement::Tessellate),
    ] {
        let s = parse(&format!(
            "[materials.m]\nbase_color = \"grey\"\nheight = \"rough\"\nheight_scale = 0.2\ndisplacement = \"{name}\"\n"
        ))
        .unwrap();
        let m = &s.materials["m"];
        assert_eq!(
            (m.displacement, m.height.as_deref(), m.height_scale),
            (want, Some("rough"), 0.2)
        );
        assert_eq!(want.name(), name);
    }
}

/// Layered materials: keys, defaults, the mesh's texture slot, and every refusal with its reason.
#[test]
fn layered_materials_parse_and_bad_ones_are_refused() {
    let s = parse(
        r#"
[textures.mask]
procedural = "splat"
size = 16
layers = 2
color = "linear"
[materials.m]
mask = "mask"
blend = "height"
blend_depth = 0.1
layer_order = "blend-then-filter"
displacement = "bump"
[[materials.m.layers]]
base_color = "grey"
roughness = 0.7
normal = "bumps"
height = "rough"
[[materials.m.layers]]
base_color = [0.5, 0.4, 0.3]
height = 0.25
"#,
    )
    .unwrap();
    let m = &s.materials["m"];
    assert_eq!(m.layers.len(), 2);
    assert_eq!(
        (m.blend, m.blend_depth, m.layer_order),
        (LayerBlendSpec::Height, 0.1, LayerOrder::BlendThenFilter)
    );
    assert_eq!(
        m.layers[0].height,
        Some(ScalarInput::Texture("rough".into()))
    );
    assert_eq!(m.layers[1].height, Some(ScalarInput::Value(0.25)));
    assert_eq!(m.layers[1].roughness, LayerSpec::default().roughness);
    assert_eq!(
        m.layers[1].base_color,
        ColorInput::Rgb(Vec3::new(0.5, 0.4, 0.3))
    );
    assert!(m.has_heights() && m.textures().contains(&"bumps"));
    // The mesh's texture slot names the mask (the draw shows the layers' colour).
    assert_eq!(s.meshes[0].texture, "mask");
    let mask = "[textures.mask]\nprocedural = \"splat\"\nsize = 16\ncolor = \"linear\"\n";
    let layer = "[[materials.m.layers]]\nbase_color = \"grey\"\n";
    let five = layer.repeat(5);
    let cases = [
        (
            format!("{mask}[materials.m]\nmask = \"mask\"\n{five}"),
            "5 layers given; at most 4",
        ),
        (
            format!("[materials.m]\n{layer}{layer}"),
            "2 layers need a mask",
        ),
        (
            format!("{mask}[materials.m]\nmask = \"mask\"\nroughness = 0.3\n{layer}"),
            "takes base_color, roughness, normal and height from its layers",
        ),
        (
            "[materials.m]\nbase_color = \"grey\"\nmask = \"grey\"\n".to_string(),
            "belong to layered materials",
        ),
        (
            format!("[materials.m]\nmask = \"grey\"\n{layer}"),
            "mask \"grey\" holds weights, not colours",
        ),
        (
            format!("[materials.m]\n{layer}roughness = 2.0\n"),
            "layer 0: roughness = 2 must be in [0, 1]",
        ),
        (
            "[materials.m]\n[[materials.m.layers]]\nnormal = \"grey\"\n".to_string(),
            "layer 0: normal map \"grey\" holds vectors",
        ),
        (
            format!("{mask}[materials.m]\nmask = \"mask\"\nblend_depth = 0.0\n{layer}"),
            "blend_depth = 0 must be in (0, 1]",
        ),
        (
            format!("[materials.m]\n{layer}gloss = 1.0\n"),
            "unknown field `gloss`",
        ),
        (
            format!("[materials.m]\nlayer_order = \"sideways\"\n{layer}"),
            "unknown variant `sideways`",
        ),
        (
            "[materials.m]\n[[materials.m.layers]]\nbase_color = [0.5, 0.5, 0.5]\n".to_string(),
            "reads no texture",
        ),
    ];
    for (extra, needle) in &cases {
        let e = parse(extra).unwrap_err().to_string();
        assert!(e.contains(needle), "{extra}: {e}");
    }
    // A mesh that names a texture under a layered material is refused.
    let text = format!(
        "{BASE}[materials.m]\n{layer}{}",
        MESH.replace("material = \"m\"", "material = \"m\"\ntexture = \"grey\"")
    );
    let e = Scene::from_toml_str(&text, Path::new("t.toml"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("leave texture out"), "{e}");
    // The built-in terrain is a layered material of four layers.
    let t = Scene::load("builtin:terrain").unwrap();
    assert_eq!(t.materials["terrain"].layers.len(), 4);
}

#[test]
fn bad_lights_and_materials_are_refused_with_the_reason() {
    let cases: [(&str, &str); 14] = [
        (
            "[materials.m]\nbase_color = \"grey\"\nshading_samples = 0\n",
            "shading_samples = 0 must be in 1..=8",
        ),
        (
            "[materials.m]\nbase_color = \"grey\"\nshading_samples = 9\n",
            "shading_samples = 9 must be in 1..=8",
        ),
        (
            "[materials.m]\nbase_color = \"grey\"\nshading_samples = -1\n",
            "invalid value: integer `-1`, expected u32",
        ),
        (
            "[materials.m]\nbase_color = \"grey\"\nshininess = 3.0\n",
            "unknown field `shininess`",
        ),
        ("[materials.m]\nbase_color = \"nope\"\n", "texture \"nope\", which is not defined"),
        (
            "[materials.m]\nbase_color = \"grey\"\nroughness = 1.5\n",
            "roughness = 1.5 must be in [0, 1]",
        ),
        (
            "[materials.m]\nbase_color = \"grey\"\nnormal = \"grey\"\n",
            "give it color = \"linear\"",
        ),
        (
            "[materials.m]\nbase_color = \"grey\"\ndisplacement = \"pom\"\n",
            "displacement = \"pom\" needs a height map",
        ),
        (
            "[materials.m]\nbase_color = \"grey\"\ndisplacement = \"bump\"\nheight = \"grey\"\n",
            "height map \"grey\" holds heights, not colours",
        ),
        (
            "[materials.m]\nbase_color = \"grey\"\nheight = \"rough\"\nheight_scale = -0.1\n",
            "height_scale = -0.1 must be at least 0",
        ),
        (
            "[materials.m]\nbase_color = \"grey\"\nspecular_aa = \"sharpen\"\n",
            "unknown variant `sharpen`",
        ),
        (
            "[[lights]]\ntype = \"directional\"\ndirection = [0.0, 0.0, 0.0]\nintensity = [1.0, 1.0, 1.0]\n[materials.m]\nbase_color = \"grey\"\n",
            "direction is zero",
        ),
        (
            "[[lights]]\ntype = \"spot\"\nintensity = [1.0, 1.0, 1.0]\n[materials.m]\nbase_color = \"grey\"\n",
            "spot",
        ),
        (
            "[[lights]]\ntype = \"ambient\"\nintensity = [-1.0, 1.0, 1.0]\n[materials.m]\nbase_color = \"grey\"\n",
            "negative",
        ),
    ];
    for (extra, needle) in cases {
        let e = parse(extra).unwrap_err().to_string();
        assert!(e.contains(needle), "{extra}: {e}");
    }
    let nine: String = (0..9)
        .map(|_| "[[lights]]\ntype = \"ambient\"\nintensity = [0.1, 0.1, 0.1]\n")
        .collect();
    let e = parse(&format!("{nine}[materials.m]\nbase_color = \"grey\"\n"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("more than the 8"), "{e}");
    let e = Scene::from_toml_str(
        &format!(
            "{BASE}{}",
            MESH.replace("material = \"m\"", "material = \"q\"\ntexture = \"grey\"")
        ),
        Path::new("t.toml"),
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("material \"q\" is not defined"), "{e}");
}

/// MikkTSpace tangents follow glTF: `w * cross(n, t)` points up the image (towards decreasing v).
#[test]
fn generated_tangents_point_along_u_and_up_the_image() {
    // A plane in y = 0 facing +y with u along +x: with v along +z up the image is -z, with v
    // along -z it is +z (the two handednesses). Triangles are counter-clockwise seen from +y.
    for (v_dir, want_up, triangles) in [
        (1.0f32, -Vec3::Z, vec![[0, 2, 1], [0, 3, 2]]),
        (-1.0, Vec3::Z, vec![[0, 1, 2], [0, 2, 3]]),
    ] {
        let positions = vec![
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, v_dir),
            Vec3::new(0.0, 0.0, v_dir),
        ];
        let uvs = vec![Vec2::ZERO, Vec2::X, Vec2::ONE, Vec2::Y];
        let mut mesh = Mesh {
            positions,
            uvs,
            normals: Some(vec![Vec3::Y; 4]),
            colors: None,
            triangles,
            texture: "t".into(),
            address_mode_u: texel_texture::AddressMode::Repeat,
            address_mode_v: texel_texture::AddressMode::Repeat,
            filters: None,
            material: None,
            tangents: None,
            uv_mapping: None,
        };
        mesh.generate_tangents();
        for t in mesh.tangents.as_ref().unwrap() {
            assert!((t.truncate() - Vec3::X).length() < 1e-5, "{t}");
            let up = Vec3::Y.cross(t.truncate()) * t.w;
            assert!(
                (up - want_up).length() < 1e-5,
                "v along {v_dir}: up {up}, tangent {t}"
            );
            assert_eq!(t.w.abs(), 1.0);
        }
    }
}

#[test]
fn bump_normals_are_unit_and_slope_limited() {
    let (size, cells, slope) = (64, 4, 0.6f32);
    let mut steepest = 0.0f64;
    for j in 0..size {
        for i in 0..size {
            let n = Procedural::bump_normal(size, cells, slope, i, j);
            let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
            assert!((len - 1.0).abs() < 1e-12);
            steepest = steepest.max((n[0] * n[0] + n[1] * n[1]).sqrt() / n[2]);
        }
    }
    // The gradient's largest magnitude is the slope (reached where both sines peak together,
    // within the sampling of the texel centres).
    assert!(
        steepest <= f64::from(slope) + 1e-9 && steepest > f64::from(slope) * 0.9,
        "{steepest}"
    );
    // Encoded codes decode back within half a code.
    let p = Procedural::Bumps { size, cells, slope };
    let c = p.code(5, 9);
    let n = Procedural::bump_normal(size, cells, slope, 5, 9);
    for k in 0..3 {
        let back = f64::from(c[k]) / 255.0 * 2.0 - 1.0;
        assert!((back - n[k]).abs() <= 1.0 / 255.0 + 1e-12);
    }
}
