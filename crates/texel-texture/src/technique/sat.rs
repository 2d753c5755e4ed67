//! Summed-area tables (Crow 1984, "Summed-Area Tables for Texture Mapping", SIGGRAPH '84): the box
//! mean over the footprint's axis-aligned bounding rectangle, with fractional edges and exact
//! wrapping.
//!
//! Table: `S(i, j) = sum_{i' < i, j' < j} T(i', j')` for `0 <= i <= W`, `0 <= j <= H` (a zero first
//! row and column), per channel, of level 0 decoded to linear light. The texture is piecewise
//! constant (texel `(i, j)` covers `[i, i+1) x [j, j+1)`), so its integral over `[0, x) x [0, y)`
//! for real `x`, `y` is exactly the bilinear interpolation of `S` at `(x, y)` (Crow sec. 3; up to
//! four entries, one when both are integers). A box `[x0, x1) x [y0, y1)` then sums to
//! `I(x1, y1) - I(x0, y1) - I(x1, y0) + I(x0, y0)` of the address-mode extension's integral `I`.
//!
//! Address modes, exactly (conventions): per axis, the integral of the extended texture from 0 to
//! `x` is a short combination of `P(p) = integral of the texture from 0 to p`, `p` in `[0, n]`:
//! - Repeat: `x = q n + r` gives `q P(n) + P(r)` (whole periods counted, the box split at the edge);
//! - MirrorRepeat: period `2 n`, `x = 2 q n + r`: `2 q P(n) + P(r)` for `r <= n`, else
//!   `(2 q + 2) P(n) - P(2 n - r)`;
//! - ClampToEdge (edges extended): `x P(1)` for `x < 0`, `P(n) + (x - n)(P(n) - P(n - 1))` for
//!   `x > n`; MirrorClampToEdge: `sign(x)` times that of `|x|`;
//! - ClampToBorder: `P(clamp(x, 0, n))`, plus the border colour times the area outside.
//!
//! The two axes combine as a product of these combinations (Fubini), so any mix of modes is exact.
//! Before evaluating, a periodic axis's box is shifted by whole periods to start in the first
//! period, so far-away boxes lose no precision to `q P(n)` terms.
//!
//! Filter: the footprint's parallelogram (`uv +- Px/2 +- Py/2`) has the bounding box
//! `bx = |Px.x| + |Py.x|` by `by = |Px.y| + |Py.y|` texels of level 0; the box side is
//! `2^clamp(log2(bx) + lod_bias, lod_min_clamp, min(lod_max_clamp, 40))`, which is at least one
//! texel (`lod_min_clamp >= 0`): a thinner box would point-sample the blocky box reconstruction.
//! A footprint at 45 degrees gets a square box as long as its major axis (blur, never alias).
//!
//! Precision (why `f64`, not `u64`): entries reach `W H max|T| <= 2^28` for 8-bit data at 16384^2,
//! which `f64` holds with an absolute error of `2^28 * 2^-53 = 3e-8`, so the mean of a one-texel
//! box is off by at most about `1e-7`, far below 8-bit resolution (`4e-3`). `u64` would be exact
//! for linear 8-bit codes but cannot hold sRGB-decoded or `f32` (HDR, negative) texels without a
//! fixed-point scale that loses either range or resolution. The cost is 32 bytes per texel
//! (4 channels x 8 bytes): 134 MB for 2048^2, 8.6 GB for 16384^2 (over the default 4 GiB limit:
//! [`crate::TextureError::StructureOverMemoryLimit`], and sampling falls back to trilinear).
//!
//! Reads (counted as "texels read"): table entries, 4 per evaluated corner (fewer on integer
//! edges); a box inside the texture evaluates 4 corners, 16 entries, and a box crossing the
//! texture's edge is split, so it reads more.
//!
//! Memory, build time, throughput and entries read per sample (2048x2048, `benches/aniso.rs`) are
//! in docs/benchmarks.md.

use glam::Vec4;
use rayon::prelude::*;

use crate::base::address::{Address, AddressMode};
use crate::base::error::TextureError;
use crate::base::footprint::{lod_from_rho, Query};
use crate::storage::fetch::Fetch;
use crate::storage::tables::SummedAreaTable;
use crate::storage::texture::Texture;
use crate::storage::view::{with_pyramid, Pyramid};
use crate::technique::Params;

/// Boxes narrower than this (texels) are widened to it, centred: the mean of a vanishing box is
/// the texel under it, and `f64` cancellation makes narrower boxes meaningless.
pub const MIN_BOX_WIDTH: f64 = 1e-3;

