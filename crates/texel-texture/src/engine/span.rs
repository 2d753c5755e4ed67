//! A sampler bound to one texture ([`BoundSampler`]): the route its spans of footprints take
//! through the engine is chosen once, in [`Sampler::bind`], from the sampler's technique, the
//! texture's storage and size, and what the caller takes ([`Wants`]); [`BoundSampler::sample_span`]
//! is the one entry point that follows it.

use glam::Vec4;

use crate::base::address::Address;
use crate::base::color::{rgba_to_srgb8, rgba_to_unorm8};
use crate::base::filter::{FilterMode, MipmapFilterMode};
use crate::base::floor::integer_bytes4;
use crate::base::footprint_batch::{chunks, FootprintBatch, Source};
use crate::engine::batch;
use crate::engine::sampler::{Sampler, Technique};
use crate::kernel::staged::{self, Chunk, CHUNK};
use crate::storage::fetch::{Codes8, Fetch};
use crate::storage::lanes::Lanes;
use crate::storage::texture::{Format, Texture};
use crate::storage::view::{codes_of, with_pyramid, Pyramid, Stored};
use crate::technique::aniso::{filter_planned, plan_chunk, Plan, Probes};
use crate::technique::ewa_probes::ewa_probes;

/// What a caller takes from a span besides linear floats.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Wants {
    /// The caller writes 8-bit colour as the texture's format stores it, and nothing changes a
    /// sample on its way there: a sampler that reads one texel hands over the texel's stored
    /// bytes ([`SpanKind::Stored`]).
    pub stored_bytes: bool,
    /// GPU-style fixed-point filtering ([`crate::kernel::fixed8`]) where it applies
    /// ([`SpanKind::Fixed8`]).
    pub fixed8: bool,
}

/// What a bound sampler's spans produce.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SpanKind {
    /// Linear RGBA floats: `out[k] = sample(texture, f)` for footprint `k`, `f`, bit for bit.
    Float,
    /// The stored bytes of the texel each footprint reads (nearest filtering with no or nearest
    /// mipmaps, on an 8-bit texture): the texel whose decoding [`Sampler::sample`] returns (the
    /// same query, level and texel), or, where `ClampToBorder` reads outside the texture, the
    /// border colour encoded in the texture's format (sRGB RGB and linear alpha for
    /// `Rgba8Srgb`, all linear for `Rgba8Unorm`; [`crate::base::color::rgba_to_srgb8`],
    /// [`crate::base::color::rgba_to_unorm8`]). Encoding a sample in the texture's own format
    /// gives these bytes (the decode tables round-trip every code), so a renderer writing an
    /// 8-bit target of that format may copy them and skip the decode and the encode.
    Stored,
    /// GPU-style fixed-point filtering ([`crate::kernel::fixed8`]) of an `Rgba8Unorm` texture by
    /// the core kernels (nearest or bilinear, `mag_filter == min_filter`, any mipmap filter): per
    /// footprint the unorm8 code that 8-bit sub-texel and mip weights give, with one rounding per
    /// blend; the same query, lod, levels and texels as [`Sampler::sample`], whose result it
    /// approximates. Where `ClampToBorder` reads outside the texture the border colour enters as
    /// its unorm8 codes.
    Fixed8,
}

/// The path a bound sampler's spans take; [`Sampler::bind`] is the one function that picks it.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Route {
    /// Nearest in level 0: the stored bytes copied (`batch::point_bytes`).
    StoredPoint,
    /// The nearest texel of the nearest level: the staged core kernels over stored codes.
    StoredCodes,
    /// Fixed-point weights over stored codes (`batch::run_fixed`).
    Fixed8,
    /// The staged core kernels in `f32` (`batch::run`), on a level 0 they take.
    Core,
    /// Anisotropic probes filtered together with those of neighbouring samples
    /// (`batch::anisotropic`), on a level 0 the staged kernels take.
    Anisotropic,
    /// Anisotropic probe plans a chunk at a time, then each sample's probes.
    AnisotropicPlanned,
    /// EWA from weighted trilinear probes, with this eccentricity clamp.
    EwaProbes(f32),
    /// Every sample through the sampler's one-sample filter, queries a chunk at a time.
    PerSample,
}

/// Samples per kernel call of the byte routes: the rasterizer's span (four 64-pixel tile rows).
const CODES_RUN: usize = 256;

/// A sampler bound to a texture, with its spans' route chosen ([`Sampler::bind`]).
pub struct BoundSampler<'a> {
    sampler: &'a Sampler,
    texture: &'a Texture,
    route: Route,
    /// The texture's stored codes, for the byte routes.
    codes: Option<Stored<'a, Codes8>>,
    /// The sampler's address modes with the border colour as codes of the texture's format,
    /// for the byte routes.
    codes_addr: Address,
}

