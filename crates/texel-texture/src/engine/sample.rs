//! The sampling entry points of a [`Sampler`]: one sample ([`Sampler::sample`], its stages
//! `query` and `filter`), and batches ([`Sampler::sample_batch`] and its variants), which run the
//! staged engine (`batch.rs`) on the instruction-set copies of
//! [`crate::engine::dispatch`].

use glam::Vec4;

use crate::base::address::Address;
use crate::base::color::{rgba_to_srgb8, rgba_to_unorm8};
use crate::base::filter::{FilterMode, MipmapFilterMode};
use crate::base::floor::integer_bytes4;
pub use crate::base::footprint::UV_LIMIT;
use crate::base::footprint::{finite_uv, lod_from_rho_squared, rho_squared, Footprint, Query};
use crate::base::footprint_batch::{chunks, FootprintBatch, Source};
use crate::engine::batch;
use crate::engine::sampler::{Sampler, Technique};
use crate::kernel::bilinear::Bilinear;
use crate::kernel::filter_level;
use crate::kernel::staged::{self, Chunk, CHUNK};
use crate::storage::fetch::Fetch;
use crate::storage::lanes::Lanes;
use crate::storage::texture::{Format, Texture};
use crate::storage::view::{codes_of, with_pyramid, Counted, Pyramid};
use crate::technique::aniso::Probes;
use crate::technique::aniso::{anisotropic, filter_planned, plan_chunk, Plan};
use crate::technique::ewa::ewa;
use crate::technique::ewa_probes::ewa_probes;
use crate::technique::lab::Rules;
use crate::technique::mip::{mip_nearest, trilinear};
use crate::technique::ripmap::ripmap;
use crate::technique::sat::summed_area;

impl Sampler {
    /// The lod this sampler uses for `footprint` on `texture` (before clamping to the last level):
    /// `log2(rho) + lod_bias` clamped to `[lod_min_clamp, lod_max_clamp]`, computed as
    /// `0.5 * log2(rho^2)` with [`crate::base::footprint::fast_log2`] (within about one
    /// unit in the last place of [`crate::base::footprint::lod_from_rho`]; exact on integer lods), the same value the sampling path uses.
    pub fn lod(&self, texture: &Texture, footprint: &Footprint) -> f32 {
        let d = &self.desc;
        let rho2 = rho_squared(footprint, texture.width(), texture.height());
        lod_from_rho_squared(rho2, d.lod_bias, d.lod_min_clamp, d.lod_max_clamp)
    }

    /// Sample `texture` over `footprint`; linear RGBA.
    ///
    /// Non-finite `u` or `v` sample at 0, finite ones are clamped to `[-UV_LIMIT, UV_LIMIT]`;
    /// non-finite derivatives select the coarsest level.
    pub fn sample(&self, texture: &Texture, footprint: &Footprint) -> [f32; 4] {
        with_pyramid!(texture, |p| self.sample_pyramid(&p, footprint)).to_array()
    }

    /// As [`Sampler::sample`], also returning how many texels the filter read.
    pub fn sample_counted(&self, texture: &Texture, footprint: &Footprint) -> ([f32; 4], u32) {
        with_pyramid!(texture, |p| {
            let counted = Counted {
                inner: p,
                count: std::cell::Cell::new(0),
            };
            let c = self.sample_pyramid(&counted, footprint);
            (c.to_array(), counted.count.get())
        })
    }

    /// Whether every sample reads exactly one texel (or the border colour) and returns it as it
    /// is: nearest filtering (`min_filter == mag_filter == Nearest`) with no mipmaps or nearest
    /// mipmaps. Such samples need no blending, so [`Sampler::sample_batch_stored`] can return the
    /// stored bytes.
    pub fn reads_one_texel(&self) -> bool {
        self.batched
            && self.desc.min_filter == FilterMode::Nearest
            && self.desc.mipmap_filter != MipmapFilterMode::Linear
    }

