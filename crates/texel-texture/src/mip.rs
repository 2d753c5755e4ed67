//! Mipmapped filtering: nearest level (`mip_nearest`) and trilinear.
//!
//! Level selection follows the Vulkan spec ("Level-of-Detail Operation" and "Image Level(s)
//! Selection") with `level_base = 0` and `q` the last level: `d' = clamp(lod, 0, q)`;
//! - nearest level: `d = ceil(d' + 1/2) - 1` (so `lod = 0.5` still picks level 0, `0.5 + eps` level 1);
//! - linear: `d_hi = floor(d')`, `d_lo = min(d_hi + 1, q)`, `delta = fract(d')`, and the result is
//!   `lerp(filter(d_hi), filter(d_lo), delta)`; the last level holds.
//!
//! When `delta == 0` the second level is not read (the lerp would return the first value exactly),
//! which halves the reads on integer lods and at the last level.

use glam::Vec4;

use crate::address::Address;
use crate::bicubic::bicubic;
use crate::bilinear::bilinear;
use crate::fetch::{Fetch, Pyramid};
use crate::nearest::nearest;
use crate::sampler::FilterMode;

/// Filter one level with a within-level filter (Nearest, Linear or Cubic).
///
/// The minification-only filters (`Ewa`, `Ripmap`, `SummedArea`) never reach this function (the
/// sampler dispatches them first and rejects them as `mag_filter`); should one arrive it is
/// treated as Linear.
#[inline(always)]
pub(crate) fn filter_level<F: Fetch>(
    mode: &FilterMode,
    level: &F,
    addr: &Address,
    u: f32,
    v: f32,
) -> Vec4 {
    match mode {
        FilterMode::Nearest => nearest(level, addr, u, v),
        FilterMode::Linear => bilinear(level, addr, u, v),
        FilterMode::Cubic(c) => bicubic(level, addr, c, u, v),
        FilterMode::Ewa | FilterMode::Ripmap | FilterMode::SummedArea => {
            bilinear(level, addr, u, v)
        }
    }
}

/// A within-level filter, as a type: [`Linear`] (bilinear) is resolved at compile time, so the mip
/// paths built on it carry no per-call dispatch on [`FilterMode`]; `&FilterMode` dispatches at run
/// time.
pub(crate) trait LevelFilter: Copy {
    /// Filter `level` at `(u, v)`.
    fn apply<F: Fetch>(self, level: &F, addr: &Address, u: f32, v: f32) -> Vec4;
}

/// Bilinear inside each level.
#[derive(Clone, Copy)]
pub(crate) struct Linear;

impl LevelFilter for Linear {
    #[inline(always)]
    fn apply<F: Fetch>(self, level: &F, addr: &Address, u: f32, v: f32) -> Vec4 {
        bilinear(level, addr, u, v)
    }
}

impl LevelFilter for &FilterMode {
    #[inline(always)]
    fn apply<F: Fetch>(self, level: &F, addr: &Address, u: f32, v: f32) -> Vec4 {
        filter_level(self, level, addr, u, v)
    }
}

/// The Vulkan nearest-level rule `ceil(lod + 1/2) - 1`, clamped to `[0, last]`.
#[inline]
pub fn mip_nearest_level(lod: f32, last: usize) -> usize {
    let e = lod.clamp(0.0, last as f32) + 0.5;
    // ceil(e) - 1 for e in [0.5, last + 0.5] (NaN clamps to NaN and converts to level 0), by
    // truncating conversion: no libm `ceilf` call on the x86-64 baseline. Through `i32` (one
    // `cvttss2si` and a NaN select): a conversion to `usize` needs a range fix-up for values
    // above `i64::MAX`, about 20 instructions, a measurable share of a 1:1 mip-nearest sample
    // (docs/perf-log.md).
    // `last` is below 2^24 (a level count), so `e` and `t` are exact.
    let t = e as i32;
    (t + i32::from((t as f32) < e) - 1).max(0) as usize
}

/// Nearest-level mipmapping: `mode` in level [`mip_nearest_level`].
#[inline]
pub(crate) fn mip_nearest<P: Pyramid, L: LevelFilter>(
    p: &P,
    mode: L,
    addr: &Address,
    u: f32,
    v: f32,
    lod: f32,
) -> Vec4 {
    let level = mip_nearest_level(lod, p.level_count() - 1);
    mode.apply(&p.level(level), addr, u, v)
}

/// Trilinear (linear-between-levels) mipmapping at `lod` with `mode` inside each level.
#[inline]
pub(crate) fn trilinear<P: Pyramid, L: LevelFilter>(
    p: &P,
    mode: L,
    addr: &Address,
    u: f32,
    v: f32,
    lod: f32,
) -> Vec4 {
    let last = p.level_count() - 1;
    let d = lod.clamp(0.0, last as f32);
    // d >= 0, so truncation is the floor (no libm `floorf`); NaN gives level 0 and delta NaN,
    // which reads level 0 only.
    let k = d as usize;
    let delta = d - k as f32;
    let a = mode.apply(&p.level(k), addr, u, v);
    if delta > 0.0 && k < last {
        let b = mode.apply(&p.level(k + 1), addr, u, v);
        a + (b - a) * delta
    } else {
        a
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn vulkan_nearest_rounding() {
        assert_eq!(mip_nearest_level(0.0, 10), 0);
        assert_eq!(mip_nearest_level(0.5, 10), 0);
        assert_eq!(mip_nearest_level(0.500_001, 10), 1);
        assert_eq!(mip_nearest_level(1.49, 10), 1);
        assert_eq!(mip_nearest_level(1.5, 10), 1);
        assert_eq!(mip_nearest_level(1.51, 10), 2);
        assert_eq!(mip_nearest_level(99.0, 10), 10);
        assert_eq!(mip_nearest_level(-3.0, 10), 0);
        assert_eq!(mip_nearest_level(f32::NAN, 10), 0);
    }

    /// The integer rounding equals the float formula `ceil(clamp(lod) + 1/2) - 1` everywhere.
    #[test]
    fn nearest_level_matches_float_formula() {
        for k in -100..1400 {
            let lod = k as f32 * 0.01;
            for lod in [lod, f32::from_bits(lod.to_bits() + 1)] {
                let d = lod.clamp(0.0, 12.0);
                let want = ((d + 0.5).ceil() - 1.0).max(0.0) as usize;
                assert_eq!(mip_nearest_level(lod, 12), want, "lod = {lod}");
            }
        }
    }
}
