//! Bilinear filtering within one level.
//!
//! `base = floor(xy - 0.5)`, `(a, b) = fract(xy - 0.5)` (Vulkan spec "Texel Selection", LINEAR,
//! eq. for `i0 = floor(u - 1/2)`); the result is
//! `(1-a)(1-b) T[i0,j0] + a(1-b) T[i1,j0] + (1-a) b T[i0,j1] + a b T[i1,j1]`. Each of the four indices
//! is wrapped separately, so an edge texel blends with the opposite edge under Repeat and with the
//! border colour under ClampToBorder. Four texel reads.
//!
//! Fast path: when all four texels lie inside the level (every address mode is the identity there)
//! they are read as two 2-texel row slices ([`Fetch::quad`]), skipping the four wraps and the
//! border test; only samples within half a texel of an edge take the general path. Results are
//! bit-identical to the general path.

use glam::Vec4;

use crate::address::{floor_index, Address};
use crate::fetch::Fetch;

/// Read texel `(i, j)` if both indices survived wrapping, else the border colour.
#[inline(always)]
pub(crate) fn texel_or_border<F: Fetch>(
    level: &F,
    addr: &Address,
    i: Option<u32>,
    j: Option<u32>,
) -> Vec4 {
    match (i, j) {
        (Some(i), Some(j)) => level.texel(i, j),
        _ => addr.border,
    }
}

/// Bilinear sample of `level` at normalised `(u, v)` (finite).
#[inline(always)]
pub(crate) fn bilinear<F: Fetch>(level: &F, addr: &Address, u: f32, v: f32) -> Vec4 {
    let (w, h) = level.size();
    let x = u * w as f32 - 0.5;
    let y = v * h as f32 - 0.5;
    let (i0, j0) = (floor_index(x), floor_index(y));
    // `i0 as f32` is `x.floor()` exactly (see `floor_index`), so the weights are unchanged.
    let (a, b) = (x - i0 as f32, y - j0 as f32);
    let [t00, t10, t01, t11] =
        if (0..i64::from(w) - 1).contains(&i0) && (0..i64::from(h) - 1).contains(&j0) {
            // Fast path: all four texels inside the level, where every address mode is the identity.
            level.quad(i0 as u32, j0 as u32)
        } else {
            let i = [addr.u.wrap(i0, w), addr.u.wrap(i0.saturating_add(1), w)];
            let j = [addr.v.wrap(j0, h), addr.v.wrap(j0.saturating_add(1), h)];
            [
                texel_or_border(level, addr, i[0], j[0]),
                texel_or_border(level, addr, i[1], j[0]),
                texel_or_border(level, addr, i[0], j[1]),
                texel_or_border(level, addr, i[1], j[1]),
            ]
        };
    let top = t00 + (t10 - t00) * a;
    let bottom = t01 + (t11 - t01) * a;
    top + (bottom - top) * b
}