    /// The stored bytes of the texel each footprint reads: for a sampler that
    /// [reads one texel](Sampler::reads_one_texel) on an 8-bit texture, `out[k]` is the texel
    /// whose decoding `sample(texture, f)` of footprint `k`, `f`, returns (the same query, level and texel,
    /// bit for bit), or, where `ClampToBorder` reads outside the texture, the border colour
    /// encoded in the texture's format (sRGB RGB and linear alpha for `Rgba8Srgb`, all linear
    /// for `Rgba8Unorm`; [`crate::base::color::rgba_to_srgb8`], [`crate::base::color::rgba_to_unorm8`]).
    ///
    /// Encoding a sample in the texture's own format gives these bytes (the decode tables
    /// round-trip every code), so a renderer writing an 8-bit target of that format may copy
    /// them and skip the decode and the encode. Returns `false`, writing nothing, when the path
    /// does not apply: another filter, float storage, or a level 0 wider or taller than the
    /// staged kernels take.
    ///
    /// # Panics
    /// If `footprints.len() != out.len()` (a programming error, not bad input).
    // Not inlined into the tile rasterizer's copies: its kernels (`batch::point_bytes`,
    // `batch::run`) run on their own instruction-set copies (`crate::engine::dispatch`).
    pub fn sample_batch_stored(
        &self,
        texture: &Texture,
        footprints: impl FootprintBatch,
        out: &mut [[u8; 4]],
    ) -> bool {
        let applies = self.reads_one_texel();
        self.run_codes(applies, texture, footprints.source(), out, false)
    }

    /// Whether [`Sampler::sample_batch_fixed8`] filters `texture`: the core kernels (nearest or
    /// bilinear, `mag_filter == min_filter`, any mipmap filter) on an `Rgba8Unorm` texture whose
    /// level 0 the staged kernels take.
    pub fn filters_fixed8(&self, texture: &Texture) -> bool {
        self.batched
            && texture.format() == Format::Rgba8Unorm
            && staged::staged((texture.width(), texture.height()))
    }

    /// GPU-style fixed-point filtering ([`crate::kernel::fixed8`]): for each footprint the unorm8 code
    /// that 8-bit sub-texel and mip weights give, with one rounding per blend; the same query,
    /// lod, levels and texels as [`Sampler::sample`], whose result it approximates. Where
    /// `ClampToBorder` reads outside the texture the border colour enters as its unorm8 codes.
    /// Nearest samples (with no or nearest mipmaps) are [`Sampler::sample_batch_stored`]'s.
    ///
    /// Returns `false`, writing nothing, where [`Sampler::filters_fixed8`] says it does not apply.
    ///
    /// # Panics
    /// If `footprints.len() != out.len()` (a programming error, not bad input).
    pub fn sample_batch_fixed8(
        &self,
        texture: &Texture,
        footprints: impl FootprintBatch,
        out: &mut [[u8; 4]],
    ) -> bool {
        let applies = self.filters_fixed8(texture);
        self.run_codes(applies, texture, footprints.source(), out, true)
    }

    /// Where the path `applies`, run the staged kernels (`fixed`: [`crate::kernel::fixed8`]'s) over
    /// `texture`'s stored codes ([`crate::storage::fetch::Codes8`]) and narrow the results to bytes; the
    /// border colour enters as codes of the texture's format. `false` where it does not apply,
    /// for float storage or a level 0 beyond the staged kernels. Panics if the lengths differ.
    fn run_codes<S: Source>(
        &self,
        applies: bool,
        texture: &Texture,
        footprints: S,
        out: &mut [[u8; 4]],
        fixed: bool,
    ) -> bool {
        assert_eq!(
            footprints.len(),
            out.len(),
            "sample_batch_stored/fixed8: footprints and out differ in length"
        );
        if !applies {
            return false;
        }
        let Some(p) = codes_of(texture) else {
            return false;
        };
        if !staged::staged(p.level(0).size()) {
            return false;
        }
        let border = match texture.format() {
            Format::Rgba8Srgb => rgba_to_srgb8(self.params.addr.border.to_array()),
            _ => rgba_to_unorm8(self.params.addr.border.to_array()),
        };
        let addr = Address {
            border: Vec4::from_array(border.map(f32::from)),
            ..self.params.addr
        };
        if !fixed && self.desc.mipmap_filter == MipmapFilterMode::None {
            // Nearest in level 0 (`applies`: both filters nearest): copy the bytes.
            batch::point_bytes(&p.level(0), &addr, footprints, out);
            return true;
        }
        let mut codes = [[0.0f32; 4]; CHUNK];
        for (fps, out) in chunks(footprints, CHUNK).zip(out.chunks_mut(CHUNK)) {
            let codes = &mut codes[..fps.len()];
            if fixed {
                batch::run_fixed(&p, self, addr, fps, codes);
            } else {
                batch::run(&p, self, addr, fps, codes);
            }
            for (o, c) in out.iter_mut().zip(codes.iter()) {
                // Codes are integers in 0..=255: read from bits, without a saturating float
                // conversion per channel.
                *o = integer_bytes4(*c);
            }
        }
        true
    }

