//! Kernels: the filters inside one level (nearest, bilinear, bicubic and the 8-bit fixed-point
//! forms of nearest and bilinear). A kernel reads texels through [`crate::storage::fetch`] and
//! knows nothing of mip levels, samplers or batches.

pub mod bicubic;
pub(crate) mod bilinear;
pub mod fixed8;
pub(crate) mod nearest;
