//! `texel warp`: a perspective warp of an image through a homography, filtered with the exact
//! per-pixel footprint.
//!
//! The output size (`--size`, else the source's) is checked from the image header before the
//! pixels are decoded, so a size error names its cause at once.

use anyhow::{bail, Context, Result};
use glam::DVec2;
use texel::raster::{warp_perspective, WarpError, MAX_WARP_PIXELS};
use texel::texture::{AddressMode, Sampler, Texture};

use crate::cli::WarpArgs;
use crate::input::Input;
use crate::output::write_linear;
use texel::memory::FRAME_BYTES_PER_PIXEL;

/// Run `texel warp`.
pub(crate) fn run(args: &WarpArgs, input: &mut Input) -> Result<()> {
    if let Some(s) = args.size {
        let pixels = u64::from(s.width) * u64::from(s.height);
        if pixels > MAX_WARP_PIXELS {
            bail!(
                "invalid --size {}x{}: {pixels} pixels, over the warp's limit of {MAX_WARP_PIXELS}",
                s.width,
                s.height
            );
        }
    }
    crate::output::check_outputs(&[("-o", &args.output)])?;
    let cannot = || format!("cannot load image {}", args.input.display());
    let bytes =
        texel_io::read_regular(&args.input, input.budget.remaining()).with_context(cannot)?;
    let (sw, sh, _) = Texture::header(&bytes).with_context(cannot)?;
    let (w, h) = match args.size {
        Some(s) => (s.width, s.height),
        None => {
            if u64::from(sw) * u64::from(sh) > MAX_WARP_PIXELS {
                bail!(
                    "the source is {sw}x{sh} and no --size was given, so the output would be {sw}x{sh}, over {MAX_WARP_PIXELS} pixels: pass a smaller --size"
                );
            }
            (sw, sh)
        }
    };
    input.budget.take(
        &format!("the {w}x{h} output"),
        u64::from(w) * u64::from(h) * FRAME_BYTES_PER_PIXEL,
    )?;
    let options = input.texture_options(args.color);
    let loaded = Texture::decode_with(&bytes, &options)
        .map_err(|e| input.explain(e.into()))
        .with_context(cannot)?;
    drop(bytes);
    input.warn_replaced(&args.input.display().to_string(), loaded.replaced);
    let tex = loaded.texture;
    let c = &args.corners.0;
    let corners = [0, 2, 4, 6].map(|k| DVec2::new(c[k], c[k + 1]));
    let mut desc = args
        .filter
        .descriptor(AddressMode::ClampToBorder, AddressMode::ClampToBorder);
    desc.border_color = texel::texture::BorderColor::TransparentBlack;
    let sampler = Sampler::new(desc)?;
    let pixels = warp_perspective(&tex, &sampler, corners, w, h).map_err(|e| {
        let what = match e {
            WarpError::InvalidSize { .. } => "invalid --size",
            _ => "invalid --corners",
        };
        anyhow::Error::new(e).context(what)
    })?;
    write_linear(&args.output, w, h, &pixels, args.color)
}
