//! Scene files: TOML, as `scenes/ground.toml` shows, parsed with serde.
//!
//! ```toml
//! [output]                      # width, height (1..=16384); background = [r, g, b, a] sRGB 8-bit
//! width = 1280                  #   (default [0, 0, 0, 255])
//! height = 720
//! [camera]                      # eye, target, up (default [0, 1, 0]), fovy_deg, near, far
//! eye = [0.0, 1.0, 0.0]
//! target = [0.0, 0.75, -10.0]
//! fovy_deg = 50.0
//! near = 0.05
//! far = 2000.0
//! [textures.checker]            # path = "file.png" (relative to the scene file) or
//! procedural = "checker"        # procedural = checker | zoneplate | grid | uv | solid | bumps |
//! size = 1024                   # waves | wave-heights | bricks | brick-heights | noise |
//! checks = 8                    # noise-heights | splat | globe | globe-mercator;
//!                               # color = "srgb" (default) | "linear";
//! color = "srgb"                # see `Procedural` for each kind's parameters (size or width +
//!                               # height, checks, cells, line_width, rgba, slope, waves, seed,
//!                               # rows, columns, mortar, bevel, layers)
//! [[meshes]]                    # texture = NAME; address_mode (both axes), address_mode_u/_v:
//! texture = "checker"           # repeat | mirror-repeat | clamp-to-edge | clamp-to-border |
//! address_mode = "repeat"       # mirror-clamp-to-edge (default repeat, or the glTF sampler's)
//! positions = [[-1.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]
//! uvs = [[0.0, 1.0], [1.0, 1.0], [0.5, 0.0]]
//! triangles = [[0, 1, 2]]       # optional: normals = [[x, y, z], ...], colors = [[r, g, b, a], ...]
//! # or: obj = "file.obj"  /  gltf = "file.gltf" or "file.glb" (relative to the scene file)
//! # material = "NAME" (optional; `texture` may then be left out if the material's base_color
//! # is a texture; a glTF mesh without one uses the file's own materials and textures, named
//! # "FILE#materialN" and "FILE#textureN.srgb" / ".linear", and `texture` may be left out)
//! # sphere_uv = "equirect" | "mercator" (optional): the uvs are that projection of each point's
//! # direction from sphere_centre = [x, y, z] (default origin), Mercator cut at
//! # mercator_cut_deg (default 85.0511, Web Mercator's square); drawn exactly per pixel
//! # (the CLI's --surface-uv vertex interpolates the uvs instead)
//! [[lights]]                    # type = "directional" (direction towards the light) |
//! type = "directional"          #   "point" (position) | "ambient"; intensity = [r, g, b]
//! direction = [0.0, 0.25, -1.0] #   linear (glTF KHR_lights_punctual units); at most 8 lights
//! intensity = [5.0, 5.0, 5.0]
//! [environment]                 # path = "map.hdr" (PNG, JPEG, EXR or HDR), faces = [six files
//! procedural = "sky"            #   +x -x +y -y +z -z] or procedural = "sky" (size: equirect
//! intensity = 1.0               #   width 1024, cube face 256, octahedral side 512; sun = [x, y,
//! background = true             #   z] towards the sun; seed); mapping = "equirect" | "cube"
//!                               #   (path: a 4x3 or 3x4 cross) | "octahedral" (square);
//!                               #   intensity = k or [r, g, b]; background (default true)
//! [materials.glossy]            # base_color = "TEXTURE" or [r, g, b] (linear, default white);
//! base_color = "checker"        # roughness, metallic = number in [0, 1] or "TEXTURE" (red);
//! roughness = 0.25              # normal = "TEXTURE" (color = "linear"), normal_scale;
//! normal = "bumps"              # specular_aa = "none" | "toksvig" | "lean" | "projected";
//! specular_aa = "toksvig"       # height = "TEXTURE" (red, color = "linear"), height_scale
//!                               # (world units, default 0.05), displacement = "none" | "bump" |
//!                               # "pom" | "tessellate"; occlusion = "TEXTURE" (red, linear; dims
//!                               # ambient light), occlusion_strength (default 1);
//!                               # shading_samples = 1..8 (default 1: adaptive shading
//!                               # sub-samples per pixel axis where the normal turns fast)
//! [materials.terrain]           # layered: mask = "TEXTURE" (linear; channel k weighs layer k),
//! mask = "splat"                #   blend = "linear" | "height", blend_depth (default 0.2),
//! blend = "height"              #   layer_order = "filter-then-blend" | "blend-then-filter";
//! [[materials.terrain.layers]]  #   up to 4 layers: base_color, roughness, normal, normal_scale,
//! base_color = "grass"          #   height = "TEXTURE" or number in [0, 1]; metallic,
//! height = "grass-heights"      #   height_scale, displacement and specular_aa still apply
//! ```
//!
//! Every table denies unknown keys; a syntax or type error is reported with its line and column.
//! Semantic checks (sizes, indices, finiteness, camera) follow in [`Scene::validate`].

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use glam::{Vec2, Vec3, Vec4};
use serde::Deserialize;
use texel_texture::{AddressMode, ColorSpace};

