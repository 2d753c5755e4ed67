//! `SamplerDescriptor` (WebGPU vocabulary) validated once into a [`Sampler`].
//!
//! As wgpu's `create_sampler`, every check happens in [`Sampler::new`]; the per-sample path cannot
//! fail and does not re-validate. The sampler resolves its technique once; per sample it only computes
//! the lod and dispatches on that resolved choice.
//!
//! Mag/min selection (Vulkan spec, "Texel Filtering"): `lod <= 0` uses `mag_filter` at level 0,
//! `lod > 0` uses `min_filter` with `mipmap_filter` choosing the level(s). `lod` is
//! `log2(rho) + lod_bias` clamped to `[lod_min_clamp, lod_max_clamp]` (see [`crate::base::footprint`]).
//!
//! Beyond the core filters, four anisotropic techniques are selected through the same descriptor:
//!
//! | technique | descriptor | module |
//! |---|---|---|
//! | hardware-style N x anisotropic | mag, min and mipmap filters `Linear`, `anisotropy_clamp` 2..=16 (up to 64 accepted); [`SamplerDescriptor::lab_mode`] 5-8 | [`crate::technique::aniso`] |
//! | EWA | `min_filter: FilterMode::Ewa` | [`crate::technique::ewa`] |
//! | ripmap | `min_filter: FilterMode::Ripmap` | [`crate::technique::ripmap`] |
//! | summed-area table | `min_filter: FilterMode::SummedArea` | [`crate::technique::sat`] |
//!
//! Decisions for the three minification-only filters (`Ewa`, `Ripmap`, `SummedArea`):
//! - magnification works as on a GPU: when the isotropic `lod` (from `rho`, the longer axis) is
//!   `<= 0`, `mag_filter` runs at level 0. Using one of them as `mag_filter` is rejected with
//!   [`TextureError::MinificationOnlyFilter`];
//! - `mipmap_filter` is ignored: each technique chooses its own levels (EWA lerps two pyramid
//!   levels, the ripmap blends four images, the summed-area table reads level 0 only);
//! - `anisotropy_clamp` is EWA's eccentricity clamp; its WebGPU default of 1 ("not requested")
//!   means 16 for EWA ([`EWA_DEFAULT_ANISOTROPY`]). Ripmap and summed-area table ignore it
//!   (their box has no eccentricity limit);
//! - the ripmap and the summed-area table are built on first use, or by [`Texture::build_structures`]; if
//!   one would exceed the texture's [`crate::Limits`], sampling falls back to trilinear.
//!
//! ## The code path
//!
//! [`Sampler::sample`] is two stages: `Sampler::query` makes the sample's query once (`uv` made
//! finite, the isotropic lod `0.5 * log2(rho^2)` with [`crate::base::footprint::fast_log2`]; skipped when
//! it cannot matter: no mipmapping and `mag_filter == min_filter`), then `Sampler::filter`
//! dispatches on the resolved technique to one filter, each a function of the pyramid, the sampler
//! and the query ([`crate::technique::mip`], [`crate::technique::aniso`], [`crate::technique::ewa`], [`crate::technique::ripmap`],
//! [`crate::technique::sat`]).
//!
//! [`Sampler::sample_batch`] runs the same stages over chunks of 64 footprints: all queries first
//! (the one-sample path is latency-bound, one long dependency chain per sample, so letting the
//! independent lod computations overlap is what moves the wall time), then the filters. The core
//! filters (nearest or bilinear inside the levels, any mipmap mode) go through `batch.rs`, which
//! stages the very kernels of `crate::kernel::bilinear` and [`crate::technique::mip`] over the chunk; anisotropic
//! probes are planned per chunk ([`crate::technique::aniso`]). Results are bit-identical to
//! [`Sampler::sample`] (tested).
//!
//! What bounds the 8-bit path: over half of a trilinear frame is texel loads, the four table loads
//! that decode each sRGB texel, and the `Vec4` blends. The sampler bench's `bound/*` group times
//! those alone (every index and fraction precomputed) and on a float copy of the texture (no
//! decode). The figures are in docs/benchmarks.md; the decisions they back, and why AVX2
//! gathers are not used, are in docs/decisions.md.

