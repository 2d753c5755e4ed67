//! Address modes: what happens to texel indices outside `[0, n)`.
//!
//! Names follow WebGPU (`GPUAddressMode`) plus Vulkan's `MIRROR_CLAMP_TO_EDGE`. As the conventions
//! (docs/guide/conventions.md) fix, the mode is applied to the *integer* texel indices after a
//! filter has picked them (Vulkan spec, "Wrapping Operation"), separately for u and v.

use glam::Vec4;

/// How a texel index outside the texture is brought back inside (or replaced by the border colour).
///
/// Examples are for a texture 4 texels wide, as normalised `u` of a nearest lookup and as indices.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum AddressMode {
    /// Clamp to the edge texel. `u = -0.25 -> 0.0`, `u = 1.25 -> the last texel`; index `-1 -> 0`, `5 -> 3`.
    #[default]
    ClampToEdge,
    /// Tile with period 1. `u = -0.25 -> 0.75`, `u = 1.25 -> 0.25`; index `-1 -> 3`, `4 -> 0`.
    Repeat,
    /// Tile with period 2, every other tile mirrored. `u = -0.25 -> 0.25`, `u = 1.25 -> 0.75`;
    /// index `-1 -> 0`, `4 -> 3`, `8 -> 0`.
    MirrorRepeat,
    /// Outside `[0, 1)` read the sampler's border colour. `u = -0.25 -> border`; index `-1 -> border`.
    ClampToBorder,
    /// Mirror once around 0, then clamp. `u = -0.25 -> 0.25`, `u = -3.0 -> the last texel`;
    /// index `-1 -> 0`, `-5 -> 3`, `7 -> 3`.
    MirrorClampToEdge,
}

impl AddressMode {
    /// Wrap integer texel index `i` into `[0, n)`, or `None` where the border colour applies.
    ///
    /// `n >= 1`. Total for every `i` (no overflow even at `i64::MIN`).
    #[inline(always)]
    pub fn wrap(self, i: i64, n: u32) -> Option<u32> {
        let n64 = i64::from(n);
        match self {
            AddressMode::ClampToEdge => Some(i.clamp(0, n64 - 1) as u32),
            AddressMode::Repeat => {
                if (0..n64).contains(&i) {
                    Some(i as u32)
                } else {
                    Some(rem_euclid(i, n64) as u32)
                }
            }
            AddressMode::MirrorRepeat => {
                let r = rem_euclid(i, 2 * n64);
                Some(if r < n64 { r } else { 2 * n64 - 1 - r } as u32)
            }
            AddressMode::ClampToBorder => (0..n64).contains(&i).then_some(i as u32),
            AddressMode::MirrorClampToEdge => {
                let m = if i < 0 { -1 - i } else { i };
                Some(m.min(n64 - 1) as u32)
            }
        }
    }

    /// Whether the mode tiles the plane periodically (Repeat and MirrorRepeat).
    pub fn is_periodic(self) -> bool {
        matches!(self, AddressMode::Repeat | AddressMode::MirrorRepeat)
    }
}

/// `i.rem_euclid(n)` for `n >= 1`: a mask where `n` is a power of two (two's complement makes
/// `i & (n - 1)` the non-negative remainder, for negative `i` too), else the division. Textures
/// are mostly powers of two on a side, and the division is tens of cycles where the mask is one
/// (a one-sample bilinear sample outside a repeating texture wraps four taps; EWA's general
/// route wraps every texel of a line across the edge).
#[inline(always)]
fn rem_euclid(i: i64, n: i64) -> i64 {
    if n & (n - 1) == 0 {
        i & (n - 1)
    } else {
        i.rem_euclid(n)
    }
}

/// The colour read outside the texture under [`AddressMode::ClampToBorder`] (linear RGBA).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum BorderColor {
    /// `(0, 0, 0, 0)`.
    #[default]
    TransparentBlack,
    /// `(0, 0, 0, 1)`.
    OpaqueBlack,
    /// `(1, 1, 1, 1)`.
    OpaqueWhite,
    /// Any linear RGBA colour (beyond WebGPU's three).
    Custom([f32; 4]),
}

impl BorderColor {
    /// The colour as linear RGBA.
    pub fn rgba(self) -> [f32; 4] {
        match self {
            BorderColor::TransparentBlack => [0.0; 4],
            BorderColor::OpaqueBlack => [0.0, 0.0, 0.0, 1.0],
            BorderColor::OpaqueWhite => [1.0; 4],
            BorderColor::Custom(c) => c,
        }
    }
}

