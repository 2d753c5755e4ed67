//! Mipmapped filtering: nearest level (`mip_nearest`) and trilinear, and the two level rules they
//! share with the batched path (`batch.rs`) and the anisotropic probes ([`crate::technique::aniso`]).
//!
//! Level selection follows the Vulkan spec ("Level-of-Detail Operation" and "Image Level(s)
//! Selection") with `level_base = 0` and `q` the last level: `d' = clamp(lod, 0, q)`;
//! - nearest level ([`nearest_level`]): `d = ceil(d' + 1/2) - 1` (so `lod = 0.5` still picks level
//!   0, `0.5 + eps` level 1);
//! - linear (`linear_levels`): `d_hi = floor(d')`, `d_lo = min(d_hi + 1, q)`, `delta = fract(d')`,
//!   and the result is `lerp(filter(d_hi), filter(d_lo), delta)`; the last level holds.
//!
//! When `delta == 0` the second level is not read (the lerp would return the first value exactly),
//! which halves the reads on integer lods and at the last level.

use glam::Vec4;

use crate::base::address::Address;
use crate::base::floor::{ceil_clamped, ceil_i32, floor_nonneg, floor_nonneg_staged};
use crate::base::footprint::Query;
use crate::base::lerp::lerp;
use crate::kernel::LevelFilter;
use crate::storage::view::Pyramid;

/// The Vulkan nearest-level rule `ceil(clamp(lod, 0, last) + 1/2) - 1`; NaN gives level 0.
#[inline]
pub fn nearest_level(lod: f32, last: usize) -> usize {
    // `last` is below 2^24 (a level count), so `e` is exact and within `ceil_i32`'s range.
    let e = lod.clamp(0.0, last as f32) + 0.5;
    (ceil_i32(e) - 1).max(0) as usize
}

/// [`nearest_level`] for the batched path's level stage, as a `u8` (at most 32 levels): the same
/// rule through [`ceil_clamped`] instead of an integer conversion, so a loop over a chunk of lods
/// vectorises. NaN gives level 0 (`max` returns the non-NaN operand). Equal to
/// [`nearest_level`] (tested).
#[inline(always)]
pub(crate) fn nearest_level_staged(lod: f32, last: f32) -> u8 {
    #[allow(clippy::manual_clamp)] // `clamp` keeps NaN
    let d = lod.max(0.0).min(last);
    (ceil_clamped(d + 0.5, last + 1.0).0 - 1).max(0) as u8
}

/// The Vulkan linear-level rule: the finer level `floor(d)` and the blend weight `d - floor(d)`
/// toward level `floor(d) + 1`, with `d = clamp(lod, 0, last)`. NaN gives level 0 and a NaN weight,
/// which reads level 0 only (the weight fails every `delta > 0` test).
#[inline(always)]
pub(crate) fn linear_levels(lod: f32, last: usize) -> (usize, f32) {
    linear_levels_by(lod, last, floor_nonneg)
}

/// [`linear_levels`] for the batched path's level stage: the same rule with the staged floor, so
/// a loop over a chunk of lods vectorises.
#[inline(always)]
pub(crate) fn linear_levels_staged(lod: f32, last: usize) -> (usize, f32) {
    let top = (last as f32).max(1.0);
    linear_levels_by(lod, last, |d| floor_nonneg_staged(d, top))
}

/// The linear-level rule with `floor`, a floor for `[0, last]` that maps NaN to 0.
#[inline(always)]
fn linear_levels_by(lod: f32, last: usize, floor: impl Fn(f32) -> (i32, f32)) -> (usize, f32) {
    let d = lod.clamp(0.0, last as f32);
    let (k, fk) = floor(d);
    (k as usize, d - fk)
}

/// Nearest-level mipmapping: `filter` in level [`nearest_level`] of `q.lod`.
#[inline]
pub(crate) fn mip_nearest<P: Pyramid>(
    p: &P,
    filter: impl LevelFilter,
    addr: &Address,
    q: &Query,
) -> Vec4 {
    let level = nearest_level(q.lod, p.level_count() - 1);
    filter.filter(&p.level(level), addr, q.uv())
}

