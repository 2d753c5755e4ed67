//! The batched path behind [`crate::Sampler::sample_batch`]: the same kernels as the one-sample
//! path ([`crate::kernel::bilinear`], [`crate::kernel::nearest`], [`crate::technique::mip`]), staged over a chunk of samples.
//!
//! The one-sample path ([`crate::Sampler::sample`]) walks one sample through its query (uv made
//! finite, the lod), level choice, texel set-up, loads and blends: one long dependency chain per
//! sample. Here a chunk of samples goes through the same steps in stages, each a short loop over the
//! chunk whose iterations are independent, so they pipeline and (stages 0 to 2) vectorise:
//!
//! 0. [`queries`]: every sample's finite `uv` and lod;
//! 1. levels: `mip::nearest_level_staged` or `mip::linear_levels_staged` per sample;
//! 2. `Pass::coordinates`: per level pass, the filter's origin (`u * W`, or `u * W - 1/2` for
//!    bilinear), its floor ([`floor_clamped`], the staged floor), the fractions, and whether every
//!    texel the sample reads lies inside the level;
//! 3. `Pass::filtered`: loads and the blend for the samples inside the level; those within one
//!    texel of it (`Pass::near`) read their taps wrapped by selects; the rest, and any under
//!    `ClampToBorder`, call the one-sample filter with its address wrapping.
//!
//! The filters enter through [`Taps`], which `nearest.rs` and `bilinear.rs` implement with their
//! own kernels (`bilinear::blend`, `bilinear::bilinear`, ...).
//!
//! Every stage calls the one-sample path's kernels with the same operands, so the results are bit
//! for bit those of [`crate::Sampler::sample`] (`tests/core.rs`, `batch_equals_single`, over every
//! filter, mipmap mode, address mode and texel format). The staged floor agrees with the scalar one
//! because coordinates are clamped to `[-1, W]` first: inside that range it is the floor, and the
//! floor of the clamped value lies in `[0, W)` exactly when the floor of `x` does; for samples
//! inside the level the clamp is the identity, so the fractions are the one-sample path's.
//!
//! Short calls (at most 16 footprints: a small triangle's fragments) run with 16-sample scratch:
//! zeroing and filling 64-sample scratch (about 6 KB per call) costs more than sampling a small
//! triangle's few pixels (figures in docs/decisions.md).

use glam::{Vec2, Vec4};

use crate::base::address::Address;
use crate::base::filter::{FilterMode, MipmapFilterMode};
use crate::base::floor::floor_clamped;
use crate::base::footprint::{finite_uv, lod_from_rho_squared, log2_normal, rho_squared};
use crate::base::footprint_batch::{chunks, Source};
use crate::base::lerp::lerp;
use crate::engine::dispatch::{self, Kernel};
use crate::engine::sampler::Sampler;
use crate::kernel::bilinear::Bilinear;
use crate::kernel::fixed8::{Bilinear8, Point8};
use crate::kernel::nearest::Point;
use crate::kernel::staged::{Chunk, Pass, Taps, CHUNK};
use crate::kernel::LevelFilter;
use crate::storage::fetch::Fetch;
use crate::storage::lanes::Lanes;
use crate::storage::view::Pyramid;
use crate::technique::mip;

/// Level views kept per call: a power of two above the 23 levels of a [`MAX_SIDE`] texture, so
/// that `% LEVELS` is a mask.
const LEVELS: usize = 32;

/// Stage 0: the queries of `fps` (at most `N`) on a `size` level 0, as `Sampler::query` makes one:
/// [`finite_uv`], and `rho^2` ([`rho_squared`]) into [`lod_from_rho_squared`] with
/// [`crate::base::footprint::fast_log2`]'s normal-input path written branch-free, so the loop
/// vectorises. The inputs that path does not cover (`rho^2` zero or subnormal) are rare; a second
/// loop recomputes those lanes with the scalar functions.
///
/// The footprints are first copied into the chunk's lanes (one array per field), and the lod
/// arithmetic then runs over the lanes rounded up to a multiple of 16 (at most `N`; the entries beyond `n` are ones or stale and unread), so that it
/// vectorises at the full width with no remainder loop: read from the 24-byte structs, the lod
/// loop ran four lanes wide plus a scalar remainder (docs/decisions.md).
#[inline(always)]
pub(crate) fn queries<S: Source, const N: usize>(
    s: &Sampler,
    size: (u32, u32),
    fps: S,
    out: &mut Chunk<N>,
) {
    let n = fps.len();
    debug_assert!(n <= N, "a chunk holds at most N footprints");
    out.n = n;
    let deriv = s.uses_derivatives();
    let lanes = n.next_multiple_of(16).min(N);
    let [dudx, dvdx, dudy, dvdy] = &mut out.d;
    fps.uv_into(&mut out.u[..n], &mut out.v[..n]);
    if deriv {
        // Lod-free samplers skip this: they read no derivatives, and copying them anyway costs
        // bilinear frames time (docs/decisions.md).
        fps.derivatives_into([
            &mut dudx[..n],
            &mut dvdx[..n],
            &mut dudy[..n],
            &mut dvdy[..n],
        ]);
        // Ones, not zeros (nor an earlier chunk's values), up to `lanes`, so that those lanes
        // have a normal rho^2 (zeros would send every chunk shorter than a multiple of 16
        // through the scalar recomputation below).
        for lane in [&mut *dudx, &mut *dvdx, &mut *dudy, &mut *dvdy] {
            lane[n..lanes].fill(1.0);
        }
    }
    for (u, v) in out.u[..lanes].iter_mut().zip(&mut out.v[..lanes]) {
        *u = finite_uv(*u);
        *v = finite_uv(*v);
    }
    if !deriv {
        out.lod[..n].fill(0.0);
        return;
    }
    let d = s.descriptor();
    let (bias, min, max) = (d.lod_bias, d.lod_min_clamp, d.lod_max_clamp);
    let (w, h) = (size.0 as f32, size.1 as f32);
    let mut special = false;
    // Zipped slices, not indices (indexing four arrays, the loop did not vectorise).
    let lods = out.lod[..lanes].iter_mut().zip(&dudx[..lanes]);
    let lods = lods
        .zip(&dvdx[..lanes])
        .zip(&dudy[..lanes])
        .zip(&dvdy[..lanes]);
    for ((((lod, &dudx), &dvdx), &dudy), &dvdy) in lods {
        // `rho_squared`: the squared lengths of the texel-space axes, +inf if either is not finite.
        let (ax, ay) = (dudx * w, dvdx * h);
        let (bx, by) = (dudy * w, dvdy * h);
        let a = ax * ax + ay * ay;
        let b = bx * bx + by * by;
        let finite = a.is_finite() & b.is_finite();
        let rho2 = a.max(b);
        // `lod_from_rho_squared` with `fast_log2` for normal positive input; non-finite rho^2
        // gives lod_max.
        let l = (0.5 * log2_normal(rho2) + bias).clamp(min, max);
        *lod = if finite { l } else { max };
        special |= finite & (rho2 < f32::MIN_POSITIVE);
    }
    if special {
        for k in 0..n {
            let rho2 = rho_squared(&out.footprint(k), size.0, size.1);
            if rho2 < f32::MIN_POSITIVE {
                out.lod[k] = lod_from_rho_squared(rho2, bias, min, max);
            }
        }
    }
}

