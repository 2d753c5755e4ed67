//! Texture images: RGBA8 (sRGB or linear) and RGBA32F, with their full mip pyramid.
//!
//! A [`Texture`] owns every mip level in one contiguous allocation of its own texel format
//! (`[u8; 4]` or `[f32; 4]`), level 0 first, so that a filter reading two adjacent levels touches one
//! buffer. The pyramid is built at creation (see [`crate::storage::pyramid`]): level `k` is
//! `max(1, W >> k) x max(1, H >> k)`, down to 1x1.
//!
//! Decision (docs/decisions.md): levels below 0 are stored in the texture's own format, as a
//! GPU stores them, so an 8-bit sRGB texture's pyramid costs 4/3 of level 0 and every level decodes
//! through the same table. The reduction itself runs in linear `f32` from the previous *unquantised*
//! level, so rounding does not accumulate down the chain.

use std::path::Path;
use std::sync::OnceLock;

use glam::Vec4;

use crate::base::color::{linear_to_srgb8, srgb_to_linear, unorm8};
use crate::base::error::TextureError;
use crate::storage::fetch::{table8, Fetch, Float, Level};
pub(crate) use crate::storage::format::{decode_rgba8, Storage};
pub use crate::storage::format::{ColorSpace, Format, LevelInfo, LevelTexels};
use crate::storage::pyramid;
use crate::storage::tables::{Ripmap, SummedAreaTable};

/// Size and memory limits checked before anything is allocated (after image-rs `io/limits.rs`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Limits {
    /// Largest width or height in texels. Default 16384 (the common GPU maximum).
    pub max_dimension: u32,
    /// Largest number of bytes a texture may use: its pyramid plus the scratch the build needs
    /// (an `f32` copy of levels 1 and below). Default 4 GiB.
    pub max_bytes: u64,
}

impl Default for Limits {
    fn default() -> Self {
        Limits {
            max_dimension: 16384,
            max_bytes: 4 << 30,
        }
    }
}

/// How a decoded image of `color` is stored: 8-bit images as RGBA8 (sRGB or not: same size),
/// 16-bit and float images as RGBA32F ([`Texture::decode`]'s conversion).
fn stored_format(color: image::ColorType) -> Format {
    use image::ColorType as C;
    match color {
        C::L8 | C::La8 | C::Rgb8 | C::Rgba8 => Format::Rgba8Unorm,
        _ => Format::Rgba32Float,
    }
}

impl Limits {
    /// The bytes [`Texture::decode`] holds at once, at most, for an encoded file of `file_bytes`
    /// whose header says `width x height` pixels of `color`: the file, the decoded image, two
    /// copies of its texels (conversion and the texture's own), and the pyramid's coarser levels
    /// with their `f32` build scratch. An upper bound, not a measurement of one run.
    pub fn load_bytes(file_bytes: u64, width: u32, height: u32, color: image::ColorType) -> u64 {
        let px = u64::from(width) * u64::from(height);
        let texel = stored_format(color).texel_bytes();
        let below = pyramid::pyramid_texels(width, height) - px;
        file_bytes
            .saturating_add(px.saturating_mul(u64::from(color.bytes_per_pixel())))
            .saturating_add(px.saturating_mul(2 * texel))
            .saturating_add(below.saturating_mul(texel + 16))
    }

    /// Check an image file's header against these limits before decoding it: the sides
    /// ([`Limits::check`]'s rules) and [`Limits::load_bytes`] against [`Limits::max_bytes`].
    ///
    /// # Errors
    /// [`TextureError::EmptySize`], [`TextureError::TooLarge`] or
    /// [`TextureError::OverMemoryLimit`] with the figures.
    pub fn check_load(
        &self,
        file_bytes: u64,
        width: u32,
        height: u32,
        color: image::ColorType,
    ) -> Result<(), TextureError> {
        self.check(width, height, stored_format(color))?;
        let bytes = Self::load_bytes(file_bytes, width, height, color);
        self.check_bytes(width, height, bytes)
    }

