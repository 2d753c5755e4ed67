//! Hardware-style anisotropic filtering: N trilinear probes along the footprint's major axis.
//!
//! Formula (EXT_texture_filter_anisotropic, "Texture Minification"; docs/guide/conventions.md; the
//! lab handout's own formula, with probes at the footprint's ends, is [`crate::technique::lab`]'s):
//! with `Px = (dudx * W, dvdx * H)` and `Py = (dudy * W, dvdy * H)` in texels of level
//! 0, `Pmax`/`Pmin` the longer/shorter of the two,
//!
//! ```text
//! N   = min(ceil(|Pmax| / |Pmin|), anisotropy_clamp)
//! lod = log2(|Pmax| / N) + lod_bias, clamped to [lod_min_clamp, lod_max_clamp]
//! c   = 1/N * sum_{i=0}^{N-1} trilinear(uv + ((i + 0.5) / N - 0.5) * Pmax_uv, lod)
//! ```
//!
//! where `Pmax_uv` is the same screen axis in uv units (`(dudx, dvdx)` or `(dudy, dvdy)`). The
//! probes are spaced `|Pmax| / N` texels apart, so each probe's trilinear footprint (`2^lod =
//! |Pmax| / N` texels) tiles the major axis without gaps.
//!
//! Decisions:
//! - `N = 1` (an isotropic footprint, or `anisotropy_clamp = 1`) calls exactly the code path of
//!   plain trilinear with the isotropic lod, so the result is bit for bit trilinear (tested).
//! - The ratio is rounded up with a relative tolerance of [`RATIO_TOLERANCE`] (`1e-5`), so that a
//!   rotated isotropic footprint whose two lengths differ by float rounding (`|Pmax| / |Pmin| =
//!   1.0000001`) does not take two probes; an exact integer ratio `k (1 + eps)` likewise gives `k`.
//! - The magnification/minification decision is the core sampler's, from the isotropic
//!   `rho = |Pmax|`: `lod <= 0` uses the (linear) `mag_filter`. When minifying, the probes' lod may
//!   fall below 0 (`|Pmax| / N < 1`); trilinear then clamps it to level 0 (bilinear probes).
//! - Degenerate footprints: `|Pmin| = 0` gives `N = anisotropy_clamp`; `|Pmax| = 0` (reachable only
//!   with `lod_min_clamp > 0`) and non-finite derivatives give one trilinear probe at the isotropic
//!   lod (the coarsest allowed level for non-finite ones). `N` never exceeds `anisotropy_clamp`
//!   (at most 64), so the loop is bounded. Probe positions that overflow to infinity are sampled
//!   at 0, as the sampler treats non-finite `uv`.
//!
//! Cost: `N` trilinear probes, so at most `8 N` texel reads. Throughput and texels read per sample
//! at anisotropy ratios 1 to 64 are in docs/benchmarks.md (`benches/aniso.rs`); quality
//! against a brute-force Gaussian (RMS error 0.0158 for 16x vs 0.0252 for trilinear) is in
//! [`crate::technique::ewa`].
//!
//! The code path: `anisotropic` is `plan` (axes, `N`, the probes' lod) then `filter_planned`
//! (the sum above). The probes share their lod, so `crate::technique::mip::linear_levels` picks their two
//! levels once, and their trilinear samples run through the batched path's stages
//! (`batch::Probes::trilinear_sum`: the same bilinear kernels, staged over the probes).
//! [`crate::Sampler::sample_batch`] makes the plans of a chunk of 64 footprints in one loop
//! (`plan_chunk`) before reading any probe, as it does the isotropic lods; that needs a `log2`
//! without a call, so the probe lod uses [`crate::base::footprint::fast_log2`] (within 1.2 units in the
//! last place) in both paths, which therefore agree bit for bit. How each of these steps moved
//! the frame times: docs/decisions.md.

use glam::{Vec2, Vec4};

use crate::base::address::Address;
use crate::base::floor::ceil_i32;
use crate::base::footprint::{fast_log2, log2_normal, Footprint, Query};
use crate::base::lerp::lerp;
use crate::kernel::bilinear::Bilinear;
use crate::kernel::staged::{Chunk, Pass, CHUNK};
use crate::storage::fetch::Fetch;
use crate::storage::view::Pyramid;
use crate::technique::mip::{linear_levels, trilinear};
use crate::technique::Params;

/// Relative tolerance applied to `|Pmax| / |Pmin|` before rounding up (see the module docs).
pub const RATIO_TOLERANCE: f32 = 1e-5;