/// Probes gathered from several samples before they are filtered ([`anisotropic`]).
const PROBES: usize = 256;

/// Anisotropic filtering of `footprints` into `out` for a sampler whose technique is
/// anisotropic (its mag, min and mipmap filters all `Linear`: `Sampler::new`), on a pyramid whose
/// level 0 is at most [`MAX_SIDE`] per side: per chunk the queries ([`queries`]) and probe plans
/// ([`crate::technique::aniso::plan_chunk`]); every sample then lays its probes out in shared scratch, up to
/// [`PROBES`] from several samples, which are filtered together, stage by stage, as [`run`]
/// filters trilinear samples (so the lods, floors and texel loads of many probes pipeline, where
/// one sample's few probes did not). Two such batches are kept, each for the probes of one pair
/// of levels, so that samples alternating between two pairs (lods near an integer) do not make
/// one batch of mixed levels. A sample with more than one probe (and a positive lod) has
/// [`crate::technique::aniso::filter_planned`]'s probes; one with a single probe (an isotropic footprint) is
/// one probe at its `uv` and isotropic lod (`mip::trilinear`); a magnified one (`lod <= 0`) is
/// one probe in level 0 alone (the `Linear` mag filter, bilinear). Bit for bit
/// [`crate::Sampler::filter`]: the same probe positions, levels and blends, each sample's probes
/// summed in order from zero (a single probe from `-0.0`, which adds as the identity), times
/// `1 / N`.
#[inline(always)]
pub(crate) fn anisotropic<P: Pyramid, S: Source>(
    p: &P,
    s: &Sampler,
    (footprints, out): (S, &mut [[f32; 4]]),
) {
    let size0 = p.level(0).size();
    let last = p.level_count() - 1;
    let levels = p.level_count().min(LEVELS);
    let (mut dims_w, mut dims_h) = ([0.0f32; LEVELS], [0.0f32; LEVELS]);
    let mut views = [p.level(0); LEVELS];
    for (l, view) in views.iter_mut().enumerate().take(levels) {
        *view = p.level(l);
        let (w, h) = view.size();
        (dims_w[l], dims_h[l]) = (w as f32, h as f32);
    }
    let size = |l: u8| {
        let l = l as usize & (LEVELS - 1);
        (dims_w[l], dims_h[l])
    };
    let mut chunk = Chunk::<CHUNK>::new();
    let mut plans = [crate::technique::aniso::Plan::default(); CHUNK];
    // The probe scratch (about 13 KB) is reused from the thread's last call rather than made and
    // zeroed per call: a mesh of small triangles makes one call per triangle and tile, where that
    // set-up would be a large share of aniso16's work (docs/decisions.md).
    // Two batches, each for the probes of one pair of levels: neighbouring samples whose lods
    // straddle a level (a lod near an integer) alternate between two pairs, and one batch would
    // mix them, which takes the per-probe level path (docs/decisions.md).
    let mut slots = [ProbeBatch::take(s.address()), ProbeBatch::take(s.address())];
    // Which slot's batch began first: the one flushed when neither holds a sample's pair.
    let mut older = 0usize;
    // Per sample of the chunk: its probes' sum, and `1 / N`.
    let mut sums = [Vec4::ZERO; CHUNK];
    let mut inv = [0.0f32; CHUNK];
    let finite = |x: f32| if x.is_finite() { x } else { 0.0 };
    for (fps, out) in chunks(footprints, CHUNK).zip(out.chunks_mut(CHUNK)) {
        queries(s, size0, fps, &mut chunk);
        crate::technique::aniso::plan_chunk(s.params(), size0, &chunk, &mut plans);
        for k in 0..fps.len() {
            let (q, plan) = (chunk.query(k), &plans[k]);
            // A sample with one probe at its `uv` (finite: `queries`): magnified, the `Linear`
            // mag filter in level 0 (`Sampler::filter`); else trilinear at the isotropic lod
            // (`filter_planned` with `N = 1`). Its sum starts at `-0.0`, so that it is the
            // probe's value bit for bit (`+0.0 + -0.0` would be `+0.0`). Otherwise
            // `filter_planned`'s probes (`n <= 64`: `plan`), summed from zero.
            let single = !(q.lod > 0.0 && plan.n > 1);
            let (n, (l, delta)) = if !single {
                inv[k] = 1.0 / plan.n as f32;
                sums[k] = Vec4::ZERO;
                let n = (plan.n as usize).min(CHUNK);
                (n, mip::linear_levels(plan.lod, last))
            } else {
                inv[k] = 1.0;
                sums[k] = Vec4::splat(-0.0);
                let levels = if q.lod > 0.0 {
                    mip::linear_levels(q.lod, last)
                } else {
                    (0, 0.0)
                };
                (1, levels)
            };
            let coarse = delta > 0.0 && l < last;
            let pair = (l as u8, if coarse { l + 1 } else { l } as u8);
            // The slot holding this pair, or an empty one; else the older batch is flushed.
            let holds = |b: &ProbeBatch| b.m > 0 && b.pair == pair;
            let slot = if holds(&slots[0]) {
                0
            } else if holds(&slots[1]) {
                1
            } else if slots[0].m == 0 {
                0
            } else if slots[1].m == 0 {
                1
            } else {
                slots[older].flush(&views, size, &mut sums);
                older
            };
            let p = &mut *slots[slot];
            if p.m + n > PROBES {
                p.flush(&views, size, &mut sums);
            }
            if p.m == 0 {
                // A new batch: the other slot's (if any) began first.
                older = 1 - slot;
            }
            p.sample(k, pair, (delta, coarse));
            let m = p.m;
            if single {
                (p.at.u[m], p.at.v[m], p.owner[m]) = (q.fp.u, q.fp.v, k as u8);
                p.m = m + 1;
                continue;
            }
            // The probes' positions and owners in one loop over lanes; the sample's levels,
            // weight and coarse flag are recorded once, above, not per probe (docs/decisions.md).
            let invk = inv[k];
            let (us, vs) = (&mut p.at.u[m..m + n], &mut p.at.v[m..m + n]);
            let lanes = us.iter_mut().zip(vs).zip(&mut p.owner[m..m + n]);
            // `i` counts in `i32` rather than `usize` (exact either way) so that the conversion
            // vectorises.
            for (i, ((pu, pv), o)) in (0..n as i32).zip(lanes) {
                let t = (i as f32 + 0.5) * invk - 0.5;
                *pu = finite(q.fp.u + t * plan.axis.x);
                *pv = finite(q.fp.v + t * plan.axis.y);
                *o = k as u8;
            }
            p.m = m + n;
        }
        for p in &mut slots {
            p.flush(&views, size, &mut sums);
        }
        for (k, o) in out.iter_mut().enumerate().take(fps.len()) {
            *o = (sums[k] * inv[k]).to_array();
        }
    }
    let [a, b] = slots;
    a.give_back();
    b.give_back();
}