    /// `Err(OverMemoryLimit)` with the figures if `bytes` for a `width x height` image exceed
    /// [`Limits::max_bytes`].
    fn check_bytes(&self, width: u32, height: u32, bytes: u64) -> Result<(), TextureError> {
        if bytes > self.max_bytes {
            return Err(TextureError::OverMemoryLimit {
                width,
                height,
                bytes,
                max: self.max_bytes,
            });
        }
        Ok(())
    }

    /// Check a `width x height` texture of `format` against these limits.
    ///
    /// # Errors
    /// [`TextureError::EmptySize`], [`TextureError::TooLarge`] or [`TextureError::OverMemoryLimit`].
    pub fn check(&self, width: u32, height: u32, format: Format) -> Result<(), TextureError> {
        if width == 0 || height == 0 {
            return Err(TextureError::EmptySize { width, height });
        }
        if width > self.max_dimension || height > self.max_dimension {
            return Err(TextureError::TooLarge {
                width,
                height,
                max: self.max_dimension,
            });
        }
        self.check_bytes(width, height, Self::texture_bytes(width, height, format))
    }

    /// The bytes a `width x height` texture of `format` holds while it is built: its whole mip
    /// pyramid, and the linear `f32` scratch of the levels below 0. Saturates at `u64::MAX`.
    pub fn texture_bytes(width: u32, height: u32, format: Format) -> u64 {
        let texels = pyramid::pyramid_texels(width, height);
        let level0 = u64::from(width) * u64::from(height);
        texels
            .checked_mul(format.texel_bytes())
            .and_then(|b| b.checked_add((texels - level0).checked_mul(16)?))
            .unwrap_or(u64::MAX)
    }
}

/// The bytes of an image file's start that [`file_over_limit`] reads for its header.
const HEADER_BYTES: u64 = 64 << 10;

/// [`TextureError::OverMemoryLimit`] with what loading the file at `path` needs in all
/// ([`Limits::load_bytes`]), where the file is larger than `limits` allow and its header can be
/// read from its first [`HEADER_BYTES`]; `None` otherwise.
fn file_over_limit(path: &Path, limits: &Limits) -> Option<TextureError> {
    use std::io::Read;
    let len = std::fs::metadata(path).ok()?.len();
    if len <= limits.max_bytes {
        return None;
    }
    let mut head = Vec::new();
    texel_io::open_regular(path)
        .ok()?
        .take(HEADER_BYTES)
        .read_to_end(&mut head)
        .ok()?;
    let (width, height, color) = Texture::header(&head).ok()?;
    Some(TextureError::OverMemoryLimit {
        width,
        height,
        bytes: Limits::load_bytes(len, width, height, color).max(len),
        max: limits.max_bytes,
    })
}

/// How [`Texture::load_with`] and [`Texture::decode_with`] read an image file.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LoadOptions {
    /// Colour space of 8- and 16-bit images (float images are linear).
    pub color: ColorSpace,
    /// Size and memory limits.
    pub limits: Limits,
    /// Replace NaN, infinite and out-of-range float texels ([`replace_non_finite`]) instead of
    /// refusing the image; [`Loaded::replaced`] says how many values were replaced.
    pub replace_non_finite: bool,
}

impl LoadOptions {
    /// `color` and `limits`, refusing non-finite and out-of-range texels.
    pub fn new(color: ColorSpace, limits: Limits) -> Self {
        LoadOptions {
            color,
            limits,
            replace_non_finite: false,
        }
    }
}

/// A texture read from a file, and how many non-finite or out-of-range channel values were
/// replaced.
#[derive(Debug)]
pub struct Loaded {
    /// The texture.
    pub texture: Texture,
    /// Channel values replaced by [`replace_non_finite`] (0 unless asked for).
    pub replaced: u64,
}

/// The largest finite half-float (`65504`), what an infinite texel becomes: OpenEXR stores half
/// floats, so this is the brightest value such a file can hold.
pub const NON_FINITE_CLAMP: f32 = 65504.0;

