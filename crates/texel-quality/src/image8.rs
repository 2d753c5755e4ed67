//! [`Image8`]: the 8-bit RGBA display image every measurement in this crate works on.
//!
//! Decision: quality is measured on what a person sees and what the CLI writes to disk — the 8-bit
//! encoded values — not on linear floats. A linear `f32` frame is first quantised exactly as the
//! CLI quantises its output ([`Encoding::Srgb`]: `texel_texture::base::color::linear_to_srgb8`, or
//! [`Encoding::Linear`] for `--color raw`: `unorm8`), so that scores recomputed from the PNG files
//! equal the reported ones bit for bit.

use std::path::Path;

use texel_texture::base::color::{rgba_to_srgb8, rgba_to_unorm8};

use crate::error::QualityError;
use crate::size::{check_data_len, checked_len, MAX_SIDE};

/// How linear RGBA floats become 8-bit display values.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Encoding {
    /// RGB through the sRGB OETF (IEC 61966-2-1), alpha linear. Linear 0.2159 -> code 128.
    #[default]
    Srgb,
    /// Every channel `round(255 * x)`, clamped (the CLI's `--color raw`). 0.5 -> code 128.
    Linear,
}

impl Encoding {
    /// One linear RGBA value as 8-bit display values (values outside `[0, 1]` clamp; NaN is 0).
    pub fn encode(self, c: [f32; 4]) -> [u8; 4] {
        match self {
            Encoding::Srgb => rgba_to_srgb8(c),
            Encoding::Linear => rgba_to_unorm8(c),
        }
    }
}

/// A row-major 8-bit RGBA image; row 0 is the top. Sides are `1..=MAX_SIDE`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Image8 {
    width: u32,
    height: u32,
    pixels: Vec<[u8; 4]>,
}

pub(crate) fn check_same(a: (u32, u32), b: (u32, u32)) -> Result<(), QualityError> {
    if a != b {
        return Err(QualityError::SizeMismatch {
            a_width: a.0,
            a_height: a.1,
            b_width: b.0,
            b_height: b.1,
        });
    }
    Ok(())
}

impl Image8 {
    /// An image from row-major pixels.
    ///
    /// # Errors
    /// [`QualityError::EmptyImage`], [`QualityError::TooLarge`], [`QualityError::DataLength`].
    pub fn new(width: u32, height: u32, pixels: Vec<[u8; 4]>) -> Result<Self, QualityError> {
        check_data_len(width, height, 1, pixels.len())?;
        Ok(Image8 {
            width,
            height,
            pixels,
        })
    }

    /// An image from packed `RGBARGBA...` bytes (`4 * width * height` of them).
    ///
    /// # Errors
    /// As [`Image8::new`]; the length is checked in bytes.
    pub fn from_rgba_bytes(width: u32, height: u32, bytes: &[u8]) -> Result<Self, QualityError> {
        check_data_len(width, height, 4, bytes.len())?;
        let pixels = bytes
            .chunks_exact(4)
            .map(|p| [p[0], p[1], p[2], p[3]])
            .collect();
        Self::new(width, height, pixels)
    }

    /// Quantise a linear RGBA `f32` frame with `encoding` (see the module docs). Values outside
    /// `[0, 1]` clamp; NaN becomes 0.
    ///
    /// # Errors
    /// As [`Image8::new`].
    pub fn from_linear(
        width: u32,
        height: u32,
        pixels: &[[f32; 4]],
        encoding: Encoding,
    ) -> Result<Self, QualityError> {
        check_data_len(width, height, 1, pixels.len())?;
        let px = pixels.iter().map(|&c| encoding.encode(c)).collect();
        Self::new(width, height, px)
    }

    /// An image of one colour.
    ///
    /// # Errors
    /// [`QualityError::EmptyImage`], [`QualityError::TooLarge`].
    pub fn filled(width: u32, height: u32, rgba: [u8; 4]) -> Result<Self, QualityError> {
        let n = checked_len(width, height)?;
        Self::new(width, height, vec![rgba; n])
    }

    /// An image whose pixel `(x, y)` is `f(x, y)`.
    ///
    /// # Errors
    /// [`QualityError::EmptyImage`], [`QualityError::TooLarge`].
    pub fn from_fn(
        width: u32,
        height: u32,
        f: impl Fn(u32, u32) -> [u8; 4],
    ) -> Result<Self, QualityError> {
        checked_len(width, height)?;
        let px = (0..height)
            .flat_map(|y| (0..width).map(move |x| (x, y)))
            .map(|(x, y)| f(x, y))
            .collect();
        Self::new(width, height, px)
    }

