//! How sure a score is: the reference's own noise, block-mean scores, and which differences
//! between two images the reference can tell apart.
//!
//! A reference is an estimate: each pixel's linear mean `m` comes with a standard error `s`
//! (texel-raster's converging reference measures it from independent passes). On the display it
//! becomes a standard deviation `d = 255 (D(m + s) - D(m - s)) / 2` per RGB channel, with `D` the
//! display (clipped to `[0, 1]`, sRGB-encoded or not): the central difference, which a clipped
//! pixel's zero slope makes small, as it should.
//!
//! - **Noise floor**: the PSNR a perfect filter (the true expected image) would score against this
//!   reference, `psnr_from_mse(mean d^2)` over the covered pixels and R, G, B. No filter's score
//!   above it means anything.
//! - **Block means**: each image decoded to linear light and averaged over `b x b` blocks (the
//!   covered pixels of each block, blocks with none skipped), re-encoded without rounding, and
//!   scored as a PSNR on those means. A sheen is what the eye sees of glints; this score sees it
//!   and not the per-pixel noise. Its floor uses the block mean's standard error
//!   `sqrt(sum s^2) / n`, displayed the same way.
//! - **Distinguishable**: two images `a` and `b` score `MSE_a - MSE_b` against the reference
//!   `r = t + e` (truth `t`, noise `e`). The noise enters that difference only through
//!   `-2 mean((a - b) e)`, whose standard deviation is `2 sqrt(sum (a - b)^2 d^2) / (3 n)`.
//!   Two rows whose MSE difference is within 1.96 of those are within the reference's 95 %
//!   uncertainty: the reference does not rank them.

use texel_texture::base::color::{displayed, srgb_to_linear};

use crate::error::QualityError;
use crate::image8::{check_same, Encoding, Image8};
use crate::mask::{check_mask, Mask};
use crate::psnr::{mse, psnr_from_mse, PEAK};

/// Side of the blocks of the block-mean score, in pixels.
pub const DEFAULT_BLOCK: u32 = 8;

/// The 0.975 quantile of the standard normal: differences within this many standard deviations
/// are within the reference's 95 % uncertainty.
pub const Z_975: f64 = 1.959_964;

/// Displayed value in `[0, 1]` of a linear value: clipped, then encoded.
fn display(x: f64, encoding: Encoding) -> f64 {
    displayed(x, encoding == Encoding::Srgb)
}

/// Linear value of an 8-bit displayed code.
fn decode(code: u8, encoding: Encoding) -> f64 {
    let x = f32::from(code) / 255.0;
    match encoding {
        Encoding::Srgb => f64::from(srgb_to_linear(x)),
        Encoding::Linear => f64::from(x),
    }
}

/// Standard deviation, in 8-bit display units, of the displayed value of a linear mean `m` with
/// standard error `s` (see the module docs).
fn display_sd(m: f64, s: f64, encoding: Encoding) -> f64 {
    if !s.is_finite() {
        return PEAK / 2.0;
    }
    PEAK * (display(m + s, encoding) - display(m - s, encoding)) / 2.0
}

/// A reference's per-pixel estimate: its linear mean and standard error per channel (RGBA, alpha
/// unused), and how the display encodes it.
#[derive(Clone, Copy, Debug)]
pub struct ReferenceError<'a> {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Each pixel's mean in linear light.
    pub mean: &'a [[f32; 4]],
    /// Each pixel's standard error of the mean in linear light (infinite: unknown).
    pub std_error: &'a [[f32; 4]],
    /// The display's encoding.
    pub encoding: Encoding,
}