thread_local! {
    /// Each thread's probe scratch between [`anisotropic`] calls ([`ProbeBatch::take`]): the
    /// batches the last call gave back (two).
    static PROBE_SCRATCH: std::cell::RefCell<Vec<Box<ProbeBatch>>> =
        const { std::cell::RefCell::new(Vec::new()) };
}

/// [`anisotropic`]'s probe scratch: up to [`PROBES`] probes with their positions and the sample
/// they belong to (`owner`, an index into the chunk), and per sample of the chunk its two levels,
/// blend weight and whether the coarser level is weighed. Each probe's levels (`fine.level`,
/// `next.level`) are filled from its sample's only when a batch mixes levels.
struct ProbeBatch {
    m: usize,
    at: Chunk<PROBES>,
    fine: Pass<PROBES, Bilinear>,
    next: Pass<PROBES, Bilinear>,
    owner: [u8; PROBES],
    /// Stage 3's values of the probes in the finer and the coarser level
    /// ([`ProbeBatch::sum_runs`]; written before they are read).
    values: [[f32; 4]; PROBES],
    coarse_values: [[f32; 4]; PROBES],
    /// Per sample: the finer and the coarser level read.
    levels: [(u8, u8); CHUNK],
    delta: [f32; CHUNK],
    coarse: [bool; CHUNK],
    /// The first sample's levels in this batch, and whether a later sample's differ.
    pair: (u8, u8),
    mixed: bool,
}

impl ProbeBatch {
    /// The thread's probe scratch, empty and set to the address modes `addr`: one of the two the
    /// thread's last [`anisotropic`] call gave back ([`ProbeBatch::give_back`]), or a new one.
    /// Its arrays keep the last call's entries, which are stale and never used: the count `m` is
    /// reset here, and with it empty the batch's `pair` and `mixed` are set by the first
    /// [`ProbeBatch::sample`]; a sample's levels, weight and flag are written by
    /// [`ProbeBatch::sample`] and a probe's position and owner as it is added, before any read;
    /// the passes' fractions, taps and inside flags by [`Pass::coordinates`] before stage 3; the
    /// passes' per-probe levels are filled from their samples' in a batch that mixes levels, and
    /// in one that does not they are read by `coordinates` but its size closure ignores them.
    /// During thread-local teardown (no slot) the scratch is new, as before.
    #[inline(always)]
    fn take(addr: Address) -> Box<ProbeBatch> {
        let cached = PROBE_SCRATCH
            .try_with(|c| c.borrow_mut().pop())
            .ok()
            .flatten();
        match cached {
            Some(mut p) => {
                p.m = 0;
                p.fine.set_address(addr);
                p.next.set_address(addr);
                p
            }
            None => ProbeBatch::new(addr),
        }
    }

