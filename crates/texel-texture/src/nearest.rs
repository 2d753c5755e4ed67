//! Nearest-texel (point) filtering.
//!
//! `ij = floor(xy)` with `xy = (u * W, v * H)` (DESIGN.md; Vulkan spec "Texel Selection", NEAREST):
//! the texel whose square `[i, i+1) x [j, j+1)` contains the sample point. One texel read. The
//! batched path (`batch.rs`) stages the same [`origin`] and floor over a chunk of samples.

use glam::{Vec2, Vec4};

use crate::address::Address;
use crate::bilinear::texel_or_border;
use crate::fetch::Fetch;
use crate::floor::floor_index;

/// The continuous texel coordinate whose floor is the texel read along one axis: `u * n` for a
/// level `n` texels long.
#[inline(always)]
pub(crate) fn origin(u: f32, n: f32) -> f32 {
    u * n
}

/// Nearest texel of `level` at normalised `uv` (finite), after address wrapping.
#[inline(always)]
pub(crate) fn nearest<F: Fetch>(level: &F, addr: &Address, uv: Vec2) -> Vec4 {
    let (w, h) = level.size();
    let (i, j) = (
        floor_index(origin(uv.x, w as f32)),
        floor_index(origin(uv.y, h as f32)),
    );
    if (0..i64::from(w)).contains(&i) && (0..i64::from(h)).contains(&j) {
        // Inside the level every address mode is the identity.
        return level.texel(i as u32, j as u32);
    }
    texel_or_border(level, addr, addr.u.wrap(i, w), addr.v.wrap(j, h))
}
