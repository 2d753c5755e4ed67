//! sRGB transfer functions and the 256-entry decode table.
//!
//! Formulas: IEC 61966-2-1 (sRGB), as used by the Vulkan spec, "Colour space conversions"
//! (sRGB EOTF): `linear = c / 12.92` for `c <= 0.04045`, else `((c + 0.055) / 1.055)^2.4`.
//!
//! 8-bit sRGB texels are decoded through [`srgb_table`], a table built once by
//! [`srgb_to_linear`] at first use (the generating code sits beside the table, as pbrt-v4 keeps its
//! LUTs). Decoding by table costs one load per channel instead of a `powf`.

use std::sync::OnceLock;

use glam::Vec4;

use crate::base::floor::{floor_clamped4, integer_byte, integer_bytes4, round_staged};

/// sRGB-encoded value in `[0, 1]` to linear light in `[0, 1]` (IEC 61966-2-1).
///
/// Values outside `[0, 1]` are extended symmetrically (`f(-x) = -f(x)`); NaN stays NaN.
#[inline]
pub fn srgb_to_linear(c: f32) -> f32 {
    let a = c.abs();
    let l = if a <= 0.04045 {
        a / 12.92
    } else {
        ((a + 0.055) / 1.055).powf(2.4)
    };
    l.copysign(c)
}

/// Linear light in `[0, 1]` to sRGB-encoded `[0, 1]` (inverse of [`srgb_to_linear`]).
///
/// Values outside `[0, 1]` are extended symmetrically; NaN stays NaN.
#[inline]
pub fn linear_to_srgb(l: f32) -> f32 {
    let a = l.abs();
    let c = if a <= 0.003_130_8 {
        a * 12.92
    } else {
        1.055 * a.powf(1.0 / 2.4) - 0.055
    };
    c.copysign(l)
}

/// The value a display shows for linear light `l`, in `[0, 1]` before quantisation: clipped to
/// `[0, 1]` (NaN gives 0), then sRGB-encoded when `srgb`. What a reference's convergence and its
/// noise are judged on.
#[inline]
pub fn displayed(l: f64, srgb: bool) -> f64 {
    let x = if l.is_nan() { 0.0 } else { l.clamp(0.0, 1.0) };
    if srgb {
        f64::from(linear_to_srgb(x as f32))
    } else {
        x
    }
}

/// Quantise a `[0, 1]` float to 8 bits, rounding to nearest; out-of-range values clamp, NaN gives 0.
#[inline]
pub fn unorm8(x: f32) -> u8 {
    // `as u8` saturates and maps NaN to 0.
    (x * 255.0 + 0.5) as u8
}

/// Linear `[0, 1]` to an 8-bit sRGB code (rounded, clamped; NaN gives 0): exactly
/// `unorm8(linear_to_srgb(clamp(l, 0, 1)))` ([`linear_to_srgb8_exact`]), found by table instead of
/// a `powf` per channel (see [`Srgb8Encoder`]).
#[inline]
pub fn linear_to_srgb8(l: f32) -> u8 {
    srgb8_encoder().encode(l)
}

/// One linear RGBA colour as 8-bit sRGB display bytes: RGB through [`linear_to_srgb8`], alpha
/// linear ([`unorm8`]); values clamp to `[0, 1]`, NaN gives 0. What an `R8G8B8A8_SRGB` target
/// stores and what texel's PNGs hold.
#[inline(always)]
pub fn rgba_to_srgb8(c: [f32; 4]) -> [u8; 4] {
    srgb8_encoder().encode_rgba(c)
}

/// One RGBA colour as 8-bit unorm bytes, every channel [`unorm8`] (clamped, NaN gives 0), no
/// transfer function: what an `R8G8B8A8_UNORM` target stores.
#[inline(always)]
pub fn rgba_to_unorm8(c: [f32; 4]) -> [u8; 4] {
    // [`unorm8`] per channel without its saturating conversion: `x * 255 + 1/2` (NaN to 0 by
    // `max`), floored and clamped to `[0, 255]` by the staged floor, whose integer comes from
    // bits. Equal to `unorm8` for every input (tested on a sweep of all bit patterns and around
    // every threshold).
    let v = (Vec4::from_array(c) * 255.0 + Vec4::splat(0.5)).max(Vec4::ZERO);
    integer_bytes4(floor_clamped4(v, 255.0).to_array())
}

