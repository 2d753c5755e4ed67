//! Structural similarity (SSIM), exactly as Wang, Bovik, Sheikh and Simoncelli, "Image Quality
//! Assessment: From Error Visibility to Structural Similarity", IEEE TIP 13(4), 2004.
//!
//! Per window (eq. 13): `SSIM = ((2 mu_a mu_b + C1)(2 sigma_ab + C2)) /
//! ((mu_a^2 + mu_b^2 + C1)(sigma_a^2 + sigma_b^2 + C2))` with `C1 = (K1 L)^2`, `C2 = (K2 L)^2`,
//! `K1 = 0.01`, `K2 = 0.03`, `L = 255`. Local statistics use the paper's 11x11 circular-symmetric
//! Gaussian weighting, sigma 1.5, normalised to sum 1 (Section III-C, eq. 14-16; the authors'
//! `ssim_index.m`: `fspecial('gaussian', 11, 1.5)` and `filter2(..., 'valid')`), with
//! `sigma^2 = E[x^2] - mu^2` as that code computes it. The 2D window is the outer product of the
//! normalised 1D kernel, which is exactly the normalised 2D kernel, so filtering is separable.
//!
//! Decisions:
//! - Computed **per RGB channel** on the 8-bit encoded values and averaged over the three channels
//!   (as scikit-image's `channel_axis` mode), not on luma: a colour-only error (the barycentric
//!   triangle) must count, and PSNR is per channel too. For grey images the two are identical.
//! - `'valid'` windows only, as the paper's code: the SSIM map is defined at pixels at least 5 from
//!   every image edge; the mean ("MSSIM", eq. 17) is over the mask's pixels in that interior.
//!   Windows of pixels next to the mask's edge also see uncovered pixels (background in both images).
//! - No automatic downsampling (the later `ssim.m` adds it for large images; the 2004 paper has none).
//! - `f64` throughout; the two separable passes run in parallel over rows (rayon). A masked
//!   1280x720 SSIM costs little beside rendering a frame (`cargo bench -p texel-quality --bench
//!   metrics -- --quick`; figures in docs/decisions.md).

use rayon::prelude::*;

use crate::error::QualityError;
use crate::image8::{check_same, Image8};
use crate::mask::{check_mask, Mask};

/// Window side in pixels (11).
pub const WINDOW: usize = 11;
/// Gaussian standard deviation of the window, in pixels (1.5).
pub const SIGMA: f64 = 1.5;
/// `K1` of eq. 13's luminance constant (0.01).
pub const K1: f64 = 0.01;
/// `K2` of eq. 13's contrast constant (0.03).
pub const K2: f64 = 0.03;
/// Dynamic range `L` of 8-bit values (255).
pub const L: f64 = 255.0;
/// `C1 = (K1 L)^2 = 6.5025`.
pub const C1: f64 = (K1 * L) * (K1 * L);
/// `C2 = (K2 L)^2 = 58.5225`.
pub const C2: f64 = (K2 * L) * (K2 * L);

const HALF: usize = WINDOW / 2;

/// The normalised 1D Gaussian kernel: `w[k] = exp(-(k - 5)^2 / (2 sigma^2)) / sum`, `k = 0..11`.
pub fn kernel() -> [f64; WINDOW] {
    let mut w: [f64; WINDOW] = std::array::from_fn(|k| {
        let d = k as f64 - HALF as f64;
        (-(d * d) / (2.0 * SIGMA * SIGMA)).exp()
    });
    let s: f64 = w.iter().sum();
    w.iter_mut().for_each(|v| *v /= s);
    w
}

/// SSIM of one window from its local statistics (eq. 13).
pub fn ssim_from_stats(mu_a: f64, mu_b: f64, var_a: f64, var_b: f64, cov_ab: f64) -> f64 {
    ((2.0 * mu_a * mu_b + C1) * (2.0 * cov_ab + C2))
        / ((mu_a * mu_a + mu_b * mu_b + C1) * (var_a + var_b + C2))
}