    /// Keep this scratch for the thread's next [`anisotropic`] call (dropped instead during
    /// thread-local teardown).
    #[inline(always)]
    fn give_back(self: Box<Self>) {
        // `try_with` fails only while the thread's locals are being destroyed. At most two are
        // kept (what one call takes).
        let _ = PROBE_SCRATCH.try_with(|c| {
            let mut kept = c.borrow_mut();
            if kept.len() < 2 {
                kept.push(self);
            }
        });
    }

    fn new(addr: Address) -> Box<ProbeBatch> {
        Box::new(ProbeBatch {
            m: 0,
            at: Chunk::new(),
            fine: Pass::new(Bilinear, addr),
            next: Pass::new(Bilinear, addr),
            owner: [0; PROBES],
            values: [[0.0; 4]; PROBES],
            coarse_values: [[0.0; 4]; PROBES],
            levels: [(0, 0); CHUNK],
            delta: [0.0; CHUNK],
            coarse: [false; CHUNK],
            pair: (0, 0),
            mixed: false,
        })
    }

    /// Record sample `k`'s levels `pair` (finer, coarser), blend weight and whether the coarser
    /// level is weighed, before its probes are added.
    #[inline(always)]
    fn sample(&mut self, k: usize, pair: (u8, u8), (delta, coarse): (f32, bool)) {
        self.levels[k] = pair;
        self.delta[k] = delta;
        self.coarse[k] = coarse;
        if self.m == 0 {
            (self.pair, self.mixed) = (pair, false);
        } else {
            self.mixed |= pair != self.pair;
        }
    }

    /// Filter the gathered probes and add each, in order, to its sample's sum: `Probes::trilinear_sum`'s
    /// stages (the finer level's bilinear sample, blended with the coarser one's by `delta` where
    /// weighed) over probes of several samples. Empties the batch.
    #[inline(always)]
    fn flush<F: Fetch>(
        &mut self,
        views: &[F; LEVELS],
        size: impl Fn(u8) -> (f32, f32),
        sums: &mut [Vec4; CHUNK],
    ) {
        let m = self.m;
        if m == 0 {
            return;
        }
        let (us, vs) = (&self.at.u[..m], &self.at.v[..m]);
        let (l0, l1) = self.pair;
        let level = |l: u8| &views[l as usize & (LEVELS - 1)];
        if !self.mixed {
            // Every probe in the same two levels: views and sizes looked up once (as `run_in`).
            let (s0, s1) = (size(l0), size(l1));
            self.fine.coordinates(|_| s0, us, vs);
            self.next.coordinates(|_| s1, us, vs);
            let (fine, next) = (level(l0), level(l1));
            if !self.sum_runs(m, (fine, next), sums) {
                self.sum_into(m, |_| fine, |_| next, sums);
            }
        } else {
            for (k, &o) in self.owner[..m].iter().enumerate() {
                (self.fine.level[k], self.next.level[k]) = self.levels[o as usize];
            }
            self.fine.coordinates(&size, us, vs);
            self.next.coordinates(&size, us, vs);
            let (fine, next) = (&self.fine.level, &self.next.level);
            self.sum_into(m, |k| level(fine[k]), |k| level(next[k]), sums);
        }
        self.m = 0;
    }

    /// Stage 3 of the first `m` probes, all in the levels `fine` and `next` (the same for every
    /// sample of the batch, so that every sample weighs the coarser level, or none does: a
    /// sample's pair is `(l, l + 1)` exactly when it is weighed), through the views' run
    /// kernels ([`Taps::inside_run`]) where every probe lies inside both levels read: the finer
    /// level's values, the coarser level's where weighed, then each probe's blend added in order
    /// to its sample's sum. The values of [`ProbeBatch::sum_into`] bit for bit (the run kernels
    /// are the inside route's, [`lerp`] the same blend), without its per-probe route and blend
    /// tests. `false`, with nothing added, where a probe lies outside or the views have no run
    /// kernel; the caller then runs [`ProbeBatch::sum_into`] (taking runs of inside probes
    /// through the kernel and the rest through their routes is slower, docs/decisions.md).
    #[inline(always)]
    fn sum_runs<F: Fetch>(
        &mut self,
        m: usize,
        (fine, next): (&F, &F),
        sums: &mut [Vec4; CHUNK],
    ) -> bool {
        let coarse = self.pair.0 != self.pair.1;
        if !(self.fine.all_inside(m) && (!coarse || self.next.all_inside(m))) {
            return false;
        }
        let values = &mut self.values[..m];
        if !Bilinear::inside_run(fine, self.fine.run(m), values) {
            return false;
        }
        if coarse {
            let coarse_values = &mut self.coarse_values[..m];
            // Both levels are views of one pyramid: the second has a run kernel too.
            Bilinear::inside_run(next, self.next.run(m), coarse_values);
            let probes = self.owner[..m].iter().zip(values.iter());
            for ((&o, a), b) in probes.zip(coarse_values.iter()) {
                let o = o as usize % CHUNK;
                let (a, b) = (Vec4::from_array(*a), Vec4::from_array(*b));
                sums[o] += lerp(a, b, self.delta[o]);
            }
        } else {
            for (&o, a) in self.owner[..m].iter().zip(values.iter()) {
                sums[o as usize % CHUNK] += Vec4::from_array(*a);
            }
        }
        true
    }

    /// Stage 3 of the first `m` probes, each probe's level view given by `fine(k)` and
    /// `next(k)`: the finer level's bilinear sample, blended with the coarser one's by `delta`
    /// where weighed, added in order to its sample's sum.
    #[inline(always)]
    fn sum_into<'v, F: Fetch + 'v>(
        &self,
        m: usize,
        fine: impl Fn(usize) -> &'v F,
        next: impl Fn(usize) -> &'v F,
        sums: &mut [Vec4; CHUNK],
    ) {
        for k in 0..m {
            let uv = self.at.uv(k);
            let o = self.owner[k] as usize % CHUNK;
            let a = self.fine.filtered(fine(k), k, uv);
            let value = if self.coarse[o] {
                lerp(a, self.next.filtered(next(k), k, uv), self.delta[o])
            } else {
                a
            };
            sums[o] += value;
        }
    }
}

