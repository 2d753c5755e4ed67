//! Perspective image warping: every output pixel samples the source through a homography, with the
//! homography's exact derivatives as its footprint, so a shrinking warp is filtered instead of aliased.
//!
//! The projective mapping from the unit square to a quadrilateral is Heckbert's closed form
//! ("Fundamentals of Texture Mapping and Image Warping", UC Berkeley 1989, section 2.2.3):
//! with corners `p0..p3` the images of `(0,0), (1,0), (1,1), (0,1)`,
//!
//! ```text
//! X(s, t) = (a s + b t + c) / (g s + h t + 1),    Y(s, t) = (d s + e t + f) / (g s + h t + 1)
//! Sx = x0 - x1 + x2 - x3,  Sy = y0 - y1 + y2 - y3
//! if Sx = Sy = 0 (parallelogram): g = h = 0, a = x1 - x0, b = x2 - x1, d = y1 - y0, e = y2 - y1
//! else: g = det[[Sx, dx2], [Sy, dy2]] / det[[dx1, dx2], [dy1, dy2]],
//!       h = det[[dx1, Sx], [dy1, Sy]] / det[[dx1, dx2], [dy1, dy2]],
//!       dx1 = x1 - x2, dx2 = x3 - x2, dy1 = y1 - y2, dy2 = y3 - y2,
//!       a = x1 - x0 + g x1, b = x3 - x0 + h x3, d = y1 - y0 + g y1, e = y3 - y0 + h y3
//! c = x0, f = y0
//! ```
//!
//! The derivatives follow from the quotient rule, `dX/ds = (a - g X) / q` with `q = g s + h t + 1`
//! (and likewise for the other three), so the footprint is exact, not a finite difference.
//! OpenCV's `warpPerspective` samples one bilinear (or bicubic) point per pixel and aliases when the
//! warp shrinks the image; here any of texel's filters sees the true footprint.

use glam::DVec2;

use texel_texture::{Footprint, Sampler, Texture};

/// A projective map from the unit square `(s, t)` onto a quadrilateral (Heckbert 1989).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SquareToQuad {
    a: f64,
    b: f64,
    c: f64,
    d: f64,
    e: f64,
    f: f64,
    g: f64,
    h: f64,
}

/// Why four corners do not define a usable warp.
#[derive(Clone, Copy, Debug, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum WarpError {
    /// A corner coordinate is NaN or infinite.
    #[error("warp corner {index} is not finite: ({x}, {y})")]
    NonFinite {
        /// Corner index 0..4.
        index: usize,
        /// x coordinate.
        x: f64,
        /// y coordinate.
        y: f64,
    },
    /// The output would have more than [`MAX_WARP_PIXELS`] pixels (or a zero side).
    #[error("warp output {width}x{height} must have 1 to {max} pixels")]
    InvalidSize {
        /// Requested width.
        width: u32,
        /// Requested height.
        height: u32,
        /// The limit in pixels.
        max: u64,
    },
    /// The corners are not a convex quadrilateral in the stated order (collinear, self-intersecting
    /// or concave), so the mapping would fold or pass through infinity.
    #[error("warp corners do not form a convex quadrilateral in order top-left, top-right, bottom-right, bottom-left")]
    NotConvex,
}

impl SquareToQuad {
    /// The mapping taking `(0,0), (1,0), (1,1), (0,1)` to `corners[0..4]`.
    ///
    /// # Errors
    /// [`WarpError::NonFinite`] or [`WarpError::NotConvex`].
    pub fn new(corners: [DVec2; 4]) -> Result<Self, WarpError> {
        for (index, p) in corners.iter().enumerate() {
            if !p.is_finite() {
                return Err(WarpError::NonFinite {
                    index,
                    x: p.x,
                    y: p.y,
                });
            }
        }
        // Convex and non-degenerate: the four turns have one strict sign.
        let turns: Vec<f64> = (0..4)
            .map(|k| {
                let (p, q, r) = (corners[k], corners[(k + 1) % 4], corners[(k + 2) % 4]);
                (q - p).perp_dot(r - q)
            })
            .collect();
        if !(turns.iter().all(|&t| t > 0.0) || turns.iter().all(|&t| t < 0.0)) {
            return Err(WarpError::NotConvex);
        }
        let [p0, p1, p2, p3] = corners;
        let sx = p0.x - p1.x + p2.x - p3.x;
        let sy = p0.y - p1.y + p2.y - p3.y;
        let (g, h) = if sx == 0.0 && sy == 0.0 {
            (0.0, 0.0)
        } else {
            let (dx1, dx2, dy1, dy2) = (p1.x - p2.x, p3.x - p2.x, p1.y - p2.y, p3.y - p2.y);
            let den = dx1 * dy2 - dx2 * dy1;
            if den == 0.0 {
                return Err(WarpError::NotConvex);
            }
            ((sx * dy2 - dx2 * sy) / den, (dx1 * sy - sx * dy1) / den)
        };
        Ok(SquareToQuad {
            a: p1.x - p0.x + g * p1.x,
            b: p3.x - p0.x + h * p3.x,
            c: p0.x,
            d: p1.y - p0.y + g * p1.y,
            e: p3.y - p0.y + h * p3.y,
            f: p0.y,
            g,
            h,
        })
    }