/// The largest magnitude a float texel read from outside may have ([`Texture::from_rgba32f`],
/// image files), `2^64` (about `1.8e19`). A filter sums up to 16384 weighted texels (EWA) or 64
/// probes (anisotropic) in `f32`, the pyramid sums each level's texels in fours, and interpolation
/// takes differences of neighbours, so values near `f32::MAX` would overflow to infinity where the
/// average itself is finite; from inputs below `2^64` every such sum, and those of the maps
/// derived from them, stays far below `f32::MAX` (`2^128`).
pub const MAX_TEXEL: f32 = 18_446_744_073_709_551_616.0;

/// Replace every NaN channel value with 0, every infinity with `±`[`NON_FINITE_CLAMP`] and every
/// finite value beyond `±`[`MAX_TEXEL`] with `±MAX_TEXEL`; returns how many values changed.
pub fn replace_non_finite(texels: &mut [[f32; 4]]) -> u64 {
    let mut n = 0;
    for c in texels.iter_mut().flatten() {
        if !c.is_finite() {
            *c = if c.is_nan() {
                0.0
            } else {
                NON_FINITE_CLAMP.copysign(*c)
            };
            n += 1;
        } else if c.abs() > MAX_TEXEL {
            *c = MAX_TEXEL.copysign(*c);
            n += 1;
        }
    }
    n
}

fn check_jpeg_complete(bytes: &[u8], width: u32, height: u32) -> Result<(), TextureError> {
    texel_io::check_jpeg_complete(bytes, width, height).map_err(TextureError::Truncated)
}

/// A 2D texture with its complete mip pyramid, ready to be sampled by a [`crate::Sampler`].
///
/// Any size from 1x1 up to [`Limits::max_dimension`], power of two or not.
///
/// The ripmap and the summed-area table that [`crate::FilterMode::Ripmap`] and
/// [`crate::FilterMode::SummedArea`] need are built from level 0 on first use (thread-safe, once; `Texture`
/// is `Sync`), or ahead of time by [`Texture::build_structures`]. Their size is checked against the
/// [`Limits`] the texture was created with before anything is allocated.
#[derive(Debug)]
pub struct Texture {
    format: Format,
    /// The format the texels came in: [`Texture::format`], except for a decoded copy
    /// ([`Texture::to_float`]) of 8-bit texels.
    source: Format,
    levels: Vec<LevelInfo>,
    storage: Storage,
    limits: Limits,
    /// Built on first use; `Err(bytes)` records that it would have needed `bytes` (over the limit).
    pub(crate) ripmap: OnceLock<Result<Ripmap, u64>>,
    /// Built on first use; `Err(bytes)` as for `ripmap`.
    pub(crate) sat: OnceLock<Result<SummedAreaTable, u64>>,
}

impl Texture {
    /// A texture from row-major 8-bit RGBA texels (row 0 is the top of the image), building its pyramid.
    ///
    /// # Errors
    /// Size or memory limits ([`Limits::check`]) and [`TextureError::DataLength`].
    pub fn from_rgba8(
        width: u32,
        height: u32,
        texels: Vec<[u8; 4]>,
        color: ColorSpace,
        limits: &Limits,
    ) -> Result<Self, TextureError> {
        let format = match color {
            ColorSpace::Srgb => Format::Rgba8Srgb,
            ColorSpace::Linear => Format::Rgba8Unorm,
        };
        limits.check(width, height, format)?;
        check_len(width, height, texels.len())?;
        let level0 = Level {
            width,
            height,
            texels: &texels,
            decode: table8(format),
        };
        let (levels, below) = pyramid::build(width, height, |i, j| level0.texel(i, j));
        let total = levels
            .last()
            .map_or(0, |l| l.offset + l.width as usize * l.height as usize);
        let mut all = texels;
        all.reserve_exact(total - all.len());
        let encode = |c: Vec4| -> [u8; 4] {
            match color {
                ColorSpace::Srgb => [
                    linear_to_srgb8(c.x),
                    linear_to_srgb8(c.y),
                    linear_to_srgb8(c.z),
                    unorm8(c.w),
                ],
                ColorSpace::Linear => [unorm8(c.x), unorm8(c.y), unorm8(c.z), unorm8(c.w)],
            }
        };
        all.extend(below.iter().map(|&c| encode(c)));
        Ok(Texture::assemble(format, levels, Storage::U8(all), limits))
    }

