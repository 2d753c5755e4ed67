//! The exact reference: each unlit textured pixel's box-filtered integral computed, not sampled.
//!
//! What the sampled reference ([`crate::reference`]) estimates is, for pixel `(i, j)`, the mean
//! over the square `[i, i + 1] x [j, j + 1]` of the visible surface's colour: for an unlit draw
//! with interpolated `uv`, the bilinear reconstruction of the texture's level 0 at the
//! perspective-correct `uv`, times the draw's constant colour (its material's base colour and a
//! vertex colour shared by the triangle's three vertices). This module computes that mean.
//!
//! **Geometry.** The pixel square is clipped (Sutherland-Hodgman) against each triangle's three
//! edges, taken exactly from the rasterizer's snapped fixed-point edge functions, giving a convex
//! polygon per triangle. Where two polygons overlap, the one whose depth plane is nearer at every
//! vertex of their intersection hides the other there, and the hidden one's integral loses the
//! intersection's (inclusion-exclusion; the polygons hiding one triangle must not overlap one
//! another). What no polygon covers is the background colour. A pixel falls back to sampling when
//! a triangle that reaches it is lit, sphere-mapped or vertex-coloured across its vertices, when
//! two triangles interpenetrate inside it or three layers overlap, with an environment as the
//! background where the background shows, and where its preimage reaches beyond
//! [`MAX_COORDINATE`] texels or its boundary would be cut at more than [`MAX_CUTS`] knots.
//!
//! **The integral over one polygon.** The map from screen to texel coordinates `q = (s, t)`
//! (`s = u W - 1/2`, so texel `i`'s centre sits at `s = i`) is projective, `q = G (x, y, 1)` up to
//! scale, so the polygon's preimage `P` is a convex polygon too, and
//! `integral_pixel f(q(x, y)) dx dy = integral_P f(q) J(q) dq` with `J = |det H| / Z(q)^3`, where
//! `H = G^-1` and `Z(q) = H_2 . (s, t, 1)` is affine (it is the clip-space `w`). The polygon is cut
//! along lines of constant `w` (lines in screen space) into pieces over which `Z` varies by at
//! most [`PIECE_RATIO`]; on a piece `J` is its Taylor polynomial in `e = (Z - Z_c) / Z_c` of degree
//! at most 3, `J = |det H| / Z_c^3 sum_m (-1)^m (m + 1)(m + 2)/2 e^m`, whose remainder is below
//! [`WEIGHT_BOUND`] of `J`, so a weight polynomial `sum A_kl (s - s_c)^k (t - t_c)^l`.
//!
//! The bilinear reconstruction is `f(s, t) = (1 - b) g_j(s) + b g_(j+1)(s)` in the row band
//! `j <= t < j + 1` (`b = t - j`), with `g_j` the piecewise-linear interpolation of row `j`'s
//! texels, knots at integer `s`, indices wrapped by the address modes. So, band by band,
//! `integral_P f w = integral dt sum_kl A_kl (t - t_c)^l [(1 - b) R_j,k + b R_(j+1),k]` with
//! `R_j,k = integral_(s_L(t))^(s_R(t)) g_j(s) (s - s_c)^k ds` between the polygon's left and right
//! boundaries. Each row keeps the prefix sums of `integral g_j(s) s^m ds` at its knots (the moments
//! of the summed-area tables of Crow 1984, repeated integration after Heckbert 1986), over one
//! period for Repeat and MirrorRepeat (whole periods are counted with closed-form power sums) and
//! over the stretch where the other modes vary (constant outside), so `R` costs the same however
//! many texels the span covers. The `t` range is split at the polygon's vertices, at band edges
//! and where `s_L` or `s_R` crosses a knot; on each part the integrand is a polynomial of degree
//! at most 6 in `t`, integrated exactly by 4-point Gauss-Legendre quadrature. The cost grows with
//! the number of texel rows and columns the polygon's boundary crosses, not with its area.
//!
//! **Accuracy.** The weight's truncation bounds the relative error by [`WEIGHT_BOUND`]; the rest is
//! `f64` rounding. An exact pixel's stated accuracy is `WEIGHT_BOUND` times its value plus
//! [`ROUNDING_BOUND`], carried to the display.

use glam::{DMat3, DVec2, DVec3, Vec4};
use rayon::prelude::*;
use texel_texture::{AddressMode, Texture};

use crate::draw::DrawCall;
use crate::error::RasterError;
use crate::reference::Progress;
use crate::settings::RenderSettings;
use crate::setup::{setup_draws, Edge, TriangleSetup, SUBPIXEL};
use crate::tile::{bin, tile_counts, TILE};

/// Largest ratio of `w` across one piece of a polygon: `e` stays within `+-(PIECE_RATIO - 1)`.
pub const PIECE_RATIO: f64 = 1.015;

/// Bound on the relative error of the weight polynomial over a piece (the Taylor remainder at
/// `|e| <= PIECE_RATIO - 1` and degree 3).
pub const WEIGHT_BOUND: f64 = 1e-6;

/// Bound on an exact pixel's absolute rounding error in linear units (`f64` arithmetic over
/// coordinates of at most a few million texels).
pub const ROUNDING_BOUND: f64 = 1e-9;

/// Most bytes of row tables an exact reference builds; textures beyond it are sampled.
pub const MAX_TABLE_BYTES: u64 = 1 << 30;

/// Most pieces one polygon is cut into; a pixel that would need more is sampled.
const MAX_PIECES: usize = 1 << 16;

/// Most knots one polygon's boundary may be cut at; a pixel that needs more is sampled.
pub const MAX_CUTS: usize = 1 << 16;

/// Largest texel coordinate a polygon may reach (beyond it `f64` keeps too few fraction bits for
/// the moments); a pixel whose preimage reaches further is sampled.
pub const MAX_COORDINATE: f64 = 1e9;