/// Nearest sampling of `level` (level 0 of a lod-free sampler: `mipmap_filter` None, both
/// filters nearest) as stored bytes: [`run`] with [`Point`] in one level, bit for bit, without
/// the decode to codes and back. Per sample the same query ([`finite_uv`]), origin,
/// [`floor_clamped`] and inside test as [`Pass::coordinates`]; inside the level the texel's
/// bytes are copied, elsewhere [`Point`]'s one-sample filter (address wrapping, border codes
/// in `addr`) gives the codes. The indices of a chunk are computed in one loop that vectorises,
/// then the texels are copied.
/// On the instruction set's copy for the CPU ([`crate::engine::dispatch`]).
pub(crate) fn point_bytes<S: Source>(
    level: &crate::storage::fetch::Level<'_, crate::storage::fetch::Codes8>,
    addr: &Address,
    footprints: S,
    out: &mut [[u8; 4]],
) {
    dispatch::run(PointBytesJob {
        level,
        addr,
        footprints,
        out,
    });
}

/// [`point_bytes`]' arguments, as the dispatcher's unit of work.
struct PointBytesJob<'j, 'l, S> {
    level: &'j crate::storage::fetch::Level<'l, crate::storage::fetch::Codes8>,
    addr: &'j Address,
    footprints: S,
    out: &'j mut [[u8; 4]],
}

impl<S: Source> Kernel for PointBytesJob<'_, '_, S> {
    type Output = ();
    #[inline(always)]
    fn run(self, _lanes: Lanes) {
        point_bytes_in(self.level, self.addr, self.footprints, self.out);
    }
}

/// [`point_bytes`]' body.
#[inline(always)]
fn point_bytes_in<S: Source>(
    level: &crate::storage::fetch::Level<'_, crate::storage::fetch::Codes8>,
    addr: &Address,
    footprints: S,
    out: &mut [[u8; 4]],
) {
    let (w, h) = level.size();
    let (wf, hf) = (w as f32, h as f32);
    let (mut ii, mut jj) = ([0i32; CHUNK], [0i32; CHUNK]);
    let (mut us, mut vs) = ([0.0f32; CHUNK], [0.0f32; CHUNK]);
    let mut inside = [false; CHUNK];
    for (fps, out) in chunks(footprints, CHUNK).zip(out.chunks_mut(CHUNK)) {
        let n = fps.len();
        fps.uv_into(&mut us[..n], &mut vs[..n]);
        for k in 0..n {
            let (u, v) = (finite_uv(us[k]), finite_uv(vs[k]));
            let (x, y) = (u * wf - Point::HALF, v * hf - Point::HALF);
            let (i, fi) = floor_clamped(x, wf);
            let (j, fj) = floor_clamped(y, hf);
            ii[k] = i;
            jj[k] = j;
            inside[k] = fi >= 0.0 && fi < wf - Point::REACH && fj >= 0.0 && fj < hf - Point::REACH;
        }
        for (k, o) in out.iter_mut().enumerate() {
            *o = if inside[k] {
                level.texels[jj[k] as u32 as usize * w as usize + ii[k] as u32 as usize]
            } else {
                let uv = Vec2::new(finite_uv(us[k]), finite_uv(vs[k]));
                let c = Point.filter(level, addr, uv).to_array();
                crate::base::floor::integer_bytes4(c)
            };
        }
    }
}

/// Filter `footprints` into `out` (same length) with `s`'s core kernel: `min_filter` Nearest or
/// Linear (equal to `mag_filter`), any `mipmap_filter`, level 0 below [`MAX_SIDE`] per side
/// (`Sampler::new` decides; see `Sampler::sample_batch`). Texels outside the level under
/// `ClampToBorder` read `addr.border` (the sampler's own address, or for the stored-codes paths
/// its border colour as codes).
#[inline(always)]
pub(crate) fn run<P: Pyramid, S: Source>(
    p: &P,
    s: &Sampler,
    addr: Address,
    footprints: S,
    out: &mut [[f32; 4]],
) {
    run_taps(p, (Point, Bilinear), s, addr, (footprints, out));
}

/// [`run`] with [`crate::kernel::fixed8`]'s fixed-point filters, on a pyramid of stored codes. A function
/// of its own, not a flag of [`run`]: each pairing of a pyramid with a filter is compiled as a
/// kernel per instruction set, and the float pyramids never take these filters.
#[inline(always)]
pub(crate) fn run_fixed<P: Pyramid, S: Source>(
    p: &P,
    s: &Sampler,
    addr: Address,
    footprints: S,
    out: &mut [[f32; 4]],
) {
    run_taps(p, (Point8, Bilinear8), s, addr, (footprints, out));
}

/// [`run`] with `near` where `min_filter` is Nearest, else `linear`.
#[inline(always)]
fn run_taps<P: Pyramid, S: Source, N: Taps, L: Taps>(
    p: &P,
    (near, linear): (N, L),
    s: &Sampler,
    addr: Address,
    io: (S, &mut [[f32; 4]]),
) {
    match s.descriptor().min_filter {
        FilterMode::Nearest => run_with(p, near, s, addr, io),
        _ => run_with(p, linear, s, addr, io),
    }
}

/// [`run`] with the within-level filter `T`, on the instruction set's copy for the CPU
/// ([`crate::engine::dispatch`]: one function per pyramid, filter and copy).
#[inline(always)]
fn run_with<P: Pyramid, S: Source, T: Taps>(
    p: &P,
    taps: T,
    s: &Sampler,
    addr: Address,
    (footprints, out): (S, &mut [[f32; 4]]),
) {
    let job = RunJob {
        p,
        taps,
        s,
        addr,
        footprints,
        out,
    };
    dispatch::run(job);
}

