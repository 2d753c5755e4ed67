//! texel-quality: how good is a filtered image against its reference, and the report that says so.
//!
//! - [`psnr`] / [`mse`] / [`psnr_band`]: PSNR over a mask (the geometry's coverage) or the horizon
//!   band, per RGB channel on 8-bit encoded values, peak 255.
//! - [`ssim()`] / [`ssim_map`]: SSIM exactly per Wang et al. 2004 (11x11 Gaussian, sigma 1.5,
//!   K1 = 0.01, K2 = 0.03, L = 255), per RGB channel, averaged.
//! - [`ReferenceError`] / [`block_psnr`]: how sure a score is: the reference's noise floor, PSNR
//!   on block means in linear light, and whether the reference can rank two images.
//! - [`horizon_band`]: the strip just below the horizon, where minification is extreme.
//! - [`heat_map`], [`legend_svg`], [`crop_enlarge`], [`horizon_crop_rect`]: pictures of the error.
//! - [`Report`] / [`FilterRow`]: JSON, Markdown and a self-contained `index.html` with a chart.
//! - [`write_png_atomic`] / [`write_exr_atomic`]: encoded and published through
//!   [`texel_io::write_atomic`] (whole directories: [`texel_io::publish_dir`]), so no output is
//!   truncated by an interruption and only regular files (or new paths) are ever replaced.
//!
//! Decision: quality is measured on the 8-bit display values (sRGB-encoded, or linear bytes under
//! `--color raw`), i.e. exactly what is written to the PNG files and what a person sees, so that
//! anyone can recompute the numbers from the images. A linear `f32` frame is quantised first with
//! [`Image8::from_linear`].
//!
//! ```
//! use texel_quality::{horizon_band, psnr, ssim, Image8, Mask};
//!
//! let reference = Image8::from_fn(32, 24, |x, y| [(x * 8) as u8, (y * 10) as u8, 128, 255])?;
//! let mut pixels = reference.pixels().to_vec();
//! pixels[5 * 32 + 7][0] ^= 16; // one channel of one pixel off by 16
//! let image = Image8::new(32, 24, pixels)?;
//! let covered = Mask::from_fn(32, 24, |_, y| y >= 4)?; // the geometry covers rows 4..24
//!
//! // MSE = 16^2 / (3 * 640) over the 640 covered pixels.
//! let p = psnr(&reference, &image, Some(&covered))?;
//! assert!((p - 10.0 * (255f64 * 255.0 * 3.0 * 640.0 / 256.0).log10()).abs() < 1e-9);
//! // The error sits in row 5, inside an 8-row band below the horizon at row 4.
//! let band = horizon_band(&covered, 8);
//! assert!(band.get(7, 5) && band.count() == 32 * 8);
//! assert!(ssim(&reference, &reference, Some(&covered))? == 1.0);
//! assert!(ssim(&reference, &image, Some(&covered))? < 1.0);
//! # Ok::<(), texel_quality::QualityError>(())
//! ```

mod band;
mod crop;
mod encode;
mod error;
mod flicker;
mod heatmap;
pub mod html;
mod image8;
mod mask;
mod psnr;
mod report;
mod scores;
mod size;
pub mod ssim;
mod uncertainty;

pub use size::MAX_SIDE;

pub use band::{default_band_rows, horizon_band};
pub use crop::{crop_enlarge, horizon_crop_rect, Rect};
pub use encode::{
    encode_exr, encode_exr_with_text, png_with_text, write_exr_atomic, write_png_atomic,
};
pub use error::QualityError;
pub use flicker::{excess_change, mean_abs_change};
pub use heatmap::{error_map, heat_map, legend_image, legend_svg, viridis, OUTSIDE, VIRIDIS};
pub use image8::{Encoding, Image8};
pub use mask::Mask;
pub use psnr::{mse, psnr, psnr_band, psnr_from_mse, psnr_linear, PEAK};
pub use report::{FilterRow, Orbit, ReferenceSummary, Report};
pub use scores::Scores;
pub use ssim::{ssim, ssim_map, SsimMap};
pub use uncertainty::{block_psnr, MseDifference, ReferenceError, DEFAULT_BLOCK, Z_975};