    /// A texture from row-major linear `f32` RGBA texels, building its pyramid.
    ///
    /// Every value must be finite: one NaN would spread through every coarser level (and an
    /// infinity makes its averages NaN); and within `±`[`MAX_TEXEL`], so that the filters' sums
    /// stay far from overflow. [`replace_non_finite`] cleans data that breaks either rule.
    ///
    /// # Errors
    /// Size or memory limits ([`Limits::check`]), [`TextureError::DataLength`], and
    /// [`TextureError::NonFiniteTexel`] or [`TextureError::TexelOutOfRange`] naming the first
    /// value that breaks the rules in row-major order.
    pub fn from_rgba32f(
        width: u32,
        height: u32,
        texels: Vec<[f32; 4]>,
        limits: &Limits,
    ) -> Result<Self, TextureError> {
        Self::from_rgba32f_checked(width, height, texels, limits, true)
    }

    /// [`Texture::from_rgba32f`], checking the range only when `range` is set (finiteness always).
    fn from_rgba32f_checked(
        width: u32,
        height: u32,
        texels: Vec<[f32; 4]>,
        limits: &Limits,
        range: bool,
    ) -> Result<Self, TextureError> {
        limits.check(width, height, Format::Rgba32Float)?;
        check_len(width, height, texels.len())?;
        check_texels(width, &texels, range)?;
        let level0 = Level {
            width,
            height,
            texels: &texels,
            decode: Float,
        };
        let (levels, below) = pyramid::build(width, height, |i, j| level0.texel(i, j));
        let mut all = texels;
        all.extend(below.iter().map(|c| c.to_array()));
        Ok(Texture::assemble(
            Format::Rgba32Float,
            levels,
            Storage::F32(all),
            limits,
        ))
    }

    /// A float texture whose mip levels are given rather than built: `texels` holds every level of
    /// a full `width x height` chain ([`crate::storage::pyramid::level_size`], down to 1x1), level 0 first,
    /// each row-major and the levels back to back ([`crate::storage::pyramid::pyramid_texels`] in all).
    /// For pyramids whose levels are not box reductions of level 0, such as an environment map's
    /// GGX-prefiltered levels (each convolved with a wider specular lobe). Ripmaps and
    /// summed-area tables, built from level 0, know nothing of the other levels.
    ///
    /// The levels are maps code derives (from inputs within [`MAX_TEXEL`], by bounded factors),
    /// so only finiteness is checked, not the range.
    ///
    /// # Errors
    /// As [`Texture::from_rgba32f`] less [`TextureError::TexelOutOfRange`], with
    /// [`TextureError::DataLength`] against the whole chain (reported as level 0's size).
    pub fn from_rgba32f_levels(
        width: u32,
        height: u32,
        texels: Vec<[f32; 4]>,
        limits: &Limits,
    ) -> Result<Self, TextureError> {
        limits.check(width, height, Format::Rgba32Float)?;
        let total = pyramid::pyramid_texels(width, height);
        if texels.len() as u64 != total {
            return Err(TextureError::DataLength {
                width,
                height,
                expected: total as usize,
                got: texels.len(),
            });
        }
        check_texels(width, &texels, false)?;
        let mut offset = 0;
        let levels = (0..pyramid::level_count(width, height))
            .map(|k| {
                let (w, h) = pyramid::level_size(width, height, k);
                let info = LevelInfo {
                    width: w,
                    height: h,
                    offset,
                };
                offset += w as usize * h as usize;
                info
            })
            .collect();
        Ok(Texture::assemble(
            Format::Rgba32Float,
            levels,
            Storage::F32(texels),
            limits,
        ))
    }