/// Most triangles reaching one pixel that the visibility test considers; more are sampled.
const MAX_LAYER_CANDIDATES: usize = 48;

/// Polygons overlapping by less than this area (pixels squared) do not overlap.
const AREA_EPSILON: f64 = 1e-10;

/// The exact pixels of a frame.
#[derive(Clone, Debug)]
pub struct ExactImage {
    /// Each pixel's mean colour in linear light (exact pixels only; the others hold zero).
    pub color: Vec<[f32; 4]>,
    /// Each exact pixel's nearest depth (NDC); infinite where nothing is visible.
    pub depth: Vec<f32>,
    /// Whether each pixel (row-major) is exact.
    pub exact: Vec<bool>,
    /// Each exact pixel's error bound per channel, linear light ([`WEIGHT_BOUND`] of its value
    /// plus [`ROUNDING_BOUND`]).
    pub bound: Vec<[f32; 4]>,
}

/// One texel row's piecewise-linear interpolation and its moment prefix sums.
struct Row {
    /// Knot values (linear RGBA) at `base + n`, `n = 0 ..= len`.
    values: Vec<[f64; 4]>,
    /// `prefix[n][m] = integral_0^n g(base + y) y^m dy`, per channel.
    prefix: Vec<[[f64; 4]; 4]>,
}

/// The integer knots along one axis at which the bilinear reconstruction's slope can change,
/// so that a polygon's boundary is cut only there: knots where the texture is locally linear
/// (flat checks, ramps) are skipped, and a band of equal rows is one piece.
struct Knots {
    /// `Some(P)`: activity repeats with period `P` from knot 0. `None`: only `base ..= base + len`
    /// can be active.
    period: Option<i64>,
    base: i64,
    active: Vec<bool>,
    /// Periodic only: from knot `n`, the distance to the next active knot (`u32::MAX`: none).
    next: Vec<u32>,
}

impl Knots {
    fn new(period: Option<i64>, base: i64, active: Vec<bool>) -> Knots {
        let mut next = Vec::new();
        if period.is_some() {
            let p = active.len();
            next = vec![u32::MAX; p];
            if let Some(first) = active.iter().position(|&a| a) {
                // Walk backwards twice around the cycle so every knot sees its successor.
                let mut dist = p - first;
                for k in (0..2 * p).rev() {
                    let n = k % p;
                    dist += 1;
                    if k < p {
                        next[n] = dist as u32;
                    }
                    if active[n] {
                        dist = 0;
                    }
                }
            }
        }
        Knots {
            period,
            base,
            active,
            next,
        }
    }

    /// Push every active knot strictly between `lo` and `hi` (converted by `f`) onto `cuts`;
    /// `false` once `cuts` would exceed [`MAX_CUTS`].
    fn each(&self, lo: f64, hi: f64, cuts: &mut Vec<f64>, f: impl Fn(f64) -> f64) -> bool {
        if lo.partial_cmp(&hi) != Some(std::cmp::Ordering::Less) {
            return true;
        }
        let mut n = lo.floor() as i64 + 1;
        let end = hi.ceil() as i64;
        let mut push = |k: i64| {
            cuts.push(f(k as f64));
            cuts.len() <= MAX_CUTS
        };
        match self.period {
            Some(p) => {
                while n < end {
                    let idx = n.rem_euclid(p) as usize;
                    if self.active[idx] {
                        if !push(n) {
                            return false;
                        }
                        n += 1;
                    } else {
                        let d = self.next[idx];
                        if d == u32::MAX {
                            return true;
                        }
                        n += i64::from(d);
                    }
                }
            }
            None => {
                let top = self.base + self.active.len() as i64;
                for k in n.max(self.base)..end.min(top) {
                    if self.active[(k - self.base) as usize] && !push(k) {
                        return false;
                    }
                }
            }
        }
        true
    }
}

/// Whether `b - a != c - b` anywhere (a slope change at the middle knot).
fn bends(a: &[[f64; 4]], b: &[[f64; 4]], c: &[[f64; 4]]) -> bool {
    a.iter()
        .zip(b)
        .zip(c)
        .any(|((a, b), c)| (0..4).any(|k| b[k] - a[k] != c[k] - b[k]))
}

/// The rows of one texture under one sampler's address modes, ready for span integrals.
struct Rows {
    /// The distinct rows.
    rows: Vec<Row>,
    /// Texture rows `0 .. height`, then one border row (ClampToBorder in `v`), as indices into
    /// `rows`.
    index: Vec<u32>,
    height: u32,
    v_mode: AddressMode,
    /// `Some(P)`: the knots repeat with period `P` (knot `0` is `s = 0`). `None`: the knots span
    /// `base ..= base + len` and are constant outside.
    period: Option<i64>,
    base: i64,
    len: usize,
    /// Knots along `s` (columns) and `t` (rows) where the reconstruction bends.
    columns: Knots,
    row_knots: Knots,
}

/// Bytes [`Rows::new`] would take for a `width x height` texture.
fn table_bytes(width: u32, height: u32, u: AddressMode) -> u64 {
    let (_, _, len) = knot_range(width, u);
    (u64::from(height) + 1) * (len as u64 + 1) * (4 * 4 * 8 + 4 * 8)
}

/// `(period, base, len)` of the knots along `s` for `width` texels under `mode`.
fn knot_range(width: u32, mode: AddressMode) -> (Option<i64>, i64, usize) {
    let w = i64::from(width);
    match mode {
        AddressMode::Repeat => (Some(w), 0, width as usize),
        AddressMode::MirrorRepeat => (Some(2 * w), 0, 2 * width as usize),
        // Constant beyond the first and last texel.
        AddressMode::ClampToEdge => (None, 0, (w - 1) as usize),
        // The border colour from one knot outside each edge.
        AddressMode::ClampToBorder => (None, -1, (w + 1) as usize),
        // Mirrored once around 0, clamped beyond: texel `w - 1` past both ends.
        AddressMode::MirrorClampToEdge => (None, -w, (2 * w - 1) as usize),
    }
}