/// [`rgba_to_unorm8`] of every colour of `colors` into `out`, bit for bit: one loop over the
/// channels (`out` and `colors` flattened), which the compiler vectorises across colours —
/// sixteen channels per step with AVX-512, eight with AVX2 — where the one-colour form works on
/// one colour's four lanes at a time. What a renderer's resolve into an `R8G8B8A8_UNORM` target
/// runs over a row (docs/decisions.md).
///
/// # Panics
/// If `colors` and `out` differ in length (a programming error, not bad input).
#[inline(always)]
pub fn rgba_to_unorm8_slice(colors: &[[f32; 4]], out: &mut [[u8; 4]]) {
    assert_eq!(
        colors.len(),
        out.len(),
        "rgba_to_unorm8_slice: colors and out differ in length"
    );
    for (o, &x) in out.as_flattened_mut().iter_mut().zip(colors.as_flattened()) {
        *o = unorm8_lane(x);
    }
}

/// One channel of [`rgba_to_unorm8`] in the operations of its four lanes, written as selects so
/// that a loop over channels vectorises: `v = x * 255 + 1/2`; `v > 0` else 0 (NaN and negative
/// zero give 0, as the lanes' `max` with zero does); at most 255; the staged floor
/// ([`round_staged`] and a step down where it rounded up), read from the bits
/// ([`integer_byte`]).
#[inline(always)]
fn unorm8_lane(x: f32) -> u8 {
    let v = x * 255.0 + 0.5;
    let v = if v > 0.0 { v } else { 0.0 };
    let c = if v < 255.0 { v } else { 255.0 };
    let r = round_staged(c);
    integer_byte(if r > c { r - 1.0 } else { r })
}

/// The definition [`linear_to_srgb8`] is built from and tested against: `unorm8` of the sRGB OETF
/// of the clamped value, one `powf` per call.
pub fn linear_to_srgb8_exact(l: f32) -> u8 {
    unorm8(linear_to_srgb(l.clamp(0.0, 1.0)))
}

/// Bits of an `f32` dropped to find its bucket: buckets are `2^16` consecutive bit patterns, 128
/// per octave (1/128 of the value's octave wide).
const BUCKET_SHIFT: u32 = 16;

/// Buckets up to and including the one of 1.0 (`0x3F80_0000 >> 16`).
const BUCKETS: usize = (0x3F80_0000 >> BUCKET_SHIFT) as usize + 1;

/// An exact table encoder for [`linear_to_srgb8_exact`] (the way GPUs encode sRGB render targets
/// without a `pow`): `threshold[k]` is the smallest `f32` whose code is at least `k`, found by
/// binary search over bit patterns (positive floats order as their bits); `base[b]` is the code
/// of the smallest value of bucket `b`. Every bucket holds at most one threshold (checked when the
/// table is built: the codes are at least 1/(255 * 12.92) apart in linear light near 0, and about
/// 0.0089 near 1, where a bucket is 0.0039 wide), so a value's code is its bucket's base, plus one
/// if the value reaches the next threshold. 16 KB of bases and 1 KB of thresholds.
///
/// Exact for every `f32` provided `linear_to_srgb8_exact` is non-decreasing on `[0, 1]`, which
/// `cargo run --release -p texel-texture --example srgb8_exhaustive` checks for all
/// 1 065 353 217 floats in `[0, 1]`; the unit tests check every threshold and its neighbours.
pub struct Srgb8Encoder {
    base: Vec<u8>,
    threshold: [f32; 257],
}