/// Trilinear (linear-between-levels) mipmapping at `q.lod` with `filter` inside each level: the
/// levels and weight of [`linear_levels`], the coarser level read only when weighed.
#[inline]
pub(crate) fn trilinear<P: Pyramid>(
    p: &P,
    filter: impl LevelFilter,
    addr: &Address,
    q: &Query,
) -> Vec4 {
    let last = p.level_count() - 1;
    let (k, delta) = linear_levels(q.lod, last);
    let a = filter.filter(&p.level(k), addr, q.uv());
    if delta > 0.0 && k < last {
        lerp(a, filter.filter(&p.level(k + 1), addr, q.uv()), delta)
    } else {
        a
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn vulkan_nearest_rounding() {
        assert_eq!(nearest_level(0.0, 10), 0);
        assert_eq!(nearest_level(0.5, 10), 0);
        assert_eq!(nearest_level(0.500_001, 10), 1);
        assert_eq!(nearest_level(1.49, 10), 1);
        assert_eq!(nearest_level(1.5, 10), 1);
        assert_eq!(nearest_level(1.51, 10), 2);
        assert_eq!(nearest_level(99.0, 10), 10);
        assert_eq!(nearest_level(-3.0, 10), 0);
        assert_eq!(nearest_level(f32::NAN, 10), 0);
    }

    /// The staged rule equals the scalar one on a sweep of lods (both signs, the level
    /// boundaries and their neighbours, NaN and infinities) for several level counts.
    #[test]
    fn nearest_level_staged_equals_nearest_level() {
        for last in [0usize, 1, 5, 12, 22] {
            let mut lods: Vec<f32> = (-3000..3000).map(|k| k as f32 * 0.01).collect();
            for k in 0..=last + 1 {
                let b = (k as f32 + 0.5).to_bits();
                lods.extend((b - 8..=b + 8).map(f32::from_bits));
                lods.push(k as f32);
            }
            lods.extend([
                f32::NAN,
                f32::INFINITY,
                f32::NEG_INFINITY,
                -0.0,
                1e30,
                -1e30,
            ]);
            for lod in lods {
                let want = nearest_level(lod, last);
                assert_eq!(
                    usize::from(nearest_level_staged(lod, last as f32)),
                    want,
                    "{lod} {last}"
                );
            }
        }
    }

    /// The integer rounding equals the float formula `ceil(clamp(lod) + 1/2) - 1` everywhere.
    #[test]
    fn nearest_level_matches_float_formula() {
        for k in -100..1400 {
            let lod = k as f32 * 0.01;
            for lod in [lod, f32::from_bits(lod.to_bits() + 1)] {
                let d = lod.clamp(0.0, 12.0);
                let want = ((d + 0.5).ceil() - 1.0).max(0.0) as usize;
                assert_eq!(nearest_level(lod, 12), want, "lod = {lod}");
            }
        }
    }
}

#[cfg(test)]
mod level_tests {
    use super::*;

    /// Both forms of the linear rule equal its definition with libm's floor, NaN and the edges
    /// included.
    #[test]
    fn linear_levels_match_the_float_formula() {
        for last in [0usize, 1, 5, 12] {
            for k in -100..1400 {
                let lod = k as f32 * 0.0123;
                for lod in [lod, f32::from_bits(lod.to_bits() + 1)] {
                    let d = lod.clamp(0.0, last as f32);
                    for rule in [linear_levels, linear_levels_staged] {
                        let (level, delta) = rule(lod, last);
                        assert_eq!(level, d.floor() as usize, "lod {lod} last {last}");
                        assert_eq!(delta.to_bits(), (d - d.floor()).to_bits(), "lod {lod}");
                    }
                }
            }
            for rule in [linear_levels, linear_levels_staged] {
                let (level, delta) = rule(f32::NAN, last);
                assert_eq!(level, 0);
                assert!(delta.is_nan());
            }
        }
    }
}