/// Largest box side used by the filter, as a log2 (`2^40` texels): keeps products finite.
const MAX_LOD: f32 = 40.0;

impl Texture {
    /// The texture's summed-area table, built from level 0 on first call (thread-safe, once).
    ///
    /// # Errors
    /// As [`Texture::ripmap`].
    pub fn summed_area_table(&self) -> Result<&SummedAreaTable, TextureError> {
        let r = self.sat.get_or_init(|| SummedAreaTable::build_within(self));
        r.as_ref().map_err(|&bytes| over_limit(self, bytes))
    }
}

/// Up to six `(coefficient, position)` terms of one axis.
#[derive(Clone, Copy)]
struct Terms {
    items: [(f64, f64); 6],
    len: usize,
    /// Length of the box inside `[0, n]` (ClampToBorder) or the whole length.
    inside: f64,
}

impl Terms {
    fn push(&mut self, coef: f64, pos: f64) {
        if coef != 0.0 && pos != 0.0 && self.len < self.items.len() {
            self.items[self.len] = (coef, pos);
            self.len += 1;
        }
    }

    fn as_slice(&self) -> &[(f64, f64)] {
        &self.items[..self.len]
    }
}

/// Terms of `sign * integral_0^x` of a clamp-to-edge extension, `n >= 1`.
fn clamp_terms(t: &mut Terms, n: f64, x: f64, sign: f64) {
    if x < 0.0 {
        t.push(sign * x, 1.0);
    } else if x > n {
        t.push(sign, n);
        t.push(sign * (x - n), n);
        t.push(-sign * (x - n), n - 1.0);
    } else {
        t.push(sign, x);
    }
}

/// Terms of `sign * integral_0^x` of the `mode` extension of an axis of `n` texels
/// (`extension = (mode, n)`).
fn prefix_terms(t: &mut Terms, (mode, n): (AddressMode, f64), x: f64, sign: f64) {
    match mode {
        AddressMode::Repeat => {
            let q = (x / n).floor();
            let r = (x - q * n).clamp(0.0, n);
            t.push(sign * q, n);
            t.push(sign, r);
        }
        AddressMode::MirrorRepeat => {
            let p = 2.0 * n;
            let q = (x / p).floor();
            let r = (x - q * p).clamp(0.0, p);
            if r <= n {
                t.push(sign * 2.0 * q, n);
                t.push(sign, r);
            } else {
                t.push(sign * (2.0 * q + 2.0), n);
                t.push(-sign, p - r);
            }
        }
        AddressMode::ClampToEdge => clamp_terms(t, n, x, sign),
        AddressMode::MirrorClampToEdge => {
            if x >= 0.0 {
                clamp_terms(t, n, x, sign);
            } else {
                clamp_terms(t, n, -x, -sign);
            }
        }
        AddressMode::ClampToBorder => t.push(sign, x.clamp(0.0, n)),
    }
}

/// The terms of `integral_{x0}^{x1}` along one axis (`x1 > x0`).
fn axis_terms(mode: AddressMode, n: u32, mut x0: f64, mut x1: f64) -> Terms {
    let n = f64::from(n);
    let period = match mode {
        AddressMode::Repeat => n,
        AddressMode::MirrorRepeat => 2.0 * n,
        _ => 0.0,
    };
    if period > 0.0 {
        let shift = (x0 / period).floor() * period;
        if shift.is_finite() {
            x0 -= shift;
            x1 -= shift;
        }
    }
    // Beyond the edge the clamped extensions are constant along the axis, so a box lying wholly
    // there has the mean of the same box moved to the edge. Moving it keeps the prefix terms
    // small: far out (x ~ 1e8, found by fuzzing) their products cancelled to garbage in f64.
    if mode == AddressMode::MirrorClampToEdge && x1 <= 0.0 {
        (x0, x1) = (-x1, -x0);
    }
    if matches!(
        mode,
        AddressMode::ClampToEdge | AddressMode::MirrorClampToEdge
    ) {
        if x0 > n {
            x1 -= x0 - n;
            x0 = n;
        } else if x1 < 0.0 {
            x0 -= x1;
            x1 = 0.0;
        }
    }
    let mut t = Terms {
        items: [(0.0, 0.0); 6],
        len: 0,
        inside: x1 - x0,
    };
    if mode == AddressMode::ClampToBorder {
        t.inside = x1.clamp(0.0, n) - x0.clamp(0.0, n);
    }
    prefix_terms(&mut t, (mode, n), x1, 1.0);
    prefix_terms(&mut t, (mode, n), x0, -1.0);
    t
}

