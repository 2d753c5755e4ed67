//! Debug views: what a pixel shows instead of its shaded colour.
//!
//! Each view defines a *displayed* colour (what an 8-bit sRGB image of it shows, e.g. red byte =
//! `fract(u) * 255` in the uv view); the frame stores its linear equivalent (`srgb_to_linear` of the
//! displayed value) so that the ordinary sRGB encoding of [`crate::Frame::to_srgb8`] shows exactly the
//! displayed value. Scales are fixed, not normalised per image, so images are comparable.
//!
//! - uv: `(fract(u), fract(v), 0)`, with `u`, `v` the footprint's `f32` uv handed to the sampler
//!   (reduced by whole periods of the address mode, which leaves `fract` unchanged: periods are
//!   whole numbers).
//! - mip: [`MIP_PALETTE`]`[level]`, `level` = the nearest-level rule `ceil(lod + 1/2) - 1` clamped to
//!   the pyramid (the level `*_MIPMAP_NEAREST` reads), `lod` from `Sampler::lod`.
//! - lod: the palette interpolated linearly between `floor(lod)` and `floor(lod) + 1`.
//! - aniso: `ratio = |Pmax| / |Pmin|` (conventions), `t = log2(ratio) / 4` (1x .. 16x) on [`ramp`];
//!   a zero minor axis counts as infinite ratio.
//! - fetches: texels read `n`, `t = log2(1 + n) / 10` on [`ramp`] (`n = 1023` is the top).
//! - barycentric: `(lambda_0, lambda_1, lambda_2)` clamped to `[0, 1]`.

use glam::DVec3;
use texel_texture::base::color::srgb_to_linear;
use texel_texture::technique::mip::nearest_level;
use texel_texture::{Footprint, Sampler, Texture};

/// One displayed (sRGB 8-bit) colour per mip level, cycling after 16 levels.
pub const MIP_PALETTE: [[u8; 3]; 16] = [
    [230, 25, 75],   // 0 red
    [245, 130, 48],  // 1 orange
    [255, 225, 25],  // 2 yellow
    [60, 180, 75],   // 3 green
    [70, 240, 240],  // 4 cyan
    [0, 130, 200],   // 5 blue
    [145, 30, 180],  // 6 purple
    [240, 50, 230],  // 7 magenta
    [250, 250, 250], // 8 white
    [128, 128, 128], // 9 grey
    [170, 110, 40],  // 10 brown
    [0, 128, 128],   // 11 teal
    [0, 0, 128],     // 12 navy
    [250, 190, 212], // 13 pink
    [128, 128, 0],   // 14 olive
    [40, 40, 40],    // 15 near black
];

/// Stops of the heat ramp (displayed sRGB 8-bit), a five-stop approximation of Google's Turbo
/// colour map: dark violet, blue, cyan-green, orange, dark red.
pub const RAMP_STOPS: [[u8; 3]; 5] = [
    [48, 18, 59],
    [70, 134, 251],
    [26, 228, 182],
    [250, 186, 57],
    [122, 4, 3],
];

/// A displayed colour in `[0, 1]` to the linear RGBA stored in a frame (opaque).
#[inline]
pub fn displayed(rgb: [f32; 3]) -> [f32; 4] {
    [
        srgb_to_linear(rgb[0].clamp(0.0, 1.0)),
        srgb_to_linear(rgb[1].clamp(0.0, 1.0)),
        srgb_to_linear(rgb[2].clamp(0.0, 1.0)),
        1.0,
    ]
}

fn byte_color(c: [u8; 3]) -> [f32; 3] {
    c.map(|b| f32::from(b) / 255.0)
}

fn lerp3(a: [f32; 3], b: [f32; 3], t: f32) -> [f32; 3] {
    std::array::from_fn(|k| a[k] * (1.0 - t) + b[k] * t)
}

