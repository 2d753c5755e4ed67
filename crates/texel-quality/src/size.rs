//! The size rules every image of this crate obeys: sides of 1 to [`MAX_SIDE`] pixels, and data
//! of exactly the length the size calls for.

use crate::error::QualityError;

/// The largest image side, in pixels, any function here accepts (16384, the common GPU limit).
pub const MAX_SIDE: u32 = 16384;

/// Check `width x height` against the size rules and return the pixel count.
pub(crate) fn checked_len(width: u32, height: u32) -> Result<usize, QualityError> {
    if width == 0 || height == 0 {
        return Err(QualityError::EmptyImage { width, height });
    }
    if width > MAX_SIDE || height > MAX_SIDE {
        return Err(QualityError::TooLarge {
            width,
            height,
            max: MAX_SIDE,
        });
    }
    Ok(width as usize * height as usize)
}

/// [`checked_len`], then that `got` elements are `per_pixel` for each of the `width * height`
/// pixels ([`QualityError::DataLength`] otherwise). Returns the pixel count.
pub(crate) fn check_data_len(
    width: u32,
    height: u32,
    per_pixel: usize,
    got: usize,
) -> Result<usize, QualityError> {
    let n = checked_len(width, height)?;
    if got != per_pixel * n {
        return Err(QualityError::DataLength {
            width,
            height,
            expected: per_pixel * n,
            got,
        });
    }
    Ok(n)
}