impl SummedAreaTable {
    /// Bytes of the table of a `width x height` texture: `(W + 1)(H + 1) * 32`; `None` on overflow.
    /// For 2048x2048: 134,348,832 bytes.
    pub fn bytes_for(width: u32, height: u32) -> Option<u64> {
        (u64::from(width) + 1)
            .checked_mul(u64::from(height) + 1)?
            .checked_mul(32)
    }

    /// Build the table of `texture`'s level 0.
    ///
    /// # Errors
    /// [`TextureError::StructureOverMemoryLimit`] if the texture's pyramid, its other built
    /// structures and the table together exceed the texture's [`crate::Limits::max_bytes`].
    pub fn build(texture: &Texture) -> Result<SummedAreaTable, TextureError> {
        Self::build_within(texture).map_err(|bytes| over_limit(texture, bytes))
    }

    /// [`SummedAreaTable::build`], or `Err(bytes)` with the bytes it would need in all (what
    /// [`Texture::summed_area_table`] remembers).
    pub(crate) fn build_within(texture: &Texture) -> Result<SummedAreaTable, u64> {
        check(texture)?;
        Ok(with_pyramid!(texture, |p| build_from(&p.level(0))))
    }

    /// Width of the summed texture (level 0) in texels.
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Height of the summed texture (level 0) in texels.
    pub fn height(&self) -> u32 {
        self.height
    }

    /// Entry `S(i, j)`: the sum of texels `[0, i) x [0, j)`; `None` for `i > W` or `j > H`.
    pub fn entry(&self, i: u32, j: u32) -> Option<[f64; 4]> {
        (i <= self.width && j <= self.height).then(|| self.at(i as usize, j as usize))
    }

    #[inline(always)]
    fn at(&self, i: usize, j: usize) -> [f64; 4] {
        self.table[j * (self.width as usize + 1) + i]
    }

    /// Integral of the texture over `[0, x) x [0, y)`, `x` in `[0, W]`, `y` in `[0, H]` (clamped):
    /// bilinear interpolation of the table; adds the entries read to `reads`.
    #[inline]
    fn integral(&self, x: f64, y: f64, reads: &mut u32) -> [f64; 4] {
        let (w, h) = (self.width as usize, self.height as usize);
        let x = x.clamp(0.0, w as f64);
        let y = y.clamp(0.0, h as f64);
        let i = (x.floor() as usize).min(w - 1);
        let j = (y.floor() as usize).min(h - 1);
        let (fx, fy) = (x - i as f64, y - j as f64);
        let mut acc = [0.0f64; 4];
        let mut add = |ii: usize, jj: usize, wt: f64| {
            if wt != 0.0 {
                *reads += 1;
                let e = self.at(ii, jj);
                for c in 0..4 {
                    acc[c] += e[c] * wt;
                }
            }
        };
        add(i, j, (1.0 - fx) * (1.0 - fy));
        add(i + 1, j, fx * (1.0 - fy));
        add(i, j + 1, (1.0 - fx) * fy);
        add(i + 1, j + 1, fx * fy);
        acc
    }

    /// Mean of the texture (linear RGBA) over the box `[x0, x1) x [y0, y1)` (`x = [x0, x1]`,
    /// `y = [y0, y1]`) in continuous texel coordinates of level 0 (`xy = uv * (W, H)`), outside the
    /// texture extended by `addr` exactly as the samplers' address modes extend it (its border
    /// colour under ClampToBorder).
    ///
    /// The corners may come in either order; a side narrower than [`MIN_BOX_WIDTH`] is widened to
    /// it about its centre. Non-finite coordinates give NaN (no panic). Example: on a 4x1 texture
    /// `[0, 1, 2, 3]` with Repeat, the box `[3.5, 5)` (half of texel 3, then texel 0) has mean
    /// `(0.5 * 3 + 0) / 1.5 = 1`.
    pub fn box_mean(&self, x: [f64; 2], y: [f64; 2], addr: &Address) -> [f64; 4] {
        self.box_mean_counted(x, y, addr).0
    }