/// The number of probes `N = min(ceil(major / minor), max_anisotropy)`, at least 1.
///
/// `major` and `minor` are axis lengths (any unit, `major >= minor >= 0`). `minor = 0` gives
/// `max_anisotropy`; `0 / 0` and `inf / inf` give 1. Ratios within [`RATIO_TOLERANCE`] above an
/// integer round down to it: `probe_count(4.00001, 1.0, 16) = 4`, `probe_count(4.1, 1.0, 16) = 5`.
pub fn probe_count(major: f32, minor: f32, max_anisotropy: u32) -> u32 {
    let ratio = major / minor;
    if ratio.is_nan() {
        return 1;
    }
    let r = ratio * (1.0 - RATIO_TOLERANCE);
    if r > max_anisotropy as f32 {
        return max_anisotropy.max(1);
    }
    // `0 <= r <= max_anisotropy <= 64` here.
    (ceil_i32(r) as u32).clamp(1, max_anisotropy.max(1))
}

/// Anisotropic filtering of query `q` (whose lod, the isotropic one, is `> 0`) by `s`'s
/// `anisotropy_clamp`: the formula above, as [`plan`] and [`filter_planned`] evaluate it.
#[inline]
pub(crate) fn anisotropic<P: Pyramid>(p: &P, s: &Params, q: &Query) -> Vec4 {
    let (plan, _) = plan(s, p.level(0).size(), &q.fp, fast_log2);
    filter_planned(p, q, &plan, &mut Probes::new(s.addr))
}

/// What a sample's probes need from its footprint ([`plan`]).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct Plan {
    /// Probe count `N`; 1 means plain trilinear at the isotropic lod.
    pub n: u32,
    /// The probes' lod, `log2(|Pmax| / N) + bias` clamped (unused when `n == 1`).
    pub lod: f32,
    /// The major axis in uv units, `Pmax_uv`.
    pub axis: Vec2,
}

/// The [`Plan`] of footprint `fp` on a `size` level 0 under `s` (its lod bias and clamps, its
/// `anisotropy_clamp` as the most probes), with `log2` either [`fast_log2`] or its branch-free
/// normal-input path [`log2_normal`]; also whether `rho = |Pmax| / N` is zero or subnormal, where
/// the latter is wrong and the plan must be made again with [`fast_log2`]. [`Footprint::axes`],
/// [`probe_count`] and [`crate::base::footprint::lod_from_rho`]'s arithmetic (clamping by `max`/`min`,
/// which equals `clamp` for the non-NaN values reaching it), inlined so that [`plan_chunk`]'s loop
/// over a chunk pipelines.
#[inline(always)]
pub(crate) fn plan(
    s: &Params,
    (w, h): (u32, u32),
    fp: &Footprint,
    log2: impl Fn(f32) -> f32,
) -> (Plan, bool) {
    let d = s;
    let axes = fp.axes(w, h);
    let (major, minor) = (axes.major.length(), axes.minor.length());
    let n = if major.is_finite() && axes.major_uv.is_finite() {
        probe_count(major, minor, u32::from(d.anisotropy_clamp).clamp(1, 64))
    } else {
        1
    };
    // `lod_from_rho(|Pmax| / N)`.
    let rho = major / n as f32;
    let l = (log2(rho) + d.lod_bias)
        .max(d.lod_min_clamp)
        .min(d.lod_max_clamp);
    let lod = if rho.is_nan() | (rho == f32::INFINITY) {
        d.lod_max_clamp
    } else {
        l
    };
    let special = rho.is_finite() & (rho < f32::MIN_POSITIVE);
    let axis = axes.major_uv;
    (Plan { n, lod, axis }, special)
}

/// The plans of a chunk of footprints (at most [`CHUNK`]) on a `size` level 0: one
/// vectorised pass with [`log2_normal`], then the rare zero or subnormal `rho` again with
/// [`fast_log2`], so every plan equals [`plan`] with [`fast_log2`] (what [`anisotropic`] uses).
pub(crate) fn plan_chunk(
    s: &Params,
    size: (u32, u32),
    chunk: &Chunk<{ CHUNK }>,
    out: &mut [Plan; CHUNK],
) {
    let n = chunk.n;
    let mut special = false;
    for (k, o) in out[..n].iter_mut().enumerate() {
        let (p, sub) = plan(s, size, &chunk.footprint(k), log2_normal);
        *o = p;
        special |= sub;
    }
    if special {
        for (k, o) in out[..n].iter_mut().enumerate() {
            let (p, sub) = plan(s, size, &chunk.footprint(k), fast_log2);
            if sub {
                *o = p;
            }
        }
    }
}