impl Rows {
    fn new(texture: &Texture, u: AddressMode, v: AddressMode, border: [f32; 4]) -> Rows {
        let (width, height) = (texture.width(), texture.height());
        let (period, base, len) = knot_range(width, u);
        let border = border.map(f64::from);
        let knots = |r: Option<u32>| -> Vec<[f64; 4]> {
            (0..=len as i64)
                .map(|n| match (r, u.wrap(base + n, width)) {
                    (Some(r), Some(i)) => {
                        texture.texel(0, i, r).map_or(border, |c| c.map(f64::from))
                    }
                    _ => border,
                })
                .collect()
        };
        let all: Vec<Vec<[f64; 4]>> = (0..height)
            .into_par_iter()
            .map(|r| knots(Some(r)))
            .chain(rayon::iter::once(knots(None)))
            .collect();
        // Rows with equal texels share one table (a check's rows, a flat colour).
        let mut unique: std::collections::HashMap<Vec<u64>, u32> = Default::default();
        let mut index = Vec::with_capacity(all.len());
        let mut distinct = Vec::new();
        for values in all {
            let key: Vec<u64> = values.iter().flatten().map(|x| x.to_bits()).collect();
            let next = distinct.len() as u32;
            let id = *unique.entry(key).or_insert(next);
            if id == next {
                distinct.push(values);
            }
            index.push(id);
        }
        let rows: Vec<Row> = distinct
            .into_par_iter()
            .map(|values| {
                let mut prefix = vec![[[0.0; 4]; 4]; len + 1];
                for n in 0..len {
                    let cell = cell_moments(n as f64, values[n], values[n + 1], n as f64 + 1.0, 3);
                    for m in 0..4 {
                        for c in 0..4 {
                            prefix[n + 1][m][c] = prefix[n][m][c] + cell[m][c];
                        }
                    }
                }
                Row { values, prefix }
            })
            .collect();
        let columns = column_knots(&rows, period, base, len);
        let mut out = Rows {
            rows,
            index,
            height,
            v_mode: v,
            period,
            base,
            len,
            columns,
            row_knots: Knots::new(None, 0, Vec::new()),
        };
        out.row_knots = out.make_row_knots();
        out
    }

    /// The rows at which `t`'s slope can change: where row `j`'s neighbours differ from it
    /// unevenly.
    fn make_row_knots(&self) -> Knots {
        let h = i64::from(self.height);
        let (period, base, count) = match self.v_mode {
            AddressMode::Repeat => (Some(h), 0, h),
            AddressMode::MirrorRepeat => (Some(2 * h), 0, 2 * h),
            // Rows vary only within [-h, h - 1] for every other mode; one knot of margin.
            _ => (None, -h - 1, 3 * h + 3),
        };
        let active = (base..base + count)
            .into_par_iter()
            .map(|j| {
                let (a, b, c) = (self.row(j - 1), self.row(j), self.row(j + 1));
                bends(&a.values, &b.values, &c.values)
            })
            .collect();
        Knots::new(period, base, active)
    }

    /// The row of band index `j` (its wrapped texture row, or the border row).
    fn row(&self, j: i64) -> &Row {
        let r = self.v_mode.wrap(j, self.height).unwrap_or(self.height);
        &self.rows[self.index[r as usize] as usize]
    }

    /// `out[k] = integral_a^b g(s) (s - sc)^k ds` for `k <= deg`, `a <= b`, along `row`.
    fn span(&self, row: &Row, a: f64, b: f64, sc: f64, deg: usize, out: &mut [[f64; 4]; 4]) {
        *out = [[0.0; 4]; 4];
        match self.period {
            Some(p) => {
                let pf = p as f64;
                let (pa, pb) = ((a / pf).floor(), (b / pf).floor());
                if pa == pb {
                    table_part(row, pa * pf, a - pa * pf, b - pa * pf, sc, deg, out);
                    return;
                }
                table_part(row, pa * pf, a - pa * pf, pf, sc, deg, out);
                table_part(row, pb * pf, 0.0, b - pb * pf, sc, deg, out);
                if pb - pa > 1.0 {
                    whole_periods(row, pf, pa + 1.0, pb - 1.0, sc, deg, self.len, out);
                }
            }
            None => {
                let (lo, hi) = (self.base as f64, (self.base + self.len as i64) as f64);
                let first = row.values[0];
                let last = row.values[self.len];
                if a < lo {
                    constant_part(first, a, b.min(lo), sc, deg, out);
                }
                let (ca, cb) = (a.max(lo), b.min(hi));
                if ca < cb {
                    table_part(row, lo, ca - lo, cb - lo, sc, deg, out);
                }
                if b > hi {
                    constant_part(last, a.max(hi), b, sc, deg, out);
                }
            }
        }
    }
}

/// The columns at which some row's slope changes (local knots `0 ..= len` from `base`).
fn column_knots(rows: &[Row], period: Option<i64>, base: i64, len: usize) -> Knots {
    let count = if period.is_some() { len } else { len + 1 };
    let active = (0..count)
        .into_par_iter()
        .map(|n| {
            rows.iter().any(|r| {
                let v = &r.values;
                let (prev, next) = match period {
                    // v[len] is v[0]: the cycle's neighbours.
                    Some(_) => (if n == 0 { len - 1 } else { n - 1 }, n + 1),
                    None => (n.saturating_sub(1), (n + 1).min(len)),
                };
                bends(
                    std::slice::from_ref(&v[prev]),
                    std::slice::from_ref(&v[n]),
                    std::slice::from_ref(&v[next]),
                )
            })
        })
        .collect();
    Knots::new(period, base, active)
}

