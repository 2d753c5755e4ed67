//! Bilinear filtering within one level.
//!
//! `base = floor(xy - 0.5)`, `(a, b) = fract(xy - 0.5)` (Vulkan spec "Texel Selection", LINEAR,
//! eq. for `i0 = floor(u - 1/2)`); the result is
//! `(1-a)(1-b) T[i0,j0] + a(1-b) T[i1,j0] + (1-a) b T[i0,j1] + a b T[i1,j1]`, computed as two
//! horizontal [`lerp`]s and a vertical one ([`blend`]). Each of the four indices is wrapped
//! separately, so an edge texel blends with the opposite edge under Repeat and with the border
//! colour under ClampToBorder. Four texel reads.
//!
//! The kernels here — where the taps start ([`origin`]), the quad blend ([`blend`]) and the whole
//! filter ([`bilinear`]) — are the ones every path runs: the one-sample path calls [`bilinear`],
//! and the batched path (`batch.rs`) stages the same [`origin`], floor and [`blend`] over a chunk
//! of samples, so the results are bit for bit equal.
//!
//! When all four texels lie inside the level (every address mode is the identity there) they are
//! read as two 2-texel rows of one range ([`Fetch::quad`]), skipping the four wraps and the
//! border test; only samples within half a texel of an edge wrap their indices. Results are the
//! same either way.

use glam::{Vec2, Vec4};

use crate::base::address::Address;
use crate::base::floor::floor_index;
use crate::base::lerp::blend;
use crate::kernel::staged::Taps;
use crate::kernel::LevelFilter;
use crate::storage::fetch::Fetch;

/// The offset of the first tap in texels: bilinear's taps start half a texel before the sample point (texel centres sit at half-integers).
pub(crate) const HALF: f32 = 0.5;

/// The continuous texel coordinate of the top-left tap along one axis: `u * n - 1/2` for a level
/// `n` texels long (texel centres sit at half-integers).
#[inline(always)]
pub(crate) fn origin(u: f32, n: f32) -> f32 {
    u * n - HALF
}

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

/// Bilinear sample of `level` at normalised `uv` (finite).
#[inline(always)]
pub(crate) fn bilinear<F: Fetch>(level: &F, addr: &Address, uv: Vec2) -> Vec4 {
    let (quad, a, b) = taps(level, addr, uv);
    blend(quad, a, b)
}

/// The four texels (or border colours) a bilinear sample of `level` at normalised `uv` (finite)
/// reads, in [`Fetch::quad`]'s order, and its fractions `(a, b)`: [`bilinear`] before the blend
/// (also [`crate::kernel::fixed8`]'s).
#[inline(always)]
pub(crate) fn taps<F: Fetch>(level: &F, addr: &Address, uv: Vec2) -> ([Vec4; 4], f32, f32) {
    let (w, h) = level.size();
    let x = origin(uv.x, w as f32);
    let y = origin(uv.y, h as f32);
    let (i0, j0) = (floor_index(x), floor_index(y));
    // `i0 as f32` is `x.floor()` exactly (see `floor_index`).
    let (a, b) = (x - i0 as f32, y - j0 as f32);
    let quad = if (0..i64::from(w) - 1).contains(&i0) && (0..i64::from(h) - 1).contains(&j0) {
        // All four texels inside the level, where every address mode is the identity.
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
    (quad, a, b)
}

/// Bilinear as a type: the one-sample filter ([`LevelFilter`]) and its staged form for the batched
/// path (`batch.rs`'s `Taps`: the same origin, blend and edge filter).
#[derive(Clone, Copy)]
pub(crate) struct Bilinear;

impl LevelFilter for Bilinear {
    #[inline(always)]
    fn filter<F: Fetch>(self, level: &F, addr: &Address, uv: Vec2) -> Vec4 {
        bilinear(level, addr, uv)
    }
}

impl Taps for Bilinear {
    const HALF: f32 = HALF;
    const REACH: f32 = 1.0;
    #[inline(always)]
    fn inside<F: Fetch>(level: &F, i: u32, j: u32, (a, b): (f32, f32)) -> Vec4 {
        level.bilinear_quad(i, j, a, b)
    }
    #[inline(always)]
    fn inside_run<F: Fetch>(
        level: &F,
        run: crate::storage::lanes::Run<'_>,
        out: &mut [[f32; 4]],
    ) -> bool {
        level.bilinear_run(run, out)
    }
    #[inline(always)]
    fn wrapped<F: Fetch>(level: &F, i: [u32; 2], j: [u32; 2], (a, b): (f32, f32)) -> Vec4 {
        level.bilinear_wrapped(i, j, a, b)
    }
}
