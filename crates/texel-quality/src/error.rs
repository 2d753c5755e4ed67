//! The one error type of texel-quality.

use std::path::PathBuf;

use thiserror::Error;

/// Everything that can go wrong when measuring images, drawing heat maps or writing reports.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum QualityError {
    /// An image or mask with a zero side.
    #[error("image size {width}x{height} is empty: both sides must be at least 1")]
    EmptyImage {
        /// Width in pixels.
        width: u32,
        /// Height in pixels.
        height: u32,
    },
    /// An image or mask larger than [`crate::MAX_SIDE`] per side.
    #[error("image size {width}x{height} exceeds the limit of {max} pixels per side")]
    TooLarge {
        /// Width in pixels.
        width: u32,
        /// Height in pixels.
        height: u32,
        /// The limit in pixels per side.
        max: u32,
    },
    /// The pixel data length does not match `width * height`.
    #[error("pixel data has {got} elements but a {width}x{height} image needs {expected}")]
    DataLength {
        /// Width in pixels.
        width: u32,
        /// Height in pixels.
        height: u32,
        /// Elements expected.
        expected: usize,
        /// Elements given.
        got: usize,
    },
    /// Two images (or an image and a mask) that must have the same size do not.
    #[error("size mismatch: {a_width}x{a_height} against {b_width}x{b_height}")]
    SizeMismatch {
        /// Width of the first operand.
        a_width: u32,
        /// Height of the first operand.
        a_height: u32,
        /// Width of the second operand.
        b_width: u32,
        /// Height of the second operand.
        b_height: u32,
    },
    /// The mask selects no pixel (no pixel where SSIM's 11x11 window fits, for SSIM), so the
    /// mean is undefined.
    #[error("the mask selects no pixel ({what}): the mean is undefined")]
    EmptyMask {
        /// Which measurement found nothing to average.
        what: &'static str,
    },
    /// A block-mean score with blocks of 0 pixels.
    #[error("the block side of a block-mean score must be at least 1 pixel")]
    InvalidBlock,
    /// A heat-map scale that is not a finite positive number.
    #[error("invalid heat-map scale {0}: the error mapped to the top of the ramp must be finite and > 0")]
    InvalidScale(f32),
    /// A crop rectangle that is empty or not inside the image.
    #[error("crop {x},{y} {width}x{height} is empty or not inside the {image_width}x{image_height} image")]
    CropOutOfBounds {
        /// Left column of the crop.
        x: u32,
        /// Top row of the crop.
        y: u32,
        /// Crop width in pixels.
        width: u32,
        /// Crop height in pixels.
        height: u32,
        /// Image width in pixels.
        image_width: u32,
        /// Image height in pixels.
        image_height: u32,
    },
    /// An enlargement factor outside `1..=64`, or one whose result exceeds [`crate::MAX_SIDE`].
    #[error("invalid enlargement factor {factor} for a {width}x{height} crop: need 1..=64 and a result of at most {max} pixels per side", max = crate::MAX_SIDE)]
    InvalidFactor {
        /// The factor requested.
        factor: u32,
        /// Crop width in pixels.
        width: u32,
        /// Crop height in pixels.
        height: u32,
    },
    /// A file could not be read, written or renamed.
    #[error("{path}: {source}")]
    Io {
        /// The file concerned.
        path: PathBuf,
        /// The underlying error.
        source: std::io::Error,
    },
    /// An image could not be decoded or encoded.
    #[error("{path}: {source}")]
    Image {
        /// The file concerned (empty when encoding to memory).
        path: PathBuf,
        /// The underlying error.
        source: image::ImageError,
    },
    /// A report could not be parsed from JSON.
    #[error("report JSON: {0}")]
    Json(#[from] serde_json::Error),
}

impl From<texel_io::OutputError> for QualityError {
    fn from(e: texel_io::OutputError) -> Self {
        QualityError::Io {
            path: e.path,
            source: e.source,
        }
    }
}