/// The SSIM map: one value per pixel whose 11x11 window lies inside the image.
#[derive(Clone, Debug)]
pub struct SsimMap {
    width: u32,
    height: u32,
    /// Row-major over the interior `(width - 10) x (height - 10)`.
    values: Vec<f64>,
}

impl SsimMap {
    /// Image width in pixels.
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Image height in pixels.
    pub fn height(&self) -> u32 {
        self.height
    }

    /// The channel-averaged SSIM at pixel `(x, y)`; `None` within 5 pixels of an edge (or outside).
    pub fn get(&self, x: u32, y: u32) -> Option<f64> {
        let (x, y) = (x as usize, y as usize);
        let (w, h) = (self.width as usize, self.height as usize);
        if x < HALF || y < HALF || x + HALF >= w || y + HALF >= h {
            return None;
        }
        Some(self.values[(y - HALF) * (w - 2 * HALF) + (x - HALF)])
    }

    /// Mean over the pixels `mask` selects (`None`: all) that have a value.
    ///
    /// # Errors
    /// [`QualityError::SizeMismatch`], [`QualityError::EmptyMask`] when no selected pixel has one.
    pub fn mean(&self, mask: Option<&Mask>) -> Result<f64, QualityError> {
        check_mask(mask, (self.width, self.height))?;
        let mut sum = 0.0;
        let mut n = 0usize;
        for y in HALF as u32..self.height.saturating_sub(HALF as u32) {
            for x in HALF as u32..self.width.saturating_sub(HALF as u32) {
                if mask.is_none_or(|m| m.get(x, y)) {
                    sum += self.get(x, y).expect("interior");
                    n += 1;
                }
            }
        }
        if n == 0 {
            return Err(QualityError::EmptyMask {
                what: "SSIM (no selected pixel at least 5 from the image edge)",
            });
        }
        Ok(sum / n as f64)
    }
}

/// Horizontal 'valid' pass of the five moments of one channel: rows of `w - 10` values each.
fn horizontal(a: &Image8, b: &Image8, c: usize, k: &[f64; WINDOW]) -> Vec<[f64; 5]> {
    let (w, h) = (a.width() as usize, a.height() as usize);
    let ow = w - 2 * HALF;
    let mut out = vec![[0.0; 5]; ow * h];
    out.par_chunks_mut(ow).enumerate().for_each(|(y, row)| {
        let ra = &a.pixels()[y * w..(y + 1) * w];
        let rb = &b.pixels()[y * w..(y + 1) * w];
        for (x, o) in row.iter_mut().enumerate() {
            let mut m = [0.0; 5];
            for (t, &wt) in k.iter().enumerate() {
                let va = f64::from(ra[x + t][c]);
                let vb = f64::from(rb[x + t][c]);
                m[0] += wt * va;
                m[1] += wt * vb;
                m[2] += wt * va * va;
                m[3] += wt * vb * vb;
                m[4] += wt * va * vb;
            }
            *o = m;
        }
    });
    out
}

/// The SSIM map of `a` against `b` (module docs: per channel, averaged; 'valid' windows).
///
/// # Errors
/// [`QualityError::SizeMismatch`]; [`QualityError::EmptyMask`] when a side is under 11 pixels
/// (no window fits).
pub fn ssim_map(a: &Image8, b: &Image8) -> Result<SsimMap, QualityError> {
    check_same(a.size(), b.size())?;
    let (w, h) = (a.width() as usize, a.height() as usize);
    if w < WINDOW || h < WINDOW {
        return Err(QualityError::EmptyMask {
            what: "SSIM (image smaller than the 11x11 window)",
        });
    }
    let k = kernel();
    let (ow, oh) = (w - 2 * HALF, h - 2 * HALF);
    let mut values = vec![0.0; ow * oh];
    for c in 0..3 {
        let hp = horizontal(a, b, c, &k);
        values.par_chunks_mut(ow).enumerate().for_each(|(y, row)| {
            for (x, v) in row.iter_mut().enumerate() {
                let mut m = [0.0; 5];
                for (t, &wt) in k.iter().enumerate() {
                    let s = &hp[(y + t) * ow + x];
                    for q in 0..5 {
                        m[q] += wt * s[q];
                    }
                }
                let (mu_a, mu_b) = (m[0], m[1]);
                let s = ssim_from_stats(
                    mu_a,
                    mu_b,
                    m[2] - mu_a * mu_a,
                    m[3] - mu_b * mu_b,
                    m[4] - mu_a * mu_b,
                );
                *v += s / 3.0;
            }
        });
    }
    Ok(SsimMap {
        width: a.width(),
        height: a.height(),
        values,
    })
}

