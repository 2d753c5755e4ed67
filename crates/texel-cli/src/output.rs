//! Writing images: linear RGBA frames encoded to 8-bit PNG, or kept as linear float OpenEXR where
//! the output path ends in `.exr`, written atomically (through texel-quality's `Image8`,
//! `encode_exr` and `write_atomic`, so images and reports share one encoder).

use std::io::Write;
use std::path::Path;

use anyhow::{Context, Result};
use texel::quality::{Encoding, Image8};

use texel::raster::Frame;

/// Whether `path` names an OpenEXR file (extension `exr`, in any case). Such outputs hold the
/// frame's linear colour as 32-bit floats, unclamped (radiance above 1 is kept), whatever
/// `--color` says about encoding.
pub(crate) fn is_exr(path: &Path) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("exr"))
}

/// Parse an image output path for clap (any bytes, not only UTF-8): a name ending in `.png`, `.exr` or in no image format's
/// extension (`-`, `/dev/stdout`, `out.bin`) is accepted; one naming a format texel does not write
/// (`.jpg`, `.tif`, `.hdr`, ...) is refused before any work, rather than written as PNG bytes
/// under a name that says otherwise.
///
/// # Errors
/// A message naming the extension and the formats texel writes.
pub(crate) fn image_output(s: std::ffi::OsString) -> Result<std::path::PathBuf, String> {
    let path = std::path::PathBuf::from(s);
    let s = path.display().to_string();
    if let Some(ext) = path.extension().and_then(|e| e.to_str()) {
        let known = image::ImageFormat::from_extension(ext);
        if known.is_some_and(|f| f != image::ImageFormat::Png && f != image::ImageFormat::OpenExr) {
            return Err(format!(
                "{s:?} names a .{ext} image, which texel does not write: use a .png name (8-bit) \
                 or an .exr name (32-bit float)"
            ));
        }
    }
    Ok(path)
}

/// Parse a PNG-only output path for clap (`view --screenshot`): as [`image_output`], and an
/// `.exr` name is refused too.
///
/// # Errors
/// As [`image_output`].
pub(crate) fn png_output(s: std::ffi::OsString) -> Result<std::path::PathBuf, String> {
    let path = image_output(s)?;
    let s = path.display().to_string();
    if is_exr(&path) {
        return Err(format!(
            "{s:?} names an OpenEXR image; this output is 8-bit PNG only (use a .png name)"
        ));
    }
    Ok(path)
}

/// Check a command's outputs (each flag with its path) before any work: no two of them can reach
/// one file or stream, however they are spelled ([`texel_io::same_output`]: `-` and
/// `/dev/stdout`, a link and its target), and each can be written ([`texel_io::check_output`]).
///
/// # Errors
/// The two flags that name one output, or the first output that cannot be written.
pub(crate) fn check_outputs(outputs: &[(&str, &Path)]) -> Result<()> {
    for (i, &(flag, path)) in outputs.iter().enumerate() {
        for &(other_flag, other) in &outputs[..i] {
            anyhow::ensure!(
                !texel_io::same_output(path, other),
                "{other_flag} {} and {flag} {} name the same file or stream: give each output a \
                 path of its own",
                other.display(),
                path.display()
            );
        }
        texel_io::check_output(path).with_context(|| format!("cannot write {}", path.display()))?;
    }
    Ok(())
}

/// Publish `frame` at `path`: OpenEXR of its linear colour ([`is_exr`]; a float frame is
/// written as it is, an 8-bit one decoded), else PNG encoded as `encoding` ([`write_image`]).
pub(crate) fn write_frame(path: &Path, frame: &Frame, encoding: Encoding) -> Result<()> {
    write_frame_with_text(path, frame, encoding, &[])
}

/// [`write_frame`] with text entries (`keyword`, `text`): a PNG `tEXt` chunk or an OpenEXR
/// header attribute each.
pub(crate) fn write_frame_with_text(
    path: &Path,
    frame: &Frame,
    encoding: Encoding,
    text: &[(&str, &str)],
) -> Result<()> {
    if is_exr(path) {
        let bytes =
            texel::quality::encode_exr_with_text(frame.width, frame.height, &frame.linear(), text)?;
        return publish(path, &bytes);
    }
    let image = texel::frame_image(frame, encoding)?;
    publish(path, &with_text(image.to_png()?, text))
}

/// `png` with a `tEXt` chunk for each text entry.
pub(crate) fn with_text(png: Vec<u8>, text: &[(&str, &str)]) -> Vec<u8> {
    text.iter().fold(png, |png, (keyword, value)| {
        texel::quality::png_with_text(&png, keyword, value)
    })
}

/// Publish encoded image bytes at `path` ([`texel_io::write_atomic`]), or on standard output for
/// `-`.
pub(crate) fn publish(path: &Path, bytes: &[u8]) -> Result<()> {
    if path.as_os_str() == "-" {
        let mut out = std::io::stdout().lock();
        return out
            .write_all(bytes)
            .and_then(|()| out.flush())
            .context("cannot write the PNG to standard output");
    }
    texel_io::write_atomic(path, bytes).with_context(|| format!("cannot write {}", path.display()))
}

/// Publish linear RGBA pixels at `path`: OpenEXR for a `.exr` path ([`is_exr`]), else PNG
/// encoded as `color` says ([`write_image`]).
pub(crate) fn write_linear(
    path: &Path,
    width: u32,
    height: u32,
    pixels: &[[f32; 4]],
    color: texel::ColorHandling,
) -> Result<()> {
    if is_exr(path) {
        return write_exr(path, width, height, pixels);
    }
    let image = Image8::from_linear(width, height, pixels, color.encoding())?;
    write_image(path, &image)
}

/// Publish linear RGBA pixels as OpenEXR at `path` ([`texel::quality::write_exr_atomic`]).
fn write_exr(path: &Path, width: u32, height: u32, pixels: &[[f32; 4]]) -> Result<()> {
    texel::quality::write_exr_atomic(path, width, height, pixels)
        .with_context(|| format!("cannot write {}", path.display()))
}

/// Publish an 8-bit image as PNG at `path` ([`texel_io::write_atomic`]: atomically over a
/// regular file or a new path, through to a device or FIFO), or on standard output for `-`.
pub(crate) fn write_image(path: &Path, image: &Image8) -> Result<()> {
    if is_exr(path) {
        anyhow::bail!(
            "cannot write {}: this image is 8-bit, written as PNG only (use a .png name)",
            path.display()
        );
    }
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
