//! Ripmaps: every anisotropic reduction `(W >> a) x (H >> b)` of level 0, for axis-aligned
//! anisotropic footprints.
//!
//! Formula (conventions.md; the ripmap of Larson & Shah / the "rip-map" of the lectures): image
//! `R[a][b]` is level 0 box-reduced `a` times along x and `b` times along y, so it is
//! `max(1, W >> a) x max(1, H >> b)`, `a` in `0..=floor(log2 W)`, `b` in `0..=floor(log2 H)`. The
//! footprint's parallelogram (`uv +- Px/2 +- Py/2`, texels of level 0) has the axis-aligned bounding
//! box `bx = |Px.x| + |Py.x|` by `by = |Px.y| + |Py.y|`; then
//!
//! ```text
//! lod_x = clamp(log2(bx) + lod_bias, lod_min_clamp, lod_max_clamp), likewise lod_y
//! a = floor(lod_x), b = floor(lod_y), s = fract(lod_x), t = fract(lod_y)
//! c = bilerp(bilinear(R[a][b]), bilinear(R[a+1][b]), bilinear(R[a][b+1]), bilinear(R[a+1][b+1]); s, t)
//! ```
//!
//! (the last image along an axis holds). An isotropic axis-aligned footprint picks `a = b`, the lod
//! of trilinear; an axis-aligned anisotropic one keeps the short axis sharp. A footprint at
//! 45 degrees has a square bounding box as long as its major axis: the ripmap then blurs like
//! isotropic trilinear (it never aliases, since the box always contains the footprint).
//!
//! Decisions:
//! - Storage in the texture's own format (8-bit sRGB/linear or `f32`), as the pyramid, so an 8-bit
//!   ripmap costs 4 bytes per texel. Image `(0, 0)` is level 0 and is not duplicated, so the ripmap
//!   stores `(sum_a w_a)(sum_b h_b) - W H ~ 3 W H` texels (4x with level 0; the pyramid's diagonal
//!   images are stored again because their separable reduction is quantised differently).
//! - Reductions use the pyramid's exact box taps (odd sizes with fractional weights), in linear
//!   `f32` from the previous unquantised image, x first, then each column chain along y.
//! - Built on first use (a `OnceLock` in the [`Texture`]) or by [`Texture::build_structures`]; the size is
//!   checked against the texture's [`crate::Limits`] first (pyramid + other structures + ripmap +
//!   `f32` build scratch of `40 W H` bytes). Over the limit, sampling falls back to trilinear.
//! - Reads: up to four bilinear lookups, at most 16 texels.
//!
//! The build of a 2048x2048 sRGB ripmap is dominated by sRGB-encoding its 12.6 M texels (three
//! `powf` each), ten times the pyramid's. Memory, build time, throughput and texels read per sample
//! (2048x2048, `benches/aniso.rs`) are in docs/benchmarks.md.

use glam::Vec4;
use rayon::prelude::*;

use crate::base::color::{linear_to_srgb8, unorm8};
use crate::base::error::TextureError;
use crate::base::footprint::{lod_from_rho, Query};
use crate::base::lerp::lerp;
use crate::kernel::bilinear::bilinear;
use crate::storage::fetch::Fetch;
use crate::storage::pyramid::{axis_taps, level_count};
use crate::storage::tables::Ripmap;
use crate::storage::texture::decode_rgba8;
use crate::storage::texture::{Format, LevelInfo, Storage, Texture};
use crate::storage::view::{with_pyramid, Pyramid};
use crate::technique::mip::linear_levels;
use crate::technique::Params;

impl Texture {
    /// The texture's ripmap, built from level 0 on first call (thread-safe, once).
    ///
    /// # Errors
    /// [`TextureError::StructureOverMemoryLimit`] if it does not fit the texture's limits (the
    /// failure is remembered; later calls return the same error without retrying).
    pub fn ripmap(&self) -> Result<&Ripmap, TextureError> {
        let r = self.ripmap.get_or_init(|| Ripmap::build_within(self));
        r.as_ref().map_err(|&bytes| over_limit(self, bytes))
    }
}

/// Sum over `k` of `max(1, n >> k)` for the `floor(log2 n) + 1` reductions of an axis.
fn axis_total(n: u32) -> u64 {
    (0..level_count(n, 1))
        .map(|k| u64::from((n >> k).max(1)))
        .sum()
}