    /// Sample many footprints at once: `out[k] = sample(texture, f)` for footprint `k`, `f`, bit
    /// for bit. The
    /// texture's format is dispatched once for the whole batch, and the lods of up to 64
    /// footprints are computed in one loop before any is filtered (independent iterations that
    /// pipeline, instead of one long dependency chain per sample). A rasterizer should hand it a
    /// row span at a time. The kernels run on the best instruction-set copy the CPU has
    /// ([`crate::engine::dispatch`]); on x86-64-v3 and above linear 8-bit quads blend in eight lanes
    /// ([`Lanes::detect`]), else in four. Same bits on every copy.
    ///
    /// `footprints` is any [`FootprintBatch`]: structs (`&[Footprint]`, `&Vec<Footprint>`,
    /// `&[Footprint; N]`) or [`crate::FootprintLanes`], one slice per field, which a caller that
    /// computes its footprints in lanes (a rasterizer) hands over without interleaving them into
    /// structs. Both give the same bits.
    ///
    /// # Panics
    /// If `footprints.len() != out.len()` (a programming error, not bad input).
    pub fn sample_batch(
        &self,
        texture: &Texture,
        footprints: impl FootprintBatch,
        out: &mut [[f32; 4]],
    ) {
        self.sample_batch_lanes(crate::engine::dispatch::lanes(), texture, footprints, out)
    }

    /// [`Sampler::sample_batch`] with the bilinear quads of linear 8-bit textures
    /// (`Rgba8Unorm`) blended by `lanes`' kernel: the same bits with every [`Lanes`]. The
    /// kernels run on the CPU's best instruction-set copy ([`crate::engine::dispatch`]), where
    /// [`Lanes::detect`]'s intrinsics inline on the x86-64-v3 and -v4 copies; under
    /// [`crate::engine::dispatch::limit_level`]`(Baseline)` they stay calls (correct, slower).
    ///
    /// # Panics
    /// If `footprints.len() != out.len()` (a programming error, not bad input).
    pub fn sample_batch_lanes(
        &self,
        lanes: Lanes,
        texture: &Texture,
        footprints: impl FootprintBatch,
        out: &mut [[f32; 4]],
    ) {
        self.batch_source(lanes, texture, footprints.source(), out)
    }

    /// [`Sampler::sample_batch_lanes`] for either kind of batch (compiled once per kind).
    fn batch_source<S: Source>(
        &self,
        lanes: Lanes,
        texture: &Texture,
        footprints: S,
        out: &mut [[f32; 4]],
    ) {
        assert_eq!(
            footprints.len(),
            out.len(),
            "sample_batch: footprints and out differ in length"
        );
        with_pyramid!(texture, lanes, |p| {
            if self.batched && staged::staged(p.level(0).size()) {
                // `batch::run` dispatches per within-level filter.
                return batch::run(&p, self, self.params.addr, footprints, out);
            }
            crate::engine::dispatch::run(BatchJob {
                s: self,
                p: &p,
                footprints,
                out,
            })
        })
    }

    /// [`Sampler::sample_batch_lanes`] past the core kernels (`batched`): anisotropic probes
    /// batched where level 0 is within the staged kernels' side, else every sample through
    /// [`Sampler::filter`], with its query and (anisotropic) probe plan made a chunk at a time.
    #[inline(always)]
    fn batch_in<P: Pyramid, S: Source>(&self, p: &P, footprints: S, out: &mut [[f32; 4]]) {
        let size = p.level(0).size();
        if self.technique == Technique::Anisotropic && staged::staged(size) {
            // Every sample's probes (one for a magnified or isotropic sample) filtered
            // together with those of its neighbours.
            return batch::anisotropic(p, self, (footprints, out));
        }
        // Two stages per chunk: all queries first (`batch::queries`, `Sampler::query`'s
        // arithmetic vectorised), then all filters.
        let mut chunk = Chunk::<{ CHUNK }>::new();
        let parts = chunks(footprints, CHUNK).zip(out.chunks_mut(CHUNK));
        if self.technique == Technique::Anisotropic {
            // A third stage between the two: every sample's probe plan (axes, probe count,
            // probe lod), vectorised as the lods are; the probes' scratch is made once.
            let mut plans = [Plan::default(); CHUNK];
            let mut probes = Probes::new(self.params.addr);
            for (fps, outs) in parts {
                batch::queries(self, size, fps, &mut chunk);
                plan_chunk(&self.params, size, &chunk, &mut plans);
                for (k, o) in outs.iter_mut().enumerate() {
                    let q = chunk.query(k);
                    // As `filter`: magnification first.
                    *o = if q.lod > 0.0 {
                        filter_planned(p, &q, &plans[k], &mut probes)
                    } else {
                        self.filter(p, &q)
                    }
                    .to_array();
                }
            }
            return;
        }
        if let Technique::EwaProbes(max) = self.technique {
            // The probes' scratch made once, as for the anisotropic probes.
            let mut probes = Probes::new(self.params.addr);
            for (fps, outs) in parts {
                batch::queries(self, size, fps, &mut chunk);
                for (k, o) in outs.iter_mut().enumerate() {
                    let q = chunk.query(k);
                    *o = if q.lod > 0.0 {
                        ewa_probes(p, &self.params, &q, max, &mut probes)
                    } else {
                        self.filter(p, &q)
                    }
                    .to_array();
                }
            }
            return;
        }
        for (fps, outs) in parts {
            batch::queries(self, size, fps, &mut chunk);
            for (k, o) in outs.iter_mut().enumerate() {
                *o = self.filter(p, &chunk.query(k)).to_array();
            }
        }
    }

