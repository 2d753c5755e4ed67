//! Specialised kernels behind [`crate::Sampler::sample_batch`] for the four core filters: nearest
//! or bilinear inside a level, with no mipmapping (level 0), the nearest level, or trilinear.
//!
//! The per-sample path ([`crate::Sampler::sample`]) walks one sample through lod, level choice,
//! a run-time dispatch on the filter, coordinate set-up, range checks, texel loads and blends. Here a
//! chunk of samples goes through the same steps in stages, each a short loop over the chunk:
//!
//! 1. levels: each sample's level (and, for trilinear, its second level and weight);
//! 2. coordinates: per level pass, `x = u * W` (`- 1/2` for bilinear), the integer texel index by
//!    a clamp and a truncating conversion, the fractions, and whether every texel the sample reads
//!    lies inside the level. Branch-free, with no calls: the compiler vectorises it;
//! 3. texels: loads, decodes and blends for the samples inside the level; the few near an edge
//!    go through the general filter ([`crate::nearest`], [`crate::bilinear`]) with address wrapping.
//!
//! Every stage performs the per-sample path's floating-point operations in the same order, so the
//! results are bit for bit those of [`crate::Sampler::sample`] (`tests/core.rs`, `batch_equals_single`,
//! over every filter, mipmap mode, address mode and texel format).
//!
//! Short calls (at most 16 footprints) run with 16-sample scratch: zeroing and filling 64-sample
//! scratch (about 6 KB per call) costs more than sampling a small triangle's few pixels (the
//! 100k-triangle mesh of `texel-raster`'s benchmarks; figures in docs/perf-log.md).
//!
//! Why the index is exact: the per-sample path's `floor_index(x)` is `floor(x)` as an `i64`. Here
//! `x` is first clamped to `[-1, W]`; inside that range truncation toward zero, minus one where it
//! rounded up, is the floor, and the floor of the clamped value lies in `[0, W)` exactly when the
//! floor of `x` does. For samples inside the level the clamp is the identity, so the fractions
//! `x - floor(x)` are the per-sample path's.

use glam::Vec4;

use crate::address::Address;
use crate::bilinear::bilinear;
use crate::fetch::{Fetch, Pyramid};
use crate::footprint::{lod_from_rho_squared, log2_normal, rho_squared, Footprint};
use crate::mip::mip_nearest_level;
use crate::nearest::nearest;
use crate::sampler::finite_uv;

/// Samples per stage (the sampler's chunk).
pub(crate) const CHUNK: usize = 64;

/// Level views kept per call: a power of two above the 23 levels of a `MAX_SIDE` texture, so that
/// `% LEVELS` is a mask.
const LEVELS: usize = 32;

/// The filter inside a level.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Within {
    /// One texel.
    Nearest,
    /// Bilinear, 2x2 texels.
    Linear,
}

/// How levels are chosen from the lod.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Levels {
    /// Level 0 whatever the lod (no mipmapping, `mag_filter == min_filter`).
    Base,
    /// The Vulkan nearest level ([`mip_nearest_level`]); level 0 for `lod <= 0`.
    Nearest,
    /// Trilinear between `floor(d)` and `floor(d) + 1`, `d = clamp(lod, 0, last)`.
    Linear,
}

/// A kernel: the filter inside a level and the level rule. Valid when `mag_filter == min_filter`
/// (then the magnification branch, `lod <= 0`, is the level rule at level 0 with weight 0).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Kernel {
    pub within: Within,
    pub levels: Levels,
}

/// Level sizes as the coordinate stage reads them, indexed by the level masked to `LEVELS` (no
/// bounds checks).
struct Dims {
    /// `W` and `H` as `f32` (scales) and as clamp bounds.
    w: [f32; LEVELS],
    h: [f32; LEVELS],
}

/// Per-sample scratch of one level pass, for up to `N` samples.
struct Pass<const N: usize> {
    level: [u8; N],
    /// Top-left texel index (nearest: the texel).
    i: [i32; N],
    j: [i32; N],
    /// Bilinear fractions.
    a: [f32; N],
    b: [f32; N],
    /// Every texel read lies inside the level.
    inside: [bool; N],
}

impl<const N: usize> Pass<N> {
    fn new() -> Self {
        Pass {
            level: [0; N],
            i: [0; N],
            j: [0; N],
            a: [0.0; N],
            b: [0.0; N],
            inside: [false; N],
        }
    }

