//! Triangle setup, once per triangle: clipping, viewport, fixed-point edge functions with the
//! top-left fill rule, and the plane equations every pixel evaluates.
//!
//! ## Coverage: fixed-point edge functions
//! Clipped vertices are projected (the viewport of docs/guide/conventions.md) and snapped to
//! [`SUBPIXEL_BITS`] = 8 fractional bits in `i64`. For an edge `a -> b` the edge function is
//! `E(p) = (b.x - a.x)(p.y - a.y) - (b.y - a.y)(p.x - a.x)`, evaluated exactly in integers at pixel
//! centres `(256 i + 128, 256 j + 128)`. Each sub-triangle is oriented so that its interior has
//! `E >= 0` on all three edges. Top-left rule (Direct3D rasterization rules, y down): a pixel centre
//! exactly on an edge is covered only if the edge is a *top* edge (horizontal, interior below:
//! `dy == 0 && dx > 0`) or a *left* edge (interior to its right: `dy < 0`). Two triangles sharing an
//! edge see it with opposite directions, so exactly one of them owns its pixels: meshes are watertight
//! with no double coverage. The rule is folded into the constant term (`E - 1 >= 0` for the others).
//!
//! Overflow: the clipper's guard band ([`crate::clip::GUARD`] = 8 NDC units) bounds every coordinate,
//! and the projection clamps NDC to twice the band (clipping coordinates near 1e33 in `f64` can round
//! far outside it), so every coordinate is within `8.5 * MAX_DIMENSION` pixels, i.e. `|X| < 2^26` in
//! fixed point: edge coefficients stay below `2^27` and edge values below `2^55`, far from `i64`
//! overflow whatever the input (1e7, 1e30, NaN-free extremes found by fuzzing).
//!
//! ## Attributes: homogeneous plane equations (Olano & Greer 1997)
//! With `M` the 3x3 matrix whose columns are the original triangle's clip-space `(x, y, w)`, a point of
//! the triangle with barycentrics `lambda` satisfies `(x_ndc, y_ndc, 1) * w = M lambda`, so
//! `lambda / w = M^-1 (x_ndc, y_ndc, 1)`: each `lambda_k / w` is a plane in screen space, their sum is
//! `1 / w`, and `z_ndc = sum z_k lambda_k / w`. These planes are computed once per *original* triangle
//! in `f64`, with no perspective divide, so they are exact whatever the clipping (vertices behind the
//! eye included) and are evaluated at unsnapped positions: the snapping moves coverage by at most
//! 1/512 pixel but never perturbs `uv`. `det M > 0` means counter-clockwise in NDC (front-facing), for
//! vertices behind the eye too (it is the triangle's orientation seen from the eye).
//!
//! The affine mode instead interpolates `lambda` linearly across each clipped sub-triangle, from its
//! exact (unsnapped) screen positions.

use glam::{DMat3, DVec2, DVec3, DVec4, Vec4Swizzles};
use rayon::prelude::*;

use crate::clip::{clip_triangle, ClipVertex};
use crate::draw::DrawCall;
use crate::error::RasterError;
use crate::settings::RenderSettings;

/// Fractional bits of the fixed-point screen coordinates.
pub const SUBPIXEL_BITS: u32 = 8;
/// `2^SUBPIXEL_BITS`: fixed-point units per pixel.
pub const SUBPIXEL: i64 = 1 << SUBPIXEL_BITS;
/// Triangles set up per parallel task.
const SETUP_CHUNK: usize = 2048;

/// A quantity linear in screen space: `value(x, y) = c + dx * x + dy * y`, with `(x, y)` continuous
/// pixel coordinates (pixel `(i, j)` has its centre at `(i + 0.5, j + 0.5)`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Plane {
    /// Value at pixel coordinates `(0, 0)`.
    pub c: f64,
    /// Change per pixel to the right.
    pub dx: f64,
    /// Change per pixel down.
    pub dy: f64,
}

impl Plane {
    /// The value at `(x, y)`.
    #[inline(always)]
    pub fn at(&self, x: f64, y: f64) -> f64 {
        self.c + self.dx * x + self.dy * y
    }

    /// The plane through three points `(x_k, y_k, f_k)`; `None` if they are collinear in `(x, y)` or
    /// the result is not finite.
    pub fn through(p: [DVec2; 3], f: [f64; 3]) -> Option<Plane> {
        let (e1, e2) = (p[1] - p[0], p[2] - p[0]);
        let area = e1.x * e2.y - e1.y * e2.x;
        let (f1, f2) = (f[1] - f[0], f[2] - f[0]);
        let dx = (f1 * e2.y - f2 * e1.y) / area;
        let dy = (f2 * e1.x - f1 * e2.x) / area;
        let plane = Plane {
            c: f[0] - dx * p[0].x - dy * p[0].y,
            dx,
            dy,
        };
        (area != 0.0 && plane.c.is_finite() && dx.is_finite() && dy.is_finite()).then_some(plane)
    }
}