    /// A texture whose texel `(i, j)` is `f(i, j)` (linear RGBA in `[0, 1]` for 8-bit formats),
    /// stored in `format`. Handy for procedural textures, tests and the maps code derives from
    /// other maps (slope moments, baked layers, irradiance): float values must be finite but, unlike
    /// [`Texture::from_rgba32f`]'s, are not held to [`MAX_TEXEL`], since a derived map may exceed
    /// its inputs' range by the derivation's factor (a squared slope, a quadrature's rounding).
    /// The filters' sums stay finite for values up to `2^110`.
    ///
    /// # Errors
    /// As [`Texture::from_rgba8`] / [`Texture::from_rgba32f`], less
    /// [`TextureError::TexelOutOfRange`].
    pub fn from_fn(
        width: u32,
        height: u32,
        format: Format,
        limits: &Limits,
        f: impl Fn(u32, u32) -> [f32; 4],
    ) -> Result<Self, TextureError> {
        limits.check(width, height, format)?;
        let coords = (0..height).flat_map(|j| (0..width).map(move |i| (i, j)));
        match format {
            Format::Rgba32Float => {
                let texels = coords.map(|(i, j)| f(i, j)).collect();
                Self::from_rgba32f_checked(width, height, texels, limits, false)
            }
            Format::Rgba8Srgb | Format::Rgba8Unorm => {
                let srgb = format == Format::Rgba8Srgb;
                let texels = coords
                    .map(|(i, j)| {
                        let c = f(i, j);
                        let rgb = |x: f32| if srgb { linear_to_srgb8(x) } else { unorm8(x) };
                        [rgb(c[0]), rgb(c[1]), rgb(c[2]), unorm8(c[3])]
                    })
                    .collect();
                let color = if srgb {
                    ColorSpace::Srgb
                } else {
                    ColorSpace::Linear
                };
                Self::from_rgba8(width, height, texels, color, limits)
            }
        }
    }

    /// Decode an image file (PNG, JPEG, OpenEXR; format guessed from the content) into a texture.
    ///
    /// `color` applies to 8- and 16-bit images; float images (EXR) are always linear. The file
    /// must be a regular file (a FIFO or device is refused before it is opened, see
    /// [`texel_io`]); everything else is as [`Texture::decode`] says.
    ///
    /// # Errors
    /// [`TextureError::Io`], and those of [`Texture::decode`].
    pub fn load(
        path: impl AsRef<Path>,
        color: ColorSpace,
        limits: &Limits,
    ) -> Result<Self, TextureError> {
        Self::load_with(path, &LoadOptions::new(color, *limits)).map(|l| l.texture)
    }

    /// As [`Texture::load`], with the non-finite-texel policy of `options`. A file larger than
    /// [`Limits::max_bytes`] is refused before it is read, with the figures of
    /// [`Limits::check_load`] where its header can be read from the file's start.
    ///
    /// # Errors
    /// As [`Texture::load`].
    pub fn load_with(
        path: impl AsRef<Path>,
        options: &LoadOptions,
    ) -> Result<Loaded, TextureError> {
        let path = path.as_ref();
        let bytes = match texel_io::read_regular(path, options.limits.max_bytes) {
            Ok(bytes) => bytes,
            Err(e) => return Err(file_over_limit(path, &options.limits).unwrap_or(e.into())),
        };
        Self::decode_with(&bytes, options)
    }

    /// As [`Texture::load`], from the bytes of an image file in memory.
    ///
    /// Before any pixel is decoded: the header's size is checked against `limits`
    /// ([`Limits::check_load`] counts the encoded bytes, the decoded image, its conversion to
    /// texels and the pyramid with its build scratch, all held at once); a JPEG must end in its
    /// end-of-image marker and be large enough to hold one coded bit per 8x8 block (a truncated
    /// file is an error, not an image filled with grey). After decoding, a float texel that is NaN,
    /// infinite or beyond `±`[`MAX_TEXEL`] is an error naming it
    /// ([`LoadOptions::replace_non_finite`] replaces them).
    ///
    /// # Errors
    /// [`TextureError::Decode`] (corrupt, unsupported), [`TextureError::Truncated`],
    /// [`TextureError::NonFiniteTexel`], [`TextureError::TexelOutOfRange`],
    /// [`TextureError::UnsupportedFormat`] and the size errors.
    pub fn decode(bytes: &[u8], color: ColorSpace, limits: &Limits) -> Result<Self, TextureError> {
        Self::decode_with(bytes, &LoadOptions::new(color, *limits)).map(|l| l.texture)
    }