/// The u and v address modes and the border colour: how a sampler (or a summed-area table's box
/// query) extends the texture beyond its edges. [`Sampler`](crate::Sampler) resolves one from its
/// descriptor ([`Address::of`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Address {
    /// Address mode along u (texture x).
    pub u: AddressMode,
    /// Address mode along v (texture y).
    pub v: AddressMode,
    /// Linear RGBA read outside the texture under [`AddressMode::ClampToBorder`].
    pub border: Vec4,
}

impl Address {
    /// Modes `u` and `v`, and `border` read outside under ClampToBorder.
    pub fn new(u: AddressMode, v: AddressMode, border: BorderColor) -> Address {
        Address {
            u,
            v,
            border: Vec4::from_array(border.rgba()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::AddressMode::*;
    use super::*;
    use crate::base::floor::floor_index;

    /// (mode, index, n, expected) straight from the documented examples.
    const TABLE: &[(AddressMode, i64, u32, Option<u32>)] = &[
        (ClampToEdge, -1, 4, Some(0)),
        (ClampToEdge, 5, 4, Some(3)),
        (ClampToEdge, 2, 4, Some(2)),
        (Repeat, -1, 4, Some(3)),
        (Repeat, 4, 4, Some(0)),
        (Repeat, -5, 4, Some(3)),
        (Repeat, 9, 4, Some(1)),
        (MirrorRepeat, -1, 4, Some(0)),
        (MirrorRepeat, 4, 4, Some(3)),
        (MirrorRepeat, 7, 4, Some(0)),
        (MirrorRepeat, 8, 4, Some(0)),
        (MirrorRepeat, -5, 4, Some(3)),
        (ClampToBorder, -1, 4, None),
        (ClampToBorder, 4, 4, None),
        (ClampToBorder, 3, 4, Some(3)),
        (MirrorClampToEdge, -1, 4, Some(0)),
        (MirrorClampToEdge, -5, 4, Some(3)),
        (MirrorClampToEdge, 7, 4, Some(3)),
        (MirrorClampToEdge, -3, 4, Some(2)),
    ];

    #[test]
    fn index_table() {
        for &(mode, i, n, want) in TABLE {
            assert_eq!(mode.wrap(i, n), want, "{mode:?} {i} n={n}");
        }
    }

    /// Normalised-u examples from the variant docs, through nearest's floor(u * W).
    #[test]
    fn uv_table() {
        let w = 4u32;
        // Expected: the left edge of the texel read, in u.
        let cases: &[(AddressMode, f32, Option<f32>)] = &[
            (Repeat, -0.25, Some(0.75)),
            (Repeat, 1.25, Some(0.25)),
            (MirrorRepeat, -0.25, Some(0.0)), // texel 0 spans [0, 0.25)
            (MirrorRepeat, 1.25, Some(0.5)),  // mirrors to 0.75, the edge of texel [0.5, 0.75)
            (ClampToEdge, -0.25, Some(0.0)),
            (ClampToBorder, -0.25, None),
            (MirrorClampToEdge, -0.25, Some(0.0)),
        ];
        for &(mode, u, want) in cases {
            let got = mode
                .wrap(floor_index(u * w as f32), w)
                .map(|i| i as f32 / w as f32);
            assert_eq!(got, want, "{mode:?} u={u}");
        }
    }

    /// The mask for power-of-two sides equals the division's remainder: every side 1 to 70 (the
    /// powers of two and the rest), indices around zero, around multiples of the side and at
    /// `i64`'s ends.
    #[test]
    fn rem_euclid_equals_the_division() {
        for n in 1..=70i64 {
            let mut indices: Vec<i64> = (-3 * n - 2..=3 * n + 2).collect();
            indices.extend([i64::MIN, i64::MIN + 1, i64::MAX, i64::MAX - 1]);
            for i in indices {
                assert_eq!(rem_euclid(i, n), i.rem_euclid(n), "{i} mod {n}");
            }
        }
    }

    #[test]
    fn extremes_do_not_overflow() {
        for mode in [
            ClampToEdge,
            Repeat,
            MirrorRepeat,
            ClampToBorder,
            MirrorClampToEdge,
        ] {
            for i in [i64::MIN, i64::MIN + 1, -1, 0, i64::MAX] {
                for n in [1, 3, 16384] {
                    if let Some(k) = mode.wrap(i, n) {
                        assert!(k < n);
                    }
                }
            }
        }
    }
}
