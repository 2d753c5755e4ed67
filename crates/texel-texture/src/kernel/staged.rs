//! Kernels staged over a chunk of samples: the chunk's arrays ([`Chunk`]), what a kernel offers
//! a staged pass ([`Taps`]) and one level pass over the chunk ([`Pass`]): stage 2, the
//! coordinates, floors, fractions and whether each sample's taps lie inside the level, and stage
//! 3, the loads and blends (wrapped by selects within one texel of an edge, the one-sample kernel
//! beyond). The batched engine (`crate::engine::batch`) and the anisotropic probes
//! ([`crate::technique::aniso`]) drive these passes; the kernels stay bit for bit the one-sample
//! ones.

use glam::{Vec2, Vec4};

use crate::base::address::{Address, AddressMode};
use crate::base::floor::{floor_clamped, floor_index, STAGED_F32_LIMIT};
use crate::base::footprint::{Footprint, Query};
use crate::base::lerp::lerp;
use crate::kernel::LevelFilter;
use crate::storage::fetch::Fetch;
use crate::storage::lanes::Run;

/// Samples per stage (the sampler's chunk).
pub(crate) const CHUNK: usize = 64;

/// Largest level-0 side the staged kernels accept: [`floor_clamped`]'s limit. Larger textures
/// take the one-sample path sample by sample.
pub(crate) const MAX_SIDE: u32 = STAGED_F32_LIMIT as u32;

/// Whether the staged kernels take a level 0 of `(width, height)`: both sides at most
/// [`MAX_SIDE`].
pub(crate) fn staged((w, h): (u32, u32)) -> bool {
    w <= MAX_SIDE && h <= MAX_SIDE
}

/// A chunk of up to `N` queries, as arrays (so the stages vectorise); the first `n` are valid.
/// Entries from `n` on hold stale values of earlier chunks (or their initial values): stage 0
/// ([`queries`]) computes them too, so that its loops have no remainder, and nothing reads them.
pub(crate) struct Chunk<const N: usize> {
    /// Finite `u` ([`finite_uv`]).
    pub u: [f32; N],
    /// Finite `v`.
    pub v: [f32; N],
    /// The isotropic lod (0 for a lod-free sampler).
    pub lod: [f32; N],
    /// The derivatives' lanes `[du/dx, dv/dx, du/dy, dv/dy]`, written by [`queries`] for
    /// samplers that use them ([`Sampler::uses_derivatives`]), with ones from `n` to the next
    /// multiple of 16 so that those lanes have a normal rho^2. For the others they are not
    /// written and never read: NaN from [`Chunk::new`] or an earlier chunk's, so that a filter
    /// that read them by mistake would differ from `sample` with zero derivatives (the tests
    /// compare the two).
    pub d: [[f32; N]; 4],
    /// Valid entries.
    pub n: usize,
}

impl<const N: usize> Chunk<N> {
    pub(crate) fn new() -> Self {
        Chunk {
            u: [0.0; N],
            v: [0.0; N],
            lod: [0.0; N],
            d: [[f32::NAN; N]; 4],
            n: 0,
        }
    }

    /// Footprint `k` of the chunk: finite `u` and `v`, and its derivatives (stale for a sampler
    /// that does not use them, which then reads none: [`Sampler::uses_derivatives`]).
    #[inline(always)]
    pub(crate) fn footprint(&self, k: usize) -> Footprint {
        let [dudx, dvdx, dudy, dvdy] = &self.d;
        Footprint {
            u: self.u[k],
            v: self.v[k],
            dudx: dudx[k],
            dudy: dudy[k],
            dvdx: dvdx[k],
            dvdy: dvdy[k],
        }
    }

    /// Query `k` of the chunk ([`Chunk::footprint`] and its lod).
    #[inline(always)]
    pub(crate) fn query(&self, k: usize) -> Query {
        Query {
            fp: self.footprint(k),
            lod: self.lod[k],
        }
    }