impl ReferenceError<'_> {
    fn check(&self) -> Result<(), QualityError> {
        let expected = self.width as usize * self.height as usize;
        for got in [self.mean.len(), self.std_error.len()] {
            if got != expected {
                return Err(QualityError::DataLength {
                    width: self.width,
                    height: self.height,
                    expected,
                    got,
                });
            }
        }
        Ok(())
    }

    /// Each pixel's displayed standard deviation per RGB channel, in 8-bit units.
    pub fn display_sd(&self) -> Vec<[f64; 3]> {
        self.mean
            .iter()
            .zip(self.std_error)
            .map(|(m, s)| {
                std::array::from_fn(|c| display_sd(f64::from(m[c]), f64::from(s[c]), self.encoding))
            })
            .collect()
    }

    /// The PSNR (dB) a perfect filter would score against this reference over `mask`: the
    /// per-pixel noise floor. `+inf` for a reference without noise.
    ///
    /// # Errors
    /// [`QualityError::SizeMismatch`], [`QualityError::EmptyMask`].
    pub fn noise_floor(&self, mask: Option<&Mask>) -> Result<f64, QualityError> {
        self.check()?;
        check_mask(mask, (self.width, self.height))?;
        let (mut sum, mut n) = (0.0, 0usize);
        for (i, d) in self.display_sd().iter().enumerate() {
            if mask.is_none_or(|m| m.bits()[i]) {
                n += 1;
                sum += d.iter().map(|x| x * x).sum::<f64>();
            }
        }
        if n == 0 {
            return Err(QualityError::EmptyMask {
                what: "the noise floor",
            });
        }
        Ok(psnr_from_mse(sum / (3.0 * n as f64)))
    }

    /// The noise floor of the block-mean score ([`block_psnr`]) with `block`-pixel blocks.
    ///
    /// # Errors
    /// As [`ReferenceError::noise_floor`]; [`QualityError::InvalidBlock`] for a block of 0.
    pub fn block_noise_floor(&self, mask: Option<&Mask>, block: u32) -> Result<f64, QualityError> {
        self.check()?;
        check_mask(mask, (self.width, self.height))?;
        let mut sum = 0.0;
        let blocks = for_each_block(self.width, self.height, mask, block, |pixels| {
            let n = pixels.len() as f64;
            for c in 0..3 {
                let m = pixels
                    .iter()
                    .map(|&i| f64::from(self.mean[i][c]))
                    .sum::<f64>()
                    / n;
                let var = pixels
                    .iter()
                    .map(|&i| f64::from(self.std_error[i][c]).powi(2))
                    .sum::<f64>();
                let d = display_sd(m, var.sqrt() / n, self.encoding);
                sum += d * d;
            }
        })?;
        Ok(psnr_from_mse(sum / (3.0 * blocks as f64)))
    }

    /// Whether the reference can rank `a` against `b` over `mask`: their MSE difference against
    /// `reference` (the 8-bit image of this estimate) and its standard deviation from the
    /// reference's noise (module docs). Distinguishable when `|difference| > 1.96 sd`.
    ///
    /// # Errors
    /// Size mismatches; [`QualityError::EmptyMask`].
    pub fn mse_difference(
        &self,
        reference: &Image8,
        a: &Image8,
        b: &Image8,
        mask: Option<&Mask>,
    ) -> Result<MseDifference, QualityError> {
        self.check()?;
        check_same(reference.size(), (self.width, self.height))?;
        Ok(MseDifference {
            difference: mse(reference, a, mask)? - mse(reference, b, mask)?,
            sd: noise_sd(&self.display_sd(), a, b, mask)?,
        })
    }

    /// For each of `images`, the indices of the others the reference cannot rank it against
    /// ([`MseDifference::distinguishable`] is false), in order.
    ///
    /// # Errors
    /// As [`ReferenceError::mse_difference`].
    pub fn within_noise(
        &self,
        reference: &Image8,
        images: &[&Image8],
        mask: Option<&Mask>,
    ) -> Result<Vec<Vec<usize>>, QualityError> {
        self.check()?;
        check_same(reference.size(), (self.width, self.height))?;
        let sd = self.display_sd();
        let mses = images
            .iter()
            .map(|image| mse(reference, image, mask))
            .collect::<Result<Vec<_>, _>>()?;
        let mut out = vec![Vec::new(); images.len()];
        for i in 0..images.len() {
            for j in i + 1..images.len() {
                let d = MseDifference {
                    difference: mses[i] - mses[j],
                    sd: noise_sd(&sd, images[i], images[j], mask)?,
                };
                if !d.distinguishable() {
                    out[i].push(j);
                    out[j].push(i);
                }
            }
        }
        for v in &mut out {
            v.sort_unstable();
        }
        Ok(out)
    }
}