/// One edge function `E(X, Y) = a X + b Y + c` in fixed point, with the fill rule folded into `c`:
/// the pixel centre `(X, Y)` is inside the edge iff `E >= 0`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Edge {
    /// Coefficient of `X`: `a.y - b.y`.
    pub a: i64,
    /// Coefficient of `Y`: `b.x - a.x`.
    pub b: i64,
    /// Constant term, including `-1` for edges that are neither top nor left.
    pub c: i64,
}

impl Edge {
    /// The edge `from -> to` (fixed-point vertices), for a triangle whose interior lies on its
    /// `E >= 0` side.
    pub fn new(from: [i64; 2], to: [i64; 2]) -> Edge {
        let (dx, dy) = (to[0] - from[0], to[1] - from[1]);
        let (a, b) = (-dy, dx);
        let top_left = dy < 0 || (dy == 0 && dx > 0);
        Edge {
            a,
            b,
            c: -(a * from[0] + b * from[1]) - i64::from(!top_left),
        }
    }

    /// `E` at the fixed-point point `(x, y)`.
    #[inline(always)]
    pub fn at(&self, x: i64, y: i64) -> i64 {
        self.a * x + self.b * y + self.c
    }
}

/// Fixed-point coordinate of the centre of pixel `i` (or row `j`).
#[inline(always)]
pub fn pixel_center_fixed(i: u32) -> i64 {
    i64::from(i) * SUBPIXEL + SUBPIXEL / 2
}

/// A rasterisable triangle: one sub-triangle of a clipped original triangle, with everything the
/// per-pixel loop needs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TriangleSetup {
    /// Index of the draw call.
    pub draw: u32,
    /// Index of the original triangle within the draw.
    pub triangle: u32,
    /// Vertex indices of the original triangle (barycentric `k` weighs `indices[k]`).
    pub indices: [u32; 3],
    /// The three edge functions.
    pub edges: [Edge; 3],
    /// Pixels whose centres may be covered, inclusive, clamped to the frame:
    /// `[i_min, j_min, i_max, j_max]`; `None` for a triangle that covers no pixel centre (a sliver
    /// or a triangle smaller than a pixel), which only the reference renderer's sub-samples see.
    pub bbox: Option<[u32; 4]>,
    /// Pixels any part of which the triangle may cover (its fixed-point bounding box, one sub-pixel
    /// unit wider), clamped to the frame: where the reference renderer's sub-samples can hit it.
    pub sample_bbox: [u32; 4],
    /// `1 / w_clip` (sum of [`TriangleSetup::q`]).
    pub r: Plane,
    /// `lambda_k / w_clip` of the original triangle.
    pub q: [Plane; 3],
    /// NDC depth `z / w`.
    pub z: Plane,
    /// `lambda_k` interpolated linearly across this sub-triangle (the affine mode).
    pub affine: [Plane; 3],
}

impl TriangleSetup {
    /// Whether the centre of pixel `(i, j)` is covered (inside the bounding box and on the inner side
    /// of all three edges, with the top-left rule).
    #[inline]
    pub fn covers(&self, i: u32, j: u32) -> bool {
        let Some([i0, j0, i1, j1]) = self.bbox else {
            return false;
        };
        (i0..=i1).contains(&i) && (j0..=j1).contains(&j) && {
            let (x, y) = (pixel_center_fixed(i), pixel_center_fixed(j));
            self.edges.iter().all(|e| e.at(x, y) >= 0)
        }
    }
}

/// Check that every index of every draw is in range.
///
/// # Errors
/// [`RasterError::IndexOutOfRange`] for the first offending index.
pub fn validate_draws(draws: &[DrawCall]) -> Result<(), RasterError> {
    for (d, draw) in draws.iter().enumerate() {
        if draw.material.as_ref().is_some_and(|m| !m.is_valid()) {
            return Err(RasterError::InvalidMaterial { draw: d });
        }
        let n = draw.vertices.len();
        for (t, tri) in draw.triangles.iter().enumerate() {
            if let Some(&index) = tri.iter().find(|&&k| k as usize >= n) {
                return Err(RasterError::IndexOutOfRange {
                    draw: d,
                    triangle: t,
                    index,
                    vertex_count: n,
                });
            }
        }
    }
    Ok(())
}

