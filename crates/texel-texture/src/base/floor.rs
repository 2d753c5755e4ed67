//! Rounding to integers, in one place: every floor and ceil on the sampling paths (per sample) and
//! in the rasterizer's span stages. Code off those paths keeps libm's `floor`: the pyramid's and
//! ripmap's build-time taps, the summed-area table's `f64` box set-up (whose inputs may exceed the
//! `2^63` these forms are exact to), the rasterizer's fixed-point snapping and the debug views.
//!
//! Why not `f32::floor`: the x86-64 baseline (SSE2, no SSE4.1 `roundss`) has no rounding
//! instruction, so `floor`/`ceil` are calls into libm, a measurable share of a frame
//! (docs/decisions.md). Each function here is exact on the domain it states, and each has a test
//! comparing it with `f32::floor`/`f64::floor` there.
//!
//! Two forms:
//! - **scalar** (one sample at a time, any input): a truncating conversion, minus one where the
//!   truncation went up. Conversions saturate and map NaN to 0, so these are total.
//!   [`floor_index`] (texel indices), [`ceil_i32`] (level and probe counts), [`floor_f64`] /
//!   [`ceil_f64`] (EWA's spans).
//! - **staged** (loops over many samples that must vectorise): no float-to-integer conversion,
//!   whose saturating semantics need a range fix-up per value on SSE2 (docs/decisions.md);
//!   instead the value is
//!   rounded by adding and subtracting `1.5 * 2^(mantissa bits)`, and one is taken off where that
//!   rounded up. Exact below `2^22` (`f32`) or `2^51` (`f64`), which callers guarantee by clamping.
//!   [`floor_clamped`] (the batched sampler's texel indices and levels; the stored codes as
//!   bytes; the unorm8 encode), [`ceil_clamped`] (the nearest-mip level), [`round_staged`]
//!   (the fixed-point filters' weights and results), [`floor_staged`] and [`floor_staged_f64`]
//!   (the rasterizer's period reduction of `uv`).

/// `floor(x)` as an `i64` texel index, saturating at the `i64` range; NaN gives 0.
///
/// Equal to `x.floor() as i64` for every `x`. For `|x| < 2^63` the result converts back to
/// `x.floor()` exactly (below `2^24` every integer is an `f32`; above, `x` is itself an integer),
/// so `x - floor_index(x) as f32` is the fraction the filters weigh by.
#[inline(always)]
pub fn floor_index(x: f32) -> i64 {
    let t = x as i64; // truncates toward zero, saturates, NaN -> 0
    t.saturating_sub(i64::from((t as f32) > x))
}

/// `floor(x)` for `0 <= x < 2^31`, as an integer and as an `f32` (truncation is the floor there);
/// NaN gives 0. The scalar form of [`floor_nonneg_staged`].
#[inline(always)]
pub fn floor_nonneg(x: f32) -> (i32, f32) {
    let k = x as i32;
    (k, k as f32)
}

/// [`floor_nonneg`] staged: for `0 <= x <= hi`, `1 <= hi <=` [`STAGED_F32_LIMIT`], NaN giving 0,
/// through [`floor_clamped`] (no conversion, so loops over many values vectorise).
#[inline(always)]
pub fn floor_nonneg_staged(x: f32, hi: f32) -> (i32, f32) {
    floor_clamped(if x.is_nan() { 0.0 } else { x }, hi)
}

/// `ceil(x)` as an `i32` for `|x| < 2^31`; NaN gives 0, larger values saturate.
///
/// Used where a count or a level is rounded up: the Vulkan nearest-level rule
/// (`mip::nearest_level`) and the anisotropic probe count (`aniso::probe_count`).
#[inline(always)]
pub fn ceil_i32(x: f32) -> i32 {
    // Through `i32`: one `cvttss2si`; a conversion to `usize` needs a range fix-up for values
    // above `i64::MAX`, many instructions (docs/decisions.md).
    let t = x as i32;
    t + i32::from((t as f32) < x)
}