/// `integral_n^y (v0 + (v1 - v0)(z - n)) z^m dz` for `m = 0 .. 4`, per channel.
fn cell_moments(n: f64, v0: [f64; 4], v1: [f64; 4], y: f64, deg: usize) -> [[f64; 4]; 4] {
    let mut out = [[0.0; 4]; 4];
    let (mut yp, mut np) = (y, n);
    // yp, np: y^(m+1), n^(m+1); the next powers for the slope term.
    for (m, o) in out.iter_mut().enumerate().take(deg + 1) {
        let (yq, nq) = (yp * y, np * n);
        let (i1, i2) = ((yp - np) / (m + 1) as f64, (yq - nq) / (m + 2) as f64);
        for c in 0..4 {
            let slope = v1[c] - v0[c];
            let a0 = v0[c] - slope * n;
            o[c] = a0 * i1 + slope * i2;
        }
        yp = yq;
        np = nq;
    }
    out
}

/// `integral_0^y g(base + z) z^m dz` for local `y` in `[0, len]`.
fn local_prefix(row: &Row, y: f64, deg: usize) -> [[f64; 4]; 4] {
    let len = row.values.len() - 1;
    let n = (y.floor().max(0.0) as usize).min(len.saturating_sub(1));
    let mut out = row.prefix[n];
    if len > 0 && y > n as f64 {
        let cell = cell_moments(n as f64, row.values[n], row.values[n + 1], y, deg);
        for m in 0..=deg {
            for c in 0..4 {
                out[m][c] += cell[m][c];
            }
        }
    }
    out
}

/// Binomial coefficients `C(k, m)` for `k, m <= 3`.
const BINOMIAL: [[f64; 4]; 4] = [
    [1.0, 0.0, 0.0, 0.0],
    [1.0, 1.0, 0.0, 0.0],
    [1.0, 2.0, 1.0, 0.0],
    [1.0, 3.0, 3.0, 1.0],
];

/// Add `integral g(s) (s - sc)^k ds` over `s` in `base + [ya, yb]` (within the row's table).
fn table_part(
    row: &Row,
    base: f64,
    ya: f64,
    yb: f64,
    sc: f64,
    deg: usize,
    out: &mut [[f64; 4]; 4],
) {
    if yb <= ya {
        return;
    }
    let (ta, tb) = (local_prefix(row, ya, deg), local_prefix(row, yb, deg));
    let d = base - sc;
    let pd = [1.0, d, d * d, d * d * d];
    for k in 0..=deg {
        for m in 0..=k {
            let coef = BINOMIAL[k][m] * pd[k - m];
            for c in 0..4 {
                out[k][c] += coef * (tb[m][c] - ta[m][c]);
            }
        }
    }
}

/// Add `integral_a^b v (s - sc)^k ds` for a constant `v`.
fn constant_part(v: [f64; 4], a: f64, b: f64, sc: f64, deg: usize, out: &mut [[f64; 4]; 4]) {
    if b <= a {
        return;
    }
    let (da, db) = (a - sc, b - sc);
    let (mut pa, mut pb) = (da, db);
    for (k, o) in out.iter_mut().enumerate().take(deg + 1) {
        let i = (pb - pa) / (k + 1) as f64;
        for c in 0..4 {
            o[c] += v[c] * i;
        }
        pa *= da;
        pb *= db;
    }
}

/// `sum_(p = p0)^(p1) p^i` for `i = 0 .. 4` (integers `p0 <= p1` as `f64`).
fn power_sums(p0: f64, p1: f64) -> [f64; 4] {
    let s = |n: f64| {
        let t = n * (n + 1.0) / 2.0;
        [n + 1.0, t, n * (n + 1.0) * (2.0 * n + 1.0) / 6.0, t * t]
    };
    let (hi, lo) = (s(p1), s(p0 - 1.0));
    [hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2], hi[3] - lo[3]]
}

/// Add the whole periods `p0 ..= p1` of length `pf`: `sum_p sum_m C(k, m) (p pf - sc)^(k-m) M_m`
/// with `M_m` the period's moments, the power sums taken about the period nearest `sc`.
#[allow(clippy::too_many_arguments)]
fn whole_periods(
    row: &Row,
    pf: f64,
    p0: f64,
    p1: f64,
    sc: f64,
    deg: usize,
    len: usize,
    out: &mut [[f64; 4]; 4],
) {
    let moments = row.prefix[len];
    let pc = (sc / pf).round();
    let c0 = pc * pf - sc;
    let sums = power_sums(p0 - pc, p1 - pc);
    // sum_p (p' pf + c0)^j = sum_i C(j, i) pf^i c0^(j - i) sum_p p'^i.
    let mut d = [0.0; 4];
    for (j, dj) in d.iter_mut().enumerate().take(deg + 1) {
        for i in 0..=j {
            *dj += BINOMIAL[j][i] * pf.powi(i as i32) * c0.powi((j - i) as i32) * sums[i];
        }
    }
    for k in 0..=deg {
        for m in 0..=k {
            let coef = BINOMIAL[k][m] * d[k - m];
            for c in 0..4 {
                out[k][c] += coef * moments[m][c];
            }
        }
    }
}

/// Gauss-Legendre nodes and weights on `[0, 1]`, 4 points (exact for degree 7).
const GAUSS: [(f64, f64); 4] = [
    (0.069_431_844_202_973_71, 0.173_927_422_568_726_9),
    (0.330_009_478_207_571_9, 0.326_072_577_431_273_1),
    (0.669_990_521_792_428_1, 0.326_072_577_431_273_1),
    (0.930_568_155_797_026_3, 0.173_927_422_568_726_9),
];