/// The standard deviation the reference's noise (displayed standard deviations `sd`, one per
/// pixel and RGB channel) gives the MSE difference of `a` and `b`: `2 sqrt(sum (a - b)^2 d^2) /
/// (3 n)` over the pixels `mask` selects.
fn noise_sd(
    sd: &[[f64; 3]],
    a: &Image8,
    b: &Image8,
    mask: Option<&Mask>,
) -> Result<f64, QualityError> {
    check_same(a.size(), b.size())?;
    check_mask(mask, a.size())?;
    let (mut var, mut n) = (0.0, 0usize);
    for (i, (pa, pb)) in a.pixels().iter().zip(b.pixels()).enumerate() {
        if mask.is_none_or(|m| m.bits()[i]) {
            n += 1;
            for c in 0..3 {
                let ab = f64::from(pa[c]) - f64::from(pb[c]);
                var += ab * ab * sd[i][c] * sd[i][c];
            }
        }
    }
    Ok(2.0 * var.sqrt() / (3.0 * n.max(1) as f64))
}

/// Two images' MSE difference against a reference and the part of it the reference's noise could
/// make ([`ReferenceError::mse_difference`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MseDifference {
    /// `MSE_a - MSE_b` in 8-bit units squared.
    pub difference: f64,
    /// Its standard deviation from the reference's noise.
    pub sd: f64,
}

impl MseDifference {
    /// Whether the reference ranks the two at 95 % confidence.
    pub fn distinguishable(&self) -> bool {
        self.difference.abs() > Z_975 * self.sd
    }
}

/// Call `f` with the covered pixel indices of each `block x block` block that has any; return the
/// number of such blocks.
fn for_each_block(
    width: u32,
    height: u32,
    mask: Option<&Mask>,
    block: u32,
    mut f: impl FnMut(&[usize]),
) -> Result<usize, QualityError> {
    if block == 0 {
        return Err(QualityError::InvalidBlock);
    }
    let mut pixels = Vec::with_capacity(block as usize * block as usize);
    let mut blocks = 0;
    for by in (0..height).step_by(block as usize) {
        for bx in (0..width).step_by(block as usize) {
            pixels.clear();
            for y in by..(by + block).min(height) {
                for x in bx..(bx + block).min(width) {
                    let i = y as usize * width as usize + x as usize;
                    if mask.is_none_or(|m| m.bits()[i]) {
                        pixels.push(i);
                    }
                }
            }
            if !pixels.is_empty() {
                blocks += 1;
                f(&pixels);
            }
        }
    }
    if blocks == 0 {
        return Err(QualityError::EmptyMask {
            what: "the block-mean PSNR",
        });
    }
    Ok(blocks)
}