    /// The image of `(s, t)`, with its partial derivatives `(d/ds, d/dt)`.
    pub fn map_with_derivatives(&self, s: f64, t: f64) -> (DVec2, DVec2, DVec2) {
        let q = self.g * s + self.h * t + 1.0;
        let x = (self.a * s + self.b * t + self.c) / q;
        let y = (self.d * s + self.e * t + self.f) / q;
        let dds = DVec2::new((self.a - self.g * x) / q, (self.d - self.g * y) / q);
        let ddt = DVec2::new((self.b - self.h * x) / q, (self.e - self.h * y) / q);
        (DVec2::new(x, y), dds, ddt)
    }
}

/// Largest output of [`warp_perspective`] in pixels (2^26, as the rasterizer's frames: the linear
/// result then takes at most 1 GiB).
pub const MAX_WARP_PIXELS: u64 = 1 << 26;

/// Warp `source` into a `width x height` image whose corners (top-left, top-right, bottom-right,
/// bottom-left) show the source pixel positions `corners` (pixels of level 0, `(0, 0)` the top-left
/// corner of the source). Returns linear RGBA, row-major, top row first; pixels mapping outside the
/// source follow the sampler's address modes (ClampToBorder with a transparent border leaves them
/// transparent).
///
/// # Errors
/// As [`SquareToQuad::new`], and [`WarpError::InvalidSize`] for an empty output or one over
/// [`MAX_WARP_PIXELS`] (checked before allocating).
pub fn warp_perspective(
    source: &Texture,
    sampler: &Sampler,
    corners: [DVec2; 4],
    width: u32,
    height: u32,
) -> Result<Vec<[f32; 4]>, WarpError> {
    use rayon::prelude::*;
    let pixels = u64::from(width) * u64::from(height);
    if pixels == 0 || pixels > MAX_WARP_PIXELS {
        return Err(WarpError::InvalidSize {
            width,
            height,
            max: MAX_WARP_PIXELS,
        });
    }
    let map = SquareToQuad::new(corners)?;
    let (sw, sh) = (f64::from(source.width()), f64::from(source.height()));
    let (w, h) = (f64::from(width), f64::from(height));
    let mut out = vec![[0.0f32; 4]; width as usize * height as usize];
    out.par_chunks_mut(width.max(1) as usize)
        .enumerate()
        .for_each(|(j, row)| {
            for (i, px) in row.iter_mut().enumerate() {
                let s = (i as f64 + 0.5) / w;
                let t = (j as f64 + 0.5) / h;
                let (p, dds, ddt) = map.map_with_derivatives(s, t);
                // d/dx = d/ds * ds/dx with ds/dx = 1/w; source pixels to uv divide by the source size.
                let fp = Footprint {
                    u: (p.x / sw) as f32,
                    v: (p.y / sh) as f32,
                    dudx: (dds.x / (w * sw)) as f32,
                    dvdx: (dds.y / (w * sh)) as f32,
                    dudy: (ddt.x / (h * sw)) as f32,
                    dvdy: (ddt.y / (h * sh)) as f32,
                };
                *px = sampler.sample(source, &fp);
            }
        });
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn quad() -> [DVec2; 4] {
        [
            DVec2::new(10.0, 20.0),
            DVec2::new(110.0, 5.0),
            DVec2::new(130.0, 90.0),
            DVec2::new(0.0, 70.0),
        ]
    }

    #[test]
    fn corners_map_exactly() {
        let m = SquareToQuad::new(quad()).unwrap();
        for (st, p) in [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)]
            .iter()
            .zip(quad())
        {
            let (q, _, _) = m.map_with_derivatives(st.0, st.1);
            assert!((q - p).length() < 1e-9, "{st:?} -> {q} want {p}");
        }
    }

    #[test]
    fn derivatives_match_finite_differences() {
        let m = SquareToQuad::new(quad()).unwrap();
        let eps = 1e-6;
        for &(s, t) in &[(0.3, 0.4), (0.9, 0.1), (0.5, 0.5)] {
            let (_, dds, ddt) = m.map_with_derivatives(s, t);
            let fd_s = (m.map_with_derivatives(s + eps, t).0
                - m.map_with_derivatives(s - eps, t).0)
                / (2.0 * eps);
            let fd_t = (m.map_with_derivatives(s, t + eps).0
                - m.map_with_derivatives(s, t - eps).0)
                / (2.0 * eps);
            assert!((dds - fd_s).length() < 1e-5 * dds.length().max(1.0));
            assert!((ddt - fd_t).length() < 1e-5 * ddt.length().max(1.0));
        }
    }

    #[test]
    fn parallelogram_is_affine() {
        let m = SquareToQuad::new([
            DVec2::new(0.0, 0.0),
            DVec2::new(4.0, 1.0),
            DVec2::new(5.0, 4.0),
            DVec2::new(1.0, 3.0),
        ])
        .unwrap();
        assert_eq!((m.g, m.h), (0.0, 0.0));
        let (p, _, _) = m.map_with_derivatives(0.5, 0.5);
        assert!((p - DVec2::new(2.5, 2.0)).length() < 1e-12);
    }

    #[test]
    fn absurd_sizes_are_errors_before_allocating() {
        let tex = Texture::from_fn(
            2,
            2,
            texel_texture::Format::Rgba8Unorm,
            &texel_texture::Limits::default(),
            |_, _| [1.0; 4],
        )
        .unwrap();
        let s = Sampler::new(texel_texture::SamplerDescriptor::default()).unwrap();
        for (w, h) in [(0, 5), (u32::MAX, u32::MAX), (16384, 16384)] {
            assert!(matches!(
                warp_perspective(&tex, &s, quad(), w, h),
                Err(WarpError::InvalidSize { .. })
            ));
        }
    }

    #[test]
    fn bad_corners_are_errors() {
        let mut q = quad();
        q.swap(1, 2); // self-intersecting bow tie
        assert_eq!(SquareToQuad::new(q), Err(WarpError::NotConvex));
        let line = [
            DVec2::ZERO,
            DVec2::X,
            DVec2::new(2.0, 0.0),
            DVec2::new(3.0, 0.0),
        ];
        assert_eq!(SquareToQuad::new(line), Err(WarpError::NotConvex));
        let mut q = quad();
        q[3].x = f64::NAN;
        assert!(matches!(
            SquareToQuad::new(q),
            Err(WarpError::NonFinite { index: 3, .. })
        ));
    }

    fn sampler(min: texel_texture::MipmapFilterMode) -> Sampler {
        Sampler::new(texel_texture::SamplerDescriptor {
            mag_filter: texel_texture::FilterMode::Linear,
            min_filter: texel_texture::FilterMode::Linear,
            mipmap_filter: min,
            ..Default::default()
        })
        .unwrap()
    }

    #[test]
    fn identity_warp_reproduces_the_source() {
        let tex = Texture::from_fn(
            16,
            8,
            texel_texture::Format::Rgba32Float,
            &texel_texture::Limits::default(),
            |i, j| {
                [
                    i as f32 / 16.0,
                    j as f32 / 8.0,
                    ((i * j) % 5) as f32 / 5.0,
                    1.0,
                ]
            },
        )
        .unwrap();
        let corners = [
            DVec2::new(0.0, 0.0),
            DVec2::new(16.0, 0.0),
            DVec2::new(16.0, 8.0),
            DVec2::new(0.0, 8.0),
        ];
        let out = warp_perspective(
            &tex,
            &sampler(texel_texture::MipmapFilterMode::Linear),
            corners,
            16,
            8,
        )
        .unwrap();
        for j in 0..8 {
            for i in 0..16 {
                let want = tex.texel(0, i, j).unwrap();
                let got = out[(j * 16 + i) as usize];
                for c in 0..4 {
                    assert!(
                        (got[c] - want[c]).abs() < 1e-5,
                        "({i},{j}) {got:?} {want:?}"
                    );
                }
            }
        }
    }

    /// Shrinking a one-texel checkerboard 128/15 = 8.5x (off the texel grid): trilinear through the warp's footprint gives grey,
    /// a single bilinear tap per pixel (OpenCV's approach) aliases.
    #[test]
    fn shrinking_warp_does_not_alias() {
        let tex = Texture::from_fn(
            128,
            128,
            texel_texture::Format::Rgba32Float,
            &texel_texture::Limits::default(),
            |i, j| {
                let c = ((i + j) % 2) as f32;
                [c, c, c, 1.0]
            },
        )
        .unwrap();
        let corners = [
            DVec2::new(0.0, 0.0),
            DVec2::new(128.0, 0.0),
            DVec2::new(128.0, 128.0),
            DVec2::new(0.0, 128.0),
        ];
        let spread = |m| {
            let out = warp_perspective(&tex, &sampler(m), corners, 15, 15).unwrap();
            out.iter()
                .map(|p| (p[0] - 0.5).abs())
                .fold(0.0f32, f32::max)
        };
        assert!(spread(texel_texture::MipmapFilterMode::Linear) < 1e-3);
        assert!(spread(texel_texture::MipmapFilterMode::None) > 0.4);
    }
}
