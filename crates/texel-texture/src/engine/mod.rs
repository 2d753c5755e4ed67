//! The engine: the validated [`sampler::Sampler`] that resolves a descriptor to one technique, its
//! binding to a texture that chooses a span's route once ([`crate::BoundSampler`]), the batched
//! path that stages kernels over chunks of footprints (`batch`) and the instruction-set copies it
//! runs on ([`dispatch`]). The top floor: it may use everything below.

pub(crate) mod batch;
pub mod dispatch;
pub mod sample;
pub mod sampler;
pub(crate) mod span;
