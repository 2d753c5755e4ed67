//! Writing images: linear RGBA frames encoded to 8-bit PNG, or kept as linear float OpenEXR where
//! the output path ends in `.exr`, written atomically (through texel-quality's `Image8`,
//! `encode_exr` and `write_atomic`, so images and reports share one encoder).

use std::io::Write;
use std::path::Path;

use anyhow::{Context, Result};
use texel_quality::{Encoding, Image8};

use texel::ColorHandling;
use texel_raster::Frame;

use crate::cli::ColorArg;

/// The 8-bit encoding `--color` asks for: sRGB-encoded RGB, or raw `round(255 x)`.
pub fn encoding(color: impl Into<ColorHandling>) -> Encoding {
    match color.into() {
        ColorHandling::Srgb => Encoding::Srgb,
        ColorHandling::Raw => Encoding::Linear,
    }
}

/// Whether `path` names an OpenEXR file (extension `exr`, in any case). Such outputs hold the
/// frame's linear colour as 32-bit floats, unclamped (radiance above 1 is kept), whatever
/// `--color` says about encoding.
pub fn is_exr(path: &Path) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("exr"))
}

/// Publish `frame` at `path`: OpenEXR of its linear colour ([`is_exr`]; a float frame is
/// written as it is, an 8-bit one decoded), else PNG encoded as `encoding` ([`write_image`]).
pub fn write_frame(path: &Path, frame: &Frame, encoding: Encoding) -> Result<()> {
    if is_exr(path) {
        return write_exr(path, frame.width, frame.height, &frame.linear());
    }
    write_image(path, &texel::frame_image(frame, encoding)?)
}

/// Publish linear RGBA pixels at `path`: OpenEXR for a `.exr` path ([`is_exr`]), else PNG
/// encoded as `color` says ([`write_image`]).
pub fn write_linear(
    path: &Path,
    width: u32,
    height: u32,
    pixels: &[[f32; 4]],
    color: ColorArg,
) -> Result<()> {
    if is_exr(path) {
        return write_exr(path, width, height, pixels);
    }
    let image = Image8::from_linear(width, height, pixels, encoding(color))?;
    write_image(path, &image)
}

/// Publish linear RGBA pixels as OpenEXR at `path` ([`texel_quality::write_exr_atomic`]).
fn write_exr(path: &Path, width: u32, height: u32, pixels: &[[f32; 4]]) -> Result<()> {
    texel_quality::write_exr_atomic(path, width, height, pixels)
        .with_context(|| format!("cannot write {}", path.display()))
}

/// Publish an 8-bit image as PNG at `path` ([`texel_quality::write_atomic`]: atomically over a
/// regular file or a new path, through to a device or FIFO), or on standard output for `-`.
pub fn write_image(path: &Path, image: &Image8) -> Result<()> {
    if path.as_os_str() == "-" {
        let png = image.to_png()?;
        let mut out = std::io::stdout().lock();
        return out
            .write_all(&png)
            .and_then(|()| out.flush())
            .context("cannot write the PNG to standard output");
    }
    image
        .write_png(path)
        .with_context(|| format!("cannot write {}", path.display()))
}