impl Srgb8Encoder {
    fn new() -> Srgb8Encoder {
        let mut threshold = [f32::INFINITY; 257];
        threshold[0] = 0.0;
        for (k, t) in threshold.iter_mut().enumerate().take(256).skip(1) {
            // Smallest bits in [0, bits(1.0)] with code >= k (code(1.0) = 255 >= k).
            let (mut lo, mut hi) = (0u32, 0x3F80_0000u32);
            while lo < hi {
                let mid = lo + (hi - lo) / 2;
                if linear_to_srgb8_exact(f32::from_bits(mid)) >= k as u8 {
                    hi = mid;
                } else {
                    lo = mid + 1;
                }
            }
            *t = f32::from_bits(lo);
        }
        let base: Vec<u8> = (0..BUCKETS)
            .map(|b| linear_to_srgb8_exact(f32::from_bits((b as u32) << BUCKET_SHIFT)))
            .collect();
        let encoder = Srgb8Encoder { base, threshold };
        debug_assert!((0..BUCKETS).all(|b| {
            let last = ((b as u32 + 1) << BUCKET_SHIFT) - 1;
            let top = linear_to_srgb8_exact(f32::from_bits(last.min(0x3F80_0000)));
            top <= encoder.base[b].saturating_add(1)
        }));
        encoder
    }

    /// [`rgba_to_srgb8`] with this encoder (callers encoding many colours look it up once).
    #[inline(always)]
    pub fn encode_rgba(&self, c: [f32; 4]) -> [u8; 4] {
        [
            self.encode(c[0]),
            self.encode(c[1]),
            self.encode(c[2]),
            unorm8(c[3]),
        ]
    }

    /// [`linear_to_srgb8`].
    #[inline(always)]
    pub fn encode(&self, l: f32) -> u8 {
        // NaN, zero and negatives give 0; the clamp keeps the bits within the table.
        if l.is_nan() || l <= 0.0 {
            return 0;
        }
        let l = l.min(1.0);
        let b = (l.to_bits() >> BUCKET_SHIFT) as usize;
        let k = self.base[b.min(BUCKETS - 1)];
        k + u8::from(l >= self.threshold[k as usize + 1])
    }
}

/// The shared [`Srgb8Encoder`], built at first use (about 20 000 `powf` calls).
pub fn srgb8_encoder() -> &'static Srgb8Encoder {
    static ENCODER: OnceLock<Srgb8Encoder> = OnceLock::new();
    ENCODER.get_or_init(Srgb8Encoder::new)
}

/// The 256-entry table `SRGB_TO_LINEAR[b] = srgb_to_linear(b / 255)`.
pub fn srgb_table() -> &'static [f32; 256] {
    static TABLE: OnceLock<[f32; 256]> = OnceLock::new();
    TABLE.get_or_init(|| std::array::from_fn(|b| srgb_to_linear(b as f32 / 255.0)))
}

/// The 256-entry table `UNORM8_TO_FLOAT[b] = b / 255` (linear 8-bit data).
pub fn unorm8_table() -> &'static [f32; 256] {
    static TABLE: OnceLock<[f32; 256]> = OnceLock::new();
    TABLE.get_or_init(|| std::array::from_fn(|b| b as f32 / 255.0))
}

