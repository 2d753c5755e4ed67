//! Techniques: how a footprint becomes kernel reads across levels or tables. Mipmapping
//! ([`mip`]), the hardware-style anisotropic probes ([`aniso`]), EWA ([`ewa`]), ripmaps
//! ([`ripmap`]) and summed-area tables ([`sat`]). Each takes the pyramid, a query and the small
//! parameter set it needs, never the whole sampler.

pub mod aniso;
pub mod ewa;
pub mod mip;
pub mod ripmap;
pub mod sat;
