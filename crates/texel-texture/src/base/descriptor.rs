//! The [`SamplerDescriptor`]: WebGPU's `GPUSamplerDescriptor`, with the filters of
//! [`crate::base::filter`], address modes, lod clamps and bias, anisotropy and border colour. Validated into a
//! [`crate::engine::sampler::Sampler`] by `Sampler::new`.

use crate::base::address::{Address, AddressMode, BorderColor};
use crate::base::filter::{FilterMode, MipmapFilterMode, EWA_DEFAULT_ANISOTROPY};

/// Everything that configures a [`Sampler`](crate::Sampler). Field names follow WebGPU's `GPUSamplerDescriptor`.
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

impl Address {
    /// The address modes and border colour of `desc`.
    pub fn of(desc: &SamplerDescriptor) -> Address {
        Address::new(desc.address_mode_u, desc.address_mode_v, desc.border_color)
    }
}

impl SamplerDescriptor {
    /// Hardware-style anisotropic filtering with at most `max_anisotropy` trilinear probes
    /// (linear mag/min/mipmap filters). `max_anisotropy` 1 is plain trilinear; values outside
    /// 1..=64 are rejected by [`Sampler::new`](crate::Sampler::new).
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