/// The heat ramp at `t` in `[0, 1]` (clamped; NaN gives the top), as a displayed colour.
pub fn ramp(t: f32) -> [f32; 3] {
    let t = if t.is_nan() { 1.0 } else { t.clamp(0.0, 1.0) };
    let s = t * (RAMP_STOPS.len() - 1) as f32;
    let k = (s.floor() as usize).min(RAMP_STOPS.len() - 2);
    lerp3(
        byte_color(RAMP_STOPS[k]),
        byte_color(RAMP_STOPS[k + 1]),
        s - k as f32,
    )
}

/// The uv view of `(u, v)`.
pub fn uv_color(u: f64, v: f64) -> [f32; 4] {
    displayed([(u - u.floor()) as f32, (v - v.floor()) as f32, 0.0])
}

/// The mip-level view: the palette colour of the level the nearest-level rule reads.
pub fn mip_color(sampler: &Sampler, texture: &Texture, fp: &Footprint) -> [f32; 4] {
    let last = texture.levels().len() - 1;
    let level = nearest_level(sampler.lod(texture, fp), last);
    displayed(byte_color(MIP_PALETTE[level % MIP_PALETTE.len()]))
}

/// The continuous lod view: the palette interpolated at `lod` clamped to `[0, last level]`.
pub fn lod_color(sampler: &Sampler, texture: &Texture, fp: &Footprint) -> [f32; 4] {
    let last = (texture.levels().len() - 1) as f32;
    let lod = sampler.lod(texture, fp).clamp(0.0, last);
    let k = lod.floor();
    let n = MIP_PALETTE.len();
    let a = byte_color(MIP_PALETTE[k as usize % n]);
    let b = byte_color(MIP_PALETTE[(k as usize + 1) % n]);
    displayed(lerp3(a, b, lod - k))
}

/// The footprint's anisotropy ratio `|Pmax| / |Pmin|` in texels of level 0 (`+inf` for a degenerate
/// minor axis, NaN for non-finite derivatives).
pub fn anisotropy(texture: &Texture, fp: &Footprint) -> f32 {
    let axes = fp.axes(texture.width(), texture.height());
    axes.major.length() / axes.minor.length()
}

/// The anisotropy view.
pub fn aniso_color(texture: &Texture, fp: &Footprint) -> [f32; 4] {
    let ratio = anisotropy(texture, fp);
    let t = if ratio.is_nan() {
        1.0
    } else {
        ratio.log2() / 4.0
    };
    displayed(ramp(t))
}

/// The fetches view of `texels` read.
pub fn fetches_color(texels: u32) -> [f32; 4] {
    displayed(ramp((1.0 + texels as f32).log2() / 10.0))
}

/// The barycentric view.
pub fn barycentric_color(lambda: DVec3) -> [f32; 4] {
    displayed(lambda.as_vec3().to_array())
}

#[cfg(test)]
mod tests {
    use super::*;
    use texel_texture::base::color::linear_to_srgb8;

    fn shown(c: [f32; 4]) -> [u8; 3] {
        [
            linear_to_srgb8(c[0]),
            linear_to_srgb8(c[1]),
            linear_to_srgb8(c[2]),
        ]
    }

    #[test]
    fn displayed_values_survive_encoding() {
        assert_eq!(shown(uv_color(2.25, -0.25)), [64, 191, 0]);
        assert_eq!(
            shown(barycentric_color(DVec3::new(1.0, 0.0, 0.5))),
            [255, 0, 128]
        );
        assert_eq!(shown(fetches_color(0)), RAMP_STOPS[0]);
        assert_eq!(shown(fetches_color(1023)), RAMP_STOPS[4]);
    }

    #[test]
    fn ramp_ends_and_middle() {
        assert_eq!(ramp(-1.0), byte_color(RAMP_STOPS[0]));
        assert_eq!(ramp(0.5), byte_color(RAMP_STOPS[2]));
        assert_eq!(ramp(f32::NAN), byte_color(RAMP_STOPS[4]));
    }
}