/// Set up every triangle of every draw, in draw order then triangle order (the order ties in depth
/// are resolved in). Runs in parallel on the current rayon pool; the result does not depend on it.
///
/// # Errors
/// [`RasterError::IndexOutOfRange`] (checked before anything else).
pub fn setup_draws(
    settings: &RenderSettings,
    draws: &[DrawCall],
) -> Result<Vec<TriangleSetup>, RasterError> {
    let chunks = setup_chunks(settings, draws)?;
    let mut all = Vec::with_capacity(chunks.iter().map(Vec::len).sum());
    all.extend(chunks.into_iter().flatten());
    Ok(all)
}

/// [`setup_draws`] as the chunks it is computed in (draw by draw, [`SETUP_CHUNK`] triangles a
/// chunk, in order): their concatenation is `setup_draws`'s result. The rasterizer bins the chunks
/// in place, since concatenating them copies every setup (about 330 bytes each: 33 MB for 100k
/// triangles) into a buffer that, above glibc's largest `mmap` threshold, is mapped and faulted in
/// afresh for every frame.
pub(crate) fn setup_chunks(
    settings: &RenderSettings,
    draws: &[DrawCall],
) -> Result<Vec<Vec<TriangleSetup>>, RasterError> {
    validate_draws(draws)?;
    let mut all = Vec::new();
    for (d, draw) in draws.iter().enumerate() {
        let chunks: Vec<Vec<TriangleSetup>> = draw
            .triangles
            .par_chunks(SETUP_CHUNK)
            .enumerate()
            .map(|(c, tris)| {
                let mut out = Vec::with_capacity(tris.len());
                for (k, tri) in tris.iter().enumerate() {
                    let t = c * SETUP_CHUNK + k;
                    setup_triangle(settings, draw, d as u32, t as u32, *tri, &mut out);
                }
                out
            })
            .collect();
        all.extend(chunks);
    }
    Ok(all)
}

/// Set up one triangle, pushing its (zero or more) rasterisable sub-triangles onto `out`.
///
/// Skipped silently: indices out of range, non-finite positions, triangles whose plane passes
/// through the eye (`det M = 0`), back faces when culling, and anything clipped away entirely.
pub fn setup_triangle(
    settings: &RenderSettings,
    draw: &DrawCall,
    draw_index: u32,
    triangle: u32,
    indices: [u32; 3],
    out: &mut Vec<TriangleSetup>,
) {
    if indices.iter().any(|&k| k as usize >= draw.vertices.len()) {
        return;
    }
    let vs = indices.map(|k| &draw.vertices[k as usize]);
    let m = draw.clip_from_world.as_dmat4();
    let clip: [DVec4; 3] = std::array::from_fn(|k| m * vs[k].position.as_dvec3().extend(1.0));
    if !clip.iter().all(|p| p.is_finite()) {
        return;
    }
    let Some((q, r, z)) = homogeneous_planes(&clip, settings.width, settings.height) else {
        return;
    };
    let det = DMat3::from_cols(clip[0].xyw(), clip[1].xyw(), clip[2].xyw()).determinant();
    if settings.cull_backfaces && det <= 0.0 {
        return;
    }
    let poly = clip_triangle(clip);
    let verts = poly.as_slice();
    if verts.len() < 3 {
        return;
    }
    // Project every polygon vertex once, so sub-triangles share bit-identical positions.
    let mut screen = [DVec2::ZERO; crate::clip::MAX_CLIPPED];
    let mut fixed = [[0i64; 2]; crate::clip::MAX_CLIPPED];
    for (k, v) in verts.iter().enumerate() {
        let (x, y) = project(v, settings.width, settings.height);
        screen[k] = DVec2::new(x, y);
        fixed[k] = [snap(x), snap(y)];
    }
    for k in 1..verts.len() - 1 {
        let mut ids = [0, k, k + 1];
        let area = area2(fixed[ids[0]], fixed[ids[1]], fixed[ids[2]]);
        if area == 0 {
            continue;
        }
        if area < 0 {
            ids.swap(1, 2);
        }
        let [f0, f1, f2] = ids.map(|i| fixed[i]);
        let Some(sample_bbox) = touched_bbox([f0, f1, f2], settings.width, settings.height) else {
            continue;
        };
        let bbox = pixel_bbox([f0, f1, f2], settings.width, settings.height);
        let pos = ids.map(|i| screen[i]);
        let lam = ids.map(|i| verts[i].lambda);
        let affine = std::array::from_fn(|c| {
            Plane::through(pos, lam.map(|l| l[c])).unwrap_or(Plane {
                c: lam[0][c],
                dx: 0.0,
                dy: 0.0,
            })
        });
        out.push(TriangleSetup {
            draw: draw_index,
            triangle,
            indices,
            edges: [Edge::new(f1, f2), Edge::new(f2, f0), Edge::new(f0, f1)],
            bbox,
            sample_bbox,
            r,
            q,
            z,
            affine,
        });
    }
}