    /// The size and pixel type an image file's header declares, without decoding its pixels.
    ///
    /// # Errors
    /// [`TextureError::Decode`] for an unknown format or a corrupt header.
    pub fn header(bytes: &[u8]) -> Result<(u32, u32, image::ColorType), TextureError> {
        let reader = image::ImageReader::new(std::io::Cursor::new(bytes)).with_guessed_format()?;
        let decoder =
            texel_io::guarded(|| reader.into_decoder()).map_err(TextureError::DecoderFailed)??;
        let (w, h) = image::ImageDecoder::dimensions(&decoder);
        Ok((w, h, image::ImageDecoder::color_type(&decoder)))
    }

    /// As [`Texture::decode`], with the non-finite-texel policy of `options`.
    ///
    /// # Errors
    /// As [`Texture::decode`].
    pub fn decode_with(bytes: &[u8], options: &LoadOptions) -> Result<Loaded, TextureError> {
        let (color, limits) = (options.color, &options.limits);
        let mut reader =
            image::ImageReader::new(std::io::Cursor::new(bytes)).with_guessed_format()?;
        let format = reader.format();
        let mut l = image::Limits::default();
        l.max_image_width = Some(limits.max_dimension);
        l.max_image_height = Some(limits.max_dimension);
        l.max_alloc = Some(limits.max_bytes);
        reader.limits(l);
        let decoder =
            texel_io::guarded(|| reader.into_decoder()).map_err(TextureError::DecoderFailed)??;
        let (width, height) = image::ImageDecoder::dimensions(&decoder);
        let decoded_color = image::ImageDecoder::color_type(&decoder);
        limits.check_load(bytes.len() as u64, width, height, decoded_color)?;
        if format == Some(image::ImageFormat::Jpeg) {
            check_jpeg_complete(bytes, width, height)?;
        }
        let img = texel_io::guarded(|| image::DynamicImage::from_decoder(decoder))
            .map_err(TextureError::DecoderFailed)??;
        use image::ColorType as C;
        match img.color() {
            C::L8 | C::La8 | C::Rgb8 | C::Rgba8 => {
                let texels = img.into_rgba8().pixels().map(|p| p.0).collect();
                Self::from_rgba8(width, height, texels, color, limits).map(|texture| Loaded {
                    texture,
                    replaced: 0,
                })
            }
            C::L16 | C::La16 | C::Rgb16 | C::Rgba16 | C::Rgb32F | C::Rgba32F => {
                let encoded =
                    !matches!(img.color(), C::Rgb32F | C::Rgba32F) && color == ColorSpace::Srgb;
                let mut texels: Vec<[f32; 4]> = img
                    .into_rgba32f()
                    .pixels()
                    .map(|p| {
                        let [r, g, b, a] = p.0;
                        if encoded {
                            [srgb_to_linear(r), srgb_to_linear(g), srgb_to_linear(b), a]
                        } else {
                            [r, g, b, a]
                        }
                    })
                    .collect();
                let replaced = if options.replace_non_finite {
                    replace_non_finite(&mut texels)
                } else {
                    0
                };
                Self::from_rgba32f(width, height, texels, limits)
                    .map(|texture| Loaded { texture, replaced })
            }
            other => Err(TextureError::UnsupportedFormat(other)),
        }
    }

    fn assemble(format: Format, levels: Vec<LevelInfo>, storage: Storage, limits: &Limits) -> Self {
        Texture {
            format,
            source: format,
            levels,
            storage,
            limits: *limits,
            ripmap: OnceLock::new(),
            sat: OnceLock::new(),
        }
    }

    /// The limits the texture was created with (they also bound its ripmap and summed-area table).
    pub fn limits(&self) -> &Limits {
        &self.limits
    }