/// The weight polynomial over one piece: `sum A_kl (s - sc)^k (t - tc)^l`, `k + l <= deg`.
struct Weight {
    sc: f64,
    tc: f64,
    deg: usize,
    a: [[f64; 4]; 4],
}

/// `integral_P f w` over the convex texel-space polygon `poly` (either orientation); `None`
/// when its boundary crosses more than [`MAX_CUTS`] bending knots.
fn polygon_integral(rows: &Rows, poly: &[DVec2], w: &Weight) -> Option<[f64; 4]> {
    let mut total = [0.0; 4];
    let n = poly.len();
    if n < 3 {
        return Some(total);
    }
    let (mut tmin, mut tmax) = (f64::INFINITY, f64::NEG_INFINITY);
    for p in poly {
        tmin = tmin.min(p.y);
        tmax = tmax.max(p.y);
    }
    if tmax <= tmin {
        return Some(total);
    }
    let mut cuts: Vec<f64> = poly.iter().map(|p| p.y).collect();
    if !rows.row_knots.each(tmin, tmax, &mut cuts, |j| j) {
        return None;
    }
    for e in 0..n {
        let (a, b) = (poly[e], poly[(e + 1) % n]);
        if a.y == b.y || a.x == b.x {
            continue;
        }
        let (lo, hi) = (a.x.min(b.x), a.x.max(b.x));
        let at = |s: f64| a.y + (s - a.x) / (b.x - a.x) * (b.y - a.y);
        if !rows.columns.each(lo, hi, &mut cuts, at) {
            return None;
        }
    }
    cuts.sort_by(f64::total_cmp);
    cuts.dedup();
    let mut span = [[0.0; 4]; 4];
    let mut span1 = [[0.0; 4]; 4];
    for pair in cuts.windows(2) {
        let (ta, tb) = (pair[0], pair[1]);
        if tb <= ta {
            continue;
        }
        let tm = 0.5 * (ta + tb);
        // The two edges crossing height tm, as s(t) = s0 + slope (t - t0).
        let mut sides = [(0.0, 0.0, 0.0); 2];
        let mut found = 0;
        for e in 0..n {
            let (a, b) = (poly[e], poly[(e + 1) % n]);
            if (a.y < tm) != (b.y < tm) && found < 2 {
                let slope = (b.x - a.x) / (b.y - a.y);
                sides[found] = (a.x, a.y, slope);
                found += 1;
            }
        }
        if found < 2 {
            continue;
        }
        let h = tb - ta;
        for (x, gw) in GAUSS {
            let t = ta + x * h;
            // Between bending rows the reconstruction is linear in t: any band gives it.
            let band = t.floor();
            let (r0, r1) = (rows.row(band as i64), rows.row(band as i64 + 1));
            let s0 = sides[0].0 + sides[0].2 * (t - sides[0].1);
            let s1 = sides[1].0 + sides[1].2 * (t - sides[1].1);
            let (sl, sr) = (s0.min(s1), s0.max(s1));
            let beta = t - band;
            rows.span(r0, sl, sr, w.sc, w.deg, &mut span);
            rows.span(r1, sl, sr, w.sc, w.deg, &mut span1);
            let dt = t - w.tc;
            let mut pt = [1.0; 4];
            for l in 1..4 {
                pt[l] = pt[l - 1] * dt;
            }
            for k in 0..=w.deg {
                let coef: f64 = w.a[k][..=w.deg - k]
                    .iter()
                    .zip(&pt)
                    .map(|(a, p)| a * p)
                    .sum();
                let coef = coef * gw * h;
                for c in 0..4 {
                    total[c] += coef * ((1.0 - beta) * span[k][c] + beta * span1[k][c]);
                }
            }
        }
    }
    Some(total)
}

/// `sum_(m > deg) (m + 1)(m + 2)/2 d^m`: the Taylor remainder of `(1 + e)^-3` at `|e| <= d`.
fn remainder(deg: usize, d: f64) -> f64 {
    let mut sum = 0.0;
    let mut p = d.powi(deg as i32 + 1);
    for m in deg + 1..deg + 200 {
        let term = ((m + 1) * (m + 2)) as f64 / 2.0 * p;
        sum += term;
        if term < 1e-30 {
            break;
        }
        p *= d;
    }
    sum
}

/// A triangle ready for exact integration.
#[derive(Clone, Copy)]
struct Exactable {
    /// Texel coordinates from screen: `(s Z, t Z, Z) = g (x, y, 1)`.
    g: DMat3,
    /// `g^-1`, its determinant's magnitude.
    h: DMat3,
    det_h: f64,
    /// The draw's constant colour times the triangle's shared vertex colour.
    factor: [f64; 4],
    /// Index into the frame's row tables.
    rows: usize,
}

