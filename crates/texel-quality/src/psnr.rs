//! Peak signal-to-noise ratio over a mask.
//!
//! Definition: `MSE = sum over selected pixels p and channels c in {R, G, B} of (a[p][c] - b[p][c])^2
//! / (3 * n)` on 8-bit encoded values, and `PSNR = 10 * log10(255^2 / MSE)` dB (peak 255; alpha is
//! ignored). Identical images give `+inf`. Both images are quantised the same way first (see
//! [`crate::Image8`]), so a score recomputed from the written PNGs equals the reported one.
//! Accumulated in `u64` (exact: at most `3 * 255^2 * 16384^2 < 2^64`).

use crate::band::horizon_band;
use crate::error::QualityError;
use crate::image8::{check_same, Encoding, Image8};
use crate::mask::{check_mask, Mask};

/// The 8-bit peak value of PSNR.
pub const PEAK: f64 = 255.0;

/// Sum of squared RGB differences and the number of selected pixels.
fn sse(a: &Image8, b: &Image8, mask: Option<&Mask>) -> Result<(u64, usize), QualityError> {
    check_same(a.size(), b.size())?;
    check_mask(mask, a.size())?;
    let mut sum = 0u64;
    let mut n = 0usize;
    for (i, (pa, pb)) in a.pixels().iter().zip(b.pixels()).enumerate() {
        if mask.is_none_or(|m| m.bits()[i]) {
            n += 1;
            for c in 0..3 {
                let d = i64::from(pa[c]) - i64::from(pb[c]);
                sum += (d * d) as u64;
            }
        }
    }
    Ok((sum, n))
}

/// Mean squared error per RGB channel over the pixels `mask` selects (`None`: all), in 8-bit units
/// squared.
///
/// # Errors
/// [`QualityError::SizeMismatch`] (images or mask), [`QualityError::EmptyMask`].
pub fn mse(a: &Image8, b: &Image8, mask: Option<&Mask>) -> Result<f64, QualityError> {
    let (sum, n) = sse(a, b, mask)?;
    if n == 0 {
        return Err(QualityError::EmptyMask { what: "PSNR" });
    }
    Ok(sum as f64 / (3.0 * n as f64))
}

/// PSNR in dB from a mean squared error in 8-bit units: `10 log10(255^2 / mse)`; `+inf` for 0.
pub fn psnr_from_mse(mse: f64) -> f64 {
    if mse == 0.0 {
        f64::INFINITY
    } else {
        10.0 * (PEAK * PEAK / mse).log10()
    }
}

/// PSNR in dB of `b` against `a` over the pixels `mask` selects (`None`: all); symmetric.
/// `+inf` when they are equal there.
///
/// # Errors
/// [`QualityError::SizeMismatch`] (images or mask), [`QualityError::EmptyMask`].
pub fn psnr(a: &Image8, b: &Image8, mask: Option<&Mask>) -> Result<f64, QualityError> {
    mse(a, b, mask).map(psnr_from_mse)
}

/// PSNR over the horizon band of `coverage` ([`crate::horizon_band`] with `rows`).
///
/// # Errors
/// As [`psnr`]; [`QualityError::EmptyMask`] when the coverage is empty.
pub fn psnr_band(a: &Image8, b: &Image8, coverage: &Mask, rows: u32) -> Result<f64, QualityError> {
    psnr(a, b, Some(&horizon_band(coverage, rows)))
}

