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
//! Beyond the core filters, five anisotropic techniques are selected through the same descriptor:
//!
//! | technique | descriptor | module |
//! |---|---|---|
//! | hardware-style N x anisotropic | mag, min and mipmap filters `Linear`, `anisotropy_clamp` 2..=16 (up to 64 accepted); [`Filter::from_lab_mode`] 5-8 | [`crate::technique::aniso`] |
//! | EWA | `min_filter: FilterMode::Ewa` | [`crate::technique::ewa`] |
//! | EWA from weighted trilinear probes | `min_filter: FilterMode::EwaProbes` | [`crate::technique::ewa_probes`] |
//! | ripmap | `min_filter: FilterMode::Ripmap` | [`crate::technique::ripmap`] |
//! | summed-area table | `min_filter: FilterMode::SummedArea` | [`crate::technique::sat`] |
//!
//! Decisions for the four minification-only filters (`Ewa`, `EwaProbes`, `Ripmap`, `SummedArea`):
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

use crate::base::address::Address;
use crate::base::descriptor::SamplerDescriptor;
use crate::base::error::TextureError;
use crate::base::filter::{
    FilterMode, MipmapFilterMode, EWA_DEFAULT_ANISOTROPY, MAX_CUBIC_PARAMETER,
};
pub use crate::base::footprint::UV_LIMIT;
use crate::base::named::Filter;
use crate::storage::tables::{Ripmap, SummedAreaTable};
use crate::storage::texture::Texture;
use crate::technique::lab::Convention;
use crate::technique::Params;

/// The minification technique, resolved once in [`Sampler::new`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Technique {
    /// `mipmap_filter` with `min_filter` inside the levels (nearest, bilinear, bicubic, trilinear).
    Mip,
    /// Hardware-style anisotropic with at most `anisotropy_clamp` trilinear probes (2..=64).
    Anisotropic,
    /// EWA with this eccentricity clamp (1..=64).
    Ewa(f32),
    /// EWA from weighted trilinear probes, with this eccentricity clamp (1..=64).
    EwaProbes(f32),
    /// Ripmap.
    Ripmap,
    /// Summed-area table.
    SummedArea,
    /// Lab mode 1-8 under the lab handout's formulas ([`crate::technique::lab`]).
    Lab(u8),
}

/// A validated sampler. Cheap to copy; sampling never fails.
#[derive(Clone, Copy, Debug)]
pub struct Sampler {
    pub(super) desc: SamplerDescriptor,
    pub(super) technique: Technique,
    /// The result does not depend on the lod (no mipmapping and `mag_filter == min_filter`), so
    /// the per-sample lod computation is skipped.
    pub(super) lod_free: bool,
    /// [`Sampler::sample_batch`] runs the staged core kernels (`batch::run`): nearest or bilinear
    /// inside the levels, any `mipmap_filter`, `mag_filter == min_filter`.
    pub(super) batched: bool,
    /// What the techniques read of the descriptor.
    pub(super) params: Params,
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
                let ok = |x: f32| x.abs() <= MAX_CUBIC_PARAMETER;
                if !ok(c.b) || !ok(c.c) {
                    return Err(TextureError::InvalidCubic { b: c.b, c: c.c });
                }
            }
        }
        if desc.mag_filter.is_minification_only() {
            return Err(TextureError::MinificationOnlyFilter(desc.mag_filter));
        }
        let clamp = desc.anisotropy_clamp;
        let ewa_clamp = f32::from(if clamp == 1 {
            EWA_DEFAULT_ANISOTROPY
        } else {
            clamp
        });
        let technique = match desc.min_filter {
            FilterMode::Ewa => Technique::Ewa(ewa_clamp),
            FilterMode::EwaProbes => Technique::EwaProbes(ewa_clamp),
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
            params: Params::of(&desc),
        })
    }

    /// The address modes and border colour samples are read with.
    pub fn address(&self) -> Address {
        self.params.addr
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

    /// This sampler under `convention`: [`Convention::Gl`] is the descriptor's own filter;
    /// [`Convention::Lab`] evaluates the descriptor's lab mode by the handout's formulas
    /// ([`crate::technique::lab`], texel by texel).
    ///
    /// # Errors
    /// [`TextureError::LabConventionNeedsLabMode`] for [`Convention::Lab`] on a descriptor that
    /// is not one of the eight lab modes (with any address modes and border colour).
    pub fn with_convention(self, convention: Convention) -> Result<Sampler, TextureError> {
        let fresh = Sampler::new(self.desc)?;
        if convention == Convention::Gl {
            return Ok(fresh);
        }
        let d = self.desc;
        let mode = (1..=8u8)
            .find(|&m| {
                Filter::from_lab_mode(m).is_ok_and(|f| {
                    SamplerDescriptor {
                        border_color: d.border_color,
                        ..f.descriptor(d.address_mode_u, d.address_mode_v)
                    } == d
                })
            })
            .ok_or(TextureError::LabConventionNeedsLabMode)?;
        Ok(Sampler {
            technique: Technique::Lab(mode),
            lod_free: false,
            batched: false,
            ..fresh
        })
    }

    /// The convention this sampler's lab mode follows ([`Sampler::with_convention`]).
    pub fn convention(&self) -> Convention {
        match self.technique {
            Technique::Lab(_) => Convention::Lab,
            _ => Convention::Gl,
        }
    }

    /// What the techniques read of the descriptor.
    pub(crate) fn params(&self) -> &Params {
        &self.params
    }
}