/// Anisotropic filtering of `q` by its [`Plan`]:
/// `c = 1/N sum_{i=0}^{N-1} trilinear(uv + ((i + 0.5) / N - 0.5) Pmax_uv, plan.lod)`, or trilinear
/// at the isotropic lod when `N = 1`. `probes` is scratch (reused across a batch:
/// `Sampler::sample_batch`); the result does not depend on its contents.
#[inline(always)]
pub(crate) fn filter_planned<P: Pyramid>(
    p: &P,
    q: &Query,
    plan: &Plan,
    probes: &mut Probes,
) -> Vec4 {
    let n = plan.n;
    if n == 1 {
        return trilinear(p, Bilinear, probes.address(), q);
    }
    let inv = 1.0 / n as f32;
    let finite = |x: f32| if x.is_finite() { x } else { 0.0 };
    // The probes' positions along the major axis (`n <= 64`: `plan`).
    let n = (n as usize).min(CHUNK);
    let at = &mut probes.at;
    at.n = n;
    for (i, (pu, pv)) in at.u[..n].iter_mut().zip(&mut at.v[..n]).enumerate() {
        let t = (i as f32 + 0.5) * inv - 0.5;
        *pu = finite(q.fp.u + t * plan.axis.x);
        *pv = finite(q.fp.v + t * plan.axis.y);
    }
    // Every probe shares the lod, so the two levels are chosen once; the probes' trilinear
    // samples are then staged (`Probes::trilinear_sum`).
    probes.trilinear_sum(p, linear_levels(plan.lod, p.level_count() - 1)) * inv
}

/// The anisotropic probes' stage ([`crate::technique::aniso`]): their coordinates, written by the caller, and
/// two bilinear level passes. Made once per [`crate::Sampler::sample_batch`] call and reused by
/// every sample (zeroing scratch per sample costs measurable frame time: docs/decisions.md).
/// Entries beyond a sample's probe count are stale and never read.
pub(crate) struct Probes {
    /// The probes' coordinates (`lod` unused), written by the caller for the first `at.n`.
    pub at: Chunk<CHUNK>,
    fine: Pass<CHUNK, Bilinear>,
    next: Pass<CHUNK, Bilinear>,
}

impl Probes {
    /// Scratch for probes under the address modes `addr`.
    pub(crate) fn new(addr: Address) -> Self {
        Probes {
            at: Chunk::new(),
            fine: Pass::new(Bilinear, addr),
            next: Pass::new(Bilinear, addr),
        }
    }

    /// The address modes the probes apply.
    pub(crate) fn address(&self) -> &Address {
        &self.fine.addr
    }

    /// The sum over the probes at `self.at` of a trilinear sample in `levels` (the finer level
    /// and the blend weight from [`mip::linear_levels`]; the coarser level read only when weighed,
    /// as in [`mip::trilinear`]): stages 2 and 3 of [`run`] with every probe in the same levels,
    /// so their views are made once. Bit for bit the sum of [`mip::trilinear`] per probe, in order.
    #[inline(always)]
    pub(crate) fn trilinear_sum<P: Pyramid>(&mut self, p: &P, levels: (usize, f32)) -> Vec4 {
        self.sum_by(p, levels, |_, t| t)
    }

    /// [`Probes::trilinear_sum`] with probe `i` weighed by `weights[i]` (one weight per probe
    /// at `self.at`): `sum w_i trilinear_i`, in order.
    #[inline(always)]
    pub(crate) fn trilinear_weighted_sum<P: Pyramid>(
        &mut self,
        p: &P,
        levels: (usize, f32),
        weights: &[f32],
    ) -> Vec4 {
        debug_assert!(weights.len() >= self.at.n.min(CHUNK));
        self.sum_by(p, levels, |i, t| t * weights[i])
    }

    /// The sum over the probes at `self.at` of `term(i, trilinear_i)`, in order, with every
    /// probe's trilinear sample in `levels`.
    #[inline(always)]
    fn sum_by<P: Pyramid>(
        &mut self,
        p: &P,
        (k, delta): (usize, f32),
        term: impl Fn(usize, Vec4) -> Vec4,
    ) -> Vec4 {
        let last = p.level_count() - 1;
        let coarse = delta > 0.0 && k < last;
        let n = self.at.n.min(CHUNK);
        let fine_level = p.level(k);
        let next_level = p.level(if coarse { k + 1 } else { k });
        let size_of = |level: &P::Level<'_>| {
            let (w, h) = level.size();
            (w as f32, h as f32)
        };
        let fine_size = size_of(&fine_level);
        let (us, vs) = (&self.at.u[..n], &self.at.v[..n]);
        self.fine.coordinates(|_| fine_size, us, vs);
        if coarse {
            let next_size = size_of(&next_level);
            self.next.coordinates(|_| next_size, us, vs);
        }
        let mut sum = Vec4::ZERO;
        for i in 0..n {
            let uv = self.at.uv(i);
            let a = self.fine.filtered(&fine_level, i, uv);
            sum += term(
                i,
                if coarse {
                    lerp(a, self.next.filtered(&next_level, i, uv), delta)
                } else {
                    a
                },
            );
        }
        sum
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::base::descriptor::SamplerDescriptor;
    use crate::engine::sampler::Sampler;
    use crate::kernel::bilinear::bilinear;
    use crate::storage::lanes::Lanes;
    use crate::storage::texture::{Format, Limits, Texture};
    use crate::storage::view::pyramid_with;