use glam::Vec4;

use crate::base::address::{Address, AddressMode, BorderColor};
use crate::base::color::{rgba_to_srgb8, rgba_to_unorm8};
use crate::base::error::TextureError;
use crate::base::floor::integer_bytes4;
pub use crate::base::footprint::UV_LIMIT;
use crate::base::footprint::{finite_uv, lod_from_rho_squared, rho_squared, Footprint, Query};
use crate::base::footprint_batch::{chunks, FootprintBatch, Source};
use crate::engine::batch::{self, Chunk, Probes};
use crate::kernel::bicubic::Cubic;
use crate::kernel::bilinear::Bilinear;
use crate::storage::fetch::{codes_of, with_pyramid, Counted, Fetch, Pyramid};
use crate::storage::lanes::Lanes;
use crate::storage::texture::{Format, Texture};
use crate::technique::aniso::{anisotropic, filter_planned, plan_chunk, Plan};
use crate::technique::ewa::ewa;
use crate::technique::mip::{filter_level, mip_nearest, trilinear};
use crate::technique::ripmap::ripmap;
use crate::technique::sat::summed_area;

/// Filter used within one mip level (WebGPU `GPUFilterMode`, plus cubic).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum FilterMode {
    /// The texel containing the sample point (1 read).
    #[default]
    Nearest,
    /// Bilinear interpolation of the 2x2 nearest texel centres (4 reads).
    Linear,
    /// Bicubic Mitchell-Netravali with the given `(B, C)` over 4x4 texels (16 reads).
    Cubic(Cubic),
    /// Elliptically weighted average (Heckbert 1989, pbrt-v4 structure) over the footprint's
    /// ellipse in two pyramid levels; `min_filter` only. See [`crate::technique::ewa`].
    Ewa,
    /// Anisotropically reduced images `(W >> a) x (H >> b)` chosen from the footprint's
    /// axis-aligned bounding box, four blended; `min_filter` only. See [`crate::technique::ripmap`].
    Ripmap,
    /// Box mean over the footprint's axis-aligned bounding rectangle from a summed-area table
    /// (Crow 1984); `min_filter` only. See [`crate::technique::sat`].
    SummedArea,
}

impl FilterMode {
    /// Whether this filter is valid only as `min_filter` (`Ewa`, `Ripmap`, `SummedArea`).
    pub fn is_minification_only(self) -> bool {
        matches!(
            self,
            FilterMode::Ewa | FilterMode::Ripmap | FilterMode::SummedArea
        )
    }
}

/// EWA's eccentricity clamp when `anisotropy_clamp` is left at its WebGPU default of 1.
pub const EWA_DEFAULT_ANISOTROPY: u16 = 16;

/// How mip levels are chosen and combined when minifying (WebGPU `GPUMipmapFilterMode`, plus `None`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum MipmapFilterMode {
    /// No mipmapping: minification filters level 0 only (OpenGL's `GL_LINEAR`/`GL_NEAREST` min filter).
    None,
    /// The nearest level (Vulkan rounding `ceil(lod + 1/2) - 1`).
    #[default]
    Nearest,
    /// Linear blend of the two levels around `lod` (trilinear when the min filter is Linear).
    Linear,
}

