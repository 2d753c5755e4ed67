//! [`Scores`]: the three numbers a report row carries, computed together.

use crate::band::horizon_band;
use crate::error::QualityError;
use crate::image8::Image8;
use crate::mask::Mask;
use crate::psnr::psnr;
use crate::ssim::ssim;

/// PSNR over the coverage, PSNR over the horizon band and SSIM over the coverage.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Scores {
    /// PSNR in dB over every covered pixel ([`crate::psnr`]); `+inf` when identical there.
    pub psnr_all: f64,
    /// PSNR in dB over the horizon band ([`crate::horizon_band`]).
    pub psnr_band: f64,
    /// Mean SSIM over the covered pixels at least 5 from the image edge ([`crate::ssim()`]).
    pub ssim: f64,
}

impl Scores {
    /// Score `image` against `reference` over `coverage`, with a band `band_rows` deep
    /// (use [`crate::default_band_rows`] for the default).
    ///
    /// # Errors
    /// Size mismatches; [`QualityError::EmptyMask`] when the coverage (or its band, or its
    /// interior for SSIM) is empty.
    pub fn compute(
        reference: &Image8,
        image: &Image8,
        coverage: &Mask,
        band_rows: u32,
    ) -> Result<Scores, QualityError> {
        let band = horizon_band(coverage, band_rows);
        Ok(Scores {
            psnr_all: psnr(reference, image, Some(coverage))?,
            psnr_band: psnr(reference, image, Some(&band))?,
            ssim: ssim(reference, image, Some(coverage))?,
        })
    }
}