/// PSNR of two linear RGBA `f32` frames of `width x height`, each quantised with `encoding` first.
///
/// # Errors
/// As [`Image8::from_linear`] and [`psnr`].
pub fn psnr_linear(
    a: &[[f32; 4]],
    b: &[[f32; 4]],
    width: u32,
    height: u32,
    mask: Option<&Mask>,
    encoding: Encoding,
) -> Result<f64, QualityError> {
    let a = Image8::from_linear(width, height, a, encoding)?;
    let b = Image8::from_linear(width, height, b, encoding)?;
    psnr(&a, &b, mask)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn identical_is_infinite() {
        let a = Image8::from_fn(7, 5, |x, y| [x as u8, y as u8, 3, 9]).unwrap();
        assert_eq!(psnr(&a, &a, None).unwrap(), f64::INFINITY);
    }

    #[test]
    fn known_values() {
        // Every channel off by 1: MSE 1, PSNR = 20 log10(255) = 48.1308 dB.
        let a = Image8::filled(4, 4, [10, 20, 30, 255]).unwrap();
        let b = Image8::filled(4, 4, [11, 19, 31, 0]).unwrap();
        let p = psnr(&a, &b, None).unwrap();
        assert!((p - 20.0 * 255f64.log10()).abs() < 1e-12);
        assert!((p - 48.130_803_608_679_1).abs() < 1e-9);
        // Only R off by 3: MSE = 9 / 3 = 3.
        let c = Image8::filled(4, 4, [13, 20, 30, 255]).unwrap();
        assert!((mse(&a, &c, None).unwrap() - 3.0).abs() < 1e-15);
    }

    #[test]
    fn mask_restricts_and_is_checked() {
        let a = Image8::filled(4, 2, [0, 0, 0, 255]).unwrap();
        // Right half differs by 255 everywhere.
        let b =
            Image8::from_fn(4, 2, |x, _| if x >= 2 { [255; 4] } else { [0, 0, 0, 255] }).unwrap();
        let left = Mask::from_fn(4, 2, |x, _| x < 2).unwrap();
        let right = Mask::from_fn(4, 2, |x, _| x >= 2).unwrap();
        assert_eq!(psnr(&a, &b, Some(&left)).unwrap(), f64::INFINITY);
        assert!(psnr(&a, &b, Some(&right)).unwrap().abs() < 1e-12); // MSE = 255^2 -> 0 dB
                                                                    // All pixels: MSE = 255^2 / 2 -> 10 log10(2) dB.
        assert!((psnr(&a, &b, None).unwrap() - 10.0 * 2f64.log10()).abs() < 1e-12);
        let none = Mask::from_fn(4, 2, |_, _| false).unwrap();
        assert!(matches!(
            psnr(&a, &b, Some(&none)),
            Err(QualityError::EmptyMask { .. })
        ));
        let wrong = Mask::full(2, 4).unwrap();
        assert!(matches!(
            psnr(&a, &b, Some(&wrong)),
            Err(QualityError::SizeMismatch { .. })
        ));
        let small = Image8::filled(3, 2, [0; 4]).unwrap();
        assert!(matches!(
            psnr(&a, &small, None),
            Err(QualityError::SizeMismatch { .. })
        ));
    }

    #[test]
    fn linear_convenience_equals_quantised() {
        let a: Vec<[f32; 4]> = (0..12).map(|i| [i as f32 / 11.0, 0.3, 0.7, 1.0]).collect();
        let b: Vec<[f32; 4]> = (0..12).map(|i| [i as f32 / 12.0, 0.31, 0.7, 1.0]).collect();
        for enc in [Encoding::Srgb, Encoding::Linear] {
            let p = psnr_linear(&a, &b, 4, 3, None, enc).unwrap();
            let qa = Image8::from_linear(4, 3, &a, enc).unwrap();
            let qb = Image8::from_linear(4, 3, &b, enc).unwrap();
            assert_eq!(p, psnr(&qa, &qb, None).unwrap());
        }
    }

    #[test]
    fn band_variant_uses_band() {
        // Coverage: rows 2.. ; the error sits in row 9 only, below a 3-row band.
        let cov = Mask::from_fn(5, 12, |_, y| y >= 2).unwrap();
        let a = Image8::filled(5, 12, [50, 50, 50, 255]).unwrap();
        let b = Image8::from_fn(
            5,
            12,
            |_, y| if y == 9 { [0; 4] } else { [50, 50, 50, 255] },
        )
        .unwrap();
        assert_eq!(psnr_band(&a, &b, &cov, 3).unwrap(), f64::INFINITY);
        assert!(psnr_band(&a, &b, &cov, 8).unwrap().is_finite());
    }
}