    /// Stage 2 for the first `n` samples at their `level`s, whose sizes `size(level)` gives.
    #[inline(always)]
    fn coordinates(
        &mut self,
        within: Within,
        size: impl Fn(u8) -> (f32, f32),
        us: &[f32],
        vs: &[f32],
    ) {
        let n = us.len();
        let half = match within {
            Within::Nearest => 0.0,
            Within::Linear => 0.5,
        };
        // Bilinear reads texel i0 + 1 too: i0 must be below W - 1.
        let reach = match within {
            Within::Nearest => 0.0,
            Within::Linear => 1.0,
        };
        for k in 0..n {
            let (w, h) = size(self.level[k]);
            let x = us[k] * w - half;
            let y = vs[k] * h - half;
            let (i, fi) = clamped_floor(x, w);
            let (j, fj) = clamped_floor(y, h);
            self.i[k] = i;
            self.j[k] = j;
            self.a[k] = x - fi;
            self.b[k] = y - fj;
            self.inside[k] = fi >= 0.0 && fi < w - reach && fj >= 0.0 && fj < h - reach;
        }
    }
}

/// Largest level-0 side the kernels accept (2^22): [`clamped_floor`] is exact below it. Larger
/// textures take the generic path.
pub(crate) const MAX_SIDE: u32 = 1 << 22;

/// `1.5 * 2^23`: added to an `f32` of magnitude below `2^22`, the sum lies in `[2^23, 2^24)`, where
/// the spacing is 1, so it is rounded to an integer, which its low mantissa bits hold.
const ROUND: f32 = 12_582_912.0;

/// `floor(x)` for `x` clamped to `[-1, hi]`, as an integer and as an `f32`; `1 <= hi < 2^22`, `x`
/// finite. Rounds by adding and subtracting [`ROUND`] and reads the integer from the sum's bits:
/// no float-to-integer conversion, whose saturating semantics (NaN to 0, out of range to the
/// limits) cost about 20 instructions per sample on SSE2 (callgrind).
#[inline(always)]
fn clamped_floor(x: f32, hi: f32) -> (i32, f32) {
    let c = x.max(-1.0).min(hi);
    let sum = c + ROUND;
    let rounded = sum - ROUND;
    // Integer value of the rounded sum: its bits minus those of ROUND.
    let r = sum.to_bits() as i32 - ROUND.to_bits() as i32;
    let down = rounded > c;
    (
        r - i32::from(down),
        if down { rounded - 1.0 } else { rounded },
    )
}

/// What the lod stage needs: level 0's size and the sampler's bias and clamps.
#[derive(Clone, Copy, Debug)]
pub(crate) struct LodParams {
    pub width: u32,
    pub height: u32,
    pub bias: f32,
    pub min: f32,
    pub max: f32,
}

/// Stage 0: finite `(u, v)` ([`finite_uv`]) and, with `lod` (the sampler is not lod-free), the lod
/// of every footprint, as `Sampler::prepare` computes them: `rho^2` ([`rho_squared`]) and
/// [`lod_from_rho_squared`] with [`crate::footprint::fast_log2`]'s normal-input path written
/// branch-free, so the loop vectorises. The inputs that path does not cover (`rho^2` zero or
/// subnormal) are rare; a second loop recomputes those lanes with the scalar functions.
#[inline(always)]
pub(crate) fn prepare(
    fps: &[Footprint],
    lod: Option<LodParams>,
    us: &mut [f32],
    vs: &mut [f32],
    lods: &mut [f32],
) {
    for ((f, u), v) in fps.iter().zip(us.iter_mut()).zip(vs.iter_mut()) {
        *u = finite_uv(f.u);
        *v = finite_uv(f.v);
    }
    let Some(q) = lod else {
        lods[..fps.len()].fill(0.0);
        return;
    };
    let (w, h) = (q.width as f32, q.height as f32);
    let mut special = false;
    for (f, lod) in fps.iter().zip(lods.iter_mut()) {
        // `rho_squared`: the squared lengths of the texel-space axes, +inf if either is not finite.
        let (ax, ay) = (f.dudx * w, f.dvdx * h);
        let (bx, by) = (f.dudy * w, f.dvdy * h);
        let a = ax * ax + ay * ay;
        let b = bx * bx + by * by;
        let finite = a.is_finite() & b.is_finite();
        let rho2 = a.max(b);
        // `fast_log2` for normal positive input.
        let log2 = log2_normal(rho2);
        // `lod_from_rho_squared`: non-finite rho^2 gives lod_max.
        let l = (0.5 * log2 + q.bias).clamp(q.min, q.max);
        *lod = if finite { l } else { q.max };
        special |= finite & (rho2 < f32::MIN_POSITIVE);
    }
    if special {
        for (f, lod) in fps.iter().zip(lods.iter_mut()) {
            let rho2 = rho_squared(f, q.width, q.height);
            if rho2 < f32::MIN_POSITIVE {
                *lod = lod_from_rho_squared(rho2, q.bias, q.min, q.max);
            }
        }
    }
}