/// `floor(x)` for `f64`, exact for `|x| < 2^63`; NaN stays NaN; beyond that range the result
/// saturates (EWA's visit bounds absorb it).
#[inline(always)]
pub fn floor_f64(x: f64) -> f64 {
    if x.is_nan() {
        return x;
    }
    let t = x as i64 as f64;
    if t > x {
        t - 1.0
    } else {
        t
    }
}

/// `ceil(x)` as [`floor_f64`]: `-floor(-x)`.
#[inline(always)]
pub fn ceil_f64(x: f64) -> f64 {
    -floor_f64(-x)
}

use glam::Vec4;

/// Largest `hi` [`floor_clamped`] accepts (`2^22`): the sum with its rounding constant must stay
/// in `[2^23, 2^24)`, where `f32` spacing is 1.
pub const STAGED_F32_LIMIT: f32 = 4_194_304.0;

/// `1.5 * 2^23`: added to an `f32` of magnitude below `2^22`, the sum lies in `[2^23, 2^24)`, where
/// the spacing is 1, so it is rounded to an integer, which its low mantissa bits hold.
pub(crate) const ROUND_F32: f32 = 12_582_912.0;

/// Staged `round(x)` to the nearest integer, halves to even (IEEE's rounding of the sum), for
/// `|x| <` [`STAGED_F32_LIMIT`]: the rounding step [`floor_clamped`] and [`ceil_clamped`] start
/// from. Branch-free and conversion-free.
#[inline(always)]
pub fn round_staged(x: f32) -> f32 {
    (x + ROUND_F32) - ROUND_F32
}

/// [`round_staged`] in four lanes (one vector addition and subtraction).
#[inline(always)]
pub fn round_staged4(x: Vec4) -> Vec4 {
    let r = Vec4::splat(ROUND_F32);
    (x + r) - r
}

/// [`floor_clamped`]'s `f32` result in four lanes: `floor(clamp(x, -1, hi))` per lane, same
/// domain; callers clear NaN first (glam's lane-wise `max` does not promise which operand a NaN
/// gives).
#[inline(always)]
pub fn floor_clamped4(x: Vec4, hi: f32) -> Vec4 {
    let c = x.max(Vec4::splat(-1.0)).min(Vec4::splat(hi));
    let r = round_staged4(c);
    Vec4::select(r.cmpgt(c), r - Vec4::ONE, r)
}

/// Lanes holding integers in `0..=255` as bytes, read from the bits of their sum with the
/// rounding constant (the integer sits in the low mantissa bits): no saturating conversion.
#[inline(always)]
pub fn integer_bytes4(x: [f32; 4]) -> [u8; 4] {
    x.map(integer_byte)
}

/// [`integer_bytes4`] for one lane: an `f32` holding an integer in `0..=255` as that byte.
#[inline(always)]
pub fn integer_byte(x: f32) -> u8 {
    (x + ROUND_F32).to_bits() as u8
}

/// `x` rounded by [`round_staged`] (the clamped value `c`), as an integer read from the sum's
/// bits and as an `f32`.
#[inline(always)]
fn round_parts(c: f32) -> (i32, f32) {
    let sum = c + ROUND_F32;
    // Integer value of the rounded sum: its bits minus those of ROUND_F32.
    (
        sum.to_bits() as i32 - ROUND_F32.to_bits() as i32,
        sum - ROUND_F32,
    )
}

/// Staged `floor(clamp(x, -1, hi))` as an integer and as an `f32`, for `1 <= hi <=`
/// [`STAGED_F32_LIMIT`] and any `x` except NaN (NaN clamps to -1).
///
/// Branch-free and conversion-free (the integer is read from the rounded sum's bits), so a loop
/// over a chunk of samples vectorises. The clamp keeps texel indices in `[-1, hi]`: the floor of
/// the clamped value lies in `[0, hi)` exactly when the floor of `x` does, so callers can test
/// "inside the level" on the result, and inside it the clamp is the identity.
#[inline(always)]
pub fn floor_clamped(x: f32, hi: f32) -> (i32, f32) {
    let c = x.max(-1.0).min(hi);
    let (r, rounded) = round_parts(c);
    let down = rounded > c;
    (
        r - i32::from(down),
        if down { rounded - 1.0 } else { rounded },
    )
}

