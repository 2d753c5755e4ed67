//! The scene data model: what to render, independent of how it is rasterized.

use std::collections::BTreeMap;
use std::path::PathBuf;

use glam::{Vec2, Vec3, Vec4};
use texel_texture::{AddressMode, ColorSpace, FilterMode, MipmapFilterMode};

use crate::camera::Camera;
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
}

/// The origin of a texture's texels.
#[derive(Clone, Debug, PartialEq)]
pub enum TextureSource {
    /// An image file (PNG, JPEG, OpenEXR), already resolved against the scene file's directory.
    File(PathBuf),
    /// A generated texture.
    Procedural(Procedural),
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