    #[inline(always)]
    pub(crate) fn uv(&self, k: usize) -> Vec2 {
        Vec2::new(self.u[k], self.v[k])
    }
}

/// A within-level filter's staged form: what a level pass needs of it. Implemented next to each
/// one-sample filter, from its own kernels ([`nearest::Point`], [`bilinear::Bilinear`]).
pub(crate) trait Taps: LevelFilter {
    /// Offset of the first tap, in texels: the pass's origin is `u * W - HALF` (the filter's
    /// `origin`; `x - 0` is `x`).
    const HALF: f32;
    /// Taps beyond the first along each axis: a sample is inside when its first tap lies in
    /// `[0, W - REACH)`.
    const REACH: f32;
    /// The value of a sample whose taps lie inside `level`: first tap `(i, j)`, fractions `ab`.
    fn inside<F: Fetch>(level: &F, i: u32, j: u32, ab: (f32, f32)) -> Vec4;
    /// [`Taps::inside`] of each sample of `run` (all inside `level`) into `out` (the run's
    /// length), in one call: `true`, or `false` with `out` untouched where the filter and view
    /// have no run kernel (the default), and the caller runs its per-sample loop.
    #[inline(always)]
    fn inside_run<F: Fetch>(level: &F, run: Run<'_>, out: &mut [[f32; 4]]) -> bool {
        let _ = (level, run, out);
        false
    }
    /// The value of a sample near an edge whose taps the pass wrapped: first taps `i[0]`,
    /// `j[0]`, the next ones `i[1]`, `j[1]` (all inside `level`), fractions `ab`. Bit for bit the
    /// one-sample filter's, which reads the same texels (conventions: the address mode applies to
    /// the integer taps).
    fn wrapped<F: Fetch>(level: &F, i: [u32; 2], j: [u32; 2], ab: (f32, f32)) -> Vec4;
    /// The blend of two levels' values with weight `t` on `b` ([`lerp`]; the fixed-point
    /// filters of [`crate::kernel::fixed8`] round it).
    #[inline(always)]
    fn mix(a: Vec4, b: Vec4, t: f32) -> Vec4 {
        lerp(a, b, t)
    }
}

/// One level pass over a chunk with the within-level filter `T`, under the address modes `addr`:
/// per sample its level, first tap, fractions and whether all its taps lie inside the level.
pub(crate) struct Pass<const N: usize, T> {
    pub(crate) level: [u8; N],
    /// First tap (nearest: the texel).
    pub(crate) i: [i32; N],
    pub(crate) j: [i32; N],
    /// Fractions (bilinear weights).
    pub(crate) a: [f32; N],
    pub(crate) b: [f32; N],
    /// Every tap lies inside the level.
    pub(crate) inside: [bool; N],
    pub(crate) addr: Address,
    /// Neither address mode is `ClampToBorder`, so that taps within one texel of the level wrap
    /// to texels ([`Pass::near`]); and which of the two modes is `Repeat` (not `MirrorRepeat`,
    /// which maps the taps `-1` and `W` as `ClampToEdge` does).
    pub(crate) wraps: bool,
    pub(crate) repeat: (bool, bool),
    pub(crate) taps: T,
}

/// The first tap `i` of a sample near an edge (`-1 <= i < n`, `n` the level's side) and the
/// next one `i + 1`, wrapped into `[0, n)`: by `Repeat` (`-1 -> n - 1`, `n -> 0`) where
/// `repeat`, else as `ClampToEdge`, `MirrorRepeat` and `MirrorClampToEdge` all map these two
/// indices (`-1 -> 0`, `n -> n - 1`; [`crate::base::address::AddressMode::wrap`]): two selects, no
/// division.
#[inline(always)]
pub(crate) fn wrap_pair(i: i32, n: i32, repeat: bool) -> (i32, i32) {
    let first = if i < 0 {
        if repeat {
            n - 1
        } else {
            0
        }
    } else {
        i
    };
    let second = if i + 1 >= n {
        if repeat {
            0
        } else {
            n - 1
        }
    } else {
        i + 1
    };
    (first, second)
}