/// [`run_with`]'s arguments, as the dispatcher's unit of work.
struct RunJob<'j, P, S, T> {
    p: &'j P,
    taps: T,
    s: &'j Sampler,
    addr: Address,
    footprints: S,
    out: &'j mut [[f32; 4]],
}

impl<P: Pyramid, S: Source, T: Taps> Kernel for RunJob<'_, P, S, T> {
    type Output = ();
    /// Ignores `lanes`: a linear 8-bit pyramid carries its quad kernel (`fetch::Unorm8`).
    #[inline(always)]
    fn run(self, _lanes: Lanes) {
        let (p, taps, s, addr) = (self.p, self.taps, self.s, self.addr);
        let io = (self.footprints, self.out);
        if io.0.len() <= 16 {
            run_in::<P, S, T, 16, 1>(p, taps, s, addr, io);
        } else {
            run_in::<P, S, T, CHUNK, LEVELS>(p, taps, s, addr, io);
        }
    }
}

/// [`run`] in chunks of `N` samples, with `V` level views made up front (`V = LEVELS`), or (`V = 1`)
/// each sample's view made when it is read, which is cheaper for a handful of samples than making
/// 32 views.
#[inline(always)]
fn run_in<P: Pyramid, S: Source, T: Taps, const N: usize, const V: usize>(
    p: &P,
    taps: T,
    s: &Sampler,
    addr: Address,
    (footprints, out): (S, &mut [[f32; 4]]),
) {
    // Level 0 is at most 2^22 per side (`MAX_SIDE`), so there are at most 23 levels.
    let levels = p.level_count().min(LEVELS);
    let (mut dims_w, mut dims_h) = ([0.0f32; LEVELS], [0.0f32; LEVELS]);
    let base = p.level(0);
    let mut views = [base; V];
    for l in 0..levels {
        let view = p.level(l);
        let (w, h) = view.size();
        (dims_w[l], dims_h[l]) = (w as f32, h as f32);
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
    let d = s.descriptor();
    let mut first = Pass::<N, T>::new(taps, addr);
    let mut second = Pass::<N, T>::new(taps, addr);
    let mut delta = [0.0f32; N];
    // The coarser level's values of a chunk filtered level by level (`filter_two_levels`).
    let mut scratch = [[0.0f32; 4]; N];
    let mut chunk = Chunk::<N>::new();
    let last = levels - 1;
    let size0 = base.size();
    let trilinear = d.mipmap_filter == MipmapFilterMode::Linear;
    for (fps, out) in chunks(footprints, N).zip(out.chunks_mut(N)) {
        let n = fps.len();
        queries(s, size0, fps, &mut chunk);
        if d.mipmap_filter == MipmapFilterMode::None {
            // Every sample in level 0: stages 2 and 3 with its view and size, no per-sample
            // level lookups. The one-level chunk below would give the same values, but its
            // stage 1 fill and level scan cost bilinear frames time (docs/decisions.md).
            let size = (dims_w[0], dims_h[0]);
            first.coordinates(|_| size, &chunk.u[..n], &chunk.v[..n]);
            filter_one_level(&first, &chunk, base, out);
            continue;
        }
        // Stage 1: levels (u8: at most 32 levels for a 2^31 side; textures are far smaller).
        match d.mipmap_filter {
            MipmapFilterMode::None => first.level[..n].fill(0),
            MipmapFilterMode::Nearest => {
                let top = last as f32;
                for (l, &lod) in first.level[..n].iter_mut().zip(&chunk.lod) {
                    *l = mip::nearest_level_staged(lod, top);
                }
            }
            MipmapFilterMode::Linear => {
                for (k, &lod) in chunk.lod[..n].iter().enumerate() {
                    let (l, t) = mip::linear_levels_staged(lod, last);
                    first.level[k] = l as u8;
                    second.level[k] = (l as u8 + 1).min(last as u8);
                    delta[k] = t;
                }
            }
        }
        // Stages 2 and 3.
        let size = |l: u8| {
            let l = l as usize & (LEVELS - 1);
            (dims_w[l], dims_h[l])
        };
        let l0 = first.level[0];
        // A fold, not `all`: branch-free, it compares the chunk's levels in vector lanes (an
        // early-exit `all` is a byte loop with a branch per sample, docs/decisions.md).
        let one_level = first.level[..n]
            .iter()
            .fold(true, |one, &l| one & (l == l0));
        if one_level {
            // The whole chunk in one level (neighbouring pixels' lods are close, so chunks along
            // a row often are): its view and size looked up once, the same arithmetic.
            let (fine, s0) = (view(l0), size(l0));
            first.coordinates(|_| s0, &chunk.u[..n], &chunk.v[..n]);
            // As `mip::trilinear`: the coarser level only when it is weighed.
            if !(trilinear && (l0 as usize) < last) {
                filter_one_level(&first, &chunk, fine, out);
                continue;
            }
            let l1 = second.level[0];
            let (coarse, s1) = (view(l1), size(l1));
            second.coordinates(|_| s1, &chunk.u[..n], &chunk.v[..n]);
            let stages = (&first, &second, &chunk, &delta);
            filter_two_levels(stages, (fine, coarse), &mut scratch, out);
            continue;
        }
        first.coordinates(size, &chunk.u[..n], &chunk.v[..n]);
        if !trilinear {
            let fl = &first.level;
            filter_unblended(&first, &chunk, |k| view(fl[k]), out);
            continue;
        }
        second.coordinates(size, &chunk.u[..n], &chunk.v[..n]);
        let (fl, sl) = (&first.level, &second.level);
        let stages = (&first, &second, &chunk, &delta);
        filter_chunk(stages, |k| view(fl[k]), |k| view(sl[k]), out);
    }
}

/// Stage 3 of [`run_in`] where no sample blends two levels (no mipmaps, nearest mip level, or a
/// trilinear chunk wholly in the last level): each sample's value filtered in `level(k)`'s view.
/// The same values as [`filter_chunk`] with nothing weighed, without its per-sample blend test:
/// with that test in the loop, LLVM stores each filtered value to the stack and reloads it after
/// the test, and a mip-nearest profile's samples sit on that reload (docs/decisions.md). A chunk
/// whose samples all lie inside their levels takes a loop of that
/// route alone ([`Pass::inside_value`]).
#[inline(always)]
fn filter_unblended<T: Taps, F: Fetch, const N: usize>(
    first: &Pass<N, T>,
    chunk: &Chunk<N>,
    level: impl Fn(usize) -> F,
    out: &mut [[f32; 4]],
) {
    if first.all_inside(out.len()) {
        for (k, o) in out.iter_mut().enumerate() {
            *o = first.inside_value(&level(k), k).to_array();
        }
        return;
    }
    for (k, o) in out.iter_mut().enumerate() {
        *o = first.filtered(&level(k), k, chunk.uv(k)).to_array();
    }
}

/// [`filter_unblended`] for a chunk whose samples all read the one view `level` (no mipmaps, or one
/// mip level): where every sample lies inside it and the view has a run kernel
/// ([`Taps::inside_run`]: linear 8-bit texels, sampled with an AVX2 `Lanes` token), the whole chunk
/// in one loop that tests the token once; otherwise [`filter_unblended`] (docs/decisions.md,
/// "The sampler's kernels are dispatched apart from the tile copies").
#[inline(always)]
fn filter_one_level<T: Taps, F: Fetch, const N: usize>(
    first: &Pass<N, T>,
    chunk: &Chunk<N>,
    level: F,
    out: &mut [[f32; 4]],
) {
    let n = out.len();
    if first.all_inside(n) && T::inside_run(&level, first.run(n), out) {
        return;
    }
    filter_unblended(first, chunk, |_| level, out);
}

/// [`filter_chunk`] for a chunk whose samples all read the views `fine` and `coarse` (one pair of
/// levels). Where the views have a run kernel ([`Taps::inside_run`]), level by level: with every
/// blend weight positive and every sample inside both levels, the finer level's run into `out`,
/// the coarser one's into `scratch`, then the blends ([`Taps::mix`], as [`filter_chunk`]
/// computes them); with none positive and every sample inside the finer level, the finer run
/// alone. Otherwise [`filter_chunk`], which reads the coarser level only for the samples it
/// weighs: a chunk never reads a texel the per-sample loop would not.
#[inline(always)]
fn filter_two_levels<T: Taps, F: Fetch, const N: usize>(
    (first, second, chunk, delta): (&Pass<N, T>, &Pass<N, T>, &Chunk<N>, &[f32; N]),
    (fine, coarse): (F, F),
    scratch: &mut [[f32; 4]; N],
    out: &mut [[f32; 4]],
) {
    let n = out.len();
    if first.all_inside(n) {
        // A fold, branch-free, as `Pass::all_inside`.
        let (all, any) = delta[..n].iter().fold((true, false), |(all, any), &t| {
            (all & (t > 0.0), any | (t > 0.0))
        });
        // No weight positive: the coarser level is not read, so need not be inside.
        if !any && T::inside_run(&fine, first.run(n), out) {
            return;
        }
        let coarse_values = &mut scratch[..n];
        if all
            && second.all_inside(n)
            && T::inside_run(&fine, first.run(n), out)
            && T::inside_run(&coarse, second.run(n), coarse_values)
        {
            for ((o, c), &t) in out.iter_mut().zip(coarse_values.iter()).zip(delta) {
                *o = T::mix(Vec4::from_array(*o), Vec4::from_array(*c), t).to_array();
            }
            return;
        }
    }
    filter_chunk((first, second, chunk, delta), |_| fine, |_| coarse, out);
}

/// Stage 3 of [`run_in`] for a chunk's samples (`out.len()` of them): the finer level's value
/// from `fine(k)`'s view, blended with the coarser one's from `coarse(k)` by `delta` where
/// `delta > 0`. That test is [`mip::trilinear`]'s `delta > 0 && k < last`: the level stage's
/// `delta` ([`mip::linear_levels_staged`]) is 0 in the last level, whose lod is clamped to it.
/// A chunk whose samples all lie inside both their levels takes a loop of the inside route alone
/// ([`Pass::inside_value`]).
#[inline(always)]
fn filter_chunk<T: Taps, F: Fetch, const N: usize>(
    (first, second, chunk, delta): (&Pass<N, T>, &Pass<N, T>, &Chunk<N>, &[f32; N]),
    fine: impl Fn(usize) -> F,
    coarse: impl Fn(usize) -> F,
    out: &mut [[f32; 4]],
) {
    let n = out.len();
    if first.all_inside(n) && second.all_inside(n) {
        for (k, o) in out.iter_mut().enumerate() {
            let a = first.inside_value(&fine(k), k);
            *o = if delta[k] > 0.0 {
                T::mix(a, second.inside_value(&coarse(k), k), delta[k])
            } else {
                a
            }
            .to_array();
        }
        return;
    }
    for (k, o) in out.iter_mut().enumerate() {
        let uv = chunk.uv(k);
        let a = first.filtered(&fine(k), k, uv);
        *o = if delta[k] > 0.0 {
            T::mix(a, second.filtered(&coarse(k), k, uv), delta[k])
        } else {
            a
        }
        .to_array();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::base::address::{AddressMode, BorderColor};
    use crate::storage::fetch::{Codes8, Level, Unorm8};
    use crate::storage::lanes::Lanes;

    const MODES: [AddressMode; 5] = [
        AddressMode::ClampToEdge,
        AddressMode::Repeat,
        AddressMode::MirrorRepeat,
        AddressMode::ClampToBorder,
        AddressMode::MirrorClampToEdge,
    ];

    /// Every sample of a pass over `(us, vs)` on `level` (any route: inside, near an edge with
    /// the pass's wrapped taps, or the one-sample filter) equals `T`'s one-sample filter bit for
    /// bit; returns how many took the wrapped route.
    fn check_pass<T: Taps, F: Fetch>(taps: T, level: &F, addr: Address, uvs: &[Vec2]) -> usize {
        let (w, h) = level.size();
        let mut near = 0;
        for part in uvs.chunks(16) {
            let mut pass = Pass::<16, T>::new(taps, addr);
            let us: Vec<f32> = part.iter().map(|p| p.x).collect();
            let vs: Vec<f32> = part.iter().map(|p| p.y).collect();
            pass.coordinates(|_| (w as f32, h as f32), &us, &vs);
            for (k, &uv) in part.iter().enumerate() {
                let got = pass.filtered(level, k, uv);
                let want = taps.filter(level, &addr, uv);
                assert_eq!(
                    got.to_array().map(f32::to_bits),
                    want.to_array().map(f32::to_bits),
                    "{w}x{h} {addr:?} uv {uv} inside {} near {:?}",
                    pass.inside[k],
                    pass.near((w, h), k)
                );
                near += usize::from(!pass.inside[k] && pass.near((w, h), k).is_some());
            }
        }
        near
    }

    /// The wrapped taps of samples near an edge (`Pass::near`, `wrap_pair`)
    /// read exactly the texels the one-sample filters read through `AddressMode::wrap`: origins
    /// in steps of 1/8 texel (and just inside each texel boundary) from two texels before to two
    /// after the level along both axes, levels 1 to 5 texels a side, every pair of address modes,
    /// nearest and bilinear, exact (also with [`Lanes::detect`]'s eight-lane quads) and
    /// fixed-point. Border modes never take the wrapped route;
    /// the others take it for exactly the origins in `[-1, W) x [-1, H)` not inside the level.
    #[test]
    fn wrapped_taps_equal_the_one_sample_filter() {
        for (w, h) in [(1u32, 1u32), (2, 3), (5, 2), (3, 5), (4, 4)] {
            let bytes: Vec<[u8; 4]> = (0..w * h)
                .map(|k| {
                    [
                        (k * 37 % 251) as u8,
                        (k * 91 % 253) as u8,
                        (k * 13) as u8,
                        255,
                    ]
                })
                .collect();
            let exact = Level {
                width: w,
                height: h,
                texels: &bytes,
                decode: Unorm8::default(),
            };
            // The same level blending its quads in eight lanes where the CPU has them.
            let wide = Level {
                decode: Unorm8 {
                    lanes: Lanes::detect(),
                },
                ..exact
            };
            let codes = Level {
                width: w,
                height: h,
                texels: &bytes,
                decode: Codes8::default(),
            };
            let offsets = |n: u32| -> Vec<f32> {
                let mut xs = Vec::new();
                for m in -16..=(8 * n as i32 + 16) {
                    let x = m as f32 / 8.0;
                    xs.extend([x, x - 1e-4]);
                }
                xs
            };
            for mu in MODES {
                for mv in MODES {
                    let addr = Address::new(mu, mv, BorderColor::Custom([0.25, 0.5, 0.75, 1.0]));
                    let (xs, ys) = (offsets(w), offsets(h));
                    // Bilinear's origin is `u W - 1/2`, nearest's `u W`.
                    let uvs = |half: f32| -> Vec<Vec2> {
                        let mut v = Vec::new();
                        for &x in &xs {
                            for &y in &ys {
                                v.push(Vec2::new((x + half) / w as f32, (y + half) / h as f32));
                            }
                        }
                        v
                    };
                    let (bl, pt) = (uvs(0.5), uvs(0.0));
                    // The samples that should take the wrapped route: origin (as the pass
                    // computes it) in [-1, W) x [-1, H) but not inside.
                    let expect = |uvs: &[Vec2], half: f32, reach: f32| {
                        let (wf, hf) = (w as f32, h as f32);
                        let within = |x: f32, n: f32| (-1.0..n).contains(&x);
                        let inside = |x: f32, n: f32| x >= 0.0 && x.floor() < n - reach;
                        let near = |p: &&Vec2| {
                            let (x, y) = (p.x * wf - half, p.y * hf - half);
                            within(x, wf) && within(y, hf) && !(inside(x, wf) && inside(y, hf))
                        };
                        uvs.iter().filter(near).count()
                    };
                    let counts = [
                        check_pass(Bilinear, &exact, addr, &bl),
                        check_pass(Bilinear8, &codes, addr, &bl),
                        check_pass(Point, &exact, addr, &pt),
                        check_pass(Point8, &codes, addr, &pt),
                    ];
                    assert_eq!(check_pass(Bilinear, &wide, addr, &bl), counts[0]);
                    let border =
                        mu == AddressMode::ClampToBorder || mv == AddressMode::ClampToBorder;
                    if border {
                        assert_eq!(counts, [0; 4], "{addr:?}");
                    } else {
                        let (b, p) = (expect(&bl, 0.5, 1.0), expect(&pt, 0.0, 0.0));
                        assert!(b > 8 * (w + h) as usize && p > 0, "{w}x{h} {b} {p}");
                        assert_eq!(counts, [b, b, p, p], "{w}x{h} {addr:?}");
                    }
                }
            }
        }
    }
}
