//! Command-line interface: every command, flag and its help text (clap derive).

use std::path::PathBuf;

use clap::{Args, Parser, Subcommand, ValueEnum};

use crate::filters::FilterName;

/// texel: texture mapping and texture filtering on the CPU, measured.
#[derive(Debug, Parser)]
#[command(name = "texel", version, about, long_about = None, propagate_version = true)]
pub struct Cli {
    /// The command to run.
    #[command(subcommand)]
    pub command: Command,
}

/// The commands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Perspective-warp an image without aliasing: the output's corners show four source points.
    ///
    /// Example: texel warp photo.jpg --corners 0,0,4000,300,4000,2700,0,3000 --size 800x600 -o out.png
    Warp(WarpArgs),
    /// Write every mip level of a texture, and one image of the whole chain.
    ///
    /// Example: texel mips brick.png --out mips/
    Mips(MipsArgs),
}

/// How 8-bit texture bytes and output bytes are interpreted.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, ValueEnum)]
pub enum ColorArg {
    /// Textures marked sRGB are decoded to linear light for filtering; output is sRGB-encoded.
    #[default]
    Srgb,
    /// Every texture's bytes are linear; output bytes are linear (as a GPU sampling plain RGBA8).
    Raw,
}

/// Output size `WIDTHxHEIGHT`, each side 1 to 16384.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Size {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
}

/// Largest output side accepted (pixels).
pub const MAX_SIDE: u32 = 16384;

impl std::str::FromStr for Size {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        let (w, h) = s
            .split_once(['x', 'X'])
            .ok_or_else(|| format!("size {s:?} is not WIDTHxHEIGHT (e.g. 640x360)"))?;
        let side = |t: &str| -> Result<u32, String> {
            let v: u32 = t.trim().parse().map_err(|_| format!("size {s:?}: {t:?} is not a whole number"))?;
            if v == 0 || v > MAX_SIDE {
                return Err(format!("size {s:?}: each side must be between 1 and {MAX_SIDE}"));
            }
            Ok(v)
        };
        Ok(Size {
            width: side(w)?,
            height: side(h)?,
        })
    }
}

/// `texel warp`.
#[derive(Debug, Args)]
pub struct WarpArgs {
    /// Source image (PNG, JPEG or OpenEXR).
    pub input: PathBuf,
    /// Source pixel positions shown at the output's top-left, top-right, bottom-right and
    /// bottom-left corners: x0,y0,x1,y1,x2,y2,x3,y3 (pixels; (0,0) is the source's top-left corner).
    #[arg(long, value_delimiter = ',', num_args = 8, required = true, allow_negative_numbers = true)]
    pub corners: Vec<f64>,
    /// Output size; defaults to the source size.
    #[arg(long)]
    pub size: Option<Size>,
    /// Texture filter.
    #[arg(long, default_value = "ewa")]
    pub filter: FilterName,
    /// Colour handling.
    #[arg(long, value_enum, default_value_t)]
    pub color: ColorArg,
    /// Output PNG.
    #[arg(short, long)]
    pub output: PathBuf,
}

/// `texel mips`.
#[derive(Debug, Args)]
pub struct MipsArgs {
    /// The texture (PNG, JPEG or OpenEXR).
    pub texture: PathBuf,
    /// Colour handling: srgb averages in linear light, raw averages the bytes.
    #[arg(long, value_enum, default_value_t)]
    pub color: ColorArg,
    /// Output directory (created if missing).
    #[arg(long)]
    pub out: PathBuf,
}