/// Staged `ceil(clamp(x, -1, hi))`, as [`floor_clamped`] (same domain; NaN clamps to -1): the
/// rounded value plus one where rounding went down.
#[inline(always)]
pub fn ceil_clamped(x: f32, hi: f32) -> (i32, f32) {
    let c = x.max(-1.0).min(hi);
    let (r, rounded) = round_parts(c);
    let up = rounded < c;
    (r + i32::from(up), if up { rounded + 1.0 } else { rounded })
}

/// Staged `floor(t)` for `f32`, exact for `|t| <` [`STAGED_F32_LIMIT`] (callers check the range
/// and keep their input beyond it; NaN stays NaN). Branch-free, as [`floor_staged_f64`]: the
/// rasterizer's `f32` period reduction of `uv`.
#[inline(always)]
pub fn floor_staged(t: f32) -> f32 {
    let r = (t + ROUND_F32) - ROUND_F32;
    if r > t {
        r - 1.0
    } else {
        r
    }
}

/// `1.5 * 2^52`, [`ROUND_F32`]'s `f64` counterpart.
const ROUND_F64: f64 = 6_755_399_441_055_744.0;

/// Largest `|t|` [`floor_staged_f64`] is exact for (`2^51`).
pub const STAGED_F64_LIMIT: f64 = 2_251_799_813_685_248.0;

