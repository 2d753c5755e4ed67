//! The sampling entry points of a [`Sampler`]: one sample ([`Sampler::sample`], its stages
//! `query` and `filter`), and batches ([`Sampler::sample_batch`] and its variants), which run the
//! staged engine (`batch.rs`) on the instruction-set copies of
//! [`crate::engine::dispatch`].

use glam::Vec4;

use crate::base::filter::MipmapFilterMode;
pub use crate::base::footprint::UV_LIMIT;
use crate::base::footprint::{finite_uv, lod_from_rho_squared, rho_squared, Footprint, Query};
use crate::base::footprint_batch::FootprintBatch;
use crate::engine::sampler::{Sampler, Technique};
use crate::engine::span::Wants;
use crate::kernel::bilinear::Bilinear;
use crate::kernel::filter_level;
use crate::storage::fetch::Fetch;
use crate::storage::lanes::Lanes;
use crate::storage::texture::Texture;
use crate::storage::view::{with_pyramid, Counted, Pyramid};
use crate::technique::aniso::anisotropic;
use crate::technique::aniso::Probes;
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

    /// Sample many footprints at once: `out[k] = sample(texture, f)` for footprint `k`, `f`, bit
    /// for bit. The texture's format is dispatched once for the whole batch, and the lods of up
    /// to 64 footprints are computed in one loop before any is filtered (independent iterations
    /// that pipeline, instead of one long dependency chain per sample). A rasterizer should hand
    /// it a row span at a time. The kernels run on the best instruction-set copy the CPU has
    /// ([`crate::engine::dispatch`]); on x86-64-v3 and above linear 8-bit quads blend in eight
    /// lanes ([`Lanes::detect`]), else in four. Same bits on every copy. A caller that samples
    /// many spans of one texture binds the sampler to it once ([`Sampler::bind`]).
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
        self.bind(texture, Wants::default())
            .sample_span(lanes, footprints, out, &mut []);
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
    pub(super) fn query(&self, (w, h): (u32, u32), fp: &Footprint) -> Query {
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
    pub(super) fn filter<P: Pyramid>(&self, p: &P, q: &Query) -> Vec4 {
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