impl Exactable {
    /// `integral f J` over the screen-space convex polygon `poly`, cut into pieces of bounded
    /// `w` ratio; `None` if it would need more than [`MAX_PIECES`].
    fn integral(&self, rows: &Rows, poly: &[DVec2]) -> Option<[f64; 4]> {
        // Z along the screen: the third row of g, `1 / w` up to scale.
        let z_row = self.g.row(2);
        let z = |p: DVec2| z_row.x * p.x + z_row.y * p.y + z_row.z;
        let (mut zmin, mut zmax) = (f64::INFINITY, 0.0f64);
        for &p in poly {
            let v = z(p).abs();
            zmin = zmin.min(v);
            zmax = zmax.max(v);
        }
        if !(zmin > 0.0 && zmax.is_finite()) {
            return None;
        }
        let ratio = zmax / zmin;
        let pieces = (ratio.ln() / PIECE_RATIO.ln()).ceil().max(1.0);
        if pieces > MAX_PIECES as f64 {
            return None;
        }
        let pieces = pieces as usize;
        let sign = z(poly[0]).signum();
        let mut total = [0.0; 4];
        let mut piece = Vec::with_capacity(poly.len() + 2);
        let mut scratch = Vec::with_capacity(poly.len() + 2);
        let step = ratio.powf(1.0 / pieces as f64);
        for k in 0..pieces {
            piece.clear();
            piece.extend_from_slice(poly);
            if pieces > 1 {
                let lo = zmin * step.powi(k as i32);
                let hi = zmin * step.powi(k as i32 + 1);
                let (a, b, c) = (z_row.x * sign, z_row.y * sign, z_row.z * sign);
                if k > 0 {
                    clip(&piece, &mut scratch, |p| a * p.x + b * p.y + c - lo);
                    std::mem::swap(&mut piece, &mut scratch);
                }
                if k + 1 < pieces {
                    clip(&piece, &mut scratch, |p| hi - (a * p.x + b * p.y + c));
                    std::mem::swap(&mut piece, &mut scratch);
                }
            }
            if piece.len() < 3 {
                continue;
            }
            let part = self.piece_integral(rows, &piece)?;
            for c in 0..4 {
                total[c] += part[c];
            }
        }
        Some(total)
    }

    /// One piece: its texel-space polygon and weight polynomial.
    fn piece_integral(&self, rows: &Rows, piece: &[DVec2]) -> Option<[f64; 4]> {
        let q: Vec<DVec2> = piece
            .iter()
            .map(|p| {
                let v = self.g * DVec3::new(p.x, p.y, 1.0);
                DVec2::new(v.x / v.z, v.y / v.z)
            })
            .collect();
        if q.iter()
            .any(|p| !p.is_finite() || p.abs().max_element() > MAX_COORDINATE)
        {
            return None;
        }
        let qc = q.iter().copied().sum::<DVec2>() / q.len() as f64;
        let hz = self.h.row(2);
        let zc = hz.x * qc.x + hz.y * qc.y + hz.z;
        let gs = DVec2::new(hz.x, hz.y) / zc;
        let delta = q.iter().map(|p| gs.dot(*p - qc).abs()).fold(0.0, f64::max);
        let deg = (0..=3).find(|&d| remainder(d, delta) <= WEIGHT_BOUND)?;
        let scale = self.det_h / zc.abs().powi(3);
        let mut a = [[0.0; 4]; 4];
        for (k, ak) in a.iter_mut().enumerate() {
            for (l, akl) in ak.iter_mut().enumerate() {
                let m = k + l;
                if m <= deg {
                    let cm = if m % 2 == 0 { 1.0 } else { -1.0 } * ((m + 1) * (m + 2)) as f64 / 2.0;
                    *akl = scale * cm * BINOMIAL[m][k] * gs.x.powi(k as i32) * gs.y.powi(l as i32);
                }
            }
        }
        let w = Weight {
            sc: qc.x,
            tc: qc.y,
            deg,
            a,
        };
        polygon_integral(rows, &q, &w)
    }
}

/// Sutherland-Hodgman: the part of convex `poly` where `f >= 0` (`f` affine), into `out`.
fn clip(poly: &[DVec2], out: &mut Vec<DVec2>, f: impl Fn(DVec2) -> f64) {
    out.clear();
    let n = poly.len();
    for i in 0..n {
        let (a, b) = (poly[i], poly[(i + 1) % n]);
        let (fa, fb) = (f(a), f(b));
        if fa >= 0.0 {
            out.push(a);
        }
        if (fa >= 0.0) != (fb >= 0.0) {
            let t = fa / (fa - fb);
            out.push(a + (b - a) * t);
        }
    }
}

/// The intersection of convex polygons `a` and `b` when its area exceeds [`AREA_EPSILON`].
fn intersection(a: &[DVec2], b: &[DVec2], scratch: &mut Vec<DVec2>) -> Option<Vec<DVec2>> {
    let orient = area(b).signum();
    let mut inter = a.to_vec();
    for e in 0..b.len() {
        let (p, q) = (b[e], b[(e + 1) % b.len()]);
        clip(&inter, scratch, |v| orient * (q - p).perp_dot(v - p));
        std::mem::swap(&mut inter, scratch);
        if inter.len() < 3 {
            return None;
        }
    }
    (area(&inter).abs() > AREA_EPSILON).then_some(inter)
}

/// Signed area (shoelace).
fn area(poly: &[DVec2]) -> f64 {
    let n = poly.len();
    (0..n)
        .map(|i| poly[i].perp_dot(poly[(i + 1) % n]))
        .sum::<f64>()
        * 0.5
}

/// An edge function as the affine function of continuous pixel coordinates it is, without the
/// fill rule's offset: `>= 0` inside.
fn edge_fn(e: &Edge) -> impl Fn(DVec2) -> f64 {
    let top_left = e.a > 0 || (e.a == 0 && e.b > 0);
    let c = (e.c + i64::from(!top_left)) as f64;
    let (a, b) = (e.a as f64 * SUBPIXEL as f64, e.b as f64 * SUBPIXEL as f64);
    move |p: DVec2| a * p.x + b * p.y + c
}

/// Triangle `t`'s part of `poly`.
fn clip_to_triangle(t: &TriangleSetup, poly: &[DVec2], a: &mut Vec<DVec2>, b: &mut Vec<DVec2>) {
    a.clear();
    a.extend_from_slice(poly);
    for e in &t.edges {
        clip(a, b, edge_fn(e));
        std::mem::swap(a, b);
        if a.len() < 3 {
            a.clear();
            return;
        }
    }
}

