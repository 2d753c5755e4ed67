//! `texel mips`: every level of a texture's pyramid, and one image of the whole chain.
//!
//! Memory: the texture loads within what `--max-memory` leaves (see [`texel::texture::Limits`]);
//! then each level is encoded straight from the pyramid to an 8-bit image and written before the
//! next (4 bytes per pixel plus the encoder's copies, [`ENCODE_BYTES_PER_PIXEL`]), and the chain
//! likewise. The directory is published as a whole ([`texel_io::publish_dir`]).

use anyhow::{Context, Result};
use texel::quality::{Image8, MAX_SIDE};
use texel::texture::Texture;
use texel_io::publish_dir;

use crate::cli::MipsArgs;
use crate::input::Input;
use crate::output::write_image;

/// What writing one image holds per pixel: the 8-bit image (4), its RGBA bytes for the encoder
/// (4) and the PNG (at most about 4 plus headers), rounded up.
pub(crate) const ENCODE_BYTES_PER_PIXEL: u64 = 16;

/// Run `texel mips`.
pub(crate) fn run(args: &MipsArgs, input: &mut Input) -> Result<()> {
    let options = input.texture_options(args.color);
    let loaded = Texture::load_with(&args.texture, &options)
        .map_err(|e| input.explain(e.into()))
        .with_context(|| format!("cannot load texture {}", args.texture.display()))?;
    input.warn_replaced(&args.texture.display().to_string(), loaded.replaced);
    let tex = loaded.texture;
    input.budget.take("the pyramid", tex.pyramid_bytes())?;
    let levels = tex.levels().to_vec();
    // The classic layout: level 0 on the left, levels 1.. stacked top to bottom to its right. For
    // wide textures the stack (whose last levels are 1 row each) can be taller than level 0.
    let (w0, h0) = (levels[0].width, levels[0].height);
    let right = levels.get(1).map_or(0, |l| l.width);
    let stack: u32 = levels.iter().skip(1).map(|l| l.height).sum();
    let (cw, ch) = (w0 + right, h0.max(stack));
    let chain_fits = cw <= MAX_SIDE && ch <= MAX_SIDE;
    let largest = if chain_fits {
        u64::from(cw) * u64::from(ch)
    } else {
        u64::from(w0) * u64::from(h0)
    };
    input
        .budget
        .take("encoding the levels", largest * ENCODE_BYTES_PER_PIXEL)?;
    let enc = args.color.encoding();
    publish_dir(&args.out, &[args.texture.as_path()], |dir| -> Result<()> {
        for (k, l) in levels.iter().enumerate() {
            let image = Image8::from_fn(l.width, l.height, |i, j| {
                enc.encode(tex.texel(k, i, j).unwrap_or_default())
            })?;
            let name = format!("level-{k:02}-{}x{}.png", l.width, l.height);
            write_image(&dir.join(name), &image)?;
        }
        if chain_fits {
            let chain = Image8::from_fn(cw, ch, |x, y| {
                let (k, i, j) = if x < w0 {
                    (0, x, y)
                } else {
                    // Find the stacked level holding row y.
                    let mut y0 = 0;
                    let mut at = None;
                    for (k, l) in levels.iter().enumerate().skip(1) {
                        if y < y0 + l.height {
                            at = Some((k, x - w0, y - y0));
                            break;
                        }
                        y0 += l.height;
                    }
                    match at {
                        Some(a) => a,
                        None => return [0; 4],
                    }
                };
                tex.texel(k, i, j).map_or([0; 4], |c| enc.encode(c))
            })?;
            write_image(&dir.join("chain.png"), &chain)?;
        }
        Ok(())
    })
    .with_context(|| format!("cannot write the levels to {}", args.out.display()))?;
    if !chain_fits {
        texel_io::stderr_line(format_args!(
            "texel mips: chain.png skipped: the chain would be {cw}x{ch}, over {MAX_SIDE} pixels per side"
        ));
    }
    texel_io::stderr_line(format_args!(
        "wrote {} levels ({} bytes of pyramid){} to {}",
        levels.len(),
        tex.pyramid_bytes(),
        if chain_fits { " and chain.png" } else { "" },
        args.out.display()
    ));
    Ok(())
}
