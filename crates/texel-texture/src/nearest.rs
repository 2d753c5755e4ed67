//! Nearest-texel (point) filtering.
//!
//! `ij = floor(xy)` with `xy = (u * W, v * H)` (DESIGN.md; Vulkan spec "Texel Selection", NEAREST):
//! the texel whose square `[i, i+1) x [j, j+1)` contains the sample point. One texel read.

use glam::Vec4;

use crate::address::{floor_index, Address};
use crate::fetch::Fetch;

/// Nearest texel of `level` at normalised `(u, v)` (finite), after address wrapping.
#[inline(always)]
pub(crate) fn nearest<F: Fetch>(level: &F, addr: &Address, u: f32, v: f32) -> Vec4 {
    let (w, h) = level.size();
    let (i, j) = (floor_index(u * w as f32), floor_index(v * h as f32));
    if (0..i64::from(w)).contains(&i) && (0..i64::from(h)).contains(&j) {
        // Inside the level every address mode is the identity.
        return level.texel(i as u32, j as u32);
    }
    match (addr.u.wrap(i, w), addr.v.wrap(j, h)) {
        (Some(i), Some(j)) => level.texel(i, j),
        _ => addr.border,
    }
}