/// Each draw's constant colour when it can be integrated exactly (unlit, interpolated `uv`, no
/// layers), else `None`.
fn draw_factor(settings: &RenderSettings, d: &DrawCall) -> Option<[f64; 4]> {
    if settings.is_lit() || d.uv_mapping.is_some() {
        return None;
    }
    match d.material {
        None => Some([1.0; 4]),
        Some(m) if m.layers.is_none() => Some(m.base_color.to_array().map(f64::from)),
        Some(_) => None,
    }
}

/// The exact pixels of `draws` (see the module docs), on the settings' thread pool. `progress`
/// is called after each tile with `(pixels done, total)`.
///
/// # Errors
/// As [`crate::render`].
pub fn render_exact(
    settings: &RenderSettings,
    draws: &[DrawCall],
    progress: Option<Progress>,
) -> Result<ExactImage, RasterError> {
    settings.validate()?;
    crate::setup::validate_draws(draws)?;
    crate::with_threads(settings.threads, || {
        let (width, height) = (settings.width, settings.height);
        let setups = setup_draws(settings, draws)?;
        // Row tables, one per (texture, address modes, border), within the byte budget.
        let mut keys: Vec<(usize, usize)> = Vec::new();
        let mut tables: Vec<Rows> = Vec::new();
        let mut table_of: Vec<Option<usize>> = Vec::with_capacity(draws.len());
        let mut bytes = 0u64;
        for (k, d) in draws.iter().enumerate() {
            if draw_factor(settings, d).is_none() {
                table_of.push(None);
                continue;
            }
            let found = keys.iter().position(|&(_, other)| {
                let o = &draws[other];
                std::ptr::eq(o.texture, d.texture)
                    && same_addressing(o.sampler.descriptor(), d.sampler.descriptor())
            });
            if let Some(i) = found {
                table_of.push(Some(keys[i].0));
                continue;
            }
            let desc = d.sampler.descriptor();
            let need = table_bytes(d.texture.width(), d.texture.height(), desc.address_mode_u);
            if bytes + need > MAX_TABLE_BYTES {
                table_of.push(None);
                continue;
            }
            bytes += need;
            tables.push(Rows::new(
                d.texture,
                desc.address_mode_u,
                desc.address_mode_v,
                desc.border_color.rgba(),
            ));
            keys.push((tables.len() - 1, k));
            table_of.push(Some(tables.len() - 1));
        }
        let prepared: Vec<Option<Exactable>> = setups
            .par_iter()
            .map(|t| exactable(settings, draws, t, &table_of))
            .collect();
        let bins = bin(
            &setups,
            width,
            height,
            |t| Some(t.sample_bbox),
            |s, _| s as u32,
        );
        let ctx = Frame {
            settings,
            setups: &setups,
            prepared: &prepared,
            tables: &tables,
        };
        Ok(ctx.render(&bins, progress))
    })
}

/// Whether two samplers address a texture alike (the row tables depend on nothing else).
fn same_addressing(
    a: &texel_texture::SamplerDescriptor,
    b: &texel_texture::SamplerDescriptor,
) -> bool {
    a.address_mode_u == b.address_mode_u
        && a.address_mode_v == b.address_mode_v
        && a.border_color.rgba() == b.border_color.rgba()
}

/// Triangle `t` made ready, when its draw and vertices allow.
fn exactable(
    settings: &RenderSettings,
    draws: &[DrawCall],
    t: &TriangleSetup,
    table_of: &[Option<usize>],
) -> Option<Exactable> {
    let d = &draws[t.draw as usize];
    let rows = table_of[t.draw as usize]?;
    let mut factor = draw_factor(settings, d)?;
    let verts = t.indices.map(|k| &d.vertices[k as usize]);
    let color = verts[0].color;
    if verts.iter().any(|v| v.color != color) {
        return None;
    }
    if color != Vec4::ONE {
        for c in 0..4 {
            factor[c] *= f64::from(color[c]);
        }
    }
    let (w, h) = (f64::from(d.texture.width()), f64::from(d.texture.height()));
    let uv = verts.map(|v| v.uv.as_dvec2());
    // s Z = W U Z - Z / 2 with U Z = sum uv_k q_k and Z = r = 1 / w_clip, planes in (x, y).
    let plane = |f: &dyn Fn(usize) -> f64| {
        let (mut dx, mut dy, mut c) = (0.0, 0.0, 0.0);
        for k in 0..3 {
            dx += f(k) * t.q[k].dx;
            dy += f(k) * t.q[k].dy;
            c += f(k) * t.q[k].c;
        }
        DVec3::new(dx, dy, c)
    };
    let r = DVec3::new(t.r.dx, t.r.dy, t.r.c);
    let su = plane(&|k| uv[k].x) * w - r * 0.5;
    let tv = plane(&|k| uv[k].y) * h - r * 0.5;
    let g = DMat3::from_cols(su, tv, r).transpose();
    let hm = g.inverse();
    let det_h = hm.determinant().abs();
    (det_h.is_finite() && det_h > 0.0 && hm.is_finite()).then_some(Exactable {
        g,
        h: hm,
        det_h,
        factor,
        rows,
    })
}

/// What the exact pass reads.
struct Frame<'a> {
    settings: &'a RenderSettings<'a>,
    setups: &'a [TriangleSetup],
    prepared: &'a [Option<Exactable>],
    tables: &'a [Rows],
}

/// One pixel's result: colour, depth and bound, or `None` to sample it.
type PixelResult = Option<([f64; 4], f32, [f64; 4])>;

