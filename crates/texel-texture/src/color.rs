//! sRGB transfer functions and the 256-entry decode table.
//!
//! Formulas: IEC 61966-2-1 (sRGB), as used by the Vulkan spec, "Colour space conversions"
//! (sRGB EOTF): `linear = c / 12.92` for `c <= 0.04045`, else `((c + 0.055) / 1.055)^2.4`.
//!
//! 8-bit sRGB texels are decoded through [`srgb_table`], a table built once by
//! [`srgb_to_linear`] at first use (the generating code sits beside the table, as pbrt-v4 keeps its
//! LUTs). Decoding by table costs one load per channel instead of a `powf`.

use std::sync::OnceLock;

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

/// Quantise a `[0, 1]` float to 8 bits, rounding to nearest; out-of-range values clamp, NaN gives 0.
#[inline]
pub fn unorm8(x: f32) -> u8 {
    // `as u8` saturates and maps NaN to 0.
    (x * 255.0 + 0.5) as u8
}

/// Linear `[0, 1]` to an 8-bit sRGB code (rounded, clamped; NaN gives 0).
#[inline]
pub fn linear_to_srgb8(l: f32) -> u8 {
    unorm8(linear_to_srgb(l.clamp(0.0, 1.0)))
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

    #[test]
    fn round_trip_every_code() {
        for b in 0..=255u8 {
            assert_eq!(linear_to_srgb8(srgb_table()[b as usize]), b);
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