    /// [`SummedAreaTable::box_mean`] and the number of table entries it read.
    pub(crate) fn box_mean_counted(
        &self,
        [x0, x1]: [f64; 2],
        [y0, y1]: [f64; 2],
        addr: &Address,
    ) -> ([f64; 4], u32) {
        let mut reads = 0;
        let widen = |a: f64, b: f64| {
            let (lo, hi) = if a <= b { (a, b) } else { (b, a) };
            if hi - lo >= MIN_BOX_WIDTH {
                (lo, hi)
            } else {
                let mid = 0.5 * (lo + hi);
                (mid - 0.5 * MIN_BOX_WIDTH, mid + 0.5 * MIN_BOX_WIDTH)
            }
        };
        let (x0, x1) = widen(x0, x1);
        let (y0, y1) = widen(y0, y1);
        if !(x0.is_finite() && x1.is_finite() && y0.is_finite() && y1.is_finite()) {
            return ([f64::NAN; 4], reads);
        }
        let tx = axis_terms(addr.u, self.width, x0, x1);
        let ty = axis_terms(addr.v, self.height, y0, y1);
        let mut sum = [0.0f64; 4];
        for &(cy, py) in ty.as_slice() {
            for &(cx, px) in tx.as_slice() {
                let v = self.integral(px, py, &mut reads);
                for c in 0..4 {
                    sum[c] += cx * cy * v[c];
                }
            }
        }
        let area = (x1 - x0) * (y1 - y0);
        let outside = area - tx.inside * ty.inside;
        if outside > 0.0 {
            let border = addr.border.to_array().map(f64::from);
            for c in 0..4 {
                sum[c] += border[c] * outside;
            }
        }
        (sum.map(|s| s / area), reads)
    }
}

/// `Err(bytes)` if adding the table to `texture` would exceed its limits.
fn check(texture: &Texture) -> Result<(), u64> {
    texture.structure_budget(
        SummedAreaTable::bytes_for(texture.width(), texture.height()),
        0,
    )
}

pub(crate) fn over_limit(texture: &Texture, bytes: u64) -> TextureError {
    texture.over_budget("summed-area table", bytes)
}

fn build_from<F: Fetch + Sync>(level0: &F) -> SummedAreaTable {
    let (w, h) = level0.size();
    let stride = w as usize + 1;
    let mut table = vec![[0.0f64; 4]; stride * (h as usize + 1)];
    // Row prefix sums in parallel (row j + 1 of the table holds texel row j)...
    table[stride..]
        .par_chunks_mut(stride)
        .enumerate()
        .for_each(|(j, row)| {
            let mut acc = [0.0f64; 4];
            for i in 0..w as usize {
                let t = level0.texel(i as u32, j as u32).to_array();
                for c in 0..4 {
                    acc[c] += f64::from(t[c]);
                }
                row[i + 1] = acc;
            }
        });
    // ...then the running sum down the columns.
    for j in 1..=h as usize {
        let (above, rest) = table.split_at_mut(j * stride);
        let prev = &above[(j - 1) * stride..];
        for (e, p) in rest[..stride].iter_mut().zip(prev) {
            for c in 0..4 {
                e[c] += p[c];
            }
        }
    }
    SummedAreaTable {
        width: w,
        height: h,
        table,
    }
}