impl<const N: usize, T: Taps> Pass<N, T> {
    /// Apply the address modes `addr` (and the flags derived from them) to later passes.
    pub(crate) fn set_address(&mut self, addr: Address) {
        self.addr = addr;
        self.wraps = addr.u != AddressMode::ClampToBorder && addr.v != AddressMode::ClampToBorder;
        self.repeat = (addr.u == AddressMode::Repeat, addr.v == AddressMode::Repeat);
    }

    pub(crate) fn new(taps: T, addr: Address) -> Self {
        let mut pass = Pass {
            level: [0; N],
            i: [0; N],
            j: [0; N],
            a: [0.0; N],
            b: [0.0; N],
            inside: [false; N],
            addr,
            wraps: false,
            repeat: (false, false),
            taps,
        };
        pass.set_address(addr);
        pass
    }

    /// Stage 2 for the chunk's samples at their `level`s, whose sizes `size(level)` gives:
    /// the filter's origin and the staged floor, branch-free, with no calls.
    #[inline(always)]
    pub(crate) fn coordinates(&mut self, size: impl Fn(u8) -> (f32, f32), us: &[f32], vs: &[f32]) {
        for k in 0..us.len() {
            let (w, h) = size(self.level[k]);
            let (x, y) = (us[k] * w - T::HALF, vs[k] * h - T::HALF);
            let (i, fi) = floor_clamped(x, w);
            let (j, fj) = floor_clamped(y, h);
            self.i[k] = i;
            self.j[k] = j;
            self.a[k] = x - fi;
            self.b[k] = y - fj;
            self.inside[k] = fi >= 0.0 && fi < w - T::REACH && fj >= 0.0 && fj < h - T::REACH;
        }
    }

    /// The wrapped taps `([i, i + 1], [j, j + 1])` of sample `k` (not inside) of a level
    /// `w` x `h` texels, when its origin lies within one texel of the level, `-1 <= x < w` and
    /// `-1 <= y < h`, and the address modes map such taps to texels (all but `ClampToBorder`);
    /// else `None`. There [`floor_clamped`]'s clamp is the identity, so `i` is `floor(x)` and the
    /// fractions are the one-sample filter's; an origin below -1 is clamped to -1 and leaves a
    /// negative fraction, one at or beyond `w` the index `w`. Decided per sample, from what
    /// [`Pass::coordinates`] stored: computed there for every sample, the wrapped taps cost more
    /// than the edge route saved (docs/decisions.md).
    #[inline(always)]
    pub(crate) fn near(&self, (w, h): (u32, u32), k: usize) -> Option<([u32; 2], [u32; 2])> {
        let (i, j, w, h) = (self.i[k], self.j[k], w as i32, h as i32);
        let near = i >= -1 && i < w && j >= -1 && j < h;
        if !(self.wraps && near && self.a[k] >= 0.0 && self.b[k] >= 0.0) {
            return None;
        }
        let ((i0, i1), (j0, j1)) = (
            wrap_pair(i, w, self.repeat.0),
            wrap_pair(j, h, self.repeat.1),
        );
        Some(([i0 as u32, i1 as u32], [j0 as u32, j1 as u32]))
    }

    /// Whether the first `n` samples all lie inside their levels (their taps need no wrapping):
    /// a fold over the flags, which compares them in vector lanes, no branch per sample.
    #[inline(always)]
    pub(crate) fn all_inside(&self, n: usize) -> bool {
        self.inside[..n]
            .iter()
            .fold(true, |all, &inside| all & inside)
    }