/// The planes `lambda_k / w`, `1 / w` and `z / w` of a triangle with clip-space vertices `clip`,
/// in pixel coordinates of a `width x height` frame; `None` when `M` is singular or not finite.
fn homogeneous_planes(
    clip: &[DVec4; 3],
    width: u32,
    height: u32,
) -> Option<([Plane; 3], Plane, Plane)> {
    let m = DMat3::from_cols(clip[0].xyw(), clip[1].xyw(), clip[2].xyw());
    let det = m.determinant();
    let scale = clip[0].xyw().length() * clip[1].xyw().length() * clip[2].xyw().length();
    if !det.is_finite() || det.abs() <= 1e-14 * scale {
        return None;
    }
    let inv = m.inverse();
    let (w, h) = (f64::from(width), f64::from(height));
    // Row k of M^-1: lambda_k / w = a x_ndc + b y_ndc + c with x_ndc = 2x/W - 1, y_ndc = 1 - 2y/H.
    let q: [Plane; 3] = std::array::from_fn(|k| {
        let row = inv.row(k);
        let (a, b, c) = (row.x, row.y, row.z);
        Plane {
            c: c - a + b,
            dx: 2.0 * a / w,
            dy: -2.0 * b / h,
        }
    });
    let sum = |f: &dyn Fn(usize) -> f64| Plane {
        c: (0..3).map(|k| f(k) * q[k].c).sum(),
        dx: (0..3).map(|k| f(k) * q[k].dx).sum(),
        dy: (0..3).map(|k| f(k) * q[k].dy).sum(),
    };
    let r = sum(&|_| 1.0);
    let z = sum(&|k| clip[k].z);
    let ok = |p: &Plane| p.c.is_finite() && p.dx.is_finite() && p.dy.is_finite();
    (q.iter().all(ok) && ok(&r) && ok(&z)).then_some((q, r, z))
}

/// Continuous pixel coordinates of a clipped vertex (perspective divide and viewport).
#[inline]
fn project(v: &ClipVertex, width: u32, height: u32) -> (f64, f64) {
    let inv_w = 1.0 / v.pos.w;
    // The clipper leaves |NDC| <= GUARD up to rounding; clipping coordinates near 1e33 can round
    // far past it, so clamp to twice the band (a no-op for every vertex the band already holds).
    let bound = 2.0 * crate::clip::GUARD;
    crate::camera::viewport(
        (v.pos.x * inv_w).clamp(-bound, bound),
        (v.pos.y * inv_w).clamp(-bound, bound),
        width,
        height,
    )
}

/// Round a pixel coordinate to fixed point (saturating; the guard band keeps it far from the limits).
#[inline]
fn snap(x: f64) -> i64 {
    (x * SUBPIXEL as f64).round() as i64
}