/// Filter `footprints` with `kernel` into `out` (same length): `lod` is `None` for a lod-free
/// sampler (no mipmapping, `mag_filter == min_filter`), whose lods are all 0.
///
/// Short calls (at most 16 footprints: a small triangle's fragments) use 16-sample scratch: the
/// per-call set-up of 64-sample scratch (about 6 KB of stores) costs more than sampling three or
/// four pixels (see the module docs).
pub(crate) fn run<P: Pyramid>(
    p: &P,
    addr: &Address,
    kernel: Kernel,
    lod: Option<LodParams>,
    footprints: &[Footprint],
    out: &mut [[f32; 4]],
) {
    if footprints.len() <= 16 {
        run_in::<P, 16, 1>(p, addr, kernel, lod, footprints, out);
    } else {
        run_in::<P, CHUNK, LEVELS>(p, addr, kernel, lod, footprints, out);
    }
}

/// [`run`] in chunks of `N` samples, with `V` level views made up front (`V = LEVELS`), or (`V = 1`)
/// each sample's view made when it is read, which is cheaper for a handful of samples than making
/// 32 views.
#[inline(always)]
fn run_in<P: Pyramid, const N: usize, const V: usize>(
    p: &P,
    addr: &Address,
    kernel: Kernel,
    lod: Option<LodParams>,
    footprints: &[Footprint],
    out: &mut [[f32; 4]],
) {
    // Level 0 is below 2^22 per side (`MAX_SIDE`), so there are at most 23 levels.
    let levels = p.level_count().min(LEVELS);
    let mut dims = Dims {
        w: [0.0; LEVELS],
        h: [0.0; LEVELS],
    };
    let base = p.level(0);
    let mut views = [base; V];
    for l in 0..levels {
        let view = p.level(l);
        let (w, h) = view.size();
        (dims.w[l], dims.h[l]) = (w as f32, h as f32);
        if V == LEVELS {
            views[l % V] = view;
        }
    }
    let view = |l: u8| {
        if V == LEVELS {
            views[l as usize % V]
        } else {
            p.level(l as usize)
        }
    };
    let mut first = Pass::<N>::new();
    let mut second = Pass::<N>::new();
    let mut delta = [0.0f32; N];
    let (mut us, mut vs, mut lods) = ([0.0f32; N], [0.0f32; N], [0.0f32; N]);
    let last = levels - 1;
    for (fps, out) in footprints.chunks(N).zip(out.chunks_mut(N)) {
        let n = fps.len();
        prepare(fps, lod, &mut us, &mut vs, &mut lods);
        let (us, vs, lods) = (&us[..n], &vs[..n], &lods[..n]);
        // Stage 1: levels (u8: at most 32 levels for a 2^31 side; textures are far smaller).
        match kernel.levels {
            Levels::Base => first.level[..n].fill(0),
            Levels::Nearest => {
                for (l, &lod) in first.level[..n].iter_mut().zip(lods) {
                    *l = mip_nearest_level(lod, last) as u8;
                }
            }
            Levels::Linear => {
                let top = last as f32;
                for k in 0..n {
                    // As `mip::trilinear`: `d = clamp(lod, 0, last)`, level `floor(d)`, weight
                    // `d - floor(d)`; NaN gives level 0 and a NaN weight, which reads level 0 only.
                    let d = lods[k].clamp(0.0, top);
                    let (l, fl) = clamped_floor(if d.is_nan() { 0.0 } else { d }, top);
                    first.level[k] = l as u8;
                    second.level[k] = (l as u8 + 1).min(last as u8);
                    delta[k] = d - fl;
                }
            }
        }
        // Stages 2 and 3.
        let size = |l: u8| {
            let l = l as usize & (LEVELS - 1);
            (dims.w[l], dims.h[l])
        };
        first.coordinates(kernel.within, size, us, vs);
        let trilinear = kernel.levels == Levels::Linear;
        if trilinear {
            second.coordinates(kernel.within, size, us, vs);
        }
        for k in 0..n {
            let level = &view(first.level[k]);
            let a = texels(level, addr, kernel.within, &first, k, us[k], vs[k]);
            let c = if trilinear && delta[k] > 0.0 && (first.level[k] as usize) < last {
                let level = &view(second.level[k]);
                let b = texels(level, addr, kernel.within, &second, k, us[k], vs[k]);
                a + (b - a) * delta[k]
            } else {
                a
            };
            out[k] = c.to_array();
        }
    }
}