impl Frame<'_> {
    fn render(&self, bins: &[Vec<u32>], progress: Option<Progress>) -> ExactImage {
        let s = self.settings;
        let (width, height) = (s.width, s.height);
        let pixels = width as usize * height as usize;
        let (tx, _) = tile_counts(width, height);
        let [sx0, sy0, sx1, sy1] = s.scissor_rect();
        let done = std::sync::atomic::AtomicU64::new(0);
        let tiles: Vec<Vec<(usize, PixelResult)>> = bins
            .par_iter()
            .enumerate()
            .with_max_len(1)
            .map(|(k, bin)| {
                let (x0, y0) = ((k as u32 % tx) * TILE, (k as u32 / tx) * TILE);
                let mut out = Vec::new();
                let mut scratch = Scratch::default();
                for j in y0..(y0 + TILE).min(height) {
                    for i in x0..(x0 + TILE).min(width) {
                        if !(sx0..sx1).contains(&i) || !(sy0..sy1).contains(&j) {
                            continue;
                        }
                        let idx = j as usize * width as usize + i as usize;
                        out.push((idx, self.pixel(bin, i, j, &mut scratch)));
                    }
                }
                let n = out.len() as u64;
                let now = done.fetch_add(n, std::sync::atomic::Ordering::Relaxed) + n;
                if let Some(p) = progress {
                    p(now, pixels as u64);
                }
                out
            })
            .collect();
        let mut image = ExactImage {
            color: vec![[0.0; 4]; pixels],
            depth: vec![f32::INFINITY; pixels],
            exact: vec![false; pixels],
            bound: vec![[0.0; 4]; pixels],
        };
        for (idx, r) in tiles.into_iter().flatten() {
            if let Some((c, z, b)) = r {
                image.color[idx] = c.map(|x| x as f32);
                image.depth[idx] = z;
                image.exact[idx] = true;
                image.bound[idx] = b.map(|x| x as f32);
            }
        }
        image
    }

    /// Pixel `(i, j)` from the triangles of its tile's `bin`.
    fn pixel(&self, bin: &[u32], i: u32, j: u32, s: &mut Scratch) -> PixelResult {
        let (x, y) = (f64::from(i), f64::from(j));
        let square = [
            DVec2::new(x, y),
            DVec2::new(x + 1.0, y),
            DVec2::new(x + 1.0, y + 1.0),
            DVec2::new(x, y + 1.0),
        ];
        s.layers.clear();
        for &id in bin {
            let t = &self.setups[id as usize];
            let [bi0, bj0, bi1, bj1] = t.sample_bbox;
            if i < bi0 || i > bi1 || j < bj0 || j > bj1 {
                continue;
            }
            clip_to_triangle(t, &square, &mut s.a, &mut s.b);
            if s.a.len() < 3 || area(&s.a).abs() <= AREA_EPSILON {
                continue;
            }
            self.prepared[id as usize]?;
            if s.layers.len() == MAX_LAYER_CANDIDATES {
                return None;
            }
            s.layers.push((id, s.a.clone()));
        }
        let mut sum = [0.0; 4];
        let mut magnitude = [0.0f64; 4];
        let mut covered = 0.0;
        let mut depth = f32::INFINITY;
        let n = s.layers.len();
        // For each layer, the layers in front of it that overlap it, with the overlap.
        for a in 0..n {
            let (ida, ref pa) = s.layers[a];
            let ta = &self.setups[ida as usize];
            let ea = self.prepared[ida as usize].expect("checked above");
            let rows = &self.tables[ea.rows];
            let mut hidden: Vec<Vec<DVec2>> = Vec::new();
            for b in 0..n {
                if a == b {
                    continue;
                }
                let (idb, ref pb) = s.layers[b];
                let tb = &self.setups[idb as usize];
                let Some(inter) = intersection(pa, pb, &mut s.b) else {
                    continue;
                };
                let da: Vec<f64> = inter.iter().map(|v| ta.z.at(v.x, v.y)).collect();
                let db: Vec<f64> = inter.iter().map(|v| tb.z.at(v.x, v.y)).collect();
                let b_front = da.iter().zip(&db).all(|(za, zb)| zb < za);
                let a_front = da.iter().zip(&db).all(|(za, zb)| za < zb);
                if b_front {
                    hidden.push(inter);
                } else if !a_front {
                    // They cross (or tie) inside the pixel.
                    return None;
                }
            }
            // The layers hiding `a` must not overlap one another there.
            for u in 0..hidden.len() {
                for v in u + 1..hidden.len() {
                    if intersection(&hidden[u], &hidden[v], &mut s.b).is_some() {
                        return None;
                    }
                }
            }
            let mut value = ea.integral(rows, pa)?;
            let mut visible = area(pa).abs();
            for hpoly in &hidden {
                let v = ea.integral(rows, hpoly)?;
                for c in 0..4 {
                    value[c] -= v[c];
                }
                visible -= area(hpoly).abs();
            }
            if visible > AREA_EPSILON {
                for v in pa {
                    depth = depth.min(ta.z.at(v.x, v.y) as f32);
                }
            }
            covered += visible;
            for c in 0..4 {
                let v = value[c] * ea.factor[c];
                sum[c] += v;
                magnitude[c] += v.abs();
            }
        }
        let open = (1.0 - covered).max(0.0);
        if open > AREA_EPSILON && self.settings.environment.is_some() {
            return None;
        }
        let bg = self.settings.background.map(f64::from);
        for c in 0..4 {
            sum[c] += bg[c] * open;
        }
        let bound = magnitude.map(|m| WEIGHT_BOUND * m + ROUNDING_BOUND);
        sum.iter()
            .all(|v| v.is_finite())
            .then_some((sum, depth, bound))
    }
}

/// Per-thread buffers.
#[derive(Default)]
struct Scratch {
    a: Vec<DVec2>,
    b: Vec<DVec2>,
    layers: Vec<(u32, Vec<DVec2>)>,
}
