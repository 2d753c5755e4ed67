//! The scene data model: what to render, independent of how it is rasterized.

use std::collections::BTreeMap;
use std::path::PathBuf;

use glam::{Vec2, Vec3, Vec4};
use texel_texture::{AddressMode, ColorSpace, FilterMode, MipmapFilterMode};

use crate::camera::Camera;
use crate::environment::EnvironmentSpec;
use crate::procedural::Procedural;

/// The largest output width or height accepted (16384, the common GPU limit).
pub const MAX_OUTPUT_SIDE: u32 = 16384;

/// A complete scene: output settings, camera, named textures and meshes.
#[derive(Clone, Debug, PartialEq)]
pub struct Scene {
    /// Image size and background.
    pub output: Output,
    /// The viewpoint.
    pub camera: Camera,
    /// Textures by name (meshes refer to them by name).
    pub textures: BTreeMap<String, TextureSpec>,
    /// The meshes, drawn in order (depth-tested).
    pub meshes: Vec<Mesh>,
    /// Lights (`[[lights]]`); none renders unlit, as before materials existed.
    pub lights: Vec<LightSpec>,
    /// Materials by name (`[materials.NAME]`; meshes refer to them by name).
    pub materials: BTreeMap<String, MaterialSpec>,
    /// The environment map (`[environment]`), if any: it lights the scene (the frame is lit
    /// even without lights), is reflected by materials and may be the background.
    pub environment: Option<EnvironmentSpec>,
}

/// The most lights a scene has.
pub const MAX_SCENE_LIGHTS: usize = 8;

/// A light of a scene file (`[[lights]]`), linear RGB; units as glTF's `KHR_lights_punctual`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum LightSpec {
    /// `type = "directional"`: `direction` towards the light, `intensity` the illuminance on a
    /// surface facing it.
    Directional {
        /// Direction towards the light (not zero).
        direction: Vec3,
        /// Illuminance, linear RGB.
        intensity: Vec3,
    },
    /// `type = "point"`: `position`, `intensity` (illuminance `intensity / d^2` at distance `d`).
    Point {
        /// World-space position.
        position: Vec3,
        /// Luminous intensity, linear RGB.
        intensity: Vec3,
    },
    /// `type = "ambient"`: light from every direction, `intensity` the radiance.
    Ambient {
        /// Radiance, linear RGB.
        intensity: Vec3,
    },
}

/// A colour input: a texture (by name) or a constant linear RGB colour.
#[derive(Clone, Debug, PartialEq)]
pub enum ColorInput {
    /// The texture of this name.
    Texture(String),
    /// A constant linear RGB colour.
    Rgb(Vec3),
}

/// A scalar input: a constant, or a texture's channel (linear) by name.
#[derive(Clone, Debug, PartialEq)]
pub enum ScalarInput {
    /// A constant in `[0, 1]`.
    Value(f32),
    /// The red channel of the texture of this name.
    Texture(String),
    /// Channel `channel` (`0` red ... `3` alpha) of texture `texture` times `factor` (`[0, 1]`),
    /// as glTF's `metallicRoughnessTexture` (roughness green, metalness blue, each times its
    /// factor).
    Channel {
        /// The texture's name.
        texture: String,
        /// The channel read, `0..=3`.
        channel: u8,
        /// Multiplies the channel, in `[0, 1]`.
        factor: f32,
    },
}

impl ScalarInput {
    /// The texture read, if any.
    pub fn texture(&self) -> Option<&str> {
        match self {
            ScalarInput::Value(_) => None,
            ScalarInput::Texture(t) | ScalarInput::Channel { texture: t, .. } => Some(t),
        }
    }

    /// The factor, the texture's name and the channel: `(v, None)` for a constant `v`,
    /// `(1, Some((name, 0)))` for a texture's red channel.
    pub fn parts(&self) -> (f32, Option<(&str, u8)>) {
        match self {
            ScalarInput::Value(v) => (*v, None),
            ScalarInput::Texture(t) => (1.0, Some((t, 0))),
            ScalarInput::Channel {
                texture,
                channel,
                factor,
            } => (*factor, Some((texture, *channel))),
        }
    }
}

/// How a material's height map displaces the surface (`displacement = ...`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum Displacement {
    /// `"none"`.
    #[default]
    #[cfg_attr(feature = "clap", value(help = "The height map is not used"))]
    None,
    /// `"bump"`: normals from the height map.
    #[cfg_attr(
        feature = "clap",
        value(help = "Bump mapping: normals from the height map, flat geometry")
    )]
    Bump,
    /// `"pom"`: parallax occlusion mapping.
    #[cfg_attr(
        feature = "clap",
        value(
            help = "Parallax occlusion mapping (Tatarchuk 2006): the view ray marched through the heights"
        )
    )]
    Pom,
    /// `"tessellate"`: true displacement of tessellated geometry.
    #[cfg_attr(
        feature = "clap",
        value(
            help = "True displacement: the mesh tessellated to --edge-px and its vertices moved by the heights, filtered to the edge length"
        )
    )]
    Tessellate,
}