impl std::fmt::Debug for BoundSampler<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("BoundSampler")
            .field("sampler", self.sampler)
            .field("route", &self.route)
            .finish_non_exhaustive()
    }
}

impl Sampler {
    /// This sampler bound to `texture`, taking its spans as `wants` allows: the one place the
    /// route of a span is chosen. Stored bytes where `wants.stored_bytes` and every sample reads
    /// one texel of an 8-bit texture; else fixed-point codes where `wants.fixed8` and the core
    /// kernels filter an `Rgba8Unorm` texture; else floats, through the staged core kernels,
    /// batched anisotropic probes or one sample at a time. The byte routes and the staged ones
    /// need a level 0 whose sides the staged kernels take (at most 65,536).
    pub fn bind<'a>(&'a self, texture: &'a Texture, wants: Wants) -> BoundSampler<'a> {
        let staged = staged::staged((texture.width(), texture.height()));
        let codes = codes_of(texture).filter(|_| staged);
        let nearest = self.batched
            && self.desc.min_filter == FilterMode::Nearest
            && self.desc.mipmap_filter != MipmapFilterMode::Linear;
        let unorm = texture.format() == Format::Rgba8Unorm;
        let route = match self.technique {
            _ if wants.stored_bytes && nearest && codes.is_some() => {
                if self.desc.mipmap_filter == MipmapFilterMode::None {
                    Route::StoredPoint
                } else {
                    Route::StoredCodes
                }
            }
            _ if wants.fixed8 && self.batched && unorm && codes.is_some() => Route::Fixed8,
            _ if self.batched && staged => Route::Core,
            Technique::Anisotropic if staged => Route::Anisotropic,
            Technique::Anisotropic => Route::AnisotropicPlanned,
            Technique::EwaProbes(max) => Route::EwaProbes(max),
            _ => Route::PerSample,
        };
        let border = match texture.format() {
            Format::Rgba8Srgb => rgba_to_srgb8(self.params.addr.border.to_array()),
            _ => rgba_to_unorm8(self.params.addr.border.to_array()),
        };
        BoundSampler {
            sampler: self,
            texture,
            route,
            codes: codes.filter(|_| {
                matches!(
                    route,
                    Route::StoredPoint | Route::StoredCodes | Route::Fixed8
                )
            }),
            codes_addr: Address {
                border: Vec4::from_array(border.map(f32::from)),
                ..self.params.addr
            },
        }
    }
}

impl BoundSampler<'_> {
    /// What [`BoundSampler::sample_span`] writes.
    pub fn kind(&self) -> SpanKind {
        match self.route {
            Route::StoredPoint | Route::StoredCodes => SpanKind::Stored,
            Route::Fixed8 => SpanKind::Fixed8,
            _ => SpanKind::Float,
        }
    }

    /// Samples a span of footprints, as [`BoundSampler::kind`] says: floats into `floats` (with
    /// the bilinear quads of linear 8-bit textures blended by `lanes`' kernel, the same bits with
    /// every [`Lanes`]; [`Sampler::sample_batch_lanes`]) or bytes into `bytes`; the other slice
    /// is not touched and may be empty. Returns the kind.
    ///
    /// # Panics
    /// If the slice written differs in length from `footprints` (a programming error, not bad
    /// input).
    pub fn sample_span(
        &self,
        lanes: Lanes,
        footprints: impl FootprintBatch,
        floats: &mut [[f32; 4]],
        bytes: &mut [[u8; 4]],
    ) -> SpanKind {
        match &self.codes {
            Some(p) => self.codes_span(lanes, p, footprints.source(), bytes),
            None => self.float_span(lanes, footprints.source(), floats),
        }
        self.kind()
    }

    /// The byte routes: the staged kernels (fixed-point ones for [`Route::Fixed8`], whose
    /// bilinear quads blend with `lanes`' kernel) over the texture's stored codes, narrowed to
    /// bytes; nearest in level 0 copies the bytes.
    // Not inlined into the tile rasterizer's copies: its kernels (`batch::point_bytes`,
    // `batch::run`) run on their own instruction-set copies (`crate::engine::dispatch`).
    fn codes_span<S: Source>(
        &self,
        lanes: Lanes,
        p: &Stored<'_, Codes8>,
        footprints: S,
        out: &mut [[u8; 4]],
    ) {
        let p = &Stored {
            tex: p.tex,
            levels: p.levels,
            texels: p.texels,
            decode: Codes8 { lanes },
        };
        assert_eq!(
            footprints.len(),
            out.len(),
            "sample_span: footprints and bytes differ in length"
        );
        let (s, addr) = (self.sampler, self.codes_addr);
        if self.route == Route::StoredPoint {
            return batch::point_bytes(&p.level(0), &addr, footprints, out);
        }
        // One kernel call per `CODES_RUN` samples: each call makes its level views and
        // dispatches, which per 64-sample chunk costs bilinear frames time (docs/decisions.md).
        let mut codes = [[0.0f32; 4]; CODES_RUN];
        for (fps, out) in chunks(footprints, CODES_RUN).zip(out.chunks_mut(CODES_RUN)) {
            let codes = &mut codes[..fps.len()];
            if self.route == Route::Fixed8 {
                batch::run_fixed(p, s, addr, fps, codes);
            } else {
                batch::run(p, s, addr, fps, codes);
            }
            for (o, c) in out.iter_mut().zip(codes.iter()) {
                // Codes are integers in 0..=255: read from bits, without a saturating float
                // conversion per channel.
                *o = integer_bytes4(*c);
            }
        }
    }

    /// The float routes, on the texture's pyramid view.
    fn float_span<S: Source>(&self, lanes: Lanes, footprints: S, out: &mut [[f32; 4]]) {
        assert_eq!(
            footprints.len(),
            out.len(),
            "sample_span: footprints and floats differ in length"
        );
        let s = self.sampler;
        with_pyramid!(self.texture, lanes, |p| {
            if self.route == Route::Core {
                // `batch::run` dispatches per within-level filter.
                return batch::run(&p, s, s.params.addr, footprints, out);
            }
            crate::engine::dispatch::run(BatchJob {
                s,
                route: self.route,
                p: &p,
                footprints,
                out,
            })
        })
    }
}