use crate::camera::Camera;
use crate::environment::{default_sky_size, EnvironmentSource, EnvironmentSpec, Sky};
use crate::error::SceneError;
use crate::gltf_import::GltfScene;
use crate::limits::SceneLimits;
use crate::model::{
    ColorInput, Displacement, LayerBlendSpec, LayerOrder, LayerSpec, LightSpec, MaterialSpec, Mesh,
    Output, ScalarInput, Scene, SpecularAaSpec, SphereUv, TextureSource, TextureSpec,
};
use crate::procedural::{NoiseKind, Procedural};
use texel_texture::mapping::sphere::Mapping;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawScene {
    output: RawOutput,
    camera: RawCamera,
    #[serde(default)]
    textures: BTreeMap<String, RawTexture>,
    #[serde(default)]
    meshes: Vec<RawMesh>,
    #[serde(default)]
    lights: Vec<RawLight>,
    #[serde(default)]
    materials: BTreeMap<String, RawMaterial>,
    environment: Option<RawEnvironment>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawEnvironment {
    path: Option<String>,
    faces: Option<[String; 6]>,
    procedural: Option<SkyName>,
    mapping: Option<MappingName>,
    intensity: Option<RawIntensity>,
    background: Option<bool>,
    size: Option<u32>,
    sun: Option<[f32; 3]>,
    seed: Option<u32>,
}

#[derive(Deserialize, Clone, Copy)]
#[serde(rename_all = "lowercase")]
enum SkyName {
    Sky,
}

#[derive(Deserialize, Clone, Copy, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
enum MappingName {
    Equirect,
    Cube,
    Octahedral,
}

/// One number for every channel, or `[r, g, b]`.
#[derive(Deserialize, Clone, Copy)]
#[serde(untagged)]
enum RawIntensity {
    Gray(f32),
    Rgb([f32; 3]),
}

/// The `[environment]` table as the model's.
fn environment_spec(raw: RawEnvironment, base: &Path) -> Result<EnvironmentSpec, SceneError> {
    let bad = |s: &str| Err(SceneError::Environment(s.to_string()));
    let mapping = match (raw.mapping, &raw.faces) {
        (None | Some(MappingName::Cube), Some(_)) => Mapping::Cube,
        (Some(_), Some(_)) => {
            return bad("faces = [six files] is a cube map's (mapping = \"cube\")")
        }
        (None | Some(MappingName::Equirect), None) => Mapping::Equirect,
        (Some(MappingName::Cube), None) => Mapping::Cube,
        (Some(MappingName::Octahedral), None) => Mapping::Octahedral,
    };
    let sky_keys = raw.size.is_some() || raw.sun.is_some() || raw.seed.is_some();
    if sky_keys && raw.procedural.is_none() {
        return bad("size, sun and seed are the procedural sky's; a file map takes none");
    }
    let one = "give exactly one of path = \"FILE\", faces = [six files] and procedural = \"sky\"";
    let source = match (raw.path, raw.faces, raw.procedural) {
        (Some(path), None, None) => EnvironmentSource::File(base.join(path)),
        (None, Some(faces), None) => {
            EnvironmentSource::Faces(Box::new(faces.map(|f| base.join(f))))
        }
        (None, None, Some(SkyName::Sky)) => {
            let d = Sky::default();
            EnvironmentSource::Sky(Sky {
                width: raw.size.unwrap_or(default_sky_size(mapping)),
                sun: raw.sun.map_or(d.sun, Vec3::from),
                seed: raw.seed.unwrap_or(d.seed),
            })
        }
        _ => return bad(one),
    };
    Ok(EnvironmentSpec {
        mapping,
        source,
        intensity: match raw.intensity {
            None => Vec3::ONE,
            Some(RawIntensity::Gray(k)) => Vec3::splat(k),
            Some(RawIntensity::Rgb(c)) => Vec3::from(c),
        },
        background: raw.background.unwrap_or(true),
    })
}

#[derive(Deserialize)]
#[serde(tag = "type", rename_all = "lowercase", deny_unknown_fields)]
enum RawLight {
    Directional {
        direction: [f32; 3],
        intensity: [f32; 3],
    },
    Point {
        position: [f32; 3],
        intensity: [f32; 3],
    },
    Ambient {
        intensity: [f32; 3],
    },
}

/// A texture name or a constant.
#[derive(Deserialize)]
#[serde(untagged)]
enum RawColor {
    Texture(String),
    Rgb([f32; 3]),
}

#[derive(Deserialize)]
#[serde(untagged)]
enum RawScalar {
    Texture(String),
    Value(f32),
}

#[derive(Deserialize, Clone, Copy)]
#[serde(rename_all = "lowercase")]
enum RawDisplacement {
    None,
    Bump,
    Pom,
    Tessellate,
}

#[derive(Deserialize, Clone, Copy)]
#[serde(rename_all = "lowercase")]
enum RawSpecularAa {
    None,
    Toksvig,
    Lean,
    Projected,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawMaterial {
    base_color: Option<RawColor>,
    roughness: Option<RawScalar>,
    metallic: Option<RawScalar>,
    normal: Option<String>,
    normal_scale: Option<f32>,
    height: Option<String>,
    height_scale: Option<f32>,
    displacement: Option<RawDisplacement>,
    specular_aa: Option<RawSpecularAa>,
    layers: Option<Vec<RawLayer>>,
    mask: Option<String>,
    blend: Option<RawBlend>,
    blend_depth: Option<f32>,
    layer_order: Option<RawLayerOrder>,
    occlusion: Option<String>,
    occlusion_strength: Option<f32>,
    shading_samples: Option<u32>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawLayer {
    base_color: Option<RawColor>,
    roughness: Option<RawScalar>,
    normal: Option<String>,
    normal_scale: Option<f32>,
    height: Option<RawScalar>,
}

#[derive(Deserialize, Clone, Copy)]
#[serde(rename_all = "lowercase")]
enum RawBlend {
    Linear,
    Height,
}

#[derive(Deserialize, Clone, Copy)]
#[serde(rename_all = "kebab-case")]
enum RawLayerOrder {
    FilterThenBlend,
    BlendThenFilter,
}

fn scalar(s: Option<RawScalar>, default: ScalarInput) -> ScalarInput {
    match s {
        Some(RawScalar::Texture(t)) => ScalarInput::Texture(t),
        Some(RawScalar::Value(v)) => ScalarInput::Value(v),
        None => default,
    }
}

fn color(c: Option<RawColor>, default: ColorInput) -> ColorInput {
    match c {
        Some(RawColor::Texture(t)) => ColorInput::Texture(t),
        Some(RawColor::Rgb(c)) => ColorInput::Rgb(c.into()),
        None => default,
    }
}

fn layer_spec(l: RawLayer) -> LayerSpec {
    let d = LayerSpec::default();
    LayerSpec {
        base_color: color(l.base_color, d.base_color),
        roughness: scalar(l.roughness, d.roughness),
        normal: l.normal,
        normal_scale: l.normal_scale.unwrap_or(d.normal_scale),
        height: l.height.map(|h| scalar(Some(h), ScalarInput::Value(0.5))),
    }
}

fn light_spec(l: RawLight) -> LightSpec {
    match l {
        RawLight::Directional {
            direction,
            intensity,
        } => LightSpec::Directional {
            direction: direction.into(),
            intensity: intensity.into(),
        },
        RawLight::Point {
            position,
            intensity,
        } => LightSpec::Point {
            position: position.into(),
            intensity: intensity.into(),
        },
        RawLight::Ambient { intensity } => LightSpec::Ambient {
            intensity: intensity.into(),
        },
    }
}

fn material_spec(m: RawMaterial) -> MaterialSpec {
    let d = MaterialSpec::default();
    MaterialSpec {
        base_color: color(m.base_color, d.base_color),
        roughness: scalar(m.roughness, d.roughness),
        metallic: scalar(m.metallic, d.metallic),
        normal: m.normal,
        normal_scale: m.normal_scale.unwrap_or(d.normal_scale),
        height: m.height,
        height_scale: m.height_scale.unwrap_or(d.height_scale),
        displacement: match m.displacement {
            None | Some(RawDisplacement::None) => Displacement::None,
            Some(RawDisplacement::Bump) => Displacement::Bump,
            Some(RawDisplacement::Pom) => Displacement::Pom,
            Some(RawDisplacement::Tessellate) => Displacement::Tessellate,
        },
        specular_aa: match m.specular_aa {
            None | Some(RawSpecularAa::None) => SpecularAaSpec::None,
            Some(RawSpecularAa::Toksvig) => SpecularAaSpec::Toksvig,
            Some(RawSpecularAa::Lean) => SpecularAaSpec::Lean,
            Some(RawSpecularAa::Projected) => SpecularAaSpec::Projected,
        },
        layers: m
            .layers
            .map_or_else(Vec::new, |l| l.into_iter().map(layer_spec).collect()),
        mask: m.mask,
        blend: match m.blend {
            None | Some(RawBlend::Linear) => LayerBlendSpec::Linear,
            Some(RawBlend::Height) => LayerBlendSpec::Height,
        },
        blend_depth: m.blend_depth.unwrap_or(d.blend_depth),
        layer_order: match m.layer_order {
            None | Some(RawLayerOrder::FilterThenBlend) => LayerOrder::FilterThenBlend,
            Some(RawLayerOrder::BlendThenFilter) => LayerOrder::BlendThenFilter,
        },
        occlusion: m.occlusion,
        occlusion_strength: m.occlusion_strength.unwrap_or(d.occlusion_strength),
        shading_samples: m.shading_samples.unwrap_or(d.shading_samples),
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawOutput {
    width: u32,
    height: u32,
    #[serde(default = "opaque_black")]
    background: [u8; 4],
}

fn opaque_black() -> [u8; 4] {
    [0, 0, 0, 255]
}

fn y_up() -> [f32; 3] {
    [0.0, 1.0, 0.0]
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawCamera {
    eye: [f32; 3],
    target: [f32; 3],
    #[serde(default = "y_up")]
    up: [f32; 3],
    fovy_deg: f32,
    near: f32,
    far: f32,
}

#[derive(Deserialize, Clone, Copy, PartialEq, Eq, Debug)]
#[serde(rename_all = "kebab-case")]
enum Kind {
    Checker,
    Zoneplate,
    Grid,
    Uv,
    Solid,
    Bumps,
    Waves,
    WaveHeights,
    Bricks,
    BrickHeights,
    Noise,
    NoiseHeights,
    Splat,
    Globe,
    GlobeMercator,
}

#[derive(Deserialize, Clone, Copy)]
#[serde(rename_all = "lowercase")]
enum ColorName {
    Srgb,
    Linear,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct RawTexture {
    path: Option<String>,
    procedural: Option<Kind>,
    color: Option<ColorName>,
    size: Option<u32>,
    width: Option<u32>,
    height: Option<u32>,
    checks: Option<u32>,
    cells: Option<u32>,
    line_width: Option<f32>,
    rgba: Option<[u8; 4]>,
    slope: Option<f32>,
    waves: Option<u32>,
    seed: Option<u32>,
    rows: Option<u32>,
    columns: Option<u32>,
    mortar: Option<f32>,
    bevel: Option<f32>,
    layers: Option<u32>,
}

impl Kind {
    /// The name scene files use.
    fn name(self) -> &'static str {
        match self {
            Kind::Checker => "checker",
            Kind::Zoneplate => "zoneplate",
            Kind::Grid => "grid",
            Kind::Uv => "uv",
            Kind::Solid => "solid",
            Kind::Bumps => "bumps",
            Kind::Waves => "waves",
            Kind::WaveHeights => "wave-heights",
            Kind::Bricks => "bricks",
            Kind::BrickHeights => "brick-heights",
            Kind::Noise => "noise",
            Kind::NoiseHeights => "noise-heights",
            Kind::Splat => "splat",
            Kind::Globe => "globe",
            Kind::GlobeMercator => "globe-mercator",
        }
    }
}

/// Address mode names in scene files (kebab-case WebGPU names).
#[derive(Deserialize, Clone, Copy)]
#[serde(rename_all = "kebab-case")]
enum ModeName {
    Repeat,
    MirrorRepeat,
    ClampToEdge,
    ClampToBorder,
    MirrorClampToEdge,
}

impl From<ModeName> for AddressMode {
    fn from(m: ModeName) -> Self {
        match m {
            ModeName::Repeat => AddressMode::Repeat,
            ModeName::MirrorRepeat => AddressMode::MirrorRepeat,
            ModeName::ClampToEdge => AddressMode::ClampToEdge,
            ModeName::ClampToBorder => AddressMode::ClampToBorder,
            ModeName::MirrorClampToEdge => AddressMode::MirrorClampToEdge,
        }
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawMesh {
    texture: Option<String>,
    material: Option<String>,
    address_mode: Option<ModeName>,
    address_mode_u: Option<ModeName>,
    address_mode_v: Option<ModeName>,
    positions: Option<Vec<[f32; 3]>>,
    uvs: Option<Vec<[f32; 2]>>,
    normals: Option<Vec<[f32; 3]>>,
    colors: Option<Vec<[f32; 4]>>,
    triangles: Option<Vec<[u32; 3]>>,
    obj: Option<String>,
    gltf: Option<String>,
    sphere_uv: Option<SphereUvName>,
    sphere_centre: Option<[f32; 3]>,
    mercator_cut_deg: Option<f64>,
}

#[derive(Deserialize, Clone, Copy)]
#[serde(rename_all = "kebab-case")]
enum SphereUvName {
    Equirect,
    Mercator,
}

/// The sphere mapping of `[[meshes]]` entry `m`, checked: a finite centre, a cut latitude in
/// `(0, 89.9]` degrees and only for Mercator, neither without `sphere_uv`.
fn sphere_uv(m: &RawMesh) -> Result<Option<SphereUv>, String> {
    use texel_texture::mapping::sphere::SurfaceProjection;
    let Some(name) = m.sphere_uv else {
        if m.sphere_centre.is_some() || m.mercator_cut_deg.is_some() {
            return Err("sphere_centre and mercator_cut_deg need sphere_uv".into());
        }
        return Ok(None);
    };
    let centre = Vec3::from(m.sphere_centre.unwrap_or_default());
    if !centre.is_finite() {
        return Err(format!("sphere_centre {centre} is not finite"));
    }
    let projection = match (name, m.mercator_cut_deg) {
        (SphereUvName::Equirect, None) => SurfaceProjection::Equirect,
        (SphereUvName::Equirect, Some(_)) => {
            return Err("mercator_cut_deg is for sphere_uv = \"mercator\"".into())
        }
        (SphereUvName::Mercator, None) => SurfaceProjection::MERCATOR,
        (SphereUvName::Mercator, Some(cut)) => {
            if !(cut > 0.0 && cut <= 89.9) {
                return Err(format!(
                    "mercator_cut_deg {cut} is outside (0, 89.9] (Mercator reaches infinity at the poles)"
                ));
            }
            SurfaceProjection::Mercator {
                cut: cut.to_radians(),
            }
        }
    };
    Ok(Some(SphereUv { projection, centre }))
}

/// 1-based line and column (in characters) of byte offset `at` in `text`.
pub(crate) fn line_column(text: &str, at: usize) -> (usize, usize) {
    let at = at.min(text.len());
    let before = text.get(..at).unwrap_or(text);
    let line = before.matches('\n').count() + 1;
    let col = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
    (line, col)
}

/// The `[textures.NAME]` table `t`: a file (relative to `base`) or a procedural texture.
fn texture_spec(name: &str, t: RawTexture, base: &Path) -> Result<TextureSpec, SceneError> {
    let bad = |reason: String| invalid_texture(name, reason);
    let color = match t.color.unwrap_or(ColorName::Srgb) {
        ColorName::Srgb => ColorSpace::Srgb,
        ColorName::Linear => ColorSpace::Linear,
    };
    let given = given_parameters(&t);
    let source = match (&t.path, t.procedural) {
        (Some(_), Some(_)) => return Err(bad("give either path or procedural, not both".into())),
        (None, None) => return Err(bad("give path = \"FILE\" or procedural = \"KIND\"".into())),
        (Some(p), None) => {
            if let Some(k) = given.first() {
                return Err(bad(format!(
                    "{k} is a parameter of procedural textures, not of a file"
                )));
            }
            TextureSource::File(base.join(p))
        }
        (None, Some(kind)) => {
            TextureSource::Procedural(procedural_texture(name, kind, &t, &given)?)
        }
    };
    Ok(TextureSpec::new(source, color))
}

/// The error of texture `name` for `reason`.
fn invalid_texture(name: &str, reason: String) -> SceneError {
    SceneError::InvalidTexture {
        name: name.to_string(),
        reason,
    }
}

/// The procedural parameters texture table `t` gives, in the order the scene file docs list them.
fn given_parameters(t: &RawTexture) -> Vec<&'static str> {
    [
        ("size", t.size.is_some()),
        ("width", t.width.is_some()),
        ("height", t.height.is_some()),
        ("checks", t.checks.is_some()),
        ("cells", t.cells.is_some()),
        ("line_width", t.line_width.is_some()),
        ("rgba", t.rgba.is_some()),
        ("slope", t.slope.is_some()),
        ("waves", t.waves.is_some()),
        ("seed", t.seed.is_some()),
        ("rows", t.rows.is_some()),
        ("columns", t.columns.is_some()),
        ("mortar", t.mortar.is_some()),
        ("bevel", t.bevel.is_some()),
        ("layers", t.layers.is_some()),
    ]
    .iter()
    .filter(|p| p.1)
    .map(|p| p.0)
    .collect()
}

/// The parameters a procedural texture of `kind` takes.
fn allowed_parameters(kind: Kind) -> &'static [&'static str] {
    match kind {
        Kind::Checker => &["size", "width", "height", "checks"],
        Kind::Zoneplate => &["size"],
        Kind::Grid => &["size", "width", "height", "cells", "line_width"],
        Kind::Uv => &["size", "width", "height"],
        Kind::Solid => &["size", "width", "height", "rgba"],
        Kind::Bumps => &["size", "cells", "slope"],
        Kind::Waves | Kind::WaveHeights => &["size", "waves", "cells", "slope", "seed"],
        Kind::Bricks | Kind::BrickHeights => &[
            "size", "width", "height", "rows", "columns", "mortar", "bevel",
        ],
        Kind::Noise => &["size", "cells", "seed", "rgba"],
        Kind::NoiseHeights => &["size", "cells", "seed"],
        Kind::Splat => &["size", "cells", "seed", "layers"],
        Kind::Globe | Kind::GlobeMercator => &["size", "width", "height"],
    }
}

/// Procedural texture `name` of `kind` from table `t`, whose `given` parameters must be ones
/// `kind` takes: its size resolved, its parameters checked, the work it asks for bounded.
fn procedural_texture(
    name: &str,
    kind: Kind,
    t: &RawTexture,
    given: &[&'static str],
) -> Result<Procedural, SceneError> {
    let bad = |reason: String| invalid_texture(name, reason);
    let allowed = allowed_parameters(kind);
    if let Some(k) = given.iter().find(|k| !allowed.contains(k)) {
        return Err(bad(format!(
            "{k} is not a parameter of {} (it takes {})",
            kind.name(),
            allowed.join(", ")
        )));
    }
    let (width, height) = texture_size(kind, t).map_err(bad)?;
    let procedural = build_procedural(name, kind, t, width, height)?;
    procedural.check_work().map_err(bad)?;
    Ok(procedural)
}

/// Width and height of a procedural texture of `kind` from table `t`: `size` for both, or
/// `width` and `height`, else the kind's default.
fn texture_size(kind: Kind, t: &RawTexture) -> Result<(u32, u32), String> {
    let default_size = match kind {
        Kind::Checker | Kind::Zoneplate | Kind::Grid => 1024,
        Kind::Uv => 256,
        Kind::Solid => 1,
        Kind::Bumps | Kind::Waves | Kind::WaveHeights => 512,
        Kind::Noise | Kind::NoiseHeights | Kind::Splat => 512,
        Kind::Bricks | Kind::BrickHeights | Kind::Globe | Kind::GlobeMercator => 0,
    };
    Ok(match (t.size, t.width, t.height) {
        (Some(_), Some(_), _) | (Some(_), _, Some(_)) => {
            return Err("give size or width and height, not both".into())
        }
        (Some(s), None, None) => (s, s),
        (None, Some(w), Some(h)) => (w, h),
        (None, None, None) if matches!(kind, Kind::Bricks | Kind::BrickHeights) => (1024, 512),
        (None, None, None) if matches!(kind, Kind::Globe) => (2048, 1024),
        (None, None, None) if matches!(kind, Kind::GlobeMercator) => (2048, 2048),
        (None, None, None) => (default_size, default_size),
        _ => return Err("width and height go together".into()),
    })
}

/// Parameter `key` of texture `name`: `v`, at least 1, else `default`.
fn positive_parameter(
    name: &str,
    v: Option<u32>,
    key: &str,
    default: u32,
) -> Result<u32, SceneError> {
    match v {
        Some(0) => Err(invalid_texture(name, format!("{key} must be at least 1"))),
        Some(v) => Ok(v),
        None => Ok(default),
    }
}

/// Parameter `key` of texture `name`: `v`, else `default`, finite and at least 0.
fn non_negative_parameter(
    name: &str,
    v: Option<f32>,
    key: &str,
    default: f32,
) -> Result<f32, SceneError> {
    match v.unwrap_or(default) {
        x if x.is_finite() && x >= 0.0 => Ok(x),
        x => Err(invalid_texture(
            name,
            format!("{key} = {x} must be finite and >= 0"),
        )),
    }
}

/// Procedural texture `name` of `kind`, `width` by `height`, with the parameters of table `t`
/// checked and defaulted.
fn build_procedural(
    name: &str,
    kind: Kind,
    t: &RawTexture,
    width: u32,
    height: u32,
) -> Result<Procedural, SceneError> {
    let positive =
        |v: Option<u32>, key: &str, default: u32| positive_parameter(name, v, key, default);
    let non_negative =
        |v: Option<f32>, key: &str, default: f32| non_negative_parameter(name, v, key, default);
    Ok(match kind {
        Kind::Checker => Procedural::Checker {
            width,
            height,
            checks: positive(t.checks, "checks", 8)?,
        },
        Kind::Zoneplate => Procedural::ZonePlate { size: width },
        Kind::Grid => {
            let line_width = non_negative(t.line_width, "line_width", 2.0)?;
            Procedural::Grid {
                width,
                height,
                cells: positive(t.cells, "cells", 8)?,
                line_width,
            }
        }
        Kind::Uv => Procedural::Uv { width, height },
        Kind::Bumps => Procedural::Bumps {
            size: width,
            cells: positive(t.cells, "cells", 32)?,
            slope: non_negative(t.slope, "slope", 0.5)?,
        },
        Kind::Waves | Kind::WaveHeights => Procedural::Waves {
            size: width,
            waves: positive(t.waves, "waves", 64)?,
            cells: positive(t.cells, "cells", 32)?,
            slope: non_negative(t.slope, "slope", 0.3)?,
            seed: t.seed.unwrap_or(1),
            heights: matches!(kind, Kind::WaveHeights),
        },
        Kind::Bricks | Kind::BrickHeights => Procedural::Bricks {
            width,
            height,
            rows: positive(t.rows, "rows", 14)?,
            columns: positive(t.columns, "columns", 9)?,
            mortar: non_negative(t.mortar, "mortar", 4.0)?,
            bevel: non_negative(t.bevel, "bevel", 3.0)?,
            heights: matches!(kind, Kind::BrickHeights),
        },
        Kind::Globe | Kind::GlobeMercator => Procedural::Globe {
            width,
            height,
            mercator: matches!(kind, Kind::GlobeMercator),
        },
        Kind::Solid => Procedural::Solid {
            width,
            height,
            rgba: t.rgba.unwrap_or([255; 4]),
        },
        Kind::Noise | Kind::NoiseHeights | Kind::Splat => Procedural::Noise {
            size: width,
            cells: positive(t.cells, "cells", 8)?,
            seed: t.seed.unwrap_or(1),
            kind: noise_kind(name, kind, t)?,
        },
    })
}

/// What a noise texture of `kind` (noise, noise-heights or splat) makes of its noise, from table
/// `t`: a colour, heights, or 1 to 4 splat layers.
fn noise_kind(name: &str, kind: Kind, t: &RawTexture) -> Result<NoiseKind, SceneError> {
    Ok(match kind {
        Kind::Noise => NoiseKind::Color {
            rgba: t.rgba.unwrap_or([255; 4]),
        },
        Kind::NoiseHeights => NoiseKind::Heights,
        _ => NoiseKind::Splat {
            layers: match t.layers.unwrap_or(4) {
                l @ 1..=4 => l,
                l => {
                    return Err(invalid_texture(
                        name,
                        format!("layers = {l} must be 1 to 4"),
                    ))
                }
            },
        },
    })
}

/// The texture a mesh is drawn with: its own `texture`, or its material's `base_color` texture
/// (they must agree when both are given).
fn mesh_texture(
    index: usize,
    m: &RawMesh,
    materials: &BTreeMap<String, MaterialSpec>,
) -> Result<String, SceneError> {
    let src = |reason: String| SceneError::MeshMaterial {
        mesh: index,
        reason,
    };
    let material = m.material.as_ref().and_then(|n| materials.get(n));
    if let Some(mat) = material.filter(|mat| !mat.layers.is_empty()) {
        // A layered material's colour is its layers': the mesh's texture slot names a texture
        // the material reads (its mask where it has one), which the draw does not show.
        if m.texture.is_some() {
            return Err(src(
                "its material is layered and takes its colour from its layers: leave texture out"
                    .to_string(),
            ));
        }
        let slot = mat
            .mask
            .as_deref()
            .or_else(|| mat.textures().first().copied());
        return slot.map(str::to_string).ok_or_else(|| {
            src("its layered material reads no texture: give it a mask or a layer texture".into())
        });
    }
    let from_material = match material {
        Some(MaterialSpec {
            base_color: ColorInput::Texture(t),
            ..
        }) => Some(t.clone()),
        _ => None,
    };
    match (&m.texture, from_material) {
        (Some(a), Some(b)) if *a != b => Err(src(format!(
            "texture = {a:?} differs from its material's base_color = {b:?}; give one"
        ))),
        (Some(a), _) => Ok(a.clone()),
        (None, Some(b)) => Ok(b),
        (None, None) => Err(src(
            "give texture = NAME, or a material whose base_color is a texture".to_string(),
        )),
    }
}

/// glTF files a scene has read, by what the import depended on (path, imported materials, the
/// entry's texture, the texture the meshes are drawn with): a file named by many entries is read
/// once.
type GltfCache = std::collections::HashMap<(PathBuf, bool, Option<String>, String), GltfScene>;

/// The meshes of `[[meshes]]` entry `index`; a glTF file's own textures and materials beside them
/// where the entry names no material.
fn meshes(
    index: usize,
    m: RawMesh,
    base: &Path,
    limits: &SceneLimits,
    materials: &BTreeMap<String, MaterialSpec>,
    cache: &mut GltfCache,
) -> Result<GltfScene, SceneError> {
    let src = |reason| SceneError::MeshSource {
        mesh: index,
        reason,
    };
    // A glTF mesh without a scene material brings its own, and its texture where none is named.
    let own_materials = m.gltf.is_some() && m.material.is_none();
    let texture = match own_materials {
        true => String::new(), // unused: the import takes `m.texture`
        false => mesh_texture(index, &m, materials)?,
    };
    let sources = [m.positions.is_some(), m.obj.is_some(), m.gltf.is_some()]
        .iter()
        .filter(|&&b| b)
        .count();
    if sources != 1 {
        return Err(src(
            "give exactly one geometry source: inline positions, obj = \"FILE\" or gltf = \"FILE\"",
        ));
    }
    let uv_mapping = sphere_uv(&m).map_err(|reason| SceneError::MeshMapping {
        mesh: index,
        reason,
    })?;
    let both = m.address_mode.map(AddressMode::from);
    let mode_u = m.address_mode_u.map(AddressMode::from).or(both);
    let mode_v = m.address_mode_v.map(AddressMode::from).or(both);
    let material = m.material.clone();
    let mut out = if m.positions.is_some() {
        inline_mesh(index, m, texture)?
    } else {
        file_meshes(index, m, base, limits, own_materials, texture, cache)?
    };
    for mesh in &mut out.meshes {
        if material.is_some() {
            mesh.material.clone_from(&material);
        }
        if let Some(u) = mode_u {
            mesh.address_mode_u = u;
        }
        if let Some(v) = mode_v {
            mesh.address_mode_v = v;
        }
        if uv_mapping.is_some() {
            mesh.uv_mapping = uv_mapping;
        }
    }
    Ok(out)
}

/// The mesh of `[[meshes]]` entry `index`'s inline positions, uvs, triangles and optional
/// normals and colours, drawn with `texture`.
fn inline_mesh(index: usize, m: RawMesh, texture: String) -> Result<GltfScene, SceneError> {
    let (Some(positions), Some(uvs), Some(triangles)) = (m.positions, m.uvs, m.triangles) else {
        return Err(SceneError::MeshSource {
            mesh: index,
            reason: "inline meshes need positions, uvs and triangles",
        });
    };
    Ok(GltfScene::from(vec![Mesh {
        positions: positions.into_iter().map(Vec3::from).collect(),
        uvs: uvs.into_iter().map(Vec2::from).collect(),
        normals: m.normals.map(|v| v.into_iter().map(Vec3::from).collect()),
        colors: m.colors.map(|v| v.into_iter().map(Vec4::from).collect()),
        triangles,
        texture,
        address_mode_u: AddressMode::Repeat,
        address_mode_v: AddressMode::Repeat,
        filters: None,
        material: None,
        tangents: None,
        uv_mapping: None,
    }]))
}

/// The meshes of `[[meshes]]` entry `index`'s OBJ or glTF file (relative to `base`), which takes
/// no inline arrays; a glTF file is read once per import (`cache`).
fn file_meshes(
    index: usize,
    m: RawMesh,
    base: &Path,
    limits: &SceneLimits,
    own_materials: bool,
    texture: String,
    cache: &mut GltfCache,
) -> Result<GltfScene, SceneError> {
    if m.uvs.is_some() || m.triangles.is_some() || m.normals.is_some() || m.colors.is_some() {
        return Err(SceneError::MeshSource {
            mesh: index,
            reason: "uvs, triangles, normals and colors are only allowed with inline positions",
        });
    }
    if let Some(obj) = m.obj {
        return Ok(GltfScene::from(vec![crate::obj::load_obj_with(
            &base.join(obj),
            &texture,
            limits,
        )?]));
    }
    let file = m.gltf.expect("one source");
    let path = base.join(&file);
    let key = (
        path.clone(),
        own_materials,
        m.texture.clone(),
        texture.clone(),
    );
    if let Some(done) = cache.get(&key) {
        check_cached_fits(index, &file, done, limits)?;
        return Ok(done.clone());
    }
    let loaded = match own_materials {
        true => crate::gltf_import::import_gltf(&path, m.texture.as_deref(), &file, limits)?,
        false => GltfScene::from(crate::gltf_import::load_gltf_with(&path, &texture, limits)?),
    };
    cache.insert(key, loaded.clone());
    Ok(loaded)
}

/// Checks that glTF file `file`'s meshes `done`, read for an earlier entry, fit in what the
/// scene's limits leave (`limits`) for `[[meshes]]` entry `index`.
fn check_cached_fits(
    index: usize,
    file: &str,
    done: &GltfScene,
    limits: &SceneLimits,
) -> Result<(), SceneError> {
    let tris: u64 = done.meshes.iter().map(|m| m.triangles.len() as u64).sum();
    let verts: u64 = done.meshes.iter().map(|m| m.positions.len() as u64).sum();
    let meshes = done.meshes.len() as u64;
    if tris > limits.max_triangles || verts > limits.max_vertices || meshes > limits.max_meshes {
        return Err(SceneError::TooLarge(format!(
            "meshes[{index}] ({file}) adds {meshes} meshes, {tris} triangles and \
             {verts} vertices to the meshes before it, over what the limits of the \
             scene leave ({} meshes, {} triangles, {} vertices)",
            limits.max_meshes, limits.max_triangles, limits.max_vertices
        )));
    }
    Ok(())
}

/// Add what mesh `index`'s glTF file imported into the scene's `table`; an entry the scene (or an
/// earlier import) defines otherwise is an error.
fn merge_imported<T: PartialEq>(
    into: &mut BTreeMap<String, T>,
    imported: BTreeMap<String, T>,
    index: usize,
    table: &str,
) -> Result<(), SceneError> {
    for (name, entry) in imported {
        if into.get(&name).is_some_and(|old| *old != entry) {
            return Err(SceneError::MeshMaterial {
                mesh: index,
                reason: format!(
                    "its glTF file's own {table} are imported as {table}.{name:?}, which the \
                     scene defines otherwise: rename the scene's"
                ),
            });
        }
        into.insert(name, entry);
    }
    Ok(())
}

impl Scene {
    /// Parse a scene from TOML text. `path` names the file in error messages and its directory is
    /// the base for relative texture, OBJ and glTF paths. The scene is validated
    /// ([`Scene::validate`]).
    ///
    /// # Errors
    /// As [`Scene::from_toml_str_with`].
    pub fn from_toml_str(text: &str, path: &Path) -> Result<Scene, SceneError> {
        Self::from_toml_str_with(text, path, &SceneLimits::default())
    }

    /// As [`Scene::from_toml_str`], with mesh files read within `limits`, and the whole scene's
    /// triangles and vertices within them.
    ///
    /// # Errors
    /// [`SceneError::Toml`] with line and column; mesh file errors; [`SceneError::TooLarge`];
    /// validation errors.
    pub fn from_toml_str_with(
        text: &str,
        path: &Path,
        limits: &SceneLimits,
    ) -> Result<Scene, SceneError> {
        let raw: RawScene = toml::from_str(text).map_err(|e| {
            let (line, column) = e.span().map_or((0, 0), |s| line_column(text, s.start));
            SceneError::Toml {
                path: path.to_path_buf(),
                line,
                column,
                message: e.message().trim().to_string(),
            }
        })?;
        let base = path.parent().map_or_else(PathBuf::new, Path::to_path_buf);
        let textures: BTreeMap<String, TextureSpec> = raw
            .textures
            .into_iter()
            .map(|(name, t)| texture_spec(&name, t, &base).map(|s| (name, s)))
            .collect::<Result<_, _>>()?;
        let materials: BTreeMap<String, MaterialSpec> = raw
            .materials
            .into_iter()
            .map(|(name, m)| (name, material_spec(m)))
            .collect();
        let (mut textures, mut materials) = (textures, materials);
        let mut all = Vec::new();
        let mut cache = GltfCache::new();
        let (mut tris, mut verts) = (0u64, 0u64);
        for (i, m) in raw.meshes.into_iter().enumerate() {
            // Each mesh file gets what the meshes before it left of the scene's limits.
            if all.len() as u64 >= limits.max_meshes {
                return Err(SceneError::TooLarge(format!(
                    "meshes[{i}]: the scene already has {} meshes, the limit",
                    all.len()
                )));
            }
            let left = SceneLimits {
                max_triangles: limits.max_triangles.saturating_sub(tris),
                max_vertices: limits.max_vertices.saturating_sub(verts),
                max_meshes: limits.max_meshes - all.len() as u64,
                ..*limits
            };
            let imported = meshes(i, m, &base, &left, &materials, &mut cache)?;
            for m in &imported.meshes {
                tris += m.triangles.len() as u64;
                verts += m.positions.len() as u64;
            }
            all.extend(imported.meshes);
            merge_imported(&mut textures, imported.textures, i, "textures")?;
            merge_imported(&mut materials, imported.materials, i, "materials")?;
        }
        let tris: u64 = all.iter().map(|m| m.triangles.len() as u64).sum();
        let verts: u64 = all.iter().map(|m| m.positions.len() as u64).sum();
        if tris > limits.max_triangles || verts > limits.max_vertices {
            return Err(SceneError::TooLarge(format!(
                "the scene has {tris} triangles and {verts} vertices, over the limits of {} triangles and {} vertices",
                limits.max_triangles, limits.max_vertices
            )));
        }
        let scene = Scene {
            output: Output {
                width: raw.output.width,
                height: raw.output.height,
                background: raw.output.background,
            },
            camera: Camera {
                eye: raw.camera.eye.into(),
                target: raw.camera.target.into(),
                up: raw.camera.up.into(),
                fovy_deg: raw.camera.fovy_deg,
                near: raw.camera.near,
                far: raw.camera.far,
            },
            textures,
            meshes: all,
            lights: raw.lights.into_iter().map(light_spec).collect(),
            materials,
            environment: raw
                .environment
                .map(|e| environment_spec(e, &base))
                .transpose()?,
        };
        scene.validate()?;
        Ok(scene)
    }

    /// Read and parse a scene file ([`Scene::from_toml_str`]).
    ///
    /// # Errors
    /// As [`Scene::from_path_with`].
    pub fn from_path(path: impl AsRef<Path>) -> Result<Scene, SceneError> {
        Self::from_path_with(path, &SceneLimits::default())
    }

    /// Read a scene file (a regular file of at most [`SceneLimits::max_scene_bytes`], UTF-8) and
    /// parse it ([`Scene::from_toml_str_with`]).
    ///
    /// # Errors
    /// [`SceneError::Io`] with the path (missing, not a regular file, too large, not UTF-8), and
    /// those of [`Scene::from_toml_str_with`].
    pub fn from_path_with(
        path: impl AsRef<Path>,
        limits: &SceneLimits,
    ) -> Result<Scene, SceneError> {
        let path = path.as_ref();
        let io = |source| SceneError::Io {
            path: path.to_path_buf(),
            source,
        };
        let bytes = texel_io::read_regular(path, limits.max_scene_bytes).map_err(io)?;
        let text = String::from_utf8(bytes).map_err(|e| {
            io(std::io::Error::new(
                std::io::ErrorKind::InvalidData,
                format!(
                    "is not UTF-8 text (byte {} is invalid)",
                    e.utf8_error().valid_up_to()
                ),
            ))
        })?;
        Self::from_toml_str_with(&text, path, limits)
    }

    /// A scene from a command-line argument: `builtin:NAME` ([`crate::builtin_names`]) or a path
    /// to a TOML file.
    ///
    /// # Errors
    /// [`SceneError::UnknownBuiltin`], and those of [`Scene::from_path`].
    pub fn load(arg: &str) -> Result<Scene, SceneError> {
        Self::load_with(arg, &SceneLimits::default())
    }

    /// As [`Scene::load`], with files read within `limits`.
    ///
    /// # Errors
    /// [`SceneError::UnknownBuiltin`], and those of [`Scene::from_path_with`].
    pub fn load_with(arg: &str, limits: &SceneLimits) -> Result<Scene, SceneError> {
        match arg.strip_prefix("builtin:") {
            Some(name) => crate::builtin::builtin(name),
            None => Self::from_path_with(arg, limits),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn line_column_counts_chars() {
        let t = "ab\ncdé\nx";
        assert_eq!(line_column(t, 0), (1, 1));
        assert_eq!(line_column(t, 3), (2, 1));
        assert_eq!(line_column(t, 8), (3, 1));
        assert_eq!(line_column(t, 7), (2, 4)); // after "cdé"
    }
}