impl Displacement {
    /// The name scene files use.
    pub fn name(self) -> &'static str {
        match self {
            Displacement::None => "none",
            Displacement::Bump => "bump",
            Displacement::Pom => "pom",
            Displacement::Tessellate => "tessellate",
        }
    }
}

/// Specular antialiasing of a material (`specular_aa = ...`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum SpecularAaSpec {
    /// `"none"`.
    #[default]
    None,
    /// `"toksvig"`.
    Toksvig,
    /// `"lean"`.
    Lean,
    /// `"projected"`.
    Projected,
}

/// A material (`[materials.NAME]`): glTF-style metallic-roughness parameters and maps.
#[derive(Clone, Debug, PartialEq)]
pub struct MaterialSpec {
    /// `base_color`: a texture name (replacing the mesh's texture) or `[r, g, b]` (linear,
    /// multiplying the mesh's texture). Default white.
    pub base_color: ColorInput,
    /// `roughness`: perceptual roughness, number in `[0, 1]` or texture name (red). Default 0.5.
    pub roughness: ScalarInput,
    /// `metallic`: number in `[0, 1]` or texture name (red). Default 0.
    pub metallic: ScalarInput,
    /// `normal`: tangent-space normal map (texture name, must be `color = "linear"`).
    pub normal: Option<String>,
    /// `normal_scale`: scales the normal map's x and y. Default 1.
    pub normal_scale: f32,
    /// `height`: height map (texture name).
    pub height: Option<String>,
    /// `height_scale`: world units of height per unit of the map. Default 0.05.
    pub height_scale: f32,
    /// `displacement`.
    pub displacement: Displacement,
    /// `specular_aa`.
    pub specular_aa: SpecularAaSpec,
    /// `[[materials.NAME.layers]]`: up to four layers blended by `mask` (empty: not layered).
    /// A layered material takes base colour, roughness, normals and heights from its layers.
    pub layers: Vec<LayerSpec>,
    /// `mask`: the texture whose channel `k` (red, green, blue, alpha) weighs layer `k`
    /// (`color = "linear"`); required for two layers or more.
    pub mask: Option<String>,
    /// `blend`.
    pub blend: LayerBlendSpec,
    /// `blend_depth`: the transition width of `blend = "height"`, in height units, `(0, 1]`.
    /// Default 0.2.
    pub blend_depth: f32,
    /// `layer_order`.
    pub layer_order: LayerOrder,
    /// `occlusion`: ambient occlusion map (texture name, red channel, `color = "linear"`;
    /// glTF's `occlusionTexture`): ambient light is multiplied by `1 + strength (ao - 1)`.
    pub occlusion: Option<String>,
    /// `occlusion_strength`: how much of the occlusion map applies, `[0, 1]`. Default 1.
    pub occlusion_strength: f32,
    /// `shading_samples`: adaptive shading supersampling, at most this many shading
    /// sub-samples per pixel axis where the shading normal turns faster than the specular lobe
    /// is wide, `1..=`[`MAX_SHADING_SAMPLES`]. Default 1 (off).
    pub shading_samples: u32,
}

/// The most shading sub-samples per pixel axis a material may ask for (`shading_samples`).
pub const MAX_SHADING_SAMPLES: u32 = 8;

/// The most layers a material has (one per channel of its mask).
pub const MAX_LAYERS: usize = 4;

/// One layer of a layered material (`[[materials.NAME.layers]]`).
#[derive(Clone, Debug, PartialEq)]
pub struct LayerSpec {
    /// `base_color`: a texture name or `[r, g, b]` (linear). Default white.
    pub base_color: ColorInput,
    /// `roughness`: number in `[0, 1]` or texture name (red). Default 0.5.
    pub roughness: ScalarInput,
    /// `normal`: tangent-space normal map (texture name, `color = "linear"`).
    pub normal: Option<String>,
    /// `normal_scale`. Default 1.
    pub normal_scale: f32,
    /// `height`: number in `[0, 1]` or height map name (red, `color = "linear"`); `None`: 0.5,
    /// and the layer gives no height of its own.
    pub height: Option<ScalarInput>,
}

impl Default for LayerSpec {
    fn default() -> Self {
        LayerSpec {
            base_color: ColorInput::Rgb(Vec3::ONE),
            roughness: ScalarInput::Value(0.5),
            normal: None,
            normal_scale: 1.0,
            height: None,
        }
    }
}

/// How a layered material weighs its layers (`blend = ...`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum LayerBlendSpec {
    /// `"linear"`: the mask's weights.
    #[default]
    Linear,
    /// `"height"`: the mask's weights sharpened by the layers' heights.
    Height,
}