/// Stage 3 for sample `k` of a pass, in its level `level`: the filtered value.
#[inline(always)]
fn texels<F: Fetch, const N: usize>(
    level: &F,
    addr: &Address,
    within: Within,
    pass: &Pass<N>,
    k: usize,
    u: f32,
    v: f32,
) -> Vec4 {
    let inside = pass.inside[k];
    match within {
        Within::Nearest if inside => level.texel(pass.i[k] as u32, pass.j[k] as u32),
        Within::Nearest => nearest(level, addr, u, v),
        Within::Linear if inside => {
            let [t00, t10, t01, t11] = level.quad(pass.i[k] as u32, pass.j[k] as u32);
            let (a, b) = (pass.a[k], pass.b[k]);
            let top = t00 + (t10 - t00) * a;
            let bottom = t01 + (t11 - t01) * a;
            top + (bottom - top) * b
        }
        Within::Linear => bilinear(level, addr, u, v),
    }
}

/// Scratch for [`probe_sum`]: the probes' coordinates and their two level passes, made once per
/// [`crate::Sampler::sample_batch`] call and reused by every sample (zeroing scratch per sample
/// costs measurable frame time: docs/perf-log.md). Entries beyond a sample's probe count are stale
/// and never read.
pub(crate) struct Probes {
    /// Probe coordinates, written by the caller for the first `n` probes.
    pub u: [f32; CHUNK],
    /// As `u`.
    pub v: [f32; CHUNK],
    fine: Pass<CHUNK>,
    next: Pass<CHUNK>,
}

impl Probes {
    /// Zeroed scratch.
    pub(crate) fn new() -> Self {
        Probes {
            u: [0.0; CHUNK],
            v: [0.0; CHUNK],
            fine: Pass::new(),
            next: Pass::new(),
        }
    }
}

/// The sum over the first `n` anisotropic probes at `(s.u[i], s.v[i])` (`n` at most [`CHUNK`]) of
/// a trilinear sample between levels `k` and `k + 1` with weight `delta`, the coarser level read
/// only when `coarse` (the probes of [`crate::aniso`], staged as above: bit for bit the probe
/// loop's sum).
#[inline]
pub(crate) fn probe_sum<P: Pyramid>(
    p: &P,
    addr: &Address,
    k: usize,
    coarse: bool,
    delta: f32,
    n: usize,
    s: &mut Probes,
) -> Vec4 {
    let n = n.min(CHUNK);
    let (us, vs) = (&s.u[..n], &s.v[..n]);
    let (fine, next) = (&mut s.fine, &mut s.next);
    let mut sum = Vec4::ZERO;
    // Every probe reads the same one or two levels: their views are made once.
    let fine_level = p.level(k);
    let next_level = p.level(if coarse { k + 1 } else { k });
    let size_of = |level: &P::Level<'_>| {
        let (w, h) = level.size();
        (w as f32, h as f32)
    };
    let fine_size = size_of(&fine_level);
    fine.coordinates(Within::Linear, |_| fine_size, us, vs);
    if coarse {
        let next_size = size_of(&next_level);
        next.coordinates(Within::Linear, |_| next_size, us, vs);
    }
    for i in 0..n {
        let a = texels(&fine_level, addr, Within::Linear, fine, i, us[i], vs[i]);
        sum += if coarse {
            a + (texels(&next_level, addr, Within::Linear, next, i, us[i], vs[i]) - a) * delta
        } else {
            a
        };
    }
    sum
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The rounding floor equals `f32::floor` of the clamped value everywhere it is used: level
    /// sides up to `MAX_SIDE`, fractions, negatives clamped to -1, values beyond `hi`.
    #[test]
    fn clamped_floor_is_the_floor() {
        let his = [1.0f32, 2.0, 3.0, 37.0, 1024.0, 16_384.0, MAX_SIDE as f32];
        let mut xs = vec![
            -1e30f32,
            -2.5,
            -1.0,
            -0.999_999_9,
            -1e-30,
            -0.0,
            0.0,
            1e-30,
            0.5,
        ];
        for k in 0..20_000 {
            xs.push(k as f32 * 0.173_205_08 - 3.0);
        }
        for e in [1.0f32, 2.0, 16_384.0, MAX_SIDE as f32] {
            xs.extend([e - 0.5, e - 1e-3 * e.max(1.0).sqrt(), e, e + 0.25, e * 2.0]);
        }
        for &hi in &his {
            for &x in &xs {
                let c = x.max(-1.0).min(hi);
                let (i, f) = clamped_floor(x, hi);
                assert_eq!(f, c.floor(), "x {x} hi {hi}");
                assert_eq!(i as f32, c.floor(), "x {x} hi {hi}");
            }
        }
    }
}
