//! `texel warp`: a perspective warp of an image through a homography, filtered with the exact
//! per-pixel footprint.

use anyhow::{Context, Result};
use glam::DVec2;
use texel_texture::warp::{warp_perspective, WarpError};
use texel_texture::{AddressMode, ColorSpace, Limits, Sampler, Texture};

use crate::cli::{ColorArg, WarpArgs};
use crate::output::write_png;

/// Run `texel warp`.
pub fn run(args: &WarpArgs) -> Result<()> {
    let color = match args.color {
        ColorArg::Srgb => ColorSpace::Srgb,
        ColorArg::Raw => ColorSpace::Linear,
    };
    let tex = Texture::load(&args.input, color, &Limits::default())
        .with_context(|| format!("cannot load image {}", args.input.display()))?;
    let c = &args.corners.0;
    let corners = [0, 2, 4, 6].map(|k| DVec2::new(c[k], c[k + 1]));
    let (w, h) = args
        .size
        .map_or((tex.width(), tex.height()), |s| (s.width, s.height));
    let mut desc = args
        .filter
        .descriptor(AddressMode::ClampToBorder, AddressMode::ClampToBorder)?;
    desc.border_color = texel_texture::BorderColor::TransparentBlack;
    let sampler = Sampler::new(desc)?;
    let pixels = warp_perspective(&tex, &sampler, corners, w, h).map_err(|e| {
        let what = match e {
            WarpError::InvalidSize { .. } => "invalid --size",
            _ => "invalid --corners",
        };
        anyhow::Error::new(e).context(what)
    })?;
    write_png(&args.output, w, h, &pixels, args.color)
}
