//! The texel formats and the layout of a texture's storage: [`ColorSpace`], [`Format`], where each
//! level lives ([`LevelInfo`]) and the one contiguous allocation that holds them.

use crate::base::color::{srgb_table, unorm8_table};

/// How 8-bit colour channels are to be interpreted.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ColorSpace {
    /// RGB are sRGB-encoded and decoded to linear light before filtering (alpha is always linear).
    /// Example: code 128 samples as 0.2159.
    Srgb,
    /// Bytes are linear values `b / 255` (a GPU sampling a `*Unorm` texture). Example: 128 -> 0.5020.
    Linear,
}

/// Texel storage format of a [`Texture`](crate::Texture) (and of every level of its pyramid).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Format {
    /// 8-bit RGBA, RGB sRGB-encoded, alpha linear. 4 bytes per texel.
    Rgba8Srgb,
    /// 8-bit RGBA, all channels linear `b / 255`. 4 bytes per texel.
    Rgba8Unorm,
    /// 32-bit float RGBA, linear. 16 bytes per texel.
    Rgba32Float,
}

impl Format {
    /// Bytes one texel occupies.
    pub fn texel_bytes(self) -> u64 {
        match self {
            Format::Rgba8Srgb | Format::Rgba8Unorm => 4,
            Format::Rgba32Float => 16,
        }
    }
}

/// Where one mip level lives in the texture's storage.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LevelInfo {
    /// Width in texels: `max(1, W >> level)`.
    pub width: u32,
    /// Height in texels: `max(1, H >> level)`.
    pub height: u32,
    /// Index of the level's first texel in the contiguous storage.
    pub offset: usize,
}

/// One level's stored texels ([`Texture::level_texels`](crate::Texture::level_texels)).
#[derive(Clone, Copy, Debug)]
pub enum LevelTexels<'a> {
    /// 8-bit RGBA codes (decode RGB by the texture's colour space, alpha as `b / 255`).
    Unorm8(&'a [[u8; 4]]),
    /// Linear `f32` RGBA.
    Float(&'a [[f32; 4]]),
}

/// Every level's texels, back to back, in the texture's format.
#[derive(Clone, Debug)]
pub(crate) enum Storage {
    U8(Vec<[u8; 4]>),
    F32(Vec<[f32; 4]>),
}

/// One 8-bit texel to linear RGBA through the decode tables: RGB sRGB-decoded when `srgb`, else
/// `b / 255`; alpha always `b / 255`.
pub(crate) fn decode_rgba8(t: [u8; 4], srgb: bool) -> [f32; 4] {
    let lin = unorm8_table();
    let table = if srgb { srgb_table() } else { lin };
    [
        table[t[0] as usize],
        table[t[1] as usize],
        table[t[2] as usize],
        lin[t[3] as usize],
    ]
}