/// The float routes past the core kernels: anisotropic probes batched, else every sample
/// through [`Sampler::filter`] with its query (and anisotropic probe plan) made a chunk at a time.
#[inline(always)]
fn batch_in<P: Pyramid, S: Source>(
    s: &Sampler,
    route: Route,
    p: &P,
    footprints: S,
    out: &mut [[f32; 4]],
) {
    let size = p.level(0).size();
    if route == Route::Anisotropic {
        // Every sample's probes (one for a magnified or isotropic sample) filtered together with
        // those of its neighbours.
        return batch::anisotropic(p, s, (footprints, out));
    }
    // Two stages per chunk: all queries first (`batch::queries`, `Sampler::query`'s arithmetic
    // vectorised), then all filters.
    let mut chunk = Chunk::<{ CHUNK }>::new();
    let parts = chunks(footprints, CHUNK).zip(out.chunks_mut(CHUNK));
    match route {
        Route::AnisotropicPlanned => {
            // A third stage between the two: every sample's probe plan (axes, probe count,
            // probe lod), vectorised as the lods are; the probes' scratch is made once.
            let mut plans = [Plan::default(); CHUNK];
            let mut probes = Probes::new(s.params.addr);
            for (fps, outs) in parts {
                batch::queries(s, size, fps, &mut chunk);
                plan_chunk(&s.params, size, &chunk, &mut plans);
                for (k, o) in outs.iter_mut().enumerate() {
                    let q = chunk.query(k);
                    // As `filter`: magnification first.
                    *o = if q.lod > 0.0 {
                        filter_planned(p, &q, &plans[k], &mut probes)
                    } else {
                        s.filter(p, &q)
                    }
                    .to_array();
                }
            }
        }
        Route::EwaProbes(max) => {
            // The probes' scratch made once, as for the anisotropic probes.
            let mut probes = Probes::new(s.params.addr);
            for (fps, outs) in parts {
                batch::queries(s, size, fps, &mut chunk);
                for (k, o) in outs.iter_mut().enumerate() {
                    let q = chunk.query(k);
                    *o = if q.lod > 0.0 {
                        ewa_probes(p, &s.params, &q, max, &mut probes)
                    } else {
                        s.filter(p, &q)
                    }
                    .to_array();
                }
            }
        }
        _ => {
            for (fps, outs) in parts {
                batch::queries(s, size, fps, &mut chunk);
                for (k, o) in outs.iter_mut().enumerate() {
                    *o = s.filter(p, &chunk.query(k)).to_array();
                }
            }
        }
    }
}

/// [`batch_in`]'s arguments, as the dispatcher's unit of work (one function per pyramid type
/// and instruction-set copy).
struct BatchJob<'j, P, S> {
    s: &'j Sampler,
    route: Route,
    p: &'j P,
    footprints: S,
    out: &'j mut [[f32; 4]],
}

impl<P: Pyramid, S: Source> crate::engine::dispatch::Kernel for BatchJob<'_, P, S> {
    type Output = ();
    /// Ignores `lanes`: a linear 8-bit pyramid carries its quad kernel (`fetch::Unorm8`).
    #[inline(always)]
    fn run(self, _lanes: Lanes) {
        batch_in(self.s, self.route, self.p, self.footprints, self.out)
    }
}
