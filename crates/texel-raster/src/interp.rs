//! Per-pixel interpolation: barycentrics (perspective-correct or affine), their analytic screen
//! derivatives, and the GPU-style 2x2 quad differences.
//!
//! Perspective-correct (DESIGN.md): with `q_k = lambda_k / w` and `r = 1 / w` linear in screen space
//! (planes from [`crate::setup`]), `lambda_k = q_k / r` and, by the quotient rule,
//! `d lambda_k / dx = (q_k,x r - q_k r_x) / r^2 = (q_k,x - lambda_k r_x) / r`. Any attribute
//! `a = sum_k lambda_k a_k` then has `da/dx = sum_k a_k d lambda_k / dx`: this is exactly
//! `du/dx = (q_x r - q r_x) / r^2` for `q = u / w`, evaluated in `f64`.
//! Affine: `lambda_k` is itself a plane and its derivatives are constants.
//!
//! The two formulas are the kernels `lambda` and `lambda_derivative`: the one-pixel API
//! ([`TriangleSetup::barycentrics`]) and the rasterizer's span stages (`tile.rs`, a span of
//! fragments at a time) both call them, so both give the same bits.

use glam::{DVec2, DVec3};

use crate::settings::Perspective;
use crate::setup::TriangleSetup;

/// Barycentric coordinates of the original triangle at a point, with their screen derivatives.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Barycentrics {
    /// `(lambda_0, lambda_1, lambda_2)`, summing to 1.
    pub lambda: DVec3,
    /// `d lambda / dx` (per pixel to the right).
    pub dx: DVec3,
    /// `d lambda / dy` (per pixel down).
    pub dy: DVec3,
}

impl Barycentrics {
    /// The interpolated 2D attribute `sum_k lambda_k a_k`.
    #[inline(always)]
    pub fn interpolate2(&self, a: [DVec2; 3]) -> DVec2 {
        a[0] * self.lambda.x + a[1] * self.lambda.y + a[2] * self.lambda.z
    }

    /// `(d/dx, d/dy)` of the interpolated 2D attribute.
    #[inline(always)]
    pub fn derivatives2(&self, a: [DVec2; 3]) -> (DVec2, DVec2) {
        (
            a[0] * self.dx.x + a[1] * self.dx.y + a[2] * self.dx.z,
            a[0] * self.dy.x + a[1] * self.dy.y + a[2] * self.dy.z,
        )
    }
}

/// Perspective-correct barycentric `lambda_k = q_k / r`, given `q_k` and `1 / r` at the pixel.
#[inline(always)]
pub(crate) fn lambda(q: f64, inv_r: f64) -> f64 {
    q * inv_r
}

/// `d lambda_k / dx = (q_k,x - lambda_k r_x) / r` (or `/ dy` with the `y` slopes), given the
/// slopes `dq` of `q_k` and `dr` of `r`, `lambda_k` and `1 / r` at the pixel.
#[inline(always)]
pub(crate) fn lambda_derivative(dq: f64, lambda: f64, dr: f64, inv_r: f64) -> f64 {
    (dq - lambda * dr) * inv_r
}

impl TriangleSetup {
    /// Barycentrics at continuous pixel coordinates `(x, y)` (pixel centres are at `+0.5`), without
    /// derivatives. Outside the triangle the planes extrapolate (as for a GPU's helper pixels); beyond
    /// the horizon of the triangle's plane (`1/w <= 0`) the values are meaningless or non-finite.
    #[inline(always)]
    pub fn lambda_at(&self, x: f64, y: f64, perspective: Perspective) -> DVec3 {
        match perspective {
            Perspective::Correct => {
                let inv_r = 1.0 / self.r.at(x, y);
                DVec3::from_array(self.q.map(|q| lambda(q.at(x, y), inv_r)))
            }
            Perspective::Affine => DVec3::new(
                self.affine[0].at(x, y),
                self.affine[1].at(x, y),
                self.affine[2].at(x, y),
            ),
        }
    }

    /// Barycentrics at `(x, y)` with their analytic derivatives (see the module docs).
    #[inline(always)]
    pub fn barycentrics(&self, x: f64, y: f64, perspective: Perspective) -> Barycentrics {
        match perspective {
            Perspective::Correct => {
                let inv_r = 1.0 / self.r.at(x, y);
                let l = self.q.map(|q| lambda(q.at(x, y), inv_r));
                let r = self.r;
                let d = |k: usize, dq: f64, dr: f64| lambda_derivative(dq, l[k], dr, inv_r);
                Barycentrics {
                    lambda: DVec3::from_array(l),
                    dx: DVec3::from_array(std::array::from_fn(|k| d(k, self.q[k].dx, r.dx))),
                    dy: DVec3::from_array(std::array::from_fn(|k| d(k, self.q[k].dy, r.dy))),
                }
            }
            Perspective::Affine => Barycentrics {
                lambda: self.lambda_at(x, y, perspective),
                dx: DVec3::new(self.affine[0].dx, self.affine[1].dx, self.affine[2].dx),
                dy: DVec3::new(self.affine[0].dy, self.affine[1].dy, self.affine[2].dy),
            },
        }
    }

    /// NDC depth at `(x, y)` (always screen-linear, whatever the interpolation mode).
    #[inline(always)]
    pub fn depth_at(&self, x: f64, y: f64) -> f64 {
        self.z.at(x, y)
    }
}

/// Fine 2x2 quad differences of a value given at the quad's pixels `[top-left, top-right,
/// bottom-left, bottom-right]`: for each pixel, `(d/dx, d/dy)` = (difference along its row, difference
/// along its column).
#[inline(always)]
pub fn quad_differences(v: [DVec2; 4]) -> [(DVec2, DVec2); 4] {
    let dx_top = v[1] - v[0];
    let dx_bottom = v[3] - v[2];
    let dy_left = v[2] - v[0];
    let dy_right = v[3] - v[1];
    [
        (dx_top, dy_left),
        (dx_top, dy_right),
        (dx_bottom, dy_left),
        (dx_bottom, dy_right),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quad_difference_table() {
        let v = [
            DVec2::new(0.0, 0.0),
            DVec2::new(1.0, 0.5),
            DVec2::new(0.25, 2.0),
            DVec2::new(1.5, 3.0),
        ];
        let d = quad_differences(v);
        assert_eq!(d[0], (DVec2::new(1.0, 0.5), DVec2::new(0.25, 2.0)));
        assert_eq!(d[3], (DVec2::new(1.25, 1.0), DVec2::new(0.5, 2.5)));
    }
}
