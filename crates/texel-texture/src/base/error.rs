//! The one error type of texel-texture.

use thiserror::Error;

/// Everything that can go wrong when creating a texture or a sampler.
///
/// Sampling itself cannot fail: descriptors and images are validated once, at creation.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum TextureError {
    /// Width or height is zero.
    #[error("texture size {width}x{height} is empty: both sides must be at least 1")]
    EmptySize {
        /// Requested width in texels.
        width: u32,
        /// Requested height in texels.
        height: u32,
    },
    /// A side exceeds [`crate::Limits::max_dimension`].
    #[error("texture size {width}x{height} exceeds the limit of {max} texels per side")]
    TooLarge {
        /// Requested width in texels.
        width: u32,
        /// Requested height in texels.
        height: u32,
        /// The limit in texels.
        max: u32,
    },
    /// The bytes the texture and its structures would take exceed [`crate::Limits::max_bytes`].
    #[error("texture {width}x{height} would need {bytes} bytes to load with its mip pyramid ({} MiB), over the limit of {max} bytes ({} MiB)", bytes >> 20, max >> 20)]
    OverMemoryLimit {
        /// Requested width in texels.
        width: u32,
        /// Requested height in texels.
        height: u32,
        /// Bytes needed.
        bytes: u64,
        /// The limit in bytes.
        max: u64,
    },
    /// The data length does not match `width * height`.
    #[error("texel data has {got} texels but a {width}x{height} texture needs {expected}")]
    DataLength {
        /// Width in texels.
        width: u32,
        /// Height in texels.
        height: u32,
        /// Texels expected (`width * height`).
        expected: usize,
        /// Texels given.
        got: usize,
    },
    /// The image file could not be decoded (corrupt, truncated, unsupported).
    #[error("cannot decode image: {0}")]
    Decode(#[from] image::ImageError),
    /// The image file could not be read.
    #[error("cannot read image: {0}")]
    Io(#[from] std::io::Error),
    /// The decoded image has a pixel format texel does not sample.
    #[error(
        "unsupported pixel format {0:?}: texel samples 8-bit, 16-bit and float RGB(A)/luma images"
    )]
    UnsupportedFormat(image::ColorType),
    /// `lod_min_clamp` is negative/NaN or greater than `lod_max_clamp`.
    #[error("invalid lod clamp: lod_min_clamp = {lod_min_clamp}, lod_max_clamp = {lod_max_clamp} (need 0 <= min <= max, not NaN)")]
    InvalidLodClamp {
        /// The requested minimum.
        lod_min_clamp: f32,
        /// The requested maximum.
        lod_max_clamp: f32,
    },
    /// `lod_bias` is not finite.
    #[error("invalid lod bias {0}: must be finite")]
    InvalidLodBias(f32),
    /// `anisotropy_clamp` is outside `1..=64`.
    #[error("invalid anisotropy_clamp {0}: must be between 1 and 64")]
    InvalidAnisotropyClamp(u16),
    /// Anisotropic filtering needs linear mag, min and mipmap filters (WebGPU rule).
    #[error(
        "anisotropy_clamp = {0} requires mag_filter, min_filter and mipmap_filter to be Linear"
    )]
    AnisotropyNeedsLinear(u16),
    /// A cubic filter's (B, C) parameters are not finite or outside
    /// `[-MAX_CUBIC_PARAMETER, MAX_CUBIC_PARAMETER]` ([`crate::base::filter::MAX_CUBIC_PARAMETER`]).
    #[error("invalid Mitchell-Netravali parameters B = {b}, C = {c}: each must be within [-2, 2]")]
    InvalidCubic {
        /// The B parameter.
        b: f32,
        /// The C parameter.
        c: f32,
    },
    /// [`crate::FilterMode::Ewa`], [`crate::FilterMode::Ripmap`] and
    /// [`crate::FilterMode::SummedArea`] filter a minified footprint and are valid only as
    /// `min_filter`; magnification (`lod <= 0`) uses `mag_filter`, which must be Nearest, Linear or
    /// Cubic.
    #[error("mag_filter {0:?} is a minification-only filter: use it as min_filter, with mag_filter Nearest, Linear or Cubic")]
    MinificationOnlyFilter(crate::base::filter::FilterMode),
    /// An acceleration structure (ripmap, summed-area table) would exceed
    /// [`crate::Limits::max_bytes`] together with the texture's pyramid and the other structures
    /// already built.
    #[error("the {structure} of a {width}x{height} texture would bring the texture to {bytes} bytes, over the limit of {max} bytes")]
    StructureOverMemoryLimit {
        /// `"ripmap"` or `"summed-area table"`.
        structure: &'static str,
        /// Width of level 0 in texels.
        width: u32,
        /// Height of level 0 in texels.
        height: u32,
        /// Bytes the texture would use with the structure (pyramid + structures + build scratch).
        bytes: u64,
        /// The limit in bytes.
        max: u64,
    },
    /// A float texel (level 0, pixel `x, y` of the image, row 0 at the top) is NaN or infinite.
    #[error("texel ({x}, {y}) channel {channel} is {value}: textures must be finite (the texel CLI's --sanitize, or LoadOptions::replace_non_finite, replaces NaN with 0 and infinities with +-65504)")]
    NonFiniteTexel {
        /// Column of the texel.
        x: u32,
        /// Row of the texel (0 is the top).
        y: u32,
        /// `"R"`, `"G"`, `"B"` or `"A"`.
        channel: &'static str,
        /// The value found.
        value: f32,
    },
    /// A float texel (as for [`TextureError::NonFiniteTexel`]) is finite but larger in magnitude
    /// than [`crate::MAX_TEXEL`]: a filter's weighted sums of such values overflow `f32`.
    #[error("texel ({x}, {y}) channel {channel} is {value:e}: float textures hold values within +-{max:e}, so that a filter's weighted sums stay finite (the texel CLI's --sanitize, or LoadOptions::replace_non_finite, clamps them to that)")]
    TexelOutOfRange {
        /// Column of the texel.
        x: u32,
        /// Row of the texel (0 is the top).
        y: u32,
        /// `"R"`, `"G"`, `"B"` or `"A"`.
        channel: &'static str,
        /// The value found.
        value: f32,
        /// [`crate::MAX_TEXEL`].
        max: f32,
    },
    /// The image decoder crashed on the file (a panic caught by [`texel_io::guarded`]): the
    /// file is corrupt, or uses a feature the decoder mishandles.
    #[error("cannot decode image: the decoder failed on this file (corrupt, or a feature it mishandles): {0}")]
    DecoderFailed(String),
    /// The image file ends before its data does.
    #[error("truncated image: {0}")]
    Truncated(String),
    /// A lab mode outside 1..=8.
    #[error("unknown lab mode {0}: valid modes are 1 (nearest) to 8 (anisotropic 16x)")]
    UnknownLabMode(u8),
    /// The lab convention asked of a sampler that is not one of the lab's eight modes.
    #[error("the lab convention applies to the lab's eight modes only (nearest, bilinear, mip-nearest, trilinear, aniso2-16 with their default lod range)")]
    LabConventionNeedsLabMode,
    /// A filter name that is not one of [`crate::Filter::NAMES`].
    #[error("unknown filter {name:?}: valid filters are {}, or all", valid.join(", "))]
    UnknownFilter {
        /// The name given.
        name: String,
        /// The valid names ([`crate::Filter::NAMES`]).
        valid: &'static [&'static str],
    },
    /// A filter list with no names.
    #[error("the filter list is empty: name at least one filter, or all")]
    EmptyFilterList,
}
