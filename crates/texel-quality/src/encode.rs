//! Encoding images (PNG for 8-bit display images, OpenEXR for linear floats) and writing them
//! through [`texel_io::write_atomic`].

use std::path::{Path, PathBuf};

use image::ImageEncoder;
use texel_io::write_atomic;

use crate::error::QualityError;
use crate::size::check_data_len;

/// Encode packed `RGBARGBA...` 8-bit bytes as PNG in memory.
pub(crate) fn encode_png(width: u32, height: u32, rgba8: &[u8]) -> Result<Vec<u8>, QualityError> {
    check_data_len(width, height, 4, rgba8.len())?;
    let mut out = Vec::new();
    image::codecs::png::PngEncoder::new(&mut out)
        .write_image(rgba8, width, height, image::ExtendedColorType::Rgba8)
        .map_err(|source| QualityError::Image {
            path: PathBuf::new(),
            source,
        })?;
    Ok(out)
}

/// Encode `width x height` packed 8-bit RGBA bytes (`4 * width * height`, row 0 at the top) as PNG
/// and write it with [`write_atomic`].
///
/// # Errors
/// Size errors ([`QualityError::DataLength`], ...), [`QualityError::Image`] from the encoder, and
/// the errors of [`write_atomic`].
pub fn write_png_atomic(
    path: &Path,
    width: u32,
    height: u32,
    rgba8: &[u8],
) -> Result<(), QualityError> {
    Ok(write_atomic(path, &encode_png(width, height, rgba8)?)?)
}

/// The PNG `png` with a `tEXt` chunk (PNG 1.2, 11.3.4.3) holding `keyword` and `text` right after
/// its header chunk, so that a reader (`pngcheck -t`, exiftool, Pillow's `info`) finds them. The
/// keyword is 1 to 79 Latin-1 characters; characters beyond Latin-1 become `?`.
pub fn png_with_text(png: &[u8], keyword: &str, text: &str) -> Vec<u8> {
    // Signature (8) and IHDR (length 4, type 4, 13 bytes of data, CRC 4).
    const AFTER_HEADER: usize = 8 + 25;
    let latin1 = |s: &str| -> Vec<u8> {
        s.chars()
            .map(|c| u8::try_from(u32::from(c)).unwrap_or(b'?'))
            .collect()
    };
    let mut data = latin1(keyword);
    data.truncate(79);
    data.push(0);
    data.extend(latin1(text));
    let mut chunk = Vec::with_capacity(data.len() + 12);
    chunk.extend((data.len() as u32).to_be_bytes());
    chunk.extend(b"tEXt");
    chunk.extend(&data);
    let crc = crc32fast::hash(&chunk[4..]);
    chunk.extend(crc.to_be_bytes());
    let at = AFTER_HEADER.min(png.len());
    let mut out = Vec::with_capacity(png.len() + chunk.len());
    out.extend(&png[..at]);
    out.extend(chunk);
    out.extend(&png[at..]);
    out
}

/// Encode linear RGBA floats as OpenEXR ([`encode_exr`]) with text attributes (`name`, `value`)
/// in its header; characters beyond Latin-1 become `?`.
///
/// # Errors
/// As [`encode_exr`].
pub fn encode_exr_with_text(
    width: u32,
    height: u32,
    rgba: &[[f32; 4]],
    text: &[(&str, &str)],
) -> Result<Vec<u8>, QualityError> {
    use exr::meta::attribute::{AttributeValue, Text};
    use exr::prelude::WritableImage;
    use exr::prelude::{Encoding, Image, Layer, LayerAttributes, SpecificChannels, Vec2};
    if text.is_empty() {
        return encode_exr(width, height, rgba);
    }
    check_data_len(width, height, 1, rgba.len())?;
    let w = width as usize;
    let latin1 = |s: &str| {
        let clean: String = s
            .chars()
            .map(|c| if u32::from(c) < 256 { c } else { '?' })
            .collect();
        Text::new_or_none(clean).unwrap_or_default()
    };
    let mut attributes = LayerAttributes::default();
    for (name, value) in text {
        attributes
            .other
            .insert(latin1(name), AttributeValue::Text(latin1(value)));
    }
    let channels = SpecificChannels::rgba(|Vec2(x, y): Vec2<usize>| {
        let [r, g, b, a] = rgba[y * w + x];
        (r, g, b, a)
    });
    let layer = Layer::new(
        (w, height as usize),
        attributes,
        Encoding::SMALL_LOSSLESS,
        channels,
    );
    let mut out = std::io::Cursor::new(Vec::new());
    Image::from_layer(layer)
        .write()
        .non_parallel()
        .to_buffered(&mut out)
        .map_err(|e| QualityError::Image {
            path: PathBuf::new(),
            source: image::ImageError::Encoding(image::error::EncodingError::new(
                image::error::ImageFormatHint::Exact(image::ImageFormat::OpenExr),
                e,
            )),
        })?;
    Ok(out.into_inner())
}