    /// Stage 3 for sample `k`, which lies inside `level` ([`Pass::filtered`]'s first route).
    /// Stage 3's loops take this route alone when every sample of the chunk is inside
    /// ([`Pass::all_inside`]): that loop has no per-sample test and no edge-route code, and
    /// reloads fewer of its invariants from the stack per sample (four of the three-route loop's
    /// six remain), so fewer instructions a sample (docs/decisions.md).
    #[inline(always)]
    pub(crate) fn inside_value<F: Fetch>(&self, level: &F, k: usize) -> Vec4 {
        let ab = (self.a[k], self.b[k]);
        T::inside(level, self.i[k] as u32, self.j[k] as u32, ab)
    }

    /// Stage 2's results for the first `n` samples, as a [`Run`] for [`Taps::inside_run`].
    #[inline(always)]
    pub(crate) fn run(&self, n: usize) -> Run<'_> {
        Run {
            i: &self.i[..n],
            j: &self.j[..n],
            a: &self.a[..n],
            b: &self.b[..n],
        }
    }

    /// Stage 3 for sample `k` at `uv`, in its level `level`: the filtered value. Four routes,
    /// the same value from each: every tap inside the level; within one texel of it
    /// ([`Pass::near`]: the taps wrapped by two selects each); farther out under `Repeat` on both
    /// axes of a power-of-two level ([`Pass::far_repeat`]: the taps wrapped by masks);
    /// elsewhere, or under `ClampToBorder`, the one-sample filter, which wraps its taps in `i64`
    /// (`rem_euclid`).
    #[inline(always)]
    pub(crate) fn filtered<F: Fetch>(&self, level: &F, k: usize, uv: Vec2) -> Vec4 {
        if self.inside[k] {
            self.inside_value(level, k)
        } else if let Some((i, j)) = self.near(level.size(), k) {
            T::wrapped(level, i, j, (self.a[k], self.b[k]))
        } else if let Some((i, j, ab)) = self.far_repeat(level.size(), uv) {
            T::wrapped(level, i, j, ab)
        } else {
            self.taps.filter(level, &self.addr, uv)
        }
    }

    /// The wrapped taps `([i, i + 1], [j, j + 1])` and fractions of a sample at `uv` in a level of
    /// `w` x `h` texels when both address modes are `Repeat` and both sides powers of two (every
    /// level of a power-of-two texture), else `None`: the one-sample filter's own arithmetic
    /// (origin `uv * size - HALF`, [`floor_index`], the fraction `x - floor`, the next tap by
    /// `saturating_add`), with `Repeat`'s `rem_euclid` as a mask (`i & (w - 1)` is the remainder
    /// for a power-of-two `w`, for negative `i` too). So the value is the one-sample filter's bit
    /// for bit, without its four divisions and border tests. Reached by samples more than a
    /// texel outside the level: anisotropic probes spread half a major axis beyond their sample,
    /// over several periods of a repeating texture near the ground's horizon (docs/decisions.md,
    /// "`Repeat` on power-of-two sides wraps by masks").
    #[inline(always)]
    pub(crate) fn far_repeat(&self, (w, h): (u32, u32), uv: Vec2) -> Option<WrappedTaps> {
        let pow2 = w.is_power_of_two() && h.is_power_of_two();
        if !(self.repeat.0 && self.repeat.1 && pow2) {
            return None;
        }
        let (x, y) = (uv.x * w as f32 - T::HALF, uv.y * h as f32 - T::HALF);
        let (i0, j0) = (floor_index(x), floor_index(y));
        let ab = (x - i0 as f32, y - j0 as f32);
        let (mw, mh) = (i64::from(w) - 1, i64::from(h) - 1);
        let i = [i0 & mw, i0.saturating_add(1) & mw].map(|i| i as u32);
        let j = [j0 & mh, j0.saturating_add(1) & mh].map(|j| j as u32);
        Some((i, j, ab))
    }
}

/// A sample's taps wrapped into a level, `([i, i + 1], [j, j + 1])`, and its fractions `(a, b)`
/// ([`Pass::far_repeat`]).
pub(crate) type WrappedTaps = ([u32; 2], [u32; 2], (f32, f32));
