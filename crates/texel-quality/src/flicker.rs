//! Temporal flicker: how much an image sequence changes from frame to frame, the figure that
//! shows sparkle (specular aliasing is seen in motion).

use crate::error::QualityError;
use crate::image8::{check_same, Image8};
use crate::mask::Mask;

/// The mean absolute change from `a` to `b`, in 8-bit units: over the pixels covered in both
/// (`mask_a` and `mask_b`), the mean over red, green and blue of `|b - a|`.
///
/// # Errors
/// [`QualityError::SizeMismatch`] when the images and masks differ in size;
/// [`QualityError::EmptyMask`] when no pixel is covered in both.
pub fn mean_abs_change(
    a: &Image8,
    b: &Image8,
    mask_a: &Mask,
    mask_b: &Mask,
) -> Result<f64, QualityError> {
    change([a, b], None, [mask_a, mask_b])
}

/// Flicker beyond the reference's: the mean absolute difference between an image sequence's
/// change from `frames[0]` to `frames[1]` and the reference's change over the same step
/// (`reference[0]` to `reference[1]`), per pixel and channel before the absolute value, in 8-bit
/// units: `mean |(b - a) - (b_ref - a_ref)|` over the pixels covered in both masks and over red,
/// green and blue. Motion changes both alike and cancels; sparkle and aliasing that the reference
/// does not show remain. 0 for an image sequence that is the reference plus a constant error.
///
/// # Errors
/// [`QualityError::SizeMismatch`] when the images and masks differ in size;
/// [`QualityError::EmptyMask`] when no pixel is covered in both.
pub fn excess_change(
    frames: [&Image8; 2],
    reference: [&Image8; 2],
    masks: [&Mask; 2],
) -> Result<f64, QualityError> {
    change(frames, Some(reference), masks)
}

/// `mean |(b - a) - (b_ref - a_ref)|` over the pixels in both masks and over RGB, the reference
/// terms 0 without a reference.
fn change(
    frames: [&Image8; 2],
    reference: Option<[&Image8; 2]>,
    masks: [&Mask; 2],
) -> Result<f64, QualityError> {
    let size = frames[0].size();
    let sizes = [frames[1].size()]
        .into_iter()
        .chain(reference.into_iter().flatten().map(Image8::size))
        .chain(masks.map(Mask::size));
    for s in sizes {
        check_same(size, s)?;
    }
    let step = |pair: [&Image8; 2], k: usize, c: usize| {
        i64::from(pair[1].pixels()[k][c]) - i64::from(pair[0].pixels()[k][c])
    };
    let mut sum = 0i64;
    let mut n = 0u64;
    for k in 0..frames[0].pixels().len() {
        if masks[0].bits()[k] && masks[1].bits()[k] {
            for c in 0..3 {
                let ref_change = reference.map_or(0, |r| step(r, k, c));
                sum += (step(frames, k, c) - ref_change).abs();
            }
            n += 1;
        }
    }
    if n == 0 {
        return Err(QualityError::EmptyMask {
            what: "frame-to-frame change",
        });
    }
    Ok(sum as f64 / (3 * n) as f64)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn change_is_the_mean_over_pixels_in_both_masks_and_channels() {
        let a = Image8::filled(2, 1, [10, 20, 30, 255]).unwrap();
        let b = Image8::new(2, 1, vec![[13, 20, 24, 0], [255, 255, 255, 255]]).unwrap();
        let both = Mask::full(2, 1).unwrap();
        let left = Mask::new(2, 1, vec![true, false]).unwrap();
        // Left pixel: (3 + 0 + 6) / 3 = 3; right: (245 + 235 + 225) / 3 = 235. Alpha ignored.
        assert_eq!(mean_abs_change(&a, &b, &both, &both).unwrap(), 119.0);
        assert_eq!(mean_abs_change(&a, &b, &left, &both).unwrap(), 3.0);
        assert_eq!(mean_abs_change(&b, &a, &both, &left).unwrap(), 3.0);
        assert_eq!(mean_abs_change(&a, &a, &both, &both).unwrap(), 0.0);
        let none = Mask::new(2, 1, vec![false, false]).unwrap();
        assert!(matches!(
            mean_abs_change(&a, &b, &none, &both),
            Err(QualityError::EmptyMask { .. })
        ));
        let small = Image8::filled(1, 1, [0; 4]).unwrap();
        assert!(mean_abs_change(&a, &small, &both, &both).is_err());
    }

    #[test]
    fn excess_change_cancels_what_the_reference_does_too() {
        let m = Mask::full(2, 1).unwrap();
        let r0 = Image8::new(2, 1, vec![[100, 100, 100, 255], [50, 50, 50, 255]]).unwrap();
        let r1 = Image8::new(2, 1, vec![[110, 90, 100, 255], [50, 50, 50, 255]]).unwrap();
        // The reference plus a constant error: no excess.
        let plus = |img: &Image8, d: u8| {
            Image8::new(
                2,
                1,
                img.pixels()
                    .iter()
                    .map(|p| [p[0] + d, p[1] + d, p[2] + d, p[3]])
                    .collect(),
            )
            .unwrap()
        };
        let (a0, a1) = (plus(&r0, 7), plus(&r1, 7));
        assert_eq!(
            excess_change([&a0, &a1], [&r0, &r1], [&m, &m]).unwrap(),
            0.0
        );
        // A still image against a moving reference: the reference's change, (10 + 10 + 0) / 6.
        assert_eq!(
            excess_change([&r0, &r0], [&r0, &r1], [&m, &m]).unwrap(),
            20.0 / 6.0
        );
        // Sparkle on a still reference: its change. Pixel 1 jumps by 30 in red only.
        let s1 = Image8::new(2, 1, vec![[100, 100, 100, 255], [80, 50, 50, 255]]).unwrap();
        assert_eq!(
            excess_change([&r0, &s1], [&r0, &r0], [&m, &m]).unwrap(),
            30.0 / 6.0
        );
    }
}
