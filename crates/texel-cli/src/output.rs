//! Writing images: linear RGBA frames encoded to 8-bit PNG, written atomically.

use std::path::Path;

use anyhow::{Context, Result};
use image::ImageEncoder;
use texel_texture::color::{linear_to_srgb8, unorm8};

use crate::cli::ColorArg;

/// Encode linear RGBA to 8-bit RGBA: sRGB-encoded RGB (alpha linear), or raw `round(255 x)`.
pub fn encode_rgba8(pixels: &[[f32; 4]], color: ColorArg) -> Vec<u8> {
    let mut out = Vec::with_capacity(pixels.len() * 4);
    for p in pixels {
        let rgb = |x: f32| match color {
            ColorArg::Srgb => linear_to_srgb8(x),
            ColorArg::Raw => unorm8(x),
        };
        out.extend_from_slice(&[rgb(p[0]), rgb(p[1]), rgb(p[2]), unorm8(p[3])]);
    }
    out
}

/// PNG bytes of an 8-bit RGBA image.
pub fn png_bytes(width: u32, height: u32, rgba8: &[u8]) -> Result<Vec<u8>> {
    let mut out = Vec::new();
    image::codecs::png::PngEncoder::new(&mut out)
        .write_image(rgba8, width, height, image::ExtendedColorType::Rgba8)
        .context("cannot encode PNG")?;
    Ok(out)
}

/// Write `bytes` to `path` atomically: a temporary file beside it, then a rename, so an interrupted
/// run never leaves a truncated file. The temporary file is removed on error.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let name = path
        .file_name()
        .with_context(|| format!("cannot write {}: not a file path", path.display()))?;
    let tmp = dir.join(format!(".{}.tmp{}", name.to_string_lossy(), std::process::id()));
    let result = std::fs::write(&tmp, bytes).and_then(|()| std::fs::rename(&tmp, path));
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result.with_context(|| format!("cannot write {}", path.display()))
}

/// Encode and atomically write a linear RGBA frame as PNG.
pub fn write_png(path: &Path, width: u32, height: u32, pixels: &[[f32; 4]], color: ColorArg) -> Result<()> {
    let bytes = png_bytes(width, height, &encode_rgba8(pixels, color))?;
    write_atomic(path, &bytes)
}
