//! Techniques: how a footprint becomes kernel reads across levels or tables. Mipmapping
//! ([`mip`]), the hardware-style anisotropic probes ([`aniso`]), EWA ([`ewa`]) and its approximation by weighted probes ([`ewa_probes`]), ripmaps
//! ([`ripmap`]) and summed-area tables ([`sat`]); the lab's eight modes under either convention
//! ([`lab`]). Each takes the pyramid, a query and the small
//! parameter set it needs, never the whole sampler.

pub mod aniso;
pub mod ewa;
pub mod ewa_probes;
pub mod lab;
pub mod mip;
pub mod ripmap;
pub mod sat;

use crate::base::address::Address;
use crate::base::descriptor::SamplerDescriptor;

/// What a technique needs of its sampler, made once when the sampler is validated: the address
/// modes and border colour, the lod's bias and clamps, and the anisotropy limit.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Params {
    /// Address modes and border colour.
    pub addr: Address,
    /// Added to `log2(rho)` before clamping.
    pub lod_bias: f32,
    /// Smallest lod used.
    pub lod_min_clamp: f32,
    /// Largest lod used.
    pub lod_max_clamp: f32,
    /// Largest anisotropy ratio honoured (1 to 64).
    pub anisotropy_clamp: u16,
}

impl Params {
    /// The parameters of a validated `desc`.
    pub(crate) fn of(desc: &SamplerDescriptor) -> Params {
        Params {
            addr: Address::of(desc),
            lod_bias: desc.lod_bias,
            lod_min_clamp: desc.lod_min_clamp,
            lod_max_clamp: desc.lod_max_clamp,
            anisotropy_clamp: desc.anisotropy_clamp,
        }
    }
}