/// Everything that configures a [`Sampler`]. Field names follow WebGPU's `GPUSamplerDescriptor`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SamplerDescriptor {
    /// Address mode along u (texture x).
    pub address_mode_u: AddressMode,
    /// Address mode along v (texture y).
    pub address_mode_v: AddressMode,
    /// Filter when `lod <= 0` (magnification).
    pub mag_filter: FilterMode,
    /// Filter within a level when `lod > 0` (minification).
    pub min_filter: FilterMode,
    /// How levels are chosen when minifying.
    pub mipmap_filter: MipmapFilterMode,
    /// Smallest lod used, `>= 0`. Default 0.
    pub lod_min_clamp: f32,
    /// Largest lod used, `>= lod_min_clamp`. Default 32 (levels beyond the last hold the last).
    pub lod_max_clamp: f32,
    /// Added to `log2(rho)` before clamping (Vulkan `mipLodBias`). Default 0.
    pub lod_bias: f32,
    /// Largest anisotropy ratio honoured, 1 to 64. Default 1 (isotropic). Values above 1 with the
    /// core filters need mag, min and mipmap filters `Linear` (WebGPU rule) and select the
    /// hardware-style anisotropic filter ([`crate::technique::aniso`]); with [`FilterMode::Ewa`] it is the
    /// eccentricity clamp (1 means [`EWA_DEFAULT_ANISOTROPY`]).
    pub anisotropy_clamp: u16,
    /// Colour read outside the texture under [`AddressMode::ClampToBorder`].
    pub border_color: BorderColor,
}

impl Default for SamplerDescriptor {
    /// WebGPU's defaults: clamp to edge, nearest everywhere, lod in `[0, 32]`, no anisotropy.
    fn default() -> Self {
        SamplerDescriptor {
            address_mode_u: AddressMode::ClampToEdge,
            address_mode_v: AddressMode::ClampToEdge,
            mag_filter: FilterMode::Nearest,
            min_filter: FilterMode::Nearest,
            mipmap_filter: MipmapFilterMode::Nearest,
            lod_min_clamp: 0.0,
            lod_max_clamp: 32.0,
            lod_bias: 0.0,
            anisotropy_clamp: 1,
            border_color: BorderColor::TransparentBlack,
        }
    }
}

impl SamplerDescriptor {
    /// The lab's numbered modes: 1 nearest, 2 bilinear, 3 bilinear with the nearest mip level,
    /// 4 trilinear, 5-8 anisotropic 2x/4x/8x/16x (trilinear probes). Address modes are left at
    /// their defaults (set them with [`SamplerDescriptor::with_address_mode`]).
    ///
    /// # Errors
    /// [`TextureError::UnknownLabMode`] for other numbers.
    pub fn lab_mode(mode: u8) -> Result<Self, TextureError> {
        let linear = |mipmap_filter| SamplerDescriptor {
            mag_filter: FilterMode::Linear,
            min_filter: FilterMode::Linear,
            mipmap_filter,
            ..Default::default()
        };
        Ok(match mode {
            1 => SamplerDescriptor {
                mipmap_filter: MipmapFilterMode::None,
                ..Default::default()
            },
            2 => linear(MipmapFilterMode::None),
            3 => linear(MipmapFilterMode::Nearest),
            4 => linear(MipmapFilterMode::Linear),
            5..=8 => Self::anisotropic(1 << (mode - 4)),
            _ => return Err(TextureError::UnknownLabMode(mode)),
        })
    }

    /// Hardware-style anisotropic filtering with at most `max_anisotropy` trilinear probes
    /// (linear mag/min/mipmap filters). `max_anisotropy` 1 is plain trilinear; values outside
    /// 1..=64 are rejected by [`Sampler::new`].
    pub fn anisotropic(max_anisotropy: u16) -> Self {
        SamplerDescriptor {
            mag_filter: FilterMode::Linear,
            min_filter: FilterMode::Linear,
            mipmap_filter: MipmapFilterMode::Linear,
            anisotropy_clamp: max_anisotropy,
            ..Default::default()
        }
    }

    /// `min_filter` set to one of the minification-only filters (`Ewa`, `Ripmap`, `SummedArea`)
    /// with a bilinear `mag_filter`, linear `mipmap_filter` and `anisotropy_clamp` 16.
    pub fn minification(min_filter: FilterMode) -> Self {
        SamplerDescriptor {
            mag_filter: FilterMode::Linear,
            min_filter,
            mipmap_filter: MipmapFilterMode::Linear,
            anisotropy_clamp: EWA_DEFAULT_ANISOTROPY,
            ..Default::default()
        }
    }

