//! Where a fragment is shaded: [`ShadingPoint`], the one argument that tells the shading
//! functions ([`crate::shade`], [`crate::relief`]) where they are: a triangle's vertices,
//! barycentrics, their derivatives and a footprint, travelling together.

use glam::{DVec3, Vec3};
use texel_texture::Footprint;

use crate::draw::Vertex;

/// One fragment's place on its triangle, as shading reads it.
#[derive(Clone, Copy, Debug)]
pub(crate) struct ShadingPoint<'v> {
    /// The triangle's vertices: positions, normals, tangents, colours and `uv`, interpolated
    /// by the barycentrics.
    pub verts: [&'v Vertex; 3],
    /// Perspective-correct barycentrics, in `f64`.
    pub lambda: DVec3,
    /// The barycentrics' screen derivatives per pixel right and down; zero where they are not
    /// known (the reference's point sub-samples).
    pub dlambda: [DVec3; 2],
    /// The footprint every map is read through: `uv` reduced by whole periods
    /// ([`crate::shade::DrawContext::footprint`]) and its screen derivatives.
    pub fp: Footprint,
}

impl ShadingPoint<'_> {
    /// The barycentrics in `f32`, as vertex attributes are interpolated.
    #[inline(always)]
    pub(crate) fn l(&self) -> Vec3 {
        self.lambda.as_vec3()
    }
}