    /// The staged probes (`Probes::trilinear_sum`) equal the formula's plain loop bit for bit:
    /// each probe a bilinear-in-two-levels trilinear sample in the shared levels, summed in order.
    /// On an odd-sized texture under Repeat and MirrorRepeat, and on a power-of-two one under
    /// Repeat on both axes (the staged probes' mask-wrapped route for probes far outside,
    /// `Pass::far_repeat`), with positions up to a texture away from it.
    #[test]
    fn staged_probes_equal_the_probe_loop() {
        use crate::base::address::AddressMode::{MirrorRepeat, Repeat};
        for (w, h, v_mode) in [(61, 34, MirrorRepeat), (64, 32, Repeat)] {
            check_staged_probes(w, h, v_mode);
        }
    }

    fn check_staged_probes(w: u32, h: u32, v_mode: crate::base::address::AddressMode) {
        let tex = Texture::from_fn(w, h, Format::Rgba8Srgb, &Limits::default(), |i, j| {
            let x = (i * 7 + j * 13) % 256;
            [
                x as f32 / 255.0,
                (i % 5) as f32 / 4.0,
                (j % 3) as f32 / 2.0,
                1.0,
            ]
        })
        .unwrap();
        let crate::storage::view::AnyPyramid::U8(p) = pyramid_with(&tex, Lanes::scalar()) else {
            unreachable!()
        };
        let d = SamplerDescriptor {
            address_mode_u: crate::base::address::AddressMode::Repeat,
            address_mode_v: v_mode,
            ..SamplerDescriptor::anisotropic(16)
        };
        let sampler = Sampler::new(d).unwrap();
        let addr = sampler.address();
        let mut checked = 0;
        for s in 0..4000u32 {
            let f = |k: u32| ((s.wrapping_mul(2_654_435_761) >> k) % 1000) as f32 / 1000.0;
            let fp = Footprint {
                u: 3.0 * f(0) - 1.0,
                v: 3.0 * f(3) - 1.0,
                dudx: 0.3 * (f(5) - 0.5),
                dudy: 0.02 * (f(7) - 0.5),
                dvdx: 0.01 * (f(9) - 0.5),
                dvdy: 0.2 * f(11) * (f(13) - 0.5),
            };
            let axes = fp.axes(w, h);
            let major = axes.major.length();
            let n = probe_count(major, axes.minor.length(), 16);
            if n == 1 {
                continue;
            }
            let lod = crate::base::footprint::lod_from_rho(major / n as f32, 0.0, 0.0, 32.0);
            let last = p.level_count() - 1;
            let dl = lod.clamp(0.0, last as f32);
            let k = dl as usize;
            let delta = dl - k as f32;
            let inv = 1.0 / n as f32;
            let mut sum = Vec4::ZERO;
            for i in 0..n {
                let t = (i as f32 + 0.5) * inv - 0.5;
                let (pu, pv) = (fp.u + t * axes.major_uv.x, fp.v + t * axes.major_uv.y);
                let uv = Vec2::new(pu, pv);
                let a = bilinear(&p.level(k), &addr, uv);
                sum += if delta > 0.0 && k < last {
                    a + (bilinear(&p.level(k + 1), &addr, uv) - a) * delta
                } else {
                    a
                };
            }
            let want = (sum * inv).to_array().map(f32::to_bits);
            let got = anisotropic(&p, sampler.params(), &Query { fp, lod: 1.0 });
            assert_eq!(got.to_array().map(f32::to_bits), want, "{fp:?}");
            checked += 1;
        }
        assert!(checked > 1000, "{checked}");
    }

    #[test]
    fn probe_count_table() {
        let cases: &[(f32, f32, u32, u32)] = &[
            (4.0, 1.0, 16, 4),
            (4.000_01, 1.0, 16, 4),
            (4.1, 1.0, 16, 5),
            (1.0, 1.0, 16, 1),
            (1.000_000_1, 1.0, 16, 1),
            (1.5, 1.0, 16, 2),
            (100.0, 1.0, 16, 16),
            (100.0, 1.0, 2, 2),
            (3.0, 0.0, 8, 8),
            (0.0, 0.0, 8, 1),
            (f32::INFINITY, f32::INFINITY, 8, 1),
            (1e6, 1.0, 64, 64),
            (8.0, 2.0, 1, 1),
        ];
        for &(major, minor, max, want) in cases {
            assert_eq!(
                probe_count(major, minor, max),
                want,
                "{major}/{minor} max {max}"
            );
        }
    }
}