/// `1 / 255` split into a high part of 12 significant bits, so that `b * UNORM8_HI` is exact for
/// every byte `b`, and the `f32` nearest to the rest.
pub(crate) const UNORM8_HI: f32 = f32::from_bits((1.0f32 / 255.0).to_bits() & !((1 << 12) - 1));
pub(crate) const UNORM8_LO: f32 = (1.0f64 / 255.0 - UNORM8_HI as f64) as f32;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn table_endpoints_and_known_values() {
        let t = srgb_table();
        assert_eq!(t[0], 0.0);
        assert_eq!(t[255], 1.0);
        // 0.5 sRGB is 0.21404 linear (IEC 61966-2-1); code 128 is 0.50196.
        assert!((srgb_to_linear(0.5) - 0.214_041_14).abs() < 1e-6);
        assert!((t[128] - 0.215_860_53).abs() < 1e-6);
    }

    /// The four-lane encoder and the slice encoder equal [`unorm8`] on a sweep through every
    /// `f32` bit pattern (a stride of 31, both signs, NaNs and infinities included), on 64
    /// patterns either side of every rounding threshold `(k + 1/2) / 255`, and at the special
    /// values. The slice encoder sees every value once, in runs of 1 to 37 colours (so both its
    /// vector body and its remainder run), into an output filled beforehand with the complement
    /// of the expected bytes (so a colour it skipped fails).
    #[test]
    fn four_lane_unorm8_equals_unorm8() {
        let mut run = Vec::<[f32; 4]>::new();
        let (mut want, mut bytes) = (Vec::<[u8; 4]>::new(), Vec::<[u8; 4]>::new());
        let mut flush = |run: &mut Vec<[f32; 4]>| {
            want.clear();
            want.extend(run.iter().map(|c| c.map(unorm8)));
            bytes.clear();
            bytes.extend(want.iter().map(|w| w.map(|b| !b)));
            rgba_to_unorm8_slice(run, &mut bytes);
            if let Some(k) = (0..run.len()).find(|&k| bytes[k] != want[k]) {
                panic!("slice: {:?} gave {:?}", run[k], bytes[k]);
            }
            run.clear();
        };
        let mut runs = 0;
        let mut check = |x: f32| {
            let c = [x, -x, x * 0.5, 1.0 - x];
            let want = [unorm8(x), unorm8(-x), unorm8(x * 0.5), unorm8(1.0 - x)];
            assert_eq!(rgba_to_unorm8(c), want, "{x:e} ({:#x})", x.to_bits());
            run.push(c);
            if run.len() == 1 + runs % 37 {
                runs += 1;
                flush(&mut run);
            }
        };
        (0..=u32::MAX)
            .step_by(31)
            .for_each(|b| check(f32::from_bits(b)));
        for k in 0..=256u32 {
            let t = (k as f32 + 0.5) / 255.0;
            let b = t.to_bits();
            (b - 64..=b + 64).for_each(|b| check(f32::from_bits(b)));
            check(k as f32 / 255.0);
        }
        for x in [
            0.0,
            -0.0,
            1.0,
            255.0,
            f32::NAN,
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::MAX,
        ] {
            check(x);
        }
        flush(&mut run);
    }

    #[test]
    fn round_trip_every_code() {
        for b in 0..=255u8 {
            assert_eq!(linear_to_srgb8(srgb_table()[b as usize]), b);
        }
    }

    /// The table encoder equals the `powf` definition at every threshold and the 8 floats on either
    /// side, at every bucket's ends, at the special values and on a stride through all of `[0, 1]`
    /// (the exhaustive check is `examples/srgb8_exhaustive.rs`).
    #[test]
    fn table_encoder_is_exact() {
        let e = srgb8_encoder();
        let check = |bits: u32| {
            let l = f32::from_bits(bits);
            assert_eq!(e.encode(l), linear_to_srgb8_exact(l), "{l:e} ({bits:#x})");
        };
        for &t in &e.threshold[1..256] {
            let b = t.to_bits();
            (b.saturating_sub(8)..=b + 8).for_each(check);
        }
        for b in 0..BUCKETS as u32 {
            check(b << BUCKET_SHIFT);
            check(((b + 1) << BUCKET_SHIFT) - 1);
        }
        (0..=0x3F80_0000u32).step_by(997).for_each(check);
        for l in [
            0.0,
            -0.0,
            -1.0,
            1.0,
            1.5,
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::NAN,
            f32::MIN_POSITIVE,
            1e-45,
        ] {
            assert_eq!(e.encode(l), linear_to_srgb8_exact(l), "{l}");
        }
    }

    #[test]
    fn monotonic_table() {
        let t = srgb_table();
        assert!(t.windows(2).all(|w| w[0] < w[1]));
    }

    #[test]
    fn nan_quantises_to_zero() {
        assert_eq!(unorm8(f32::NAN), 0);
        assert_eq!(linear_to_srgb8(f32::NAN), 0);
        assert_eq!(unorm8(7.0), 255);
        assert_eq!(unorm8(-1.0), 0);
    }
}