    /// Whether a structure of `bytes` (plus `scratch` bytes while it is built) still fits this
    /// texture's [`Limits::max_bytes`] next to the pyramid and the structures already built:
    /// `Err(total)` with the total it would need. `None` (an overflowing size) never fits.
    pub(crate) fn structure_budget(&self, bytes: Option<u64>, scratch: u64) -> Result<(), u64> {
        let built = |b: Option<u64>| b.unwrap_or(0);
        let ripmap = built(
            self.ripmap
                .get()
                .and_then(|r| r.as_ref().ok())
                .map(|r| r.bytes()),
        );
        let sat = built(
            self.sat
                .get()
                .and_then(|t| t.as_ref().ok())
                .map(|t| t.bytes()),
        );
        let total = bytes
            .and_then(|b| b.checked_add(self.pyramid_bytes()))
            .and_then(|b| b.checked_add(ripmap))
            .and_then(|b| b.checked_add(sat))
            .and_then(|b| b.checked_add(scratch))
            .unwrap_or(u64::MAX);
        if total > self.limits.max_bytes {
            Err(total)
        } else {
            Ok(())
        }
    }

    /// The error for a `structure` that needs `bytes` in all (from [`Texture::structure_budget`]).
    pub(crate) fn over_budget(&self, structure: &'static str, bytes: u64) -> TextureError {
        TextureError::StructureOverMemoryLimit {
            structure,
            width: self.width(),
            height: self.height(),
            bytes,
            max: self.limits.max_bytes,
        }
    }

