//! The prefiltered tables a texture builds on first use, as stored: the ripmap's reduced images
//! and the summed-area table's sums. Built and filtered by [`crate::technique::ripmap`] and
//! [`crate::technique::sat`]; held by the [`crate::Texture`] they belong to.

use crate::storage::format::{LevelInfo, Storage};

/// All anisotropic reductions of a texture's level 0 ([`crate::technique::ripmap`]).
#[derive(Debug)]
pub struct Ripmap {
    pub(crate) width: u32,
    pub(crate) height: u32,
    pub(crate) nx: usize,
    pub(crate) ny: usize,
    /// Image `(a, b)` at index `a * ny + b`; entry 0 is level 0 (stored in the texture).
    pub(crate) infos: Vec<LevelInfo>,
    pub(crate) storage: Storage,
    /// 8-bit RGB stored sRGB-encoded (the texture's format is `Rgba8Srgb`).
    pub(crate) srgb: bool,
}

impl Ripmap {
    /// Bytes the ripmap's texels occupy.
    pub fn bytes(&self) -> u64 {
        match &self.storage {
            Storage::U8(v) => v.len() as u64 * 4,
            Storage::F32(v) => v.len() as u64 * 16,
        }
    }
}

/// The summed-area table of a texture's level 0 ([`crate::technique::sat`]).
#[derive(Debug)]
pub struct SummedAreaTable {
    pub(crate) width: u32,
    pub(crate) height: u32,
    /// `(W + 1) x (H + 1)` entries, row-major, `[r, g, b, a]` sums in linear light.
    pub(crate) table: Vec<[f64; 4]>,
}

impl SummedAreaTable {
    /// Bytes the table occupies.
    pub fn bytes(&self) -> u64 {
        self.table.len() as u64 * 32
    }
}
