//! Crops enlarged with nearest-neighbour upscaling (to show the horizon's texels as blocks).

use crate::error::QualityError;
use crate::image8::Image8;
use crate::mask::Mask;
use crate::MAX_SIDE;

/// An axis-aligned pixel rectangle `[x, x + width) x [y, y + height)`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct Rect {
    /// Left column.
    pub x: u32,
    /// Top row.
    pub y: u32,
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
}

/// The `rect` of `image`, each pixel repeated `factor x factor` times (nearest neighbour): output
/// pixel `(X, Y)` is input pixel `(rect.x + X / factor, rect.y + Y / factor)`.
///
/// # Errors
/// [`QualityError::CropOutOfBounds`] for an empty rectangle or one not inside the image;
/// [`QualityError::InvalidFactor`] for `factor` outside `1..=64` or a result over [`MAX_SIDE`].
pub fn crop_enlarge(image: &Image8, rect: Rect, factor: u32) -> Result<Image8, QualityError> {
    let inside = rect.width > 0
        && rect.height > 0
        && u64::from(rect.x) + u64::from(rect.width) <= u64::from(image.width())
        && u64::from(rect.y) + u64::from(rect.height) <= u64::from(image.height());
    if !inside {
        return Err(QualityError::CropOutOfBounds {
            x: rect.x,
            y: rect.y,
            width: rect.width,
            height: rect.height,
            image_width: image.width(),
            image_height: image.height(),
        });
    }
    let ow = u64::from(rect.width) * u64::from(factor);
    let oh = u64::from(rect.height) * u64::from(factor);
    if !(1..=64).contains(&factor) || ow > u64::from(MAX_SIDE) || oh > u64::from(MAX_SIDE) {
        return Err(QualityError::InvalidFactor {
            factor,
            width: rect.width,
            height: rect.height,
        });
    }
    Image8::from_fn(ow as u32, oh as u32, |x, y| {
        image
            .pixel(rect.x + x / factor, rect.y + y / factor)
            .expect("inside by construction")
    })
}

/// A `width x height` rectangle (clamped to the image) at the horizon of `coverage`, centred
/// horizontally: its top is a quarter of its height above the highest topmost-covered row among
/// the columns it spans (so a little background shows above the horizon), clamped to the image.
/// `None` when those columns have no coverage or a requested side is 0.
pub fn horizon_crop_rect(coverage: &Mask, width: u32, height: u32) -> Option<Rect> {
    let (iw, ih) = coverage.size();
    let (w, h) = (width.min(iw), height.min(ih));
    if w == 0 || h == 0 {
        return None;
    }
    let x = (iw - w) / 2;
    let top = (x..x + w)
        .filter_map(|cx| (0..ih).find(|&y| coverage.get(cx, y)))
        .min()?;
    let y = top.saturating_sub(h / 4).min(ih - h);
    Some(Rect {
        x,
        y,
        width: w,
        height: h,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nearest_enlargement() {
        let img = Image8::from_fn(4, 3, |x, y| [x as u8, y as u8, 0, 255]).unwrap();
        let r = Rect {
            x: 1,
            y: 1,
            width: 2,
            height: 2,
        };
        let big = crop_enlarge(&img, r, 3).unwrap();
        assert_eq!(big.size(), (6, 6));
        for y in 0..6 {
            for x in 0..6 {
                assert_eq!(
                    big.pixel(x, y).unwrap(),
                    [1 + x as u8 / 3, 1 + y as u8 / 3, 0, 255]
                );
            }
        }
        assert_eq!(crop_enlarge(&img, r, 1).unwrap().pixels().len(), 4);
    }

    #[test]
    fn errors() {
        let img = Image8::filled(4, 3, [0; 4]).unwrap();
        let out = Rect {
            x: 3,
            y: 0,
            width: 2,
            height: 1,
        };
        assert!(matches!(
            crop_enlarge(&img, out, 2),
            Err(QualityError::CropOutOfBounds { .. })
        ));
        let empty = Rect {
            x: 0,
            y: 0,
            width: 0,
            height: 1,
        };
        assert!(matches!(
            crop_enlarge(&img, empty, 2),
            Err(QualityError::CropOutOfBounds { .. })
        ));
        let huge = Rect {
            x: u32::MAX,
            y: 0,
            width: 2,
            height: 1,
        };
        assert!(matches!(
            crop_enlarge(&img, huge, 2),
            Err(QualityError::CropOutOfBounds { .. })
        ));
        let ok = Rect {
            x: 0,
            y: 0,
            width: 4,
            height: 3,
        };
        assert!(matches!(
            crop_enlarge(&img, ok, 0),
            Err(QualityError::InvalidFactor { .. })
        ));
        assert!(matches!(
            crop_enlarge(&img, ok, 65),
            Err(QualityError::InvalidFactor { .. })
        ));
    }

    #[test]
    fn horizon_rect() {
        // Horizon at row 40 of a 100x80 image.
        let cov = Mask::from_fn(100, 80, |_, y| y >= 40).unwrap();
        let r = horizon_crop_rect(&cov, 20, 16).unwrap();
        assert_eq!(
            r,
            Rect {
                x: 40,
                y: 36,
                width: 20,
                height: 16
            }
        );
        // Clamped at the bottom and to the image size.
        let low = Mask::from_fn(100, 80, |_, y| y >= 79).unwrap();
        assert_eq!(
            horizon_crop_rect(&low, 200, 16).unwrap(),
            Rect {
                x: 0,
                y: 64,
                width: 100,
                height: 16
            }
        );
        let none = Mask::from_fn(100, 80, |x, _| x < 10).unwrap();
        assert_eq!(horizon_crop_rect(&none, 20, 16), None);
        assert_eq!(horizon_crop_rect(&cov, 0, 16), None);
    }
}