    /// The same descriptor with `mode` on both axes.
    pub fn with_address_mode(self, mode: AddressMode) -> Self {
        SamplerDescriptor {
            address_mode_u: mode,
            address_mode_v: mode,
            ..self
        }
    }
}

/// The minification technique, resolved once in [`Sampler::new`].
#[derive(Clone, Copy, Debug, PartialEq)]
enum Technique {
    /// `mipmap_filter` with `min_filter` inside the levels (nearest, bilinear, bicubic, trilinear).
    Mip,
    /// Hardware-style anisotropic with at most `anisotropy_clamp` trilinear probes (2..=64).
    Anisotropic,
    /// EWA with this eccentricity clamp (1..=64).
    Ewa(f32),
    /// Ripmap.
    Ripmap,
    /// Summed-area table.
    SummedArea,
}

/// A validated sampler. Cheap to copy; sampling never fails.
#[derive(Clone, Copy, Debug)]
pub struct Sampler {
    desc: SamplerDescriptor,
    technique: Technique,
    /// The result does not depend on the lod (no mipmapping and `mag_filter == min_filter`), so
    /// the per-sample lod computation is skipped.
    lod_free: bool,
    /// [`Sampler::sample_batch`] runs the staged core kernels (`batch::run`): nearest or bilinear
    /// inside the levels, any `mipmap_filter`, `mag_filter == min_filter`.
    batched: bool,
    addr: Address,
}

impl Sampler {
    /// Validate `desc` into a sampler.
    ///
    /// # Errors
    /// [`TextureError::InvalidLodClamp`], [`TextureError::InvalidLodBias`],
    /// [`TextureError::InvalidAnisotropyClamp`], [`TextureError::AnisotropyNeedsLinear`],
    /// [`TextureError::InvalidCubic`], [`TextureError::MinificationOnlyFilter`].
    pub fn new(desc: SamplerDescriptor) -> Result<Self, TextureError> {
        let (lo, hi) = (desc.lod_min_clamp, desc.lod_max_clamp);
        if lo.is_nan() || hi.is_nan() || lo < 0.0 || lo > hi {
            return Err(TextureError::InvalidLodClamp {
                lod_min_clamp: lo,
                lod_max_clamp: hi,
            });
        }
        if !desc.lod_bias.is_finite() {
            return Err(TextureError::InvalidLodBias(desc.lod_bias));
        }
        if !(1..=64).contains(&desc.anisotropy_clamp) {
            return Err(TextureError::InvalidAnisotropyClamp(desc.anisotropy_clamp));
        }
        for f in [desc.mag_filter, desc.min_filter] {
            if let FilterMode::Cubic(c) = f {
                let ok = |x: f32| x.abs() <= crate::kernel::bicubic::MAX_CUBIC_PARAMETER;
                if !ok(c.b) || !ok(c.c) {
                    return Err(TextureError::InvalidCubic { b: c.b, c: c.c });
                }
            }
        }
        if desc.mag_filter.is_minification_only() {
            return Err(TextureError::MinificationOnlyFilter(desc.mag_filter));
        }
        let clamp = desc.anisotropy_clamp;
        let technique = match desc.min_filter {
            FilterMode::Ewa => Technique::Ewa(f32::from(if clamp == 1 {
                EWA_DEFAULT_ANISOTROPY
            } else {
                clamp
            })),
            FilterMode::Ripmap => Technique::Ripmap,
            FilterMode::SummedArea => Technique::SummedArea,
            _ if clamp > 1 => {
                // WebGPU: anisotropy_clamp > 1 requires linear mag, min and mipmap filters.
                if desc.mag_filter != FilterMode::Linear
                    || desc.min_filter != FilterMode::Linear
                    || desc.mipmap_filter != MipmapFilterMode::Linear
                {
                    return Err(TextureError::AnisotropyNeedsLinear(clamp));
                }
                Technique::Anisotropic
            }
            _ => Technique::Mip,
        };
        let lod_free = technique == Technique::Mip
            && desc.mipmap_filter == MipmapFilterMode::None
            && desc.mag_filter == desc.min_filter;
        let batched = technique == Technique::Mip
            && desc.mag_filter == desc.min_filter
            && matches!(desc.min_filter, FilterMode::Nearest | FilterMode::Linear);
        Ok(Sampler {
            desc,
            technique,
            lod_free,
            batched,
            addr: Address::of(&desc),
        })
    }