/// Where a layered material's blend happens relative to texture filtering (`layer_order = ...`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum LayerOrder {
    /// `"filter-then-blend"`: every map is filtered over the pixel's footprint, then the
    /// filtered values are blended (what a shader does).
    #[default]
    #[cfg_attr(
        feature = "clap",
        value(
            help = "Every layer's maps and the mask filtered over the pixel, then blended (a shader's way)"
        )
    )]
    FilterThenBlend,
    /// `"blend-then-filter"`: the layers are blended texel by texel at level 0 into one set of
    /// maps when the scene is prepared, and those are filtered (a baked material).
    #[cfg_attr(
        feature = "clap",
        value(
            help = "The layers blended texel by texel at level 0 into baked maps, which are then filtered"
        )
    )]
    BlendThenFilter,
}

impl LayerOrder {
    /// The name scene files use.
    pub fn name(self) -> &'static str {
        match self {
            LayerOrder::FilterThenBlend => "filter-then-blend",
            LayerOrder::BlendThenFilter => "blend-then-filter",
        }
    }
}

impl Default for MaterialSpec {
    fn default() -> Self {
        MaterialSpec {
            base_color: ColorInput::Rgb(Vec3::ONE),
            roughness: ScalarInput::Value(0.5),
            metallic: ScalarInput::Value(0.0),
            normal: None,
            normal_scale: 1.0,
            height: None,
            height_scale: 0.05,
            displacement: Displacement::None,
            specular_aa: SpecularAaSpec::None,
            layers: Vec::new(),
            mask: None,
            blend: LayerBlendSpec::Linear,
            blend_depth: 0.2,
            layer_order: LayerOrder::FilterThenBlend,
            occlusion: None,
            occlusion_strength: 1.0,
            shading_samples: 1,
        }
    }
}

impl MaterialSpec {
    /// Every texture name the material reads.
    pub fn textures(&self) -> Vec<&str> {
        self.texture_uses().into_iter().map(|(t, _)| t).collect()
    }

    /// Every texture name the material reads, each with whether it holds colours (base colour
    /// textures, which the CLI's `--color raw` applies to) rather than data.
    pub fn texture_uses(&self) -> Vec<(&str, bool)> {
        fn color<'a>(c: &'a ColorInput, out: &mut Vec<(&'a str, bool)>) {
            if let ColorInput::Texture(t) = c {
                out.push((t.as_str(), true));
            }
        }
        fn scalar<'a>(s: &'a ScalarInput, out: &mut Vec<(&'a str, bool)>) {
            out.extend(s.texture().map(|t| (t, false)));
        }
        let mut out = Vec::new();
        color(&self.base_color, &mut out);
        scalar(&self.roughness, &mut out);
        scalar(&self.metallic, &mut out);
        out.extend(self.normal.as_deref().map(|t| (t, false)));
        out.extend(self.height.as_deref().map(|t| (t, false)));
        out.extend(self.mask.as_deref().map(|t| (t, false)));
        out.extend(self.occlusion.as_deref().map(|t| (t, false)));
        for l in &self.layers {
            color(&l.base_color, &mut out);
            scalar(&l.roughness, &mut out);
            out.extend(l.normal.as_deref().map(|t| (t, false)));
            if let Some(h) = &l.height {
                scalar(h, &mut out);
            }
        }
        out
    }

    /// Whether any layer gives a height (the blended height then shapes the surface).
    pub fn layer_heights(&self) -> bool {
        self.layers.iter().any(|l| l.height.is_some())
    }

    /// Whether the material has heights: a height map, or layers that give heights.
    pub fn has_heights(&self) -> bool {
        self.height.is_some() || self.layer_heights()
    }
}

/// Output image settings.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Output {
    /// Width in pixels, `1..=MAX_OUTPUT_SIDE`.
    pub width: u32,
    /// Height in pixels, `1..=MAX_OUTPUT_SIDE`.
    pub height: u32,
    /// Colour of uncovered pixels, 8-bit sRGB-encoded RGBA (alpha linear).
    pub background: [u8; 4],
}

/// Where a texture's texels come from, and how its 8-bit values are to be read.
#[derive(Clone, Debug, PartialEq)]
pub struct TextureSpec {
    /// File or procedural generator.
    pub source: TextureSource,
    /// How 8-bit values are interpreted (`color = "srgb" | "linear"`, default sRGB). The CLI's
    /// `--color raw` overrides it with linear for every texture.
    pub color: ColorSpace,
    /// The texture's own sampler (a glTF texture's), which a material reads it through; `None`
    /// (every texture of a scene file): the sampler of the mesh it is drawn on. A mesh's colour
    /// texture is always read through the mesh's sampler.
    pub sampler: Option<TextureSampler>,
}