/// `f32` scratch bytes per level-0 texel while building (decoded level 0, an x-reduced image and a
/// y chain): 2.5 images of 16 bytes.
pub(crate) const SCRATCH_BYTES_PER_TEXEL: u64 = 40;

impl Ripmap {
    /// Texels a ripmap of a `width x height` texture stores (excluding image `(0, 0)`, which is
    /// level 0): `(sum_a w_a)(sum_b h_b) - W H`.
    pub fn texels_for(width: u32, height: u32) -> u64 {
        axis_total(width) * axis_total(height) - u64::from(width) * u64::from(height)
    }

    /// Bytes of the ripmap of a `width x height` texture stored in `format`; `None` on overflow.
    /// For 2048x2048 RGBA8: 50,307,076 bytes (3 x level 0).
    pub fn bytes_for(width: u32, height: u32, format: Format) -> Option<u64> {
        Self::texels_for(width, height).checked_mul(format.texel_bytes())
    }

    /// Build the ripmap of `texture` from its level 0.
    ///
    /// # Errors
    /// [`TextureError::StructureOverMemoryLimit`] if the texture's pyramid, its other built
    /// structures, the ripmap and the build scratch together exceed the texture's
    /// [`crate::Limits::max_bytes`].
    pub fn build(texture: &Texture) -> Result<Ripmap, TextureError> {
        Self::build_within(texture).map_err(|bytes| over_limit(texture, bytes))
    }

    /// [`Ripmap::build`], or `Err(bytes)` with the bytes it would need in all (what
    /// [`Texture::ripmap`] remembers).
    pub(crate) fn build_within(texture: &Texture) -> Result<Ripmap, u64> {
        check(texture)?;
        Ok(with_pyramid!(texture, |p| build_from(texture, &p.level(0))))
    }

    /// Number of reductions along x and along y (`floor(log2 W) + 1`, `floor(log2 H) + 1`).
    pub fn counts(&self) -> (usize, usize) {
        (self.nx, self.ny)
    }

    /// Size of image `(a, b)`: `(max(1, W >> a), max(1, H >> b))`; `None` out of range.
    pub fn image_size(&self, a: usize, b: usize) -> Option<(u32, u32)> {
        (a < self.nx && b < self.ny).then(|| {
            let info = &self.infos[a * self.ny + b];
            (info.width, info.height)
        })
    }

    /// Texel `(i, j)` of image `(a, b)` in linear RGBA; `None` out of range and for image `(0, 0)`,
    /// which is the texture's level 0 ([`Texture::texel`]).
    pub fn texel(&self, a: usize, b: usize, i: u32, j: u32) -> Option<[f32; 4]> {
        let (w, h) = self.image_size(a, b)?;
        if (a, b) == (0, 0) || i >= w || j >= h {
            return None;
        }
        let info = &self.infos[a * self.ny + b];
        let idx = info.offset + j as usize * w as usize + i as usize;
        Some(match &self.storage {
            // Decode as the pyramid does.
            Storage::U8(v) => decode_rgba8(v[idx], self.srgb),
            Storage::F32(v) => v[idx],
        })
    }
}

/// `Err(bytes)` if adding the ripmap (and its build scratch) to `texture` would exceed its limits.
fn check(texture: &Texture) -> Result<(), u64> {
    let (w, h) = (texture.width(), texture.height());
    let scratch = (u64::from(w) * u64::from(h)).saturating_mul(SCRATCH_BYTES_PER_TEXEL);
    texture.structure_budget(Ripmap::bytes_for(w, h, texture.format()), scratch)
}

pub(crate) fn over_limit(texture: &Texture, bytes: u64) -> TextureError {
    texture.over_budget("ripmap", bytes)
}

/// Reduce a `w x h` image by 2 along x (exact box taps); rows in parallel.
fn reduce_x(src: &[Vec4], w: u32, h: u32) -> (Vec<Vec4>, u32) {
    let dw = (w / 2).max(1);
    let taps = axis_taps(w, dw);
    let mut out = vec![Vec4::ZERO; dw as usize * h as usize];
    out.par_chunks_mut(dw as usize)
        .zip(src.par_chunks(w as usize))
        .for_each(|(dst, row)| {
            for (d, (first, wts)) in dst.iter_mut().zip(&taps) {
                *d = wts
                    .iter()
                    .enumerate()
                    .map(|(k, &wt)| row[*first as usize + k] * wt)
                    .sum();
            }
        });
    (out, dw)
}