/// Mean SSIM (MSSIM, eq. 17) of `b` against `a` over the pixels `mask` selects (`None`: all) that lie
/// at least 5 pixels from every edge. 1 for identical images; symmetric in `a` and `b`.
///
/// # Errors
/// As [`ssim_map`] and [`SsimMap::mean`].
pub fn ssim(a: &Image8, b: &Image8, mask: Option<&Mask>) -> Result<f64, QualityError> {
    check_mask(mask, a.size())?;
    ssim_map(a, b)?.mean(mask)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Direct (non-separable) evaluation of the channel-averaged SSIM at `(x, y)`.
    fn brute(a: &Image8, b: &Image8, x: u32, y: u32) -> f64 {
        let k = kernel();
        let mut total = 0.0;
        for c in 0..3 {
            let (mut ma, mut mb, mut saa, mut sbb, mut sab) = (0.0, 0.0, 0.0, 0.0, 0.0);
            for j in 0..WINDOW {
                for i in 0..WINDOW {
                    let wt = k[i] * k[j];
                    let px = x + i as u32 - HALF as u32;
                    let py = y + j as u32 - HALF as u32;
                    let va = f64::from(a.pixel(px, py).unwrap()[c]);
                    let vb = f64::from(b.pixel(px, py).unwrap()[c]);
                    ma += wt * va;
                    mb += wt * vb;
                    saa += wt * va * va;
                    sbb += wt * vb * vb;
                    sab += wt * va * vb;
                }
            }
            total += ssim_from_stats(ma, mb, saa - ma * ma, sbb - mb * mb, sab - ma * mb);
        }
        total / 3.0
    }

    fn noise(w: u32, h: u32, seed: u32) -> Image8 {
        Image8::from_fn(w, h, |x, y| {
            let mut s = (x.wrapping_mul(73_856_093) ^ y.wrapping_mul(19_349_663) ^ seed)
                .wrapping_mul(2_654_435_761);
            let mut next = || {
                s ^= s << 13;
                s ^= s >> 17;
                s ^= s << 5;
                (s >> 24) as u8
            };
            [next(), next(), next(), 255]
        })
        .unwrap()
    }

    #[test]
    fn constants() {
        assert!((C1 - 6.5025).abs() < 1e-12);
        assert!((C2 - 58.5225).abs() < 1e-12);
        let k = kernel();
        assert!((k.iter().sum::<f64>() - 1.0).abs() < 1e-15);
        assert!((k[5] / k[4] - (1.0 / 4.5f64).exp()).abs() < 1e-12);
    }

    #[test]
    fn identical_is_one() {
        let a = noise(23, 17, 1);
        let s = ssim(&a, &a, None).unwrap();
        assert!((s - 1.0).abs() < 1e-12, "{s}");
    }

    #[test]
    fn constant_offset_by_hand() {
        // Constant images 100 and 110: sigma terms vanish, the structure factor is C2 / C2 = 1 and
        // SSIM = (2 * 100 * 110 + C1) / (100^2 + 110^2 + C1) = 22006.5025 / 22106.5025.
        let a = Image8::filled(16, 12, [100, 100, 100, 255]).unwrap();
        let b = Image8::filled(16, 12, [110, 110, 110, 255]).unwrap();
        let want: f64 = 22_006.502_5 / 22_106.502_5;
        assert!((want - 0.995_476_444_1).abs() < 1e-9);
        let s = ssim(&a, &b, None).unwrap();
        assert!((s - want).abs() < 1e-12, "{s} vs {want}");
    }

    #[test]
    fn black_against_white_by_hand() {
        // mu 0 vs 255, no variance: SSIM = C1 / (255^2 + C1) = 6.5025 / 65031.5025.
        let a = Image8::filled(11, 11, [0, 0, 0, 255]).unwrap();
        let b = Image8::filled(11, 11, [255, 255, 255, 255]).unwrap();
        let s = ssim(&a, &b, None).unwrap();
        assert!((s - 6.5025 / 65_031.502_5).abs() < 1e-15);
    }

    #[test]
    fn offset_keeps_structure() {
        // b = a + 20 (no clipping): sigma_ab = sigma_a^2 = sigma_b^2 so the contrast-structure factor
        // is exactly 1 and SSIM equals the luminance factor of each window.
        let a = Image8::from_fn(15, 15, |x, y| {
            let v = (50 + 7 * x + 5 * y) as u8;
            [v, v / 2, 230 - v, 255]
        })
        .unwrap();
        let b = Image8::from_fn(15, 15, |x, y| {
            let p = a.pixel(x, y).unwrap();
            [p[0] + 20, p[1] + 20, p[2] + 20, 255]
        })
        .unwrap();
        let map = ssim_map(&a, &b).unwrap();
        let k = kernel();
        for (x, y) in [(5, 5), (7, 9), (9, 9)] {
            let mut lum = 0.0;
            for c in 0..3 {
                let mut mu = 0.0;
                for j in 0..WINDOW {
                    for i in 0..WINDOW {
                        mu += k[i]
                            * k[j]
                            * f64::from(a.pixel(x + i as u32 - 5, y + j as u32 - 5).unwrap()[c]);
                    }
                }
                let nu = mu + 20.0;
                lum += (2.0 * mu * nu + C1) / (mu * mu + nu * nu + C1) / 3.0;
            }
            assert!((map.get(x, y).unwrap() - lum).abs() < 1e-9, "({x}, {y})");
        }
    }

    #[test]
    fn separable_equals_brute_force_and_symmetric() {
        let a = noise(19, 14, 7);
        let b = noise(19, 14, 8);
        let ab = ssim_map(&a, &b).unwrap();
        let ba = ssim_map(&b, &a).unwrap();
        for y in 0..14 {
            for x in 0..19 {
                match ab.get(x, y) {
                    Some(v) => {
                        assert!((v - brute(&a, &b, x, y)).abs() < 1e-9, "({x}, {y})");
                        assert!((v - ba.get(x, y).unwrap()).abs() < 1e-12);
                        assert!(v < 0.5); // independent noise is dissimilar
                    }
                    None => assert!(x < 5 || y < 5 || x >= 14 || y >= 9),
                }
            }
        }
        assert!((ssim(&a, &b, None).unwrap() - ssim(&b, &a, None).unwrap()).abs() < 1e-12);
    }

    #[test]
    fn negation_of_pattern_is_negative() {
        // b = 255 - a around mean 127.5: sigma_ab = -sigma^2, so the structure factor is negative.
        let a = noise(13, 13, 3);
        let b = Image8::from_fn(13, 13, |x, y| {
            let p = a.pixel(x, y).unwrap();
            [255 - p[0], 255 - p[1], 255 - p[2], 255]
        })
        .unwrap();
        assert!(ssim(&a, &b, None).unwrap() < -0.5);
    }

    #[test]
    fn mask_and_size_errors() {
        let a = noise(12, 12, 1);
        let b = noise(12, 12, 2);
        // Only the 2x2 interior has values; a mask on the border selects none of them.
        let border = Mask::from_fn(12, 12, |x, _| x == 0).unwrap();
        assert!(matches!(
            ssim(&a, &b, Some(&border)),
            Err(QualityError::EmptyMask { .. })
        ));
        let one = Mask::from_fn(12, 12, |x, y| x == 6 && y == 5).unwrap();
        let m = ssim_map(&a, &b).unwrap();
        assert_eq!(ssim(&a, &b, Some(&one)).unwrap(), m.get(6, 5).unwrap());
        let small = noise(10, 40, 1);
        assert!(matches!(
            ssim(&small, &small, None),
            Err(QualityError::EmptyMask { .. })
        ));
        assert!(matches!(
            ssim(&a, &small, None),
            Err(QualityError::SizeMismatch { .. })
        ));
    }
}