/// Staged `floor(t)` for `f64`, exact for `|t| <` [`STAGED_F64_LIMIT`] (callers check the range
/// and keep their input beyond it). Branch-free, so the rasterizer's span loops vectorise: an
/// integer-conversion floor has no packed `f64` form before AVX-512.
#[inline(always)]
pub fn floor_staged_f64(t: f64) -> f64 {
    let r = (t + ROUND_F64) - ROUND_F64;
    if r > t {
        r - 1.0
    } else {
        r
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Values of every kind: zeros, halves, values just below integers, large and huge ones.
    fn samples() -> Vec<f32> {
        let mut xs = vec![
            0.0f32,
            -0.0,
            0.5,
            -0.5,
            1.0,
            -1.0,
            0.999_999_9,
            -0.999_999_9,
            1e-30,
            -1e-30,
            16_777_215.5,
            -16_777_215.5,
            16_777_216.0,
            -16_777_217.0,
            2.5e11,
            -2.5e11,
            1e18,
            -1e18,
            9.2e18,
            -9.2e18,
        ];
        for k in -2000..2000 {
            xs.push(k as f32 * 0.25);
            xs.push(f32::from_bits((k as f32).to_bits().wrapping_sub(1)));
        }
        for k in 0..20_000 {
            xs.push(k as f32 * 0.173_205_08 - 3.0);
        }
        xs
    }

    #[test]
    fn floor_index_is_the_floor() {
        for x in samples() {
            assert_eq!(floor_index(x), x.floor() as i64, "x = {x}");
        }
        assert_eq!(floor_index(f32::NAN), 0);
        assert_eq!(floor_index(f32::INFINITY), i64::MAX);
        assert_eq!(floor_index(f32::NEG_INFINITY), i64::MIN);
    }

    #[test]
    fn nonneg_floors_are_the_floor() {
        for x in samples().into_iter().filter(|x| (0.0..1e9).contains(x)) {
            assert_eq!(floor_nonneg(x), (x.floor() as i32, x.floor()), "x = {x}");
            if x <= STAGED_F32_LIMIT {
                let hi = STAGED_F32_LIMIT;
                assert_eq!(floor_nonneg_staged(x, hi), (x.floor() as i32, x.floor()));
            }
        }
        assert_eq!(floor_nonneg(f32::NAN), (0, 0.0));
        assert_eq!(floor_nonneg_staged(f32::NAN, 4.0), (0, 0.0));
    }

    #[test]
    fn ceil_i32_is_the_ceil() {
        for x in samples().into_iter().filter(|x| x.abs() < 2e9) {
            assert_eq!(ceil_i32(x), x.ceil() as i32, "x = {x}");
        }
        assert_eq!(ceil_i32(f32::NAN), 0);
    }

    #[test]
    fn f64_floor_and_ceil_are_libm_s() {
        let xs = samples().into_iter().filter(|x| !x.is_nan()).map(f64::from);
        for x in xs.chain([1e15 + 0.5, -1e15 - 0.5, 4e18]) {
            assert_eq!(floor_f64(x), x.floor(), "floor {x}");
            assert_eq!(ceil_f64(x), x.ceil(), "ceil {x}");
            if x.abs() < STAGED_F64_LIMIT {
                assert_eq!(floor_staged_f64(x), x.floor(), "staged {x}");
            }
        }
        assert!(floor_f64(f64::NAN).is_nan() && ceil_f64(f64::NAN).is_nan());
    }

    #[test]
    fn floor_staged_is_the_floor_below_the_limit() {
        let mut xs: Vec<f32> = samples().into_iter().filter(|x| !x.is_nan()).collect();
        for e in [1.0f32, 2.0, 16_384.0, STAGED_F32_LIMIT] {
            xs.extend([e - 0.5, e - 1e-3 * e.sqrt(), e, -e, -e + 0.25, e - 0.75]);
        }
        let mut checked = 0;
        for x in xs.into_iter().filter(|x| x.abs() < STAGED_F32_LIMIT) {
            assert_eq!(floor_staged(x), x.floor(), "staged {x}");
            checked += 1;
        }
        assert!(checked > 20, "{checked}");
        assert!(floor_staged(f32::NAN).is_nan());
    }

    /// The staged floor equals `f32::floor` of the clamped value for every `hi` up to the limit.
    #[test]
    fn floor_clamped_is_the_floor_of_the_clamped_value() {
        let his = [1.0f32, 2.0, 3.0, 37.0, 1024.0, 16_384.0, STAGED_F32_LIMIT];
        let mut xs: Vec<f32> = samples().into_iter().chain([-1e30, -2.5, 1e30]).collect();
        for e in [1.0f32, 2.0, 16_384.0, STAGED_F32_LIMIT] {
            xs.extend([e - 0.5, e - 1e-3 * e.sqrt(), e, e + 0.25, e * 2.0]);
        }
        for &hi in &his {
            for &x in &xs {
                let c = x.max(-1.0).min(hi);
                let (i, f) = floor_clamped(x, hi);
                assert_eq!(f, c.floor(), "x {x} hi {hi}");
                assert_eq!(i as f32, c.floor(), "x {x} hi {hi}");
                let (i, f) = ceil_clamped(x, hi);
                assert_eq!(f, c.ceil(), "ceil: x {x} hi {hi}");
                assert_eq!(i as f32, c.ceil(), "ceil: x {x} hi {hi}");
            }
        }
    }

    /// The staged rounding is IEEE's round-half-even (`f32::round_ties_even`) inside its range;
    /// the four-lane forms equal the scalar ones lane by lane; the byte read-out is exact.
    #[test]
    fn round_staged_rounds_half_to_even() {
        for x in samples().into_iter().filter(|x| x.abs() < STAGED_F32_LIMIT) {
            assert_eq!(round_staged(x), x.round_ties_even(), "{x}");
        }
        for x in samples().into_iter().filter(|x| x.abs() < STAGED_F32_LIMIT) {
            let v = Vec4::new(x, -x, x * 0.5, x + 0.5);
            assert_eq!(
                round_staged4(v),
                v.to_array().map(round_staged).into(),
                "{x}"
            );
            for hi in [1.0f32, 255.0, 1024.0] {
                let want = v.to_array().map(|x| floor_clamped(x, hi).1);
                assert_eq!(floor_clamped4(v, hi), want.into(), "{x} {hi}");
            }
        }
        for k in 0..=255u8 {
            let v = Vec4::new(f32::from(k), 0.0, 255.0, f32::from(255 - k));
            assert_eq!(integer_bytes4(v.to_array()), [k, 0, 255, 255 - k]);
        }
        assert_eq!(round_staged(0.5), 0.0);
        assert_eq!(round_staged(1.5), 2.0);
        assert_eq!(round_staged(-2.5), -2.0);
    }
}