    /// The stored texels of level `level`, row-major, in the texture's own format (8-bit codes,
    /// sRGB or linear as [`Texture::format`] says, or linear floats): what a GPU upload needs to
    /// filter the very texels the CPU filters. `None` past the last level.
    pub fn level_texels(&self, level: usize) -> Option<LevelTexels<'_>> {
        let info = self.levels.get(level)?;
        let range = info.offset..info.offset + info.width as usize * info.height as usize;
        Some(match &self.storage {
            Storage::U8(v) => LevelTexels::Unorm8(&v[range]),
            Storage::F32(v) => LevelTexels::Float(&v[range]),
        })
    }

    /// The storage format.
    pub fn format(&self) -> Format {
        self.format
    }

    /// The format the texels came in: the storage format, or for a copy decoded by
    /// [`Texture::to_float`] the 8-bit format of its original, whose codes its values are (what
    /// a consumer asks when it allows for 8-bit quantisation, such as a normal map's slack).
    pub fn source_format(&self) -> Format {
        self.source
    }

    /// The same texture stored as linear `f32` ([`Format::Rgba32Float`]): every level's texels
    /// decoded once, to exactly the values the sampler decodes them to, so every filter samples
    /// it bit for bit as it samples `self` (its ripmap, built on first use, rounds its images to
    /// the original's 8-bit codes as the original's own ripmap does). It costs 16 bytes a texel
    /// instead of 4 and spares the filters a decode per texel read: on CPUs whose caches hold
    /// the larger pyramid, the mip and anisotropic filters (and EWA of sRGB texels) run faster
    /// on it (figures in
    /// docs/decisions.md, "Decoded float storage"). A float texture is copied as it is. The
    /// copy starts without built structures (its ripmap, built in float, takes four times the
    /// 8-bit one's bytes); its limits are `self`'s with [`Limits::max_bytes`] raised by the
    /// pyramid's growth, so that what fitted next to the 8-bit pyramid is measured against the
    /// same room.
    ///
    /// # Errors
    /// [`TextureError::OverMemoryLimit`] when [`Texture::float_pyramid_bytes`] exceeds the
    /// texture's [`Limits::max_bytes`] (nothing is allocated then).
    pub fn to_float(&self) -> Result<Texture, TextureError> {
        let bytes = self.float_pyramid_bytes();
        self.limits
            .check_bytes(self.width(), self.height(), bytes)?;
        let texels: Vec<[f32; 4]> = match &self.storage {
            Storage::F32(v) => v.clone(),
            Storage::U8(v) => {
                let srgb = self.format == Format::Rgba8Srgb;
                v.iter().map(|&t| decode_rgba8(t, srgb)).collect()
            }
        };
        let growth = bytes - self.pyramid_bytes();
        let limits = Limits {
            max_bytes: self.limits.max_bytes.saturating_add(growth),
            ..self.limits
        };
        let mut t = Texture::assemble(
            Format::Rgba32Float,
            self.levels.clone(),
            Storage::F32(texels),
            &limits,
        );
        t.source = self.source;
        Ok(t)
    }

    /// Bytes of the pyramid as [`Texture::to_float`] stores it (16 a texel).
    pub fn float_pyramid_bytes(&self) -> u64 {
        self.pyramid_bytes()
            .saturating_mul(Format::Rgba32Float.texel_bytes() / self.format.texel_bytes())
    }

    /// Width of level 0 in texels.
    pub fn width(&self) -> u32 {
        self.levels[0].width
    }

    /// Height of level 0 in texels.
    pub fn height(&self) -> u32 {
        self.levels[0].height
    }

    /// The mip levels, level 0 first, down to 1x1.
    pub fn levels(&self) -> &[LevelInfo] {
        &self.levels
    }

    /// Bytes the texels of all levels occupy (about 4/3 of level 0).
    pub fn pyramid_bytes(&self) -> u64 {
        let l = self.levels.last().expect("at least one level");
        (l.offset as u64 + 1) * self.format.texel_bytes()
    }

    /// Texel `(i, j)` of `level`, decoded to linear RGBA. `None` if out of range.
    pub fn texel(&self, level: usize, i: u32, j: u32) -> Option<[f32; 4]> {
        let info = self.levels.get(level)?;
        if i >= info.width || j >= info.height {
            return None;
        }
        let idx = info.offset + j as usize * info.width as usize + i as usize;
        Some(match &self.storage {
            Storage::U8(v) => decode_rgba8(v[idx], self.format == Format::Rgba8Srgb),
            Storage::F32(v) => v[idx],
        })
    }

    /// Mean of every texel of `level` in linear RGBA (`f64` accumulation).
    pub fn level_mean(&self, level: usize) -> [f64; 4] {
        let info = self.levels[level];
        let mut sum = [0f64; 4];
        for j in 0..info.height {
            for i in 0..info.width {
                let t = self.texel(level, i, j).expect("in range");
                for c in 0..4 {
                    sum[c] += f64::from(t[c]);
                }
            }
        }
        let n = f64::from(info.width) * f64::from(info.height);
        sum.map(|s| s / n)
    }

    pub(crate) fn storage(&self) -> &Storage {
        &self.storage
    }
}

/// [`TextureError::NonFiniteTexel`] for the first value of row-major `texels` that is not finite
/// or, with `range`, [`TextureError::TexelOutOfRange`] for the first beyond `±`[`MAX_TEXEL`]
/// (rows of `width`; past level 0, the index counts on as if the level continued).
fn check_texels(width: u32, texels: &[[f32; 4]], range: bool) -> Result<(), TextureError> {
    let bad = |c: &f32| !c.is_finite() || (range && c.abs() > MAX_TEXEL);
    if let Some(k) = texels.iter().position(|t| t.iter().any(bad)) {
        let channel = texels[k].iter().position(bad).unwrap_or(0);
        let (x, y) = ((k % width as usize) as u32, (k / width as usize) as u32);
        let (channel, value) = (["R", "G", "B", "A"][channel], texels[k][channel]);
        return Err(if value.is_finite() {
            TextureError::TexelOutOfRange {
                x,
                y,
                channel,
                value,
                max: MAX_TEXEL,
            }
        } else {
            TextureError::NonFiniteTexel {
                x,
                y,
                channel,
                value,
            }
        });
    }
    Ok(())
}

fn check_len(width: u32, height: u32, got: usize) -> Result<(), TextureError> {
    let expected = width as usize * height as usize;
    if got != expected {
        return Err(TextureError::DataLength {
            width,
            height,
            expected,
            got,
        });
    }
    Ok(())
}
