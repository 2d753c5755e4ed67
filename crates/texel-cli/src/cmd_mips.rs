//! `texel mips`: every level of a texture's pyramid, and one image of the whole chain.

use anyhow::{Context, Result};
use texel_texture::{ColorSpace, Limits, Texture};

use crate::cli::{ColorArg, MipsArgs};
use crate::output::write_png;

/// Run `texel mips`.
pub fn run(args: &MipsArgs) -> Result<()> {
    let color = match args.color {
        ColorArg::Srgb => ColorSpace::Srgb,
        ColorArg::Raw => ColorSpace::Linear,
    };
    let tex = Texture::load(&args.texture, color, &Limits::default())
        .with_context(|| format!("cannot load texture {}", args.texture.display()))?;
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("cannot create {}", args.out.display()))?;
    let levels = tex.levels();
    for (k, l) in levels.iter().enumerate() {
        let pixels: Vec<[f32; 4]> = (0..l.height)
            .flat_map(|j| (0..l.width).map(move |i| (i, j)))
            .map(|(i, j)| tex.texel(k, i, j).expect("in range"))
            .collect();
        let path = args
            .out
            .join(format!("level-{k:02}-{}x{}.png", l.width, l.height));
        write_png(&path, l.width, l.height, &pixels, args.color)?;
    }
    // The classic layout: level 0 on the left, levels 1.. stacked top to bottom to its right. For
    // wide textures the stack (whose last levels are 1 row each) can be taller than level 0.
    let (w0, h0) = (levels[0].width, levels[0].height);
    let right = levels.get(1).map_or(0, |l| l.width);
    let stack: u32 = levels.iter().skip(1).map(|l| l.height).sum();
    let (cw, ch) = (w0 + right, h0.max(stack));
    let mut chain = vec![[0.0f32; 4]; cw as usize * ch as usize];
    let mut y0 = 0u32;
    for (k, l) in levels.iter().enumerate() {
        let (x0, oy) = if k == 0 { (0, 0) } else { (w0, y0) };
        for j in 0..l.height {
            for i in 0..l.width {
                chain[((oy + j) * cw + x0 + i) as usize] = tex.texel(k, i, j).expect("in range");
            }
        }
        if k > 0 {
            y0 += l.height;
        }
    }
    write_png(&args.out.join("chain.png"), cw, ch, &chain, args.color)?;
    eprintln!(
        "wrote {} levels ({} bytes of pyramid) and chain.png to {}",
        levels.len(),
        tex.pyramid_bytes(),
        args.out.display()
    );
    Ok(())
}