    /// The address modes and border colour samples are read with.
    pub fn address(&self) -> Address {
        self.addr
    }

    /// Whether samples depend on the footprint's derivatives. `false` when there is no
    /// mipmapping and `mag_filter == min_filter` (the lod cannot change the result): no sampling
    /// path then reads the footprint's derivative fields, so a caller may skip computing them
    /// and pass any values (the rasterizer passes [`crate::FootprintLanes::points`]: none).
    pub fn uses_derivatives(&self) -> bool {
        !self.lod_free
    }

    /// The descriptor this sampler was created from.
    pub fn descriptor(&self) -> &SamplerDescriptor {
        &self.desc
    }

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
            && batch::staged((texture.width(), texture.height()))
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
        if !batch::staged(p.level(0).size()) {
            return false;
        }
        let border = match texture.format() {
            Format::Rgba8Srgb => rgba_to_srgb8(self.addr.border.to_array()),
            _ => rgba_to_unorm8(self.addr.border.to_array()),
        };
        let addr = Address {
            border: Vec4::from_array(border.map(f32::from)),
            ..self.addr
        };
        if !fixed && self.desc.mipmap_filter == MipmapFilterMode::None {
            // Nearest in level 0 (`applies`: both filters nearest): copy the bytes.
            batch::point_bytes(&p.level(0), &addr, footprints, out);
            return true;
        }
        let mut codes = [[0.0f32; 4]; batch::CHUNK];
        for (fps, out) in chunks(footprints, batch::CHUNK).zip(out.chunks_mut(batch::CHUNK)) {
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
            if self.batched && batch::staged(p.level(0).size()) {
                // `batch::run` dispatches per within-level filter.
                return batch::run(&p, self, self.addr, footprints, out);
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
        if self.technique == Technique::Anisotropic && batch::staged(size) {
            // Every sample's probes (one for a magnified or isotropic sample) filtered
            // together with those of its neighbours.
            return batch::anisotropic(p, self, (footprints, out));
        }
        // Two stages per chunk: all queries first (`batch::queries`, `Sampler::query`'s
        // arithmetic vectorised), then all filters.
        let mut chunk = Chunk::<{ batch::CHUNK }>::new();
        let parts = chunks(footprints, batch::CHUNK).zip(out.chunks_mut(batch::CHUNK));
        if self.technique == Technique::Anisotropic {
            // A third stage between the two: every sample's probe plan (axes, probe count,
            // probe lod), vectorised as the lods are; the probes' scratch is made once.
            let mut plans = [Plan::default(); batch::CHUNK];
            let mut probes = Probes::new(self.addr);
            for (fps, outs) in parts {
                batch::queries(self, size, fps, &mut chunk);
                plan_chunk(self, size, &chunk, &mut plans);
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
        let addr = &self.addr;
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
            Technique::Anisotropic => anisotropic(p, self, q),
            Technique::Ewa(max) => ewa(p, self, q, max),
            Technique::Ripmap => match p.texture().ripmap() {
                Ok(r) => ripmap(p, r, self, q),
                Err(_) => trilinear(p, Bilinear, addr, q),
            },
            Technique::SummedArea => match p.texture().summed_area_table() {
                Ok(t) => summed_area(p, t, self, q),
                Err(_) => trilinear(p, Bilinear, addr, q),
            },
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