/// Summed-area filtering of query `q` (lod `> 0`) with `t`, the table of `p`'s texture: the box
/// mean over the footprint's bounding box (`|Px.x| + |Py.x|` by `|Px.y| + |Py.y|` texels of level
/// 0), each side `2^clamp(log2(extent) + bias)` texels, centred on `uv`.
#[inline]
pub(crate) fn summed_area<P: Pyramid>(p: &P, t: &SummedAreaTable, s: &Params, q: &Query) -> Vec4 {
    let (d, addr) = (s, s.addr);
    let (px, py) = q.fp.texel_axes(t.width, t.height);
    let side = |extent: f32| {
        let l = lod_from_rho(extent, d.lod_bias, d.lod_min_clamp, d.lod_max_clamp);
        f64::from(l.clamp(0.0, MAX_LOD)).exp2()
    };
    let sx = side(px.x.abs() + py.x.abs());
    let sy = side(px.y.abs() + py.y.abs());
    let x = f64::from(q.fp.u) * f64::from(t.width);
    let y = f64::from(q.fp.v) * f64::from(t.height);
    let (m, reads) = t.box_mean_counted(
        [x - 0.5 * sx, x + 0.5 * sx],
        [y - 0.5 * sy, y + 0.5 * sy],
        &addr,
    );
    p.note_reads(reads);
    Vec4::from_array(m.map(|c| c as f32))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::base::address::BorderColor;
    use crate::storage::texture::{Format, Limits};

    fn ramp4() -> Texture {
        Texture::from_fn(4, 1, Format::Rgba32Float, &Limits::default(), |i, _| {
            [i as f32, 0.0, 0.0, 1.0]
        })
        .unwrap()
    }

    #[test]
    fn documented_example_and_table() {
        let tex = ramp4();
        let t = tex.summed_area_table().unwrap();
        assert_eq!(t.entry(4, 1).unwrap()[0], 6.0);
        assert_eq!(t.entry(2, 1).unwrap()[0], 1.0);
        assert_eq!(t.entry(3, 0).unwrap()[0], 0.0);
        assert_eq!(t.entry(5, 1), None);
        let m = t.box_mean(
            [3.5, 5.0],
            [0.0, 1.0],
            &Address::new(
                AddressMode::Repeat,
                AddressMode::Repeat,
                BorderColor::TransparentBlack,
            ),
        );
        assert!((m[0] - 1.0).abs() < 1e-12);
    }

    /// One-axis table: (mode, x0, x1, expected mean) on the ramp [0, 1, 2, 3].
    #[test]
    fn address_mode_table() {
        use AddressMode::*;
        let tex = ramp4();
        let t = tex.summed_area_table().unwrap();
        let cases: &[(AddressMode, f64, f64, f64)] = &[
            (Repeat, 0.0, 4.0, 1.5),
            (Repeat, -1.0, 1.0, 1.5), // texels 3, 0
            (Repeat, 4.0 * 1e6, 4.0 * 1e6 + 1.0, 0.0),
            (Repeat, -10.0, 10.0, 1.5), // five whole periods
            (Repeat, -10.0, 11.0, (1.5 * 20.0 + 2.0) / 21.0),
            (MirrorRepeat, 4.0, 5.0, 3.0), // mirrored: texel 3 again
            (MirrorRepeat, 4.0, 8.0, 1.5),
            (MirrorRepeat, -1.0, 0.0, 0.0),
            (ClampToEdge, -2.0, 0.0, 0.0),
            (ClampToEdge, 4.0, 6.0, 3.0),
            (ClampToEdge, 3.0, 6.0, 3.0),
            (ClampToEdge, -1.0, 1.0, 0.0),
            (ClampToBorder, -2.0, 2.0, 0.25), // (0 + 1) / 4, border 0
            (MirrorClampToEdge, -2.0, 0.0, 0.5), // texels 1, 0
            (MirrorClampToEdge, -6.0, -4.0, 3.0),
            (Repeat, 1.25, 1.75, 1.0),
        ];
        for &(mode, x0, x1, want) in cases {
            let m = t.box_mean(
                [x0, x1],
                [0.0, 1.0],
                &Address::new(mode, Repeat, BorderColor::TransparentBlack),
            );
            assert!(
                (m[0] - want).abs() < 1e-9,
                "{mode:?} [{x0}, {x1}): {} != {want}",
                m[0]
            );
        }
        // ClampToBorder with an opaque white border: alpha stays 1, red picks up the border.
        let m = t.box_mean(
            [-2.0, 2.0],
            [0.0, 1.0],
            &Address::new(ClampToBorder, Repeat, BorderColor::OpaqueWhite),
        );
        assert!((m[0] - (1.0 + 2.0) / 4.0).abs() < 1e-12 && (m[3] - 1.0).abs() < 1e-12);
    }

    #[test]
    fn degenerate_boxes_do_not_panic() {
        let tex = ramp4();
        let t = tex.summed_area_table().unwrap();
        let r = AddressMode::Repeat;
        let b = BorderColor::TransparentBlack;
        let m = t.box_mean([2.5, 2.5], [0.5, 0.5], &Address::new(r, r, b));
        assert!((m[0] - 2.0).abs() < 1e-6);
        assert!(t.box_mean([f64::NAN, 1.0], [0.0, 1.0], &Address::new(r, r, b))[0].is_nan());
        assert!(t.box_mean([0.0, f64::INFINITY], [0.0, 1.0], &Address::new(r, r, b))[0].is_nan());
        let m = t.box_mean([-1e15, 1e15], [0.0, 1.0], &Address::new(r, r, b));
        assert!((m[0] - 1.5).abs() < 1e-6);
        for mode in [AddressMode::ClampToEdge, AddressMode::ClampToBorder] {
            assert!(
                t.box_mean([-1e12, 1e12], [-1e12, 1e12], &Address::new(mode, mode, b))[0]
                    .is_finite()
            );
            // Overflowing areas may give NaN, but never panic.
            let _ = t.box_mean(
                [-1e300, 1e300],
                [-1e300, 1e300],
                &Address::new(mode, mode, b),
            );
        }
    }
}