/// Reduce a `w x h` image by 2 along y (exact box taps); destination rows in parallel.
fn reduce_y(src: &[Vec4], w: u32, h: u32) -> (Vec<Vec4>, u32) {
    let dh = (h / 2).max(1);
    let taps = axis_taps(h, dh);
    let w = w as usize;
    let mut out = vec![Vec4::ZERO; w * dh as usize];
    out.par_chunks_mut(w)
        .zip(taps.par_iter())
        .for_each(|(dst, (first, wts))| {
            for (k, &wt) in wts.iter().enumerate() {
                let row = &src[(*first as usize + k) * w..][..w];
                for (d, s) in dst.iter_mut().zip(row) {
                    *d += *s * wt;
                }
            }
        });
    (out, dh)
}

fn build_from<F: Fetch + Sync>(texture: &Texture, level0: &F) -> Ripmap {
    let (w, h) = (texture.width(), texture.height());
    let (nx, ny) = (level_count(w, 1) as usize, level_count(h, 1) as usize);
    let format = texture.format();
    let decoded: Vec<Vec4> = (0..h)
        .into_par_iter()
        .flat_map_iter(|j| (0..w).map(move |i| level0.texel(i, j)))
        .collect();
    let total = Ripmap::texels_for(w, h) as usize;
    let mut infos = Vec::with_capacity(nx * ny);
    let mut out_u8: Vec<[u8; 4]> = Vec::new();
    let mut out_f32: Vec<[f32; 4]> = Vec::new();
    match format {
        Format::Rgba32Float => out_f32.reserve_exact(total),
        _ => out_u8.reserve_exact(total),
    }
    let srgb = format == Format::Rgba8Srgb;
    // A float copy of 8-bit texels ([`Texture::to_float`]) rounds its images to the original's
    // codes, as the original's own ripmap stores them, so both sample the same values.
    let codes = match texture.source_format() {
        Format::Rgba32Float => None,
        source => Some(source == Format::Rgba8Srgb),
    };
    let texel = |c: &Vec4| match codes {
        Some(srgb) => decode_rgba8(encode_u8(*c, srgb), srgb),
        None => c.to_array(),
    };
    let mut push = |img: &[Vec4]| -> usize {
        match format {
            Format::Rgba32Float => {
                let off = out_f32.len();
                out_f32.extend(img.iter().map(texel));
                off
            }
            _ => {
                let off = out_u8.len();
                out_u8.extend(img.iter().map(|c| encode_u8(*c, srgb)));
                off
            }
        }
    };
    let mut xa = decoded;
    let mut wa = w;
    for a in 0..nx {
        if a > 0 {
            (xa, wa) = reduce_x(&xa, wa, h);
        }
        let mut img: Option<Vec<Vec4>> = None;
        let mut hb = h;
        for b in 0..ny {
            if b > 0 {
                let src = img.as_deref().unwrap_or(&xa);
                let (next, nh) = reduce_y(src, wa, hb);
                img = Some(next);
                hb = nh;
            }
            let offset = if (a, b) == (0, 0) {
                0
            } else {
                push(img.as_deref().unwrap_or(&xa))
            };
            infos.push(LevelInfo {
                width: wa,
                height: hb,
                offset,
            });
        }
    }
    let storage = match format {
        Format::Rgba32Float => Storage::F32(out_f32),
        _ => Storage::U8(out_u8),
    };
    Ripmap {
        width: w,
        height: h,
        nx,
        ny,
        infos,
        storage,
        srgb,
    }
}

fn encode_u8(c: Vec4, srgb: bool) -> [u8; 4] {
    let rgb = |x: f32| if srgb { linear_to_srgb8(x) } else { unorm8(x) };
    [rgb(c.x), rgb(c.y), rgb(c.z), unorm8(c.w)]
}