    /// Decode an image file (PNG, JPEG, ...; format from the content) to 8-bit RGBA — for images
    /// rendered elsewhere (`--extra LABEL=IMAGE`). 16-bit files are reduced to 8 bits by the `image`
    /// crate (`round(v / 257)`); grey and RGB gain opaque alpha.
    ///
    /// # Errors
    /// [`QualityError::Io`] / [`QualityError::Image`] carrying the path (a FIFO or device is an
    /// `Io` error: only regular files are read); the size errors.
    pub fn load(path: impl AsRef<Path>) -> Result<Self, QualityError> {
        let path = path.as_ref();
        let img_err = |source| QualityError::Image {
            path: path.to_path_buf(),
            source,
        };
        let io_err = |source| QualityError::Io {
            path: path.to_path_buf(),
            source,
        };
        // At most a 16384 x 16384 image of 16-bit RGBA: no larger file is a valid input.
        let bytes = texel_io::read_regular(path, 8 * u64::from(MAX_SIDE).pow(2)).map_err(io_err)?;
        let decode_err = |msg: String| {
            img_err(image::ImageError::Decoding(
                image::error::DecodingError::new(image::error::ImageFormatHint::Unknown, msg),
            ))
        };
        let mut reader = image::ImageReader::new(std::io::Cursor::new(&bytes[..]))
            .with_guessed_format()
            .map_err(io_err)?;
        let mut limits = image::Limits::default();
        limits.max_image_width = Some(MAX_SIDE);
        limits.max_image_height = Some(MAX_SIDE);
        reader.limits(limits);
        if reader.format() == Some(image::ImageFormat::Jpeg) {
            let (w, h) = texel_io::guarded(|| {
                image::ImageReader::new(std::io::Cursor::new(&bytes[..]))
                    .with_guessed_format()
                    .map_err(io_err)?
                    .into_dimensions()
                    .map_err(img_err)
            })
            .map_err(decode_err)??;
            texel_io::check_jpeg_complete(&bytes, w, h).map_err(decode_err)?;
        }
        let img = texel_io::guarded(|| reader.decode())
            .map_err(|msg| decode_err(format!("the decoder failed on this file: {msg}")))?
            .map_err(img_err)?
            .into_rgba8();
        let (w, h) = img.dimensions();
        Self::from_rgba_bytes(w, h, img.as_raw())
    }

    /// The size an image file's header declares, without decoding its pixels.
    ///
    /// # Errors
    /// As [`Image8::load`].
    pub fn dimensions(path: impl AsRef<Path>) -> Result<(u32, u32), QualityError> {
        let path = path.as_ref();
        let io_err = |source| QualityError::Io {
            path: path.to_path_buf(),
            source,
        };
        let file = texel_io::open_regular(path).map_err(io_err)?;
        let reader = image::ImageReader::new(std::io::BufReader::new(file))
            .with_guessed_format()
            .map_err(io_err)?;
        let img_err = |source| QualityError::Image {
            path: path.to_path_buf(),
            source,
        };
        texel_io::guarded(|| reader.into_dimensions())
            .map_err(|msg| {
                img_err(image::ImageError::Decoding(
                    image::error::DecodingError::new(
                        image::error::ImageFormatHint::Unknown,
                        format!("the decoder failed on this file: {msg}"),
                    ),
                ))
            })?
            .map_err(img_err)
    }

    /// Width in pixels.
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Height in pixels.
    pub fn height(&self) -> u32 {
        self.height
    }

    /// `(width, height)` in pixels.
    pub fn size(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    /// The pixels, row-major, row 0 at the top.
    pub fn pixels(&self) -> &[[u8; 4]] {
        &self.pixels
    }

    /// Pixel `(x, y)`, `None` outside the image.
    pub fn pixel(&self, x: u32, y: u32) -> Option<[u8; 4]> {
        (x < self.width && y < self.height)
            .then(|| self.pixels[y as usize * self.width as usize + x as usize])
    }

    /// The pixels as packed `RGBARGBA...` bytes.
    pub fn to_rgba_bytes(&self) -> Vec<u8> {
        self.pixels.iter().flatten().copied().collect()
    }

    /// Encode as PNG in memory.
    ///
    /// # Errors
    /// [`QualityError::Image`] (with an empty path) if the encoder fails.
    pub fn to_png(&self) -> Result<Vec<u8>, QualityError> {
        crate::encode::encode_png(self.width, self.height, &self.to_rgba_bytes())
    }

    /// Write as PNG atomically ([`crate::write_png_atomic`]).
    ///
    /// # Errors
    /// As [`texel_io::write_atomic`].
    pub fn write_png(&self, path: impl AsRef<Path>) -> Result<(), QualityError> {
        Ok(texel_io::write_atomic(path.as_ref(), &self.to_png()?)?)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn from_linear_matches_encoders() {
        let px = [[0.0, 0.215_860_53, 0.5, 1.0], [2.0, -1.0, f32::NAN, 0.5]];
        let s = Image8::from_linear(2, 1, &px, Encoding::Srgb).unwrap();
        assert_eq!(s.pixels()[0], [0, 128, 188, 255]);
        assert_eq!(s.pixels()[1], [255, 0, 0, 128]);
        let l = Image8::from_linear(2, 1, &px, Encoding::Linear).unwrap();
        assert_eq!(l.pixels()[0], [0, 55, 128, 255]);
    }

    #[test]
    fn size_errors() {
        assert!(matches!(
            Image8::new(0, 3, vec![]),
            Err(QualityError::EmptyImage { .. })
        ));
        assert!(matches!(
            Image8::new(2, 2, vec![[0; 4]; 3]),
            Err(QualityError::DataLength {
                expected: 4,
                got: 3,
                ..
            })
        ));
        assert!(matches!(
            Image8::filled(MAX_SIDE + 1, 1, [0; 4]),
            Err(QualityError::TooLarge { .. })
        ));
        assert!(matches!(
            Image8::from_rgba_bytes(1, 1, &[1, 2, 3]),
            Err(QualityError::DataLength { expected: 4, .. })
        ));
    }

    #[test]
    fn png_round_trip() {
        let img = Image8::from_fn(5, 3, |x, y| [x as u8 * 40, y as u8 * 90, 7, 200]).unwrap();
        let dir = std::env::temp_dir().join(format!("texel-quality-png-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let p = dir.join("a.png");
        img.write_png(&p).unwrap();
        assert_eq!(Image8::load(&p).unwrap(), img);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn load_reports_path() {
        let e = Image8::load("/nonexistent/texel/x.png").unwrap_err();
        assert!(e.to_string().contains("/nonexistent/texel/x.png"), "{e}");
    }
}
