//! Writing images: linear RGBA frames encoded to 8-bit PNG, written atomically (through
//! texel-quality's `Image8` and `write_atomic`, so images and reports share one encoder).

use std::path::Path;

use anyhow::{Context, Result};
use texel_quality::{Encoding, Image8};

use crate::cli::ColorArg;

/// The 8-bit encoding `--color` asks for: sRGB-encoded RGB, or raw `round(255 x)`.
pub fn encoding(color: ColorArg) -> Encoding {
    match color {
        ColorArg::Srgb => Encoding::Srgb,
        ColorArg::Raw => Encoding::Linear,
    }
}

/// Encode and atomically write a linear RGBA frame as PNG (temporary file, then rename).
pub fn write_png(
    path: &Path,
    width: u32,
    height: u32,
    pixels: &[[f32; 4]],
    color: ColorArg,
) -> Result<()> {
    Image8::from_linear(width, height, pixels, encoding(color))
        .and_then(|img| img.write_png(path))
        .with_context(|| format!("cannot write {}", path.display()))
}
