//! Per-pixel interpolation: barycentrics (perspective-correct or affine), their analytic screen
//! derivatives, and the GPU-style 2x2 quad differences.
//!
//! Perspective-correct (docs/guide/conventions.md): with `q_k = lambda_k / w` and `r = 1 / w`
//! linear in screen space (planes from [`crate::setup`]), `lambda_k = q_k / r` and, by the
//! quotient rule,
//! `d lambda_k / dx = (q_k,x r - q_k r_x) / r^2 = (q_k,x - lambda_k r_x) / r`. Any attribute
//! `a = sum_k lambda_k a_k` then has `da/dx = sum_k a_k d lambda_k / dx`: this is exactly
//! `du/dx = (q_x r - q r_x) / r^2` for `q = u / w`, evaluated in `f64` here (`UvPlanes` evaluates
//! the same formulas in `f32` from planes re-anchored per tile and triangle).
//! Affine: `lambda_k` is itself a plane and its derivatives are constants.
//!
//! The two formulas are the kernels `lambda` and `lambda_derivative`: the one-pixel API
//! ([`TriangleSetup::barycentrics`]) and the rasterizer's span stages (`tile.rs`, a span of
//! fragments at a time) both call them, so both give the same bits.

use glam::{DVec2, DVec3};
use texel_texture::Footprint;

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

/// `uv` over one triangle's pixels in one tile, as `f32` planes re-anchored there: what every
/// rasterizer path (span, per pixel, quads) interpolates `uv` with, so their footprints agree bit
/// for bit.
///
/// With `r = 1 / w` and `P_u = u / w = sum_k u_k q_k` linear in screen space (affine: `r = 1`,
/// `P_u = sum_k u_k lambda_k`), `u = P_u / r` and `du/dx = (P_u,x - u r_x) / r`. The planes are
/// evaluated in `f64` once, at an anchor pixel of the tile, and whole periods of the address mode
/// (`n`, the periods below `u` at the anchor) are taken out there: `P_u' = P_u - n r`, so
/// `u' = u - n`. Per pixel they are stepped in `f32` from the anchor by whole pixels (at most a
/// tile, exact in `f32`), so the values stay near the anchor's `u' in [0, period)` instead of the
/// ground's 250 periods. Then `u'` is reduced into `[0, period]` in `f32` (an integer number of
/// periods subtracted; the product and the difference round, so `period` itself can come out). All
/// nine coefficients are divided by `r` at the anchor in `f64` before they are rounded to `f32`,
/// so they have the size of `u` and its steps whatever the scale of `w` (`r` is 1 at the anchor).
///
/// Accuracy: a few `f32` ulps of `u'` (tested against the exact ray-plane intersection,
/// `tests/perspective.rs`); where the image is magnified `u'` stays within about one period of the
/// anchor, where an ulp is `2^-23` of a period, 1.2e-4 texel of a 1024-texel texture. The `f64`
/// barycentrics ([`TriangleSetup::barycentrics`]) remain for shading and the reference.
#[derive(Clone, Copy, Debug)]
pub(crate) struct UvPlanes {
    /// The anchor pixel (frame coordinates; its centre is where the planes' constants hold).
    pub anchor: [u32; 2],
    /// `r` as `[value at the anchor, d/dx, d/dy]`.
    pub r: [f32; 3],
    /// `P_u'` likewise.
    pub u: [f32; 3],
    /// `P_v'` likewise.
    pub v: [f32; 3],
    /// The address modes' periods in u and v (0: not periodic) and their reciprocals.
    pub period: [f32; 2],
    pub inv_period: [f32; 2],
}

impl UvPlanes {
    /// The planes of triangle `t` with vertex `uvs` for the pixels `range` (`[i_lo, j_lo, i_hi,
    /// j_hi]`, inclusive) under `perspective`, with the address modes' `period`s (0: none). The
    /// anchor is the pixel of the range's centre and corners where `r` is largest (the nearest,
    /// most magnified part, where accuracy matters most; all of them are equal when affine).
    pub(crate) fn new(
        t: &TriangleSetup,
        uvs: [DVec2; 3],
        perspective: Perspective,
        range: [u32; 4],
        period: DVec2,
    ) -> UvPlanes {
        let [i_lo, j_lo, i_hi, j_hi] = range;
        let (weights, r) = match perspective {
            Perspective::Correct => (t.q, t.r),
            Perspective::Affine => (
                t.affine,
                crate::setup::Plane {
                    c: 1.0,
                    dx: 0.0,
                    dy: 0.0,
                },
            ),
        };
        let centre = [i_lo + (i_hi - i_lo) / 2, j_lo + (j_hi - j_lo) / 2];
        let at = |p: [u32; 2]| r.at(f64::from(p[0]) + 0.5, f64::from(p[1]) + 0.5);
        let mut anchor = centre;
        for p in [[i_lo, j_lo], [i_hi, j_lo], [i_lo, j_hi], [i_hi, j_hi]] {
            if at(p) > at(anchor) {
                anchor = p;
            }
        }
        let (xa, ya) = (f64::from(anchor[0]) + 0.5, f64::from(anchor[1]) + 0.5);
        let r0 = r.at(xa, ya);
        let plane = |c: usize, p: f64| -> [f32; 3] {
            let a = |f: &dyn Fn(&crate::setup::Plane) -> f64| {
                weights
                    .iter()
                    .zip(&uvs)
                    .map(|(w, uv)| uv[c] * f(w))
                    .sum::<f64>()
            };
            let (pc, px, py) = (a(&|w| w.at(xa, ya)), a(&|w| w.dx), a(&|w| w.dy));
            // Whole periods below u at the anchor (none where u is not finite there or beyond
            // what f64 can floor).
            let t = pc / r0 / p.max(f64::MIN_POSITIVE);
            let n = if p > 0.0 && t.is_finite() && t.abs() < 1e15 {
                p * t.floor()
            } else {
                0.0
            };
            // Divided by r0 (the ratios u = P_u / r and the derivatives do not change), so the
            // f32 coefficients are of the size of u and its steps whatever the scale of w.
            [
                ((pc - n * r0) / r0) as f32,
                ((px - n * r.dx) / r0) as f32,
                ((py - n * r.dy) / r0) as f32,
            ]
        };
        let inv = |p: f64| if p > 0.0 { (1.0 / p) as f32 } else { 0.0 };
        UvPlanes {
            anchor,
            r: [1.0, (r.dx / r0) as f32, (r.dy / r0) as f32],
            u: plane(0, period.x),
            v: plane(1, period.y),
            period: [period.x as f32, period.y as f32],
            inv_period: [inv(period.x), inv(period.y)],
        }
    }