/// Ripmap filtering of query `q` (lod `> 0`) in `rip`, the ripmap of `p`'s texture: per axis,
/// the image `a = floor(l)` and the next blended by `fract(l)`, `l = log2(extent) + bias`
/// clamped ([`lod_from_rho`]), where the extents are the footprint's bounding box
/// (`|Px.x| + |Py.x|` by `|Px.y| + |Py.y|` texels of level 0); bilinear in each of the four images.
#[inline]
pub(crate) fn ripmap<P: Pyramid>(p: &P, rip: &Ripmap, s: &Params, q: &Query) -> Vec4 {
    let (d, addr, uv) = (s, s.addr, q.uv());
    let (px, py) = q.fp.texel_axes(rip.width, rip.height);
    let bx = px.x.abs() + py.x.abs();
    let by = px.y.abs() + py.y.abs();
    // The image along one axis and the weight toward the next: the linear level rule.
    let images = |extent: f32, n: usize| {
        let l = lod_from_rho(extent, d.lod_bias, d.lod_min_clamp, d.lod_max_clamp);
        linear_levels(l, n - 1)
    };
    let (a, wa) = images(bx, rip.nx);
    let (b, wb) = images(by, rip.ny);
    let sample = |a: usize, b: usize| {
        if (a, b) == (0, 0) {
            bilinear(&p.level(0), &addr, uv)
        } else {
            let view = p.image(&rip.infos[a * rip.ny + b], &rip.storage);
            bilinear(&view, &addr, uv)
        }
    };
    let row = |b: usize| {
        let c = sample(a, b);
        if wa > 0.0 && a + 1 < rip.nx {
            lerp(c, sample(a + 1, b), wa)
        } else {
            c
        }
    };
    let top = row(b);
    if wb > 0.0 && b + 1 < rip.ny {
        lerp(top, row(b + 1), wb)
    } else {
        top
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::storage::texture::Limits;

    #[test]
    fn sizes_and_memory() {
        assert_eq!(Ripmap::texels_for(4, 4), 7 * 7 - 16);
        assert_eq!(Ripmap::texels_for(1, 1), 0);
        assert_eq!(Ripmap::texels_for(5, 3), (5 + 2 + 1) * (3 + 1) - 15);
        assert_eq!(
            Ripmap::bytes_for(2048, 2048, Format::Rgba8Unorm),
            Some(4095 * 4095 * 4 - 2048 * 2048 * 4)
        );
    }

    #[test]
    fn images_are_exact_box_reductions() {
        let f = |i: u32, j: u32| [(i * 7 + j * 3) as f32 / 64.0, j as f32 / 5.0, 0.25, 1.0];
        let tex = Texture::from_fn(6, 5, Format::Rgba32Float, &Limits::default(), f).unwrap();
        let rip = tex.ripmap().unwrap();
        assert_eq!(rip.counts(), (3, 3));
        assert_eq!(rip.image_size(1, 2), Some((3, 1)));
        // (1, 0): pairs of columns averaged.
        for j in 0..5 {
            for i in 0..3 {
                let want = (f(2 * i, j)[0] + f(2 * i + 1, j)[0]) / 2.0;
                assert!((rip.texel(1, 0, i, j).unwrap()[0] - want).abs() < 1e-6);
            }
        }
        // (0, 2): 5 rows -> 2 -> 1, the mean of each column.
        for i in 0..6 {
            let want: f32 = (0..5).map(|j| f(i, j)[1]).sum::<f32>() / 5.0;
            assert!((rip.texel(0, 2, i, 0).unwrap()[1] - want).abs() < 1e-6);
        }
        assert_eq!(rip.texel(0, 0, 0, 0), None);
        assert_eq!(rip.bytes(), Ripmap::texels_for(6, 5) * 16);
    }

    #[test]
    fn over_the_limit_is_an_error_not_an_allocation() {
        let limits = Limits {
            max_dimension: 16384,
            max_bytes: 64 * 1024,
        };
        let tex = Texture::from_fn(64, 64, Format::Rgba8Unorm, &limits, |_, _| [0.5; 4]).unwrap();
        assert!(matches!(
            tex.ripmap(),
            Err(TextureError::StructureOverMemoryLimit { .. })
        ));
        assert!(tex.ripmap().is_err(), "the failure is remembered");
    }
}