/// Encode `width x height` linear RGBA floats (row 0 at the top) as OpenEXR (32-bit float
/// channels R, G, B, A) in memory.
///
/// # Errors
/// Size errors ([`QualityError::DataLength`], ...) and [`QualityError::Image`] from the encoder.
pub fn encode_exr(width: u32, height: u32, rgba: &[[f32; 4]]) -> Result<Vec<u8>, QualityError> {
    check_data_len(width, height, 1, rgba.len())?;
    let bytes: Vec<u8> = rgba
        .iter()
        .flatten()
        .flat_map(|c| c.to_le_bytes())
        .collect();
    let mut out = std::io::Cursor::new(Vec::new());
    image::codecs::openexr::OpenExrEncoder::new(&mut out)
        .write_image(&bytes, width, height, image::ExtendedColorType::Rgba32F)
        .map_err(|source| QualityError::Image {
            path: PathBuf::new(),
            source,
        })?;
    Ok(out.into_inner())
}

/// Encode linear RGBA floats as OpenEXR ([`encode_exr`]) and write them with [`write_atomic`].
///
/// # Errors
/// As [`encode_exr`] and [`write_atomic`].
pub fn write_exr_atomic(
    path: &Path,
    width: u32,
    height: u32,
    rgba: &[[f32; 4]],
) -> Result<(), QualityError> {
    Ok(write_atomic(path, &encode_exr(width, height, rgba)?)?)
}

#[cfg(test)]
mod tests {
    use std::fs;

    use super::*;

    #[test]
    fn text_reaches_png_and_exr_readers() {
        let png = encode_png(2, 1, &[1, 2, 3, 255, 4, 5, 6, 255]).unwrap();
        let marked = png_with_text(&png, "texel:partial", "interrupted at 8 samples");
        // The image decodes to the same pixels, and the chunk is there with a valid CRC (the
        // decoder checks it).
        let a = image::load_from_memory(&png).unwrap().to_rgba8();
        let b = image::load_from_memory(&marked).unwrap().to_rgba8();
        assert_eq!(a.as_raw(), b.as_raw());
        let needle = b"tEXttexel:partial\0interrupted at 8 samples";
        assert!(marked.windows(needle.len()).any(|w| w == needle));
        let px = [[0.5, -1.0, 3.0e5, 1.0], [0.0, 0.25, 1.0, 0.5]];
        let exr = encode_exr_with_text(2, 1, &px, &[("texel:partial", "yes")]).unwrap();
        let back = image::load_from_memory(&exr).unwrap().to_rgba32f();
        assert_eq!(back.as_raw(), &px.concat());
        let meta =
            exr::meta::MetaData::read_from_buffered(std::io::Cursor::new(&exr), false).unwrap();
        let value = &meta.headers[0].own_attributes.other
            [&exr::meta::attribute::Text::from("texel:partial")];
        assert!(matches!(value, exr::meta::attribute::AttributeValue::Text(t) if t == "yes"));
    }

    #[test]
    fn exr_round_trips_floats_exactly() {
        let px: Vec<[f32; 4]> = (0..6)
            .map(|k| [k as f32 * 0.25, 3.5e3, -1.0 / 3.0, 1.0])
            .collect();
        let bytes = encode_exr(3, 2, &px).unwrap();
        let img = image::load_from_memory_with_format(&bytes, image::ImageFormat::OpenExr)
            .unwrap()
            .to_rgba32f();
        assert_eq!((img.width(), img.height()), (3, 2));
        for (got, want) in img.pixels().zip(&px) {
            assert_eq!(&got.0, want);
        }
        assert!(matches!(
            encode_exr(3, 2, &px[..5]),
            Err(QualityError::DataLength { .. })
        ));
    }

    #[test]
    fn failure_leaves_nothing_behind() {
        let d = scratch("atomic-err");
        // A directory is refused before anything is written.
        let target = d.join("out.png");
        fs::create_dir_all(target.join("inside")).unwrap();
        let e = write_atomic(&target, b"data").unwrap_err();
        assert!(e.to_string().contains("out.png"), "{e}");
        assert!(e.to_string().contains("is a directory"), "{e}");
        assert_eq!(names(&d), vec!["out.png"]);
        // A missing directory: the error names the path.
        let missing = d.join("no/such/dir/x.png");
        let e = write_png_atomic(&missing, 1, 1, &[1, 2, 3, 4]).unwrap_err();
        assert!(matches!(e, QualityError::Io { .. }));
        assert!(e.to_string().contains("no/such/dir/x.png"), "{e}");
        fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn png_length_checked() {
        let d = scratch("atomic-len");
        let e = write_png_atomic(&d.join("a.png"), 2, 2, &[0; 15]).unwrap_err();
        assert!(matches!(
            e,
            QualityError::DataLength {
                expected: 16,
                got: 15,
                ..
            }
        ));
        assert!(names(&d).is_empty());
        fs::remove_dir_all(&d).unwrap();
    }

    fn scratch(tag: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("texel-quality-{tag}-{}", std::process::id()));
        let _ = fs::remove_dir_all(&d);
        fs::create_dir_all(&d).unwrap();
        d
    }

    fn names(dir: &Path) -> Vec<String> {
        let mut v: Vec<String> = fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    }
}