    /// The whole per-sample path, generic over the texel storage (and the counting wrapper).
    #[inline]
    pub(crate) fn sample_pyramid<P: Pyramid>(&self, p: &P, fp: &Footprint) -> Vec4 {
        let q = self.query(p.level(0).size(), fp);
        self.filter(p, &q)
    }

    /// First stage of a sample: its [`Query`] on a `size` level 0 — `(u, v)` made finite and the
    /// isotropic lod.
    ///
    /// Split from [`Sampler::filter`] so that [`Sampler::sample_batch`] can run it over many
    /// footprints in a short, independent loop (`batch::queries`): the lod is a long dependency
    /// chain (square, log2, clamp) that pipelines across footprints there instead of stalling
    /// each sample.
    #[inline(always)]
    fn query(&self, (w, h): (u32, u32), fp: &Footprint) -> Query {
        let d = &self.desc;
        let lod = if self.lod_free {
            // Both branches of `filter` read level 0 with the same filter: any lod gives the
            // same result, so skip the square, log2 and clamp (nearest and bilinear without mips).
            0.0
        } else {
            lod_from_rho_squared(
                rho_squared(fp, w, h),
                d.lod_bias,
                d.lod_min_clamp,
                d.lod_max_clamp,
            )
        };
        Query {
            fp: Footprint {
                u: finite_uv(fp.u),
                v: finite_uv(fp.v),
                ..*fp
            },
            lod,
        }
    }

    /// Second stage of a sample: the filter for query `q` (from [`Sampler::query`]).
    #[inline(always)]
    fn filter<P: Pyramid>(&self, p: &P, q: &Query) -> Vec4 {
        let d = &self.desc;
        let addr = &self.params.addr;
        if let Technique::Lab(mode) = self.technique {
            return crate::technique::lab::sample_rules(p, addr, mode, &Rules::LAB, &q.fp);
        }
        if q.lod <= 0.0 {
            return filter_level(&d.mag_filter, &p.level(0), addr, q.uv());
        }
        let min = &d.min_filter;
        match self.technique {
            Technique::Mip => match d.mipmap_filter {
                MipmapFilterMode::None => filter_level(min, &p.level(0), addr, q.uv()),
                MipmapFilterMode::Nearest => mip_nearest(p, min, addr, q),
                MipmapFilterMode::Linear => trilinear(p, min, addr, q),
            },
            Technique::Anisotropic => anisotropic(p, &self.params, q),
            Technique::Ewa(max) => ewa(p, &self.params, q, max),
            Technique::EwaProbes(max) => {
                ewa_probes(p, &self.params, q, max, &mut Probes::new(self.params.addr))
            }
            Technique::Ripmap => match p.texture().ripmap() {
                Ok(r) => ripmap(p, r, &self.params, q),
                Err(_) => trilinear(p, Bilinear, addr, q),
            },
            Technique::SummedArea => match p.texture().summed_area_table() {
                Ok(t) => summed_area(p, t, &self.params, q),
                Err(_) => trilinear(p, Bilinear, addr, q),
            },
            Technique::Lab(mode) => {
                crate::technique::lab::sample_rules(p, addr, mode, &Rules::LAB, &q.fp)
            }
        }
    }
}

/// [`Sampler::batch_in`]'s arguments, as the dispatcher's unit of work (one function per
/// pyramid type and instruction-set copy).
struct BatchJob<'j, P, S> {
    s: &'j Sampler,
    p: &'j P,
    footprints: S,
    out: &'j mut [[f32; 4]],
}

impl<P: Pyramid, S: Source> crate::engine::dispatch::Kernel for BatchJob<'_, P, S> {
    type Output = ();
    /// Ignores `lanes`: a linear 8-bit pyramid carries its quad kernel (`fetch::Unorm8`).
    #[inline(always)]
    fn run(self, _lanes: Lanes) {
        self.s.batch_in(self.p, self.footprints, self.out)
    }
}
