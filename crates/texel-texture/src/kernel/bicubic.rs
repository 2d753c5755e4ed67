//! Bicubic filtering with the Mitchell-Netravali family of cubic kernels.
//!
//! Kernel (Mitchell & Netravali, "Reconstruction Filters in Computer Graphics", SIGGRAPH 1988, eq. 8):
//!
//! ```text
//! k(x) = 1/6 * { (12 - 9B - 6C)|x|^3 + (-18 + 12B + 6C)|x|^2 + (6 - 2B)                 |x| < 1
//!              { (-B - 6C)|x|^3 + (6B + 30C)|x|^2 + (-12B - 48C)|x| + (8B + 24C)       1 <= |x| < 2
//!              { 0                                                                      otherwise
//! ```
//!
//! Taps: with `base = floor(xy - 0.5)` and `t = fract(xy - 0.5)` (as bilinear), texels
//! `base - 1 .. base + 2` at distances `1 + t, t, 1 - t, 2 - t`, separably in x and y (16 reads).
//! Catmull-Rom `(B, C) = (0, 1/2)` interpolates (k(0) = 1, k(±1) = k(±2) = 0); the cubic B-spline
//! `(1, 0)` has non-negative weights and never overshoots; Mitchell `(1/3, 1/3)` is the compromise.
//! All weights of one axis sum to 1 for every (B, C).

use glam::{Vec2, Vec4};

use crate::base::address::Address;
use crate::base::floor::floor_index;
use crate::kernel::bilinear::{origin, texel_or_border};
use crate::storage::fetch::Fetch;

/// Largest `|B|` and `|C|` a sampler accepts. Mitchell and Netravali's family is drawn for B and C
/// in `[0, 1]` and Keys' cubics need C up to 1; unbounded values overflow `f32` (found by fuzzing:
/// B = 6e17 gave infinite samples). Within the bound the 4 weights of an axis sum in absolute value
/// to at most 7/3 (at B = -2, C = ±2; 1.19 for Catmull-Rom), so a 4x4 sample lies within
/// (7/3)^2 < 5.5 times the largest texel magnitude.
pub const MAX_CUBIC_PARAMETER: f32 = 2.0;

/// Mitchell-Netravali cubic parameters `(B, C)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cubic {
    /// B (blur): 0 for Catmull-Rom, 1 for the B-spline.
    pub b: f32,
    /// C (ringing): 1/2 for Catmull-Rom, 0 for the B-spline.
    pub c: f32,
}

impl Default for Cubic {
    /// Catmull-Rom.
    fn default() -> Self {
        Cubic::CATMULL_ROM
    }
}

impl Cubic {
    /// Catmull-Rom `(0, 1/2)`: interpolating, sharp, slight overshoot.
    pub const CATMULL_ROM: Cubic = Cubic { b: 0.0, c: 0.5 };
    /// Mitchell `(1/3, 1/3)`: the filter Mitchell and Netravali recommend.
    pub const MITCHELL: Cubic = Cubic {
        b: 1.0 / 3.0,
        c: 1.0 / 3.0,
    };
    /// Cubic B-spline `(1, 0)`: smooth, non-negative, approximating (does not interpolate).
    pub const B_SPLINE: Cubic = Cubic { b: 1.0, c: 0.0 };

    /// The kernel `k(x)`.
    pub fn kernel(&self, x: f32) -> f32 {
        let (b, c) = (self.b, self.c);
        let x = x.abs();
        let v = if x < 1.0 {
            ((12.0 - 9.0 * b - 6.0 * c) * x + (-18.0 + 12.0 * b + 6.0 * c)) * x * x
                + (6.0 - 2.0 * b)
        } else if x < 2.0 {
            (((-b - 6.0 * c) * x + (6.0 * b + 30.0 * c)) * x + (-12.0 * b - 48.0 * c)) * x
                + (8.0 * b + 24.0 * c)
        } else {
            0.0
        };
        v / 6.0
    }

    /// The four tap weights for fractional offset `t` in `[0, 1)`.
    #[inline]
    pub fn weights(&self, t: f32) -> [f32; 4] {
        [
            self.kernel(1.0 + t),
            self.kernel(t),
            self.kernel(1.0 - t),
            self.kernel(2.0 - t),
        ]
    }
}

/// Bicubic sample of `level` at normalised `(u, v)` (finite).
#[inline]
pub(crate) fn bicubic<F: Fetch>(level: &F, addr: &Address, cubic: &Cubic, uv: Vec2) -> Vec4 {
    let (w, h) = level.size();
    // The taps start where bilinear's do, one texel further out on each side.
    let x = origin(uv.x, w as f32);
    let y = origin(uv.y, h as f32);
    let (i0, j0) = (floor_index(x), floor_index(y));
    // `i0 as f32` is `x.floor()` exactly (see `floor_index`).
    let wx = cubic.weights(x - i0 as f32);
    let wy = cubic.weights(y - j0 as f32);
    let is: [Option<u32>; 4] =
        std::array::from_fn(|k| addr.u.wrap(i0.saturating_add(k as i64 - 1), w));
    let mut acc = Vec4::ZERO;
    for (dj, &wj) in wy.iter().enumerate() {
        let j = addr.v.wrap(j0.saturating_add(dj as i64 - 1), h);
        let mut row = Vec4::ZERO;
        for (&i, &wi) in is.iter().zip(&wx) {
            row += texel_or_border(level, addr, i, j) * wi;
        }
        acc += row * wj;
    }
    acc
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn weights_sum_to_one() {
        for cubic in [
            Cubic::CATMULL_ROM,
            Cubic::MITCHELL,
            Cubic::B_SPLINE,
            Cubic { b: 0.2, c: 0.7 },
        ] {
            for k in 0..100 {
                let s: f32 = cubic.weights(k as f32 / 100.0).iter().sum();
                assert!((s - 1.0).abs() < 1e-5, "{cubic:?} t={k}");
            }
        }
    }

    #[test]
    fn known_kernel_values() {
        let cr = Cubic::CATMULL_ROM;
        assert_eq!(cr.weights(0.0), [0.0, 1.0, 0.0, 0.0]);
        // Catmull-Rom at t = 1/2: (-1/16, 9/16, 9/16, -1/16).
        let w = cr.weights(0.5);
        for (a, b) in w.iter().zip([-0.0625, 0.5625, 0.5625, -0.0625]) {
            assert!((a - b).abs() < 1e-6);
        }
        // B-spline at t = 0: (1/6, 2/3, 1/6, 0).
        let w = Cubic::B_SPLINE.weights(0.0);
        for (a, b) in w.iter().zip([1.0 / 6.0, 2.0 / 3.0, 1.0 / 6.0, 0.0]) {
            assert!((a - b).abs() < 1e-6);
        }
    }
}
