//! Homogeneous clipping before the perspective divide (Sutherland-Hodgman, Blinn & Newell 1978).
//!
//! A triangle is clipped in clip space against seven planes, each kept where `d(p) >= 0`:
//! - near `z + w >= 0` and far `w - z >= 0` (OpenGL NDC `z` in `[-1, 1]`), so triangles with
//!   vertices behind the eye keep only their visible part;
//! - `w >= W_MIN` (a safety net for matrices that are not perspective projections);
//! - a guard band `|x| <= GUARD * w`, `|y| <= GUARD * w`: vertices far off screen (1e7, say) are cut
//!   back to at most `GUARD` NDC units, so that after the viewport transform every coordinate is a
//!   few times the frame size and the fixed-point edge functions of [`crate::setup`] cannot overflow.
//!
//! Design decisions:
//! - Clipped vertices carry their barycentric coordinates `lambda` with respect to the *original*
//!   triangle instead of interpolated attributes. Perspective-correct attributes are then computed
//!   from the original triangle's homogeneous plane equations (see [`crate::setup`]), so clipping only
//!   bounds the rasterised region and cannot degrade attribute precision (no sliver sub-triangles
//!   with ill-conditioned planes). The affine mode interpolates `lambda` across each clipped
//!   sub-triangle, as a fixed-function rasterizer would.
//! - The intersection of an edge with a plane is always computed from its inside vertex towards its
//!   outside vertex, so an edge shared by two triangles is cut at bit-identical points whatever the
//!   triangles' vertex order, keeping clipped meshes watertight.
//! - Triangles entirely inside every plane (the common case) skip the clipper; triangles entirely
//!   outside one plane are rejected before any arithmetic.

use glam::{DVec3, DVec4};

/// Guard band half-width in NDC units (the visible screen is `[-1, 1]`).
pub const GUARD: f64 = 8.0;

/// Smallest clip-space `w` kept.
pub const W_MIN: f64 = 1e-12;

/// Number of clip planes.
const PLANES: usize = 7;

/// Most vertices a triangle clipped by the seven planes can have (3 + one per plane).
pub const MAX_CLIPPED: usize = 3 + PLANES;

/// A vertex during clipping: its clip-space position and its barycentric coordinates with respect to
/// the original triangle.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ClipVertex {
    /// Clip-space position `(x, y, z, w)`.
    pub pos: DVec4,
    /// Barycentric coordinates in the original triangle (sum 1).
    pub lambda: DVec3,
}

/// A convex polygon of at most [`MAX_CLIPPED`] vertices (no allocation).
#[derive(Clone, Copy, Debug)]
pub struct Polygon {
    /// The vertices; only the first `len` are meaningful.
    pub vertices: [ClipVertex; MAX_CLIPPED],
    /// Number of vertices (0 when clipped away entirely, otherwise at least 3).
    pub len: usize,
}

impl Polygon {
    /// The meaningful vertices.
    pub fn as_slice(&self) -> &[ClipVertex] {
        &self.vertices[..self.len]
    }
}

/// Signed distance of `p` to plane `k` (inside when `>= 0`).
#[inline]
fn distance(k: usize, p: DVec4) -> f64 {
    match k {
        0 => p.z + p.w,
        1 => p.w - p.z,
        2 => p.w - W_MIN,
        3 => GUARD * p.w - p.x,
        4 => GUARD * p.w + p.x,
        5 => GUARD * p.w - p.y,
        _ => GUARD * p.w + p.y,
    }
}

/// Bit `k` set where `p` is outside plane `k`.
#[inline]
fn outcode(p: DVec4) -> u32 {
    (0..PLANES).fold(0, |code, k| code | (u32::from(distance(k, p) < 0.0) << k))
}

/// Clip the triangle with clip-space positions `p` against the planes of this module.
///
/// Returns a convex polygon (possibly empty) whose vertices carry barycentric coordinates in the
/// original triangle. Non-finite positions yield an empty polygon.
pub fn clip_triangle(p: [DVec4; 3]) -> Polygon {
    let mut poly = Polygon {
        vertices: [ClipVertex::default(); MAX_CLIPPED],
        len: 0,
    };
    if !p.iter().all(|v| v.is_finite()) {
        return poly;
    }
    let lambdas = [DVec3::X, DVec3::Y, DVec3::Z];
    for k in 0..3 {
        poly.vertices[k] = ClipVertex {
            pos: p[k],
            lambda: lambdas[k],
        };
    }
    let codes = p.map(outcode);
    if codes[0] & codes[1] & codes[2] != 0 {
        return poly; // entirely outside one plane
    }
    poly.len = 3;
    if codes[0] | codes[1] | codes[2] == 0 {
        return poly; // entirely inside: nothing to clip
    }
    let all = codes[0] | codes[1] | codes[2];
    for k in 0..PLANES {
        if all & (1 << k) != 0 {
            poly = clip_plane(&poly, k);
            if poly.len < 3 {
                poly.len = 0;
                return poly;
            }
        }
    }
    poly
}

