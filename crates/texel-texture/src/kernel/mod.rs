//! Kernels: the filters inside one level (nearest, bilinear, bicubic and the 8-bit fixed-point
//! forms of nearest and bilinear). A kernel reads texels through `storage::fetch` and
//! knows nothing of mip levels, samplers or batches.

pub mod bicubic;
pub(crate) mod bilinear;
pub mod fixed8;
pub(crate) mod nearest;
pub(crate) mod staged;

use glam::{Vec2, Vec4};

use crate::base::address::Address;
use crate::base::filter::FilterMode;
use crate::storage::fetch::Fetch;
use bicubic::bicubic;
use bilinear::bilinear;
use nearest::nearest;

/// Filter one level with a within-level filter (Nearest, Linear or Cubic) at normalised `uv`.
///
/// The minification-only filters (`Ewa`, `Ripmap`, `SummedArea`) never reach this function (the
/// sampler dispatches them first and rejects them as `mag_filter`); should one arrive it is
/// treated as Linear.
#[inline(always)]
pub(crate) fn filter_level<F: Fetch>(
    mode: &FilterMode,
    level: &F,
    addr: &Address,
    uv: Vec2,
) -> Vec4 {
    match mode {
        FilterMode::Nearest => nearest(level, addr, uv),
        FilterMode::Cubic(c) => bicubic(level, addr, c, uv),
        FilterMode::Linear
        | FilterMode::Ewa
        | FilterMode::EwaProbes
        | FilterMode::Ripmap
        | FilterMode::SummedArea => bilinear(level, addr, uv),
    }
}

/// A filter inside one level at a normalised point: the kernels' own types (`bilinear::Bilinear`,
/// `nearest::Point`) resolve at compile time, a `&FilterMode` at run time ([`filter_level`]).
/// The mip rules below are generic over it, so each caller's filter is compiled into them (the
/// anisotropic probes' bilinear costs no dispatch).
pub(crate) trait LevelFilter: Copy {
    /// Filter `level` at `uv` under `addr`.
    fn filter<F: Fetch>(self, level: &F, addr: &Address, uv: Vec2) -> Vec4;
}

impl LevelFilter for &FilterMode {
    #[inline(always)]
    fn filter<F: Fetch>(self, level: &F, addr: &Address, uv: Vec2) -> Vec4 {
        filter_level(self, level, addr, uv)
    }
}