/// PSNR (dB) of `b` against `a` on `block x block` block means in linear light (module docs):
/// each block's covered pixels decoded with `encoding`, averaged, re-encoded to `[0, 255]` without
/// rounding; MSE over the blocks and R, G, B. Symmetric; `+inf` when the means are equal.
///
/// # Errors
/// Size mismatches; [`QualityError::EmptyMask`]; [`QualityError::InvalidBlock`] for a block of 0.
pub fn block_psnr(
    a: &Image8,
    b: &Image8,
    mask: Option<&Mask>,
    block: u32,
    encoding: Encoding,
) -> Result<f64, QualityError> {
    check_same(a.size(), b.size())?;
    check_mask(mask, a.size())?;
    let lut: Vec<f64> = (0..=255u8).map(|c| decode(c, encoding)).collect();
    let mut sum = 0.0;
    let blocks = for_each_block(a.width(), a.height(), mask, block, |pixels| {
        let n = pixels.len() as f64;
        for c in 0..3 {
            let mean = |img: &Image8| {
                pixels
                    .iter()
                    .map(|&i| lut[usize::from(img.pixels()[i][c])])
                    .sum::<f64>()
                    / n
            };
            let d = PEAK * (display(mean(a), encoding) - display(mean(b), encoding));
            sum += d * d;
        }
    })?;
    Ok(psnr_from_mse(sum / (3.0 * blocks as f64)))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn flat(w: u32, h: u32, v: u8) -> Image8 {
        Image8::filled(w, h, [v, v, v, 255]).unwrap()
    }

    #[test]
    fn block_means_of_a_checker_equal_its_mean_grey() {
        // A 0/255 checker and the grey of its linear mean agree on every 2x2 block mean, while
        // the per-pixel PSNR sees the full difference.
        let checker = Image8::from_fn(16, 8, |x, y| {
            let v = if (x + y) % 2 == 0 { 0 } else { 255 };
            [v, v, v, 255]
        })
        .unwrap();
        for encoding in [Encoding::Srgb, Encoding::Linear] {
            let grey = PEAK * display(0.5, encoding);
            // Codes around the grey bracket it; the block PSNR of the nearest code is its offset.
            let code = grey.round() as u8;
            let expect = psnr_from_mse((grey - f64::from(code)).powi(2));
            let got = block_psnr(&checker, &flat(16, 8, code), None, 2, encoding).unwrap();
            let decoded = PEAK * display(decode(code, encoding), encoding);
            let exact = psnr_from_mse((grey - decoded).powi(2));
            assert!((got - exact).abs() < 1e-6, "{encoding:?}: {got} vs {exact}");
            assert!((got - expect).abs() < 0.5, "{encoding:?}");
            assert!(crate::psnr(&checker, &flat(16, 8, code), None).unwrap() < 7.0);
        }
        assert_eq!(
            block_psnr(&checker, &checker, None, 8, Encoding::Srgb).unwrap(),
            f64::INFINITY
        );
        assert!(matches!(
            block_psnr(&checker, &checker, None, 0, Encoding::Srgb),
            Err(QualityError::InvalidBlock)
        ));
    }

    #[test]
    fn block_means_follow_the_mask() {
        // Only the covered pixel of each block counts: uncovered ones may differ freely.
        let a = Image8::from_fn(8, 8, |x, _| if x < 4 { [10; 4] } else { [200; 4] }).unwrap();
        let b = Image8::from_fn(8, 8, |x, _| if x < 4 { [10; 4] } else { [90; 4] }).unwrap();
        let left = Mask::from_fn(8, 8, |x, _| x < 4).unwrap();
        let p = block_psnr(&a, &b, Some(&left), 4, Encoding::Linear).unwrap();
        assert_eq!(p, f64::INFINITY);
        let none = Mask::from_fn(8, 8, |_, _| false).unwrap();
        assert!(block_psnr(&a, &b, Some(&none), 4, Encoding::Linear).is_err());
    }

    /// A reference of constant mean `m` and standard error `s` everywhere.
    fn constant(m: f32, s: f32, n: usize) -> (Vec<[f32; 4]>, Vec<[f32; 4]>) {
        (vec![[m; 4]; n], vec![[s; 4]; n])
    }

    #[test]
    fn noise_floor_of_a_linear_display_is_the_standard_error() {
        let (mean, se) = constant(0.5, 2.0 / 255.0, 12 * 10);
        let e = ReferenceError {
            width: 12,
            height: 10,
            mean: &mean,
            std_error: &se,
            encoding: Encoding::Linear,
        };
        // d = 2 steps everywhere: MSE 4.
        let floor = e.noise_floor(None).unwrap();
        assert!((floor - psnr_from_mse(4.0)).abs() < 1e-5, "{floor}");
        // Blocks of 2x2 average 4 independent errors: d = 1, MSE 1 (6 x 5 whole blocks).
        let block = e.block_noise_floor(None, 2).unwrap();
        assert!((block - psnr_from_mse(1.0)).abs() < 1e-5, "{block}");
        // A clipped pixel (mean far above 1) has no displayed noise.
        let (mean, se) = constant(5.0, 0.1, 4);
        let e = ReferenceError {
            width: 2,
            height: 2,
            mean: &mean,
            std_error: &se,
            encoding: Encoding::Srgb,
        };
        assert_eq!(e.noise_floor(None).unwrap(), f64::INFINITY);
        // Unknown error (infinite) is half the range.
        let (mean, se) = constant(0.5, f32::INFINITY, 4);
        let e = ReferenceError {
            mean: &mean,
            std_error: &se,
            ..e
        };
        let floor = e.noise_floor(None).unwrap();
        assert!((floor - psnr_from_mse(127.5 * 127.5)).abs() < 1e-9);
    }

    #[test]
    fn srgb_noise_uses_the_slope_of_the_encoding() {
        let (m, s) = (0.2f32, 0.001f32);
        let (mean, se) = constant(m, s, 1);
        let e = ReferenceError {
            width: 1,
            height: 1,
            mean: &mean,
            std_error: &se,
            encoding: Encoding::Srgb,
        };
        // The sRGB curve's slope at x > 0.0031308: 1.055 / 2.4 x^(1/2.4 - 1).
        let slope = 1.055 / 2.4 * f64::from(m).powf(1.0 / 2.4 - 1.0);
        let d = e.display_sd()[0][0];
        assert!((d - 255.0 * slope * f64::from(s)).abs() < 1e-3 * d, "{d}");
    }

    #[test]
    fn the_noise_term_of_an_mse_difference() {
        // Reference 100 everywhere, a = 100, b = 104 on one pixel of 4: the MSE difference is
        // -16 / 4; with d = 2 steps on every channel the noise's sd is 2 sqrt(3 * 16 * 4) / 12.
        let w = 2;
        let r = flat(w, 2, 100);
        let a = r.clone();
        let mut px = r.pixels().to_vec();
        px[3] = [104, 104, 104, 255];
        let b = Image8::new(w, 2, px).unwrap();
        let (mean, se) = constant(100.0 / 255.0, 2.0 / 255.0, 4);
        let e = ReferenceError {
            width: w,
            height: 2,
            mean: &mean,
            std_error: &se,
            encoding: Encoding::Linear,
        };
        let d = e.mse_difference(&r, &a, &b, None).unwrap();
        assert!((d.difference + 4.0).abs() < 1e-12);
        let sd = 2.0 * (3.0f64 * 16.0 * 4.0).sqrt() / 12.0;
        assert!((d.sd - sd).abs() < 1e-6, "{}", d.sd);
        assert_eq!(d.distinguishable(), 4.0 > Z_975 * sd);
        // A noiseless reference ranks any difference; the same images are never ranked.
        let zero = vec![[0.0f32; 4]; 4];
        let exact = ReferenceError {
            std_error: &zero,
            ..e
        };
        assert!(exact
            .mse_difference(&r, &a, &b, None)
            .unwrap()
            .distinguishable());
        assert!(!e
            .mse_difference(&r, &a, &a, None)
            .unwrap()
            .distinguishable());
        // Ranking three images: a and a copy are within noise of each other, b of neither
        // under the exact reference, of both under a very noisy one.
        let copy = a.clone();
        let ranks = exact.within_noise(&r, &[&a, &b, &copy], None).unwrap();
        assert_eq!(ranks, vec![vec![2], vec![], vec![0]]);
        let loud = vec![[1.0f32; 4]; 4];
        let noisy = ReferenceError {
            std_error: &loud,
            ..e
        };
        let ranks = noisy.within_noise(&r, &[&a, &b, &copy], None).unwrap();
        assert_eq!(ranks, vec![vec![1, 2], vec![0, 2], vec![0, 1]]);
    }
}
