//! Linear interpolation as every filter computes it, and the bilinear blend built from it. One
//! definition, so that the scalar, batched and eight-lane paths round alike.

use glam::Vec4;

/// `a + (b - a) * t`: the one interpolation every filter blends with (bilinear's three, the
/// lerp between mip levels, the ripmap's and EWA's level blends).
#[inline(always)]
pub(crate) fn lerp(a: Vec4, b: Vec4, t: f32) -> Vec4 {
    a + (b - a) * t
}

/// The bilinear blend of the quad `[T00, T10, T01, T11]` (as `Fetch::quad` orders it) with
/// fractions `a` (along x) and `b` (along y).
#[inline(always)]
pub(crate) fn blend([t00, t10, t01, t11]: [Vec4; 4], a: f32, b: f32) -> Vec4 {
    lerp(lerp(t00, t10, a), lerp(t01, t11, a), b)
}