impl TextureSpec {
    /// A texture from `source` read as `color`, with no sampler of its own.
    pub fn new(source: TextureSource, color: ColorSpace) -> Self {
        TextureSpec {
            source,
            color,
            sampler: None,
        }
    }
}

/// A texture's own address modes and filters (glTF 2.0 5.26 "Sampler").
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TextureSampler {
    /// Address mode along u (`wrapS`).
    pub address_mode_u: AddressMode,
    /// Address mode along v (`wrapT`).
    pub address_mode_v: AddressMode,
    /// `magFilter` and `minFilter`, used when no filter is named (as a mesh's [`MeshFilters`]).
    pub filters: MeshFilters,
}

/// The origin of a texture's texels.
#[derive(Clone, Debug, PartialEq)]
pub enum TextureSource {
    /// An image file (PNG, JPEG, OpenEXR), already resolved against the scene file's directory.
    File(PathBuf),
    /// A generated texture.
    Procedural(Procedural),
    /// An encoded image held in memory (a glTF image embedded in a GLB buffer or a `data:` URI).
    Encoded(EncodedImage),
}

/// The bytes of an encoded image (PNG, JPEG, ...) and where they came from.
#[derive(Clone, PartialEq)]
pub struct EncodedImage {
    /// The encoded file's bytes.
    pub bytes: std::sync::Arc<[u8]>,
    /// Where they came from, for messages (`"scene.glb, image 2"`).
    pub origin: String,
}

impl std::fmt::Debug for EncodedImage {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "EncodedImage({}, {} bytes)",
            self.origin,
            self.bytes.len()
        )
    }
}

/// A triangle mesh with one texture.
///
/// Per-vertex attributes are indexed by `triangles`; `uvs` (and `normals`, `colors` when present)
/// have exactly one entry per position. Triangles are counter-clockwise when seen from their front.
#[derive(Clone, Debug, PartialEq)]
pub struct Mesh {
    /// Vertex positions in world units.
    pub positions: Vec<Vec3>,
    /// Texture coordinates, normalised (`v = 0` is the top row of the image file, as in glTF;
    /// OBJ's bottom-up `v` is flipped on import).
    pub uvs: Vec<Vec2>,
    /// Unit normals in world space, if given.
    pub normals: Option<Vec<Vec3>>,
    /// Linear RGBA vertex colours that multiply the texture colour, if given.
    pub colors: Option<Vec<Vec4>>,
    /// Vertex indices, three per triangle.
    pub triangles: Vec<[u32; 3]>,
    /// Name of the texture in [`Scene::textures`].
    pub texture: String,
    /// Address mode along u.
    pub address_mode_u: AddressMode,
    /// Address mode along v.
    pub address_mode_v: AddressMode,
    /// Filters requested by a glTF sampler, if any (the CLI's `--filter` may override them).
    pub filters: Option<MeshFilters>,
    /// Name of the material in [`Scene::materials`], if any.
    pub material: Option<String>,
    /// Tangents (`xyz` along increasing u, `w = +-1` handedness as glTF's `TANGENT`), one per
    /// position, if given or generated ([`Mesh::generate_tangents`]).
    pub tangents: Option<Vec<Vec4>>,
    /// Whether `uvs` are a sphere mapping of the positions' directions from a centre (scene
    /// key `sphere_uv`); the renderer may then evaluate it exactly per pixel.
    pub uv_mapping: Option<SphereUv>,
}

/// A mesh's texture coordinates as a projection of its points' directions from `centre`: the
/// lecture's spherical mappings (`texel_texture::mapping::sphere::SurfaceProjection`). The mesh's own
/// `uvs` should hold the projection at each vertex (what per-vertex evaluation interpolates).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SphereUv {
    /// Equirect or Mercator (with its cut latitude).
    pub projection: texel_texture::mapping::sphere::SurfaceProjection,
    /// The sphere's centre, world units.
    pub centre: Vec3,
}

/// Texture filters a glTF sampler asks for (glTF 2.0 spec, 5.26 "Sampler"); `None` = not specified.
///
/// Mapping of `minFilter`: `NEAREST` -> (Nearest, None), `LINEAR` -> (Linear, None),
/// `NEAREST_MIPMAP_NEAREST` -> (Nearest, Nearest), `LINEAR_MIPMAP_NEAREST` -> (Linear, Nearest),
/// `NEAREST_MIPMAP_LINEAR` -> (Nearest, Linear), `LINEAR_MIPMAP_LINEAR` -> (Linear, Linear).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct MeshFilters {
    /// From `magFilter`.
    pub mag_filter: Option<FilterMode>,
    /// From `minFilter`: the in-level filter.
    pub min_filter: Option<FilterMode>,
    /// From `minFilter`: how mip levels are used.
    pub mipmap_filter: Option<MipmapFilterMode>,
}