/// One Sutherland-Hodgman pass against plane `k`.
fn clip_plane(input: &Polygon, k: usize) -> Polygon {
    let mut out = Polygon {
        vertices: [ClipVertex::default(); MAX_CLIPPED],
        len: 0,
    };
    let n = input.len;
    for a in 0..n {
        let va = input.vertices[a];
        let vb = input.vertices[(a + 1) % n];
        let (da, db) = (distance(k, va.pos), distance(k, vb.pos));
        let (ina, inb) = (da >= 0.0, db >= 0.0);
        if ina {
            push(&mut out, va);
        }
        if ina != inb {
            // From the inside vertex towards the outside one, whatever the edge's direction.
            let (vi, di, vo, dout) = if ina {
                (va, da, vb, db)
            } else {
                (vb, db, va, da)
            };
            let t = di / (di - dout);
            push(
                &mut out,
                ClipVertex {
                    pos: vi.pos + (vo.pos - vi.pos) * t,
                    lambda: vi.lambda + (vo.lambda - vi.lambda) * t,
                },
            );
        }
    }
    out
}

#[inline]
fn push(poly: &mut Polygon, v: ClipVertex) {
    // A convex polygon gains at most one vertex per plane, so this never overflows; guard anyway.
    if poly.len < MAX_CLIPPED {
        poly.vertices[poly.len] = v;
        poly.len += 1;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tri(a: [f64; 4], b: [f64; 4], c: [f64; 4]) -> [DVec4; 3] {
        [a, b, c].map(DVec4::from_array)
    }

    #[test]
    fn inside_triangle_is_untouched() {
        let t = tri(
            [0.0, 0.0, 0.0, 1.0],
            [0.5, 0.0, 0.0, 1.0],
            [0.0, 0.5, 0.0, 1.0],
        );
        let p = clip_triangle(t);
        assert_eq!(p.len, 3);
        assert_eq!(p.vertices[1].pos, t[1]);
    }

    #[test]
    fn behind_the_eye_is_rejected_and_crossing_is_cut() {
        // All three vertices have z < -w: in front of the near plane (behind the eye).
        let behind = tri(
            [0.0, 0.0, -2.0, 1.0],
            [1.0, 0.0, -2.0, 1.0],
            [0.0, 1.0, -2.0, 1.0],
        );
        assert_eq!(clip_triangle(behind).len, 0);
        // One vertex behind the near plane: a quadrilateral, every vertex on or inside the plane.
        let crossing = tri(
            [0.0, 0.0, -3.0, 1.0],
            [0.5, 0.0, 0.0, 1.0],
            [0.0, 0.5, 0.0, 1.0],
        );
        let p = clip_triangle(crossing);
        assert_eq!(p.len, 4);
        for v in p.as_slice() {
            assert!(v.pos.z + v.pos.w >= -1e-12);
            assert!((v.lambda.element_sum() - 1.0).abs() < 1e-12);
            // The position is the barycentric combination of the original vertices.
            let q = crossing[0] * v.lambda.x + crossing[1] * v.lambda.y + crossing[2] * v.lambda.z;
            assert!((q - v.pos).abs().max_element() < 1e-12);
        }
    }

    #[test]
    fn shared_edge_is_cut_identically_in_both_directions() {
        let a = DVec4::new(-3e7, 0.1, 0.0, 1.0);
        let b = DVec4::new(0.3, 0.2, 0.0, 1.0);
        let c = DVec4::new(0.0, 0.9, 0.0, 1.0);
        let d = DVec4::new(0.1, -0.9, 0.0, 1.0);
        let p1 = clip_triangle([a, b, c]);
        let p2 = clip_triangle([b, a, d]);
        // Vertices on the edge ab have a zero third barycentric coordinate: b itself and the cut.
        let on_ab = |p: &Polygon| {
            let mut v: Vec<[f64; 4]> = p
                .as_slice()
                .iter()
                .filter(|v| v.lambda.z == 0.0)
                .map(|v| v.pos.to_array())
                .collect();
            v.sort_by(|x, y| x.partial_cmp(y).unwrap());
            v
        };
        let (e1, e2) = (on_ab(&p1), on_ab(&p2));
        assert_eq!(e1.len(), 2);
        assert_eq!(e1, e2);
    }

    #[test]
    fn nan_gives_empty() {
        let t = tri(
            [f64::NAN, 0.0, 0.0, 1.0],
            [0.5, 0.0, 0.0, 1.0],
            [0.0, 0.5, 0.0, 1.0],
        );
        assert_eq!(clip_triangle(t).len, 0);
    }
}