impl Texture {
    /// Build ahead of time whatever acceleration structure `sampler` needs (the ripmap for
    /// [`FilterMode::Ripmap`], the summed-area table for [`FilterMode::SummedArea`]; nothing for the
    /// other filters), so that later samples (and frame timings) do not pay for the build.
    /// Idempotent and thread-safe.
    ///
    /// # Errors
    /// [`TextureError::StructureOverMemoryLimit`] if the structure would exceed the texture's
    /// [`crate::Limits::max_bytes`]. Sampling still works then: it falls back to trilinear filtering.
    pub fn build_structures(&self, sampler: &Sampler) -> Result<(), TextureError> {
        match sampler.descriptor().min_filter {
            FilterMode::Ripmap => self.ripmap().map(|_| ()),
            FilterMode::SummedArea => self.summed_area_table().map(|_| ()),
            _ => Ok(()),
        }
    }

    /// Bytes a build of the structures `desc` reads holds while it runs, beyond the structures
    /// themselves: for [`FilterMode::Ripmap`], the `f32` scratch of the ripmap build (the decoded
    /// level 0, an x-reduced image and a y chain, 40 bytes per level-0 texel), which the
    /// texture's own limit counts too; nothing otherwise.
    pub fn build_scratch_bytes(&self, desc: &SamplerDescriptor) -> u64 {
        match desc.min_filter {
            FilterMode::Ripmap => {
                u64::from(self.width())
                    * u64::from(self.height())
                    * crate::technique::ripmap::SCRATCH_BYTES_PER_TEXEL
            }
            _ => 0,
        }
    }

    /// Bytes of the structures a sampler configured by `desc` reads: the mip pyramid
    /// ([`Texture::pyramid_bytes`]), plus the ripmap ([`Ripmap::bytes_for`]) for
    /// [`FilterMode::Ripmap`] or the summed-area table ([`SummedAreaTable::bytes_for`]) for
    /// [`FilterMode::SummedArea`], whether already built or not. Saturates at `u64::MAX`.
    pub fn structure_bytes(&self, desc: &SamplerDescriptor) -> u64 {
        let (w, h) = (self.width(), self.height());
        let extra = match desc.min_filter {
            FilterMode::Ripmap => Ripmap::bytes_for(w, h, self.format()),
            FilterMode::SummedArea => SummedAreaTable::bytes_for(w, h),
            _ => Some(0),
        };
        extra
            .and_then(|e| e.checked_add(self.pyramid_bytes()))
            .unwrap_or(u64::MAX)
    }
}
