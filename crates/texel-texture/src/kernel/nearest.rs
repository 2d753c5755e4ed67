//! Nearest-texel (point) filtering.
//!
//! `ij = floor(xy)` with `xy = (u * W, v * H)` (docs/guide/conventions.md; Vulkan spec "Texel
//! Selection", NEAREST):
//! the texel whose square `[i, i+1) x [j, j+1)` contains the sample point. One texel read. The
//! batched path (`batch.rs`) stages the same [`origin`] and floor over a chunk of samples.

use glam::{Vec2, Vec4};

use crate::base::address::Address;
use crate::base::floor::floor_index;
use crate::kernel::bilinear::texel_or_border;
use crate::kernel::staged::Taps;
use crate::kernel::LevelFilter;
use crate::storage::fetch::Fetch;

/// The offset of the first tap in texels: nearest reads the texel containing the sample point: no offset.
pub(crate) const HALF: f32 = 0.0;

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

/// Nearest as a type: the one-sample filter ([`LevelFilter`]) and its staged form for the batched
/// path (`batch.rs`'s `Taps`: the same origin, one texel, and the edge filter).
#[derive(Clone, Copy)]
pub(crate) struct Point;

impl LevelFilter for Point {
    #[inline(always)]
    fn filter<F: Fetch>(self, level: &F, addr: &Address, uv: Vec2) -> Vec4 {
        nearest(level, addr, uv)
    }
}

impl Taps for Point {
    const HALF: f32 = HALF;
    const REACH: f32 = 0.0;
    #[inline(always)]
    fn inside<F: Fetch>(level: &F, i: u32, j: u32, _: (f32, f32)) -> Vec4 {
        level.texel(i, j)
    }
    #[inline(always)]
    fn wrapped<F: Fetch>(level: &F, i: [u32; 2], j: [u32; 2], _: (f32, f32)) -> Vec4 {
        level.texel(i[0], j[0])
    }
}