/// Twice the signed area in fixed point (positive: clockwise on screen with y down).
#[inline]
fn area2(a: [i64; 2], b: [i64; 2], c: [i64; 2]) -> i64 {
    (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
}

/// Pixels whose centres lie within the fixed-point bounding box, clamped to the frame.
fn pixel_bbox(v: [[i64; 2]; 3], width: u32, height: u32) -> Option<[u32; 4]> {
    let half = SUBPIXEL / 2;
    let range = |axis: usize, n: u32| -> Option<(u32, u32)> {
        let lo = v.iter().map(|p| p[axis]).min()?;
        let hi = v.iter().map(|p| p[axis]).max()?;
        let first = (lo - half + SUBPIXEL - 1).div_euclid(SUBPIXEL).max(0);
        let last = (hi - half).div_euclid(SUBPIXEL).min(i64::from(n) - 1);
        (first <= last).then_some((first as u32, last as u32))
    };
    let (i0, i1) = range(0, width)?;
    let (j0, j1) = range(1, height)?;
    Some([i0, j0, i1, j1])
}

/// Pixels any part of which lies within the fixed-point bounding box (widened by one sub-pixel unit,
/// so a sample rounded onto a pixel's far edge still finds the triangle), clamped to the frame.
fn touched_bbox(v: [[i64; 2]; 3], width: u32, height: u32) -> Option<[u32; 4]> {
    let range = |axis: usize, n: u32| -> Option<(u32, u32)> {
        let lo = v.iter().map(|p| p[axis]).min()?;
        let hi = v.iter().map(|p| p[axis]).max()?;
        let first = (lo - 1).div_euclid(SUBPIXEL).max(0);
        let last = hi.div_euclid(SUBPIXEL).min(i64::from(n) - 1);
        (first <= last).then_some((first as u32, last as u32))
    };
    let (i0, i1) = range(0, width)?;
    let (j0, j1) = range(1, height)?;
    Some([i0, j0, i1, j1])
}

/// Barycentric coordinates `lambda` (perspective-correct) of a point known to lie on the triangle,
/// from its clip-space vertices; used by tests as an independent reference.
pub fn lambda_from_clip(clip: &[DVec4; 3], x_ndc: f64, y_ndc: f64) -> Option<DVec3> {
    let m = DMat3::from_cols(clip[0].xyw(), clip[1].xyw(), clip[2].xyw());
    let l = m.inverse() * DVec3::new(x_ndc, y_ndc, 1.0);
    let s = l.element_sum();
    (s != 0.0 && l.is_finite()).then(|| l / s)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Regression (fuzz target `raster`): a clipped vertex whose rounding left it far outside the
    /// guard band (x = 1e33 at w = 1e-12) saturated `snap` at `i64::MAX`, and `area2` overflowed.
    #[test]
    fn projection_stays_within_twice_the_guard_band() {
        let (w, h) = (100, 96);
        for pos in [
            DVec4::new(1e33, -1e33, 0.0, 1e-12),
            DVec4::new(-1e300, 1e300, 0.0, 1.0),
            DVec4::new(7.9, -7.9, 0.0, 1.0),
        ] {
            let (x, y) = project(
                &ClipVertex {
                    pos,
                    lambda: DVec3::X,
                },
                w,
                h,
            );
            let bound = (2.0 * crate::clip::GUARD + 1.0) * 0.5;
            assert!(
                x.abs() <= bound * f64::from(w) && y.abs() <= bound * f64::from(h),
                "{x} {y}"
            );
            let f = [snap(x), snap(y)];
            assert!(f.iter().all(|c| c.abs() < 1 << 26), "{f:?}");
            // Inside the band nothing changes.
            if pos.x.abs() < 8.0 {
                assert_eq!((x, y), crate::camera::viewport(7.9, -7.9, w, h));
            }
        }
    }

    #[test]
    fn top_left_rule_table() {
        // Interior below a horizontal edge going right: top edge, owns its pixels.
        assert_eq!(Edge::new([0, 0], [256, 0]).c, 0);
        // Horizontal edge going left (interior above): bottom edge.
        assert_eq!(Edge::new([256, 0], [0, 0]).c, -1);
        // Edge going up (dy < 0): interior to its right: left edge.
        assert_eq!(Edge::new([0, 256], [0, 0]).c, 0);
        // Edge going down: right edge.
        assert_eq!(Edge::new([0, 0], [0, 256]).c, -1);
        // A point on the edge: E = 0 before the bias.
        let e = Edge::new([0, 0], [0, 256]);
        assert_eq!(e.at(0, 128), -1);
        assert_eq!(e.at(1, 128), -1 - 256);
    }

    #[test]
    fn plane_through_points() {
        let p = Plane::through(
            [
                DVec2::new(0.0, 0.0),
                DVec2::new(2.0, 0.0),
                DVec2::new(0.0, 4.0),
            ],
            [1.0, 3.0, 9.0],
        )
        .unwrap();
        assert_eq!((p.c, p.dx, p.dy), (1.0, 1.0, 2.0));
        assert!(Plane::through([DVec2::ZERO; 3], [0.0; 3]).is_none());
    }

    #[test]
    fn bbox_uses_pixel_centres() {
        // x from 0.5 to 2.5 px: centres 0.5, 1.5, 2.5 -> pixels 0..=2; y from 0.6 to 1.4: none.
        assert_eq!(
            pixel_bbox([[128, 154], [640, 154], [640, 358]], 10, 10),
            None
        );
        assert_eq!(
            pixel_bbox([[128, 128], [640, 128], [640, 384]], 10, 10),
            Some([0, 0, 2, 1])
        );
        assert_eq!(
            pixel_bbox([[-9999, -9999], [99999, 0], [0, 99999]], 4, 3),
            Some([0, 0, 3, 2])
        );
    }
}