    /// `1 / r` at `(dx, dy)` pixels from the anchor.
    #[inline(always)]
    pub(crate) fn inv_r(&self, dx: f32, dy: f32) -> f32 {
        1.0 / (self.r[0] + self.r[1] * dx + self.r[2] * dy)
    }

    /// `u'` (`c = 0`) or `v'` (`c = 1`) at `(dx, dy)` pixels from the anchor, given `1 / r` there.
    #[inline(always)]
    pub(crate) fn value(&self, c: usize, dx: f32, dy: f32, inv_r: f32) -> f32 {
        let p = if c == 0 { &self.u } else { &self.v };
        (p[0] + p[1] * dx + p[2] * dy) * inv_r
    }

    /// `(d/dx, d/dy)` of `u'` (`c = 0`) or `v'` (`c = 1`), given its value and `1 / r`.
    #[inline(always)]
    pub(crate) fn derivatives(&self, c: usize, value: f32, inv_r: f32) -> (f32, f32) {
        let p = if c == 0 { &self.u } else { &self.v };
        (
            (p[1] - value * self.r[1]) * inv_r,
            (p[2] - value * self.r[2]) * inv_r,
        )
    }

    /// The offset of pixel `(i, j)` from the anchor, in pixels (exact: both are below `2^24`).
    #[inline(always)]
    pub(crate) fn offset(&self, i: u32, j: u32) -> (f32, f32) {
        (
            (i as i32 - self.anchor[0] as i32) as f32,
            (j as i32 - self.anchor[1] as i32) as f32,
        )
    }

    /// The footprint at pixel `(i, j)`: `uv` reduced and its analytic derivatives. The span
    /// stages in `tile.rs` perform the same operations in the same order over many pixels.
    #[inline(always)]
    pub(crate) fn footprint(&self, i: u32, j: u32) -> Footprint {
        let (dx, dy) = self.offset(i, j);
        let inv = self.inv_r(dx, dy);
        let (u, v) = (self.value(0, dx, dy, inv), self.value(1, dx, dy, inv));
        let (dudx, dudy) = self.derivatives(0, u, inv);
        let (dvdx, dvdy) = self.derivatives(1, v, inv);
        Footprint {
            u: self.reduce(0, u),
            v: self.reduce(1, v),
            dudx,
            dudy,
            dvdx,
            dvdy,
        }
    }

    /// The footprints of the 2x2 quad whose top-left pixel is `(qi, qj)`, in
    /// [`quad_differences`]' order: `uv'` at the four pixels, derivatives as its differences
    /// within the quad (before the reduction, which would break them at a period's edge).
    #[inline(always)]
    pub(crate) fn quad_footprints(&self, qi: u32, qj: u32) -> [Footprint; 4] {
        let uv: [[f32; 2]; 4] = std::array::from_fn(|k| {
            let (dx, dy) = self.offset(qi + (k as u32 & 1), qj + (k as u32 >> 1));
            let inv = self.inv_r(dx, dy);
            [self.value(0, dx, dy, inv), self.value(1, dx, dy, inv)]
        });
        let d = |a: [f32; 2], b: [f32; 2]| [b[0] - a[0], b[1] - a[1]];
        let (dx_top, dx_bottom) = (d(uv[0], uv[1]), d(uv[2], uv[3]));
        let (dy_left, dy_right) = (d(uv[0], uv[2]), d(uv[1], uv[3]));
        let ds = [
            (dx_top, dy_left),
            (dx_top, dy_right),
            (dx_bottom, dy_left),
            (dx_bottom, dy_right),
        ];
        std::array::from_fn(|k| {
            let (dx, dy) = ds[k];
            Footprint {
                u: self.reduce(0, uv[k][0]),
                v: self.reduce(1, uv[k][1]),
                dudx: dx[0],
                dudy: dy[0],
                dvdx: dx[1],
                dvdy: dy[1],
            }
        })
    }

    /// `x` (a `u'` for `c = 0`, a `v'` for `c = 1`) reduced into `[0, period]` by whole periods
    /// (unchanged without a period, or for `|x / period| >= 2^22`, beyond the staged floor).
    #[inline(always)]
    pub(crate) fn reduce(&self, c: usize, x: f32) -> f32 {
        let (p, inv_p) = (self.period[c], self.inv_period[c]);
        let t = x * inv_p;
        let q = texel_texture::base::floor::floor_staged(t);
        if p > 0.0 && t.abs() < texel_texture::base::floor::STAGED_F32_LIMIT {
            x - p * q
        } else {
            x
        }
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
