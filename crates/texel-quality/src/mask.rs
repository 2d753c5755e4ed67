//! [`Mask`]: which pixels a measurement averages over (usually the geometry's coverage).

use crate::error::QualityError;
use crate::size::{check_data_len, checked_len};

/// A row-major boolean image; `true` pixels are measured. Sides are `1..=MAX_SIDE`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Mask {
    width: u32,
    height: u32,
    bits: Vec<bool>,
}

impl Mask {
    /// A mask from row-major flags (row 0 at the top).
    ///
    /// # Errors
    /// [`QualityError::EmptyImage`], [`QualityError::TooLarge`], [`QualityError::DataLength`].
    pub fn new(width: u32, height: u32, bits: Vec<bool>) -> Result<Self, QualityError> {
        check_data_len(width, height, 1, bits.len())?;
        Ok(Mask {
            width,
            height,
            bits,
        })
    }

    /// Every pixel selected.
    ///
    /// # Errors
    /// [`QualityError::EmptyImage`], [`QualityError::TooLarge`].
    pub fn full(width: u32, height: u32) -> Result<Self, QualityError> {
        let n = checked_len(width, height)?;
        Self::new(width, height, vec![true; n])
    }

    /// Pixel `(x, y)` is selected when `f(x, y)`.
    ///
    /// # Errors
    /// [`QualityError::EmptyImage`], [`QualityError::TooLarge`].
    pub fn from_fn(
        width: u32,
        height: u32,
        f: impl Fn(u32, u32) -> bool,
    ) -> Result<Self, QualityError> {
        checked_len(width, height)?;
        let bits = (0..height)
            .flat_map(|y| (0..width).map(move |x| (x, y)))
            .map(|(x, y)| f(x, y))
            .collect();
        Self::new(width, height, bits)
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

    /// The flags, row-major.
    pub fn bits(&self) -> &[bool] {
        &self.bits
    }

    /// Whether `(x, y)` is selected; `false` outside the mask.
    pub fn get(&self, x: u32, y: u32) -> bool {
        x < self.width
            && y < self.height
            && self.bits[y as usize * self.width as usize + x as usize]
    }

    /// How many pixels are selected.
    pub fn count(&self) -> usize {
        self.bits.iter().filter(|&&b| b).count()
    }
}

/// Resolve an optional mask against an image size: `None` means every pixel.
pub(crate) fn check_mask(mask: Option<&Mask>, size: (u32, u32)) -> Result<(), QualityError> {
    if let Some(m) = mask {
        crate::image8::check_same(size, m.size())?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn get_and_count() {
        let m = Mask::from_fn(4, 3, |x, y| x == y).unwrap();
        assert_eq!(m.count(), 3);
        assert!(m.get(2, 2));
        assert!(!m.get(3, 2));
        assert!(!m.get(9, 9));
        assert!(matches!(
            Mask::new(2, 2, vec![true]),
            Err(QualityError::DataLength { .. })
        ));
    }
}
