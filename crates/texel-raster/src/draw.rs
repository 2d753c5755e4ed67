//! What is drawn: vertices, indexed triangles and the texture/sampler pair of one draw call.

use glam::{Mat4, Vec2, Vec3, Vec4};
use texel_texture::mapping::sphere::SurfaceProjection;
use texel_texture::{Sampler, Texture};

use crate::material::Material;

/// One vertex of a mesh, in world space.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Vertex {
    /// World-space position.
    pub position: Vec3,
    /// Normalised texture coordinate (docs/guide/conventions.md: `(0, 0)` is the top-left of the
    /// image file; values outside `[0, 1)` are resolved by the sampler's address modes).
    pub uv: Vec2,
    /// Linear RGBA colour multiplied into the texture colour (white for a plain textured mesh).
    pub color: Vec4,
    /// World-space normal, used by lighting; need not be normalised (the interpolated normal is
    /// normalised per pixel).
    pub normal: Vec3,
    /// World-space tangent (`xyz`, along increasing u) and handedness (`w = +-1`) for normal
    /// maps, as glTF's `TANGENT`: the bitangent is `w * cross(normal, tangent)`. Zero when none.
    pub tangent: Vec4,
}

impl Vertex {
    /// A white vertex with normal `+y` at `position` with texture coordinate `uv`.
    pub fn new(position: Vec3, uv: Vec2) -> Self {
        Vertex {
            position,
            uv,
            color: Vec4::ONE,
            normal: Vec3::Y,
            tangent: Vec4::ZERO,
        }
    }
}

/// One draw call: an indexed triangle list, textured with one texture through one sampler.
///
/// Triangles whose indices are out of range make [`crate::render`] return
/// [`crate::RasterError::IndexOutOfRange`]; triangles that are degenerate (zero projected area, NaN
/// or infinite positions) are skipped silently.
#[derive(Clone, Copy, Debug)]
pub struct DrawCall<'a> {
    /// The vertices the triangles index.
    pub vertices: &'a [Vertex],
    /// Triangles as three vertex indices. Front faces are counter-clockwise in NDC (OpenGL's default,
    /// which appears counter-clockwise on screen too).
    pub triangles: &'a [[u32; 3]],
    /// The texture sampled for the base (diffuse) colour.
    pub texture: &'a Texture,
    /// How the texture is sampled (filter, address modes, lod clamps).
    pub sampler: &'a Sampler,
    /// World to clip space: `perspective * look_at * world_from_model` (see [`crate::camera`]).
    /// Lighting takes the eye's position from it (the point it maps to the clip-space direction
    /// `(0, 0, 1, 0)`, the centre of projection).
    pub clip_from_world: Mat4,
    /// Shading parameters and maps when the frame has lights ([`crate::RenderSettings::lights`]);
    /// `None` is Lambertian (see [`crate::material`]).
    pub material: Option<Material<'a>>,
    /// Texture coordinates as a sphere mapping of the surface position, if the mesh has one
    /// ([`UvMapping`]); `None`: the vertices' `uv`, interpolated.
    pub uv_mapping: Option<UvMapping>,
}

/// A mesh whose texture coordinates are a projection ([`SurfaceProjection`]: equirect or
/// Mercator) of its points' directions from a centre: the lecture's spherical mappings.
///
/// With [`UvEvaluation::PerPixel`] the rasterizer evaluates the projection at each pixel's
/// interpolated world position `p` (its direction `p - centre`; points of a flat triangle are
/// projected radially), and `uv`'s screen derivatives are the projection's Jacobian applied to
/// `dp/dx` and `dp/dy` ([`SurfaceProjection::duv`]), never differences of `u`: no seam, and in
/// the 2x2-quad mode the quad's position differences go through the same Jacobian. With
/// [`UvEvaluation::PerVertex`] it interpolates the vertices' `uv` (which should be the projection
/// at each vertex), the classic approximation whose error grows with the projection's curvature
/// across a triangle. The supersampled reference evaluates the projection at every sample in
/// both cases: it is the ground truth both approximate.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UvMapping {
    /// The projection.
    pub projection: SurfaceProjection,
    /// The sphere's centre, world space.
    pub centre: Vec3,
    /// Where the rasterizer evaluates it.
    pub evaluation: UvEvaluation,
}

/// Where a [`UvMapping`] is evaluated.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum UvEvaluation {
    /// Exactly, at every pixel (the default).
    #[default]
    #[cfg_attr(
        feature = "clap",
        value(
            name = "pixel",
            help = "The projection of each pixel's position, with its analytic derivatives"
        )
    )]
    PerPixel,
    /// At the vertices (the mesh's `uv`), interpolated across each triangle.
    #[cfg_attr(
        feature = "clap",
        value(
            name = "vertex",
            help = "The vertices' uv, interpolated across each triangle"
        )
    )]
    PerVertex,
}

impl UvEvaluation {
    /// The name the command line uses: `vertex` or `pixel`.
    pub fn name(self) -> &'static str {
        match self {
            UvEvaluation::PerVertex => "vertex",
            UvEvaluation::PerPixel => "pixel",
        }
    }
}
