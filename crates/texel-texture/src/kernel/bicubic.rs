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
use crate::base::filter::Cubic;
use crate::base::floor::floor_index;
use crate::kernel::bilinear::{origin, texel_or_border};
use crate::storage::fetch::Fetch;

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
