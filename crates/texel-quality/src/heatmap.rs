//! Error heat maps with a perceptual colour ramp, and their legend.
//!
//! Per-pixel error: the mean absolute difference over R, G, B of the 8-bit encoded values
//! (`(|dr| + |dg| + |db|) / 3`, in `[0, 255]`). It is mapped linearly onto the viridis ramp, 0 at
//! the dark-purple end and `max_error` (and anything above it) at the yellow end; pixels outside the
//! mask are black, which viridis never produces. A fixed `max_error` for every filter of a report makes
//! their heat maps comparable (the CLI default is a report-wide choice; 32 suits 8-bit errors).
//!
//! Ramp: viridis, by Stéfan van der Walt, Nathaniel Smith and Eric Firing (2015), designed to be
//! perceptually uniform and readable in greyscale and by colour-blind viewers. [`VIRIDIS`] is
//! matplotlib's `_viridis_data` (`lib/matplotlib/_cm_listed.py`, released CC0) quantised to 8 bits.
//! Generated from matplotlib 3.11.2 by:
//!
//! ```text
//! data = matplotlib._cm_listed._viridis_data            # 256 sRGB triples in [0, 1]
//! rows = [[round(255 * c) for c in rgb] for rgb in data]
//! ```

use crate::error::QualityError;
use crate::image8::{check_same, Image8};
use crate::mask::{check_mask, Mask};

/// Colour of pixels outside the mask in a heat map (black; viridis never reaches it).
pub const OUTSIDE: [u8; 4] = [0, 0, 0, 255];

/// The viridis colour map, 256 sRGB 8-bit entries from dark purple (0) to yellow (255).
/// Source and generating code: module docs.
#[rustfmt::skip]
pub const VIRIDIS: [[u8; 3]; 256] = [
    [68, 1, 84], [68, 2, 86], [69, 4, 87], [69, 5, 89], [70, 7, 90], [70, 8, 92], [70, 10, 93], [70, 11, 94],
    [71, 13, 96], [71, 14, 97], [71, 16, 99], [71, 17, 100], [71, 19, 101], [72, 20, 103], [72, 22, 104], [72, 23, 105],
    [72, 24, 106], [72, 26, 108], [72, 27, 109], [72, 28, 110], [72, 29, 111], [72, 31, 112], [72, 32, 113], [72, 33, 115],
    [72, 35, 116], [72, 36, 117], [72, 37, 118], [72, 38, 119], [72, 40, 120], [72, 41, 121], [71, 42, 122], [71, 44, 122],
    [71, 45, 123], [71, 46, 124], [71, 47, 125], [70, 48, 126], [70, 50, 126], [70, 51, 127], [70, 52, 128], [69, 53, 129],
    [69, 55, 129], [69, 56, 130], [68, 57, 131], [68, 58, 131], [68, 59, 132], [67, 61, 132], [67, 62, 133], [66, 63, 133],
    [66, 64, 134], [66, 65, 134], [65, 66, 135], [65, 68, 135], [64, 69, 136], [64, 70, 136], [63, 71, 136], [63, 72, 137],
    [62, 73, 137], [62, 74, 137], [62, 76, 138], [61, 77, 138], [61, 78, 138], [60, 79, 138], [60, 80, 139], [59, 81, 139],
    [59, 82, 139], [58, 83, 139], [58, 84, 140], [57, 85, 140], [57, 86, 140], [56, 88, 140], [56, 89, 140], [55, 90, 140],
    [55, 91, 141], [54, 92, 141], [54, 93, 141], [53, 94, 141], [53, 95, 141], [52, 96, 141], [52, 97, 141], [51, 98, 141],
    [51, 99, 141], [50, 100, 142], [50, 101, 142], [49, 102, 142], [49, 103, 142], [49, 104, 142], [48, 105, 142], [48, 106, 142],
    [47, 107, 142], [47, 108, 142], [46, 109, 142], [46, 110, 142], [46, 111, 142], [45, 112, 142], [45, 113, 142], [44, 113, 142],
    [44, 114, 142], [44, 115, 142], [43, 116, 142], [43, 117, 142], [42, 118, 142], [42, 119, 142], [42, 120, 142], [41, 121, 142],
    [41, 122, 142], [41, 123, 142], [40, 124, 142], [40, 125, 142], [39, 126, 142], [39, 127, 142], [39, 128, 142], [38, 129, 142],
    [38, 130, 142], [38, 130, 142], [37, 131, 142], [37, 132, 142], [37, 133, 142], [36, 134, 142], [36, 135, 142], [35, 136, 142],
    [35, 137, 142], [35, 138, 141], [34, 139, 141], [34, 140, 141], [34, 141, 141], [33, 142, 141], [33, 143, 141], [33, 144, 141],
    [33, 145, 140], [32, 146, 140], [32, 146, 140], [32, 147, 140], [31, 148, 140], [31, 149, 139], [31, 150, 139], [31, 151, 139],
    [31, 152, 139], [31, 153, 138], [31, 154, 138], [30, 155, 138], [30, 156, 137], [30, 157, 137], [31, 158, 137], [31, 159, 136],
    [31, 160, 136], [31, 161, 136], [31, 161, 135], [31, 162, 135], [32, 163, 134], [32, 164, 134], [33, 165, 133], [33, 166, 133],
    [34, 167, 133], [34, 168, 132], [35, 169, 131], [36, 170, 131], [37, 171, 130], [37, 172, 130], [38, 173, 129], [39, 173, 129],
    [40, 174, 128], [41, 175, 127], [42, 176, 127], [44, 177, 126], [45, 178, 125], [46, 179, 124], [47, 180, 124], [49, 181, 123],
    [50, 182, 122], [52, 182, 121], [53, 183, 121], [55, 184, 120], [56, 185, 119], [58, 186, 118], [59, 187, 117], [61, 188, 116],
    [63, 188, 115], [64, 189, 114], [66, 190, 113], [68, 191, 112], [70, 192, 111], [72, 193, 110], [74, 193, 109], [76, 194, 108],
    [78, 195, 107], [80, 196, 106], [82, 197, 105], [84, 197, 104], [86, 198, 103], [88, 199, 101], [90, 200, 100], [92, 200, 99],
    [94, 201, 98], [96, 202, 96], [99, 203, 95], [101, 203, 94], [103, 204, 92], [105, 205, 91], [108, 205, 90], [110, 206, 88],
    [112, 207, 87], [115, 208, 86], [117, 208, 84], [119, 209, 83], [122, 209, 81], [124, 210, 80], [127, 211, 78], [129, 211, 77],
    [132, 212, 75], [134, 213, 73], [137, 213, 72], [139, 214, 70], [142, 214, 69], [144, 215, 67], [147, 215, 65], [149, 216, 64],
    [152, 216, 62], [155, 217, 60], [157, 217, 59], [160, 218, 57], [162, 218, 55], [165, 219, 54], [168, 219, 52], [170, 220, 50],
    [173, 220, 48], [176, 221, 47], [178, 221, 45], [181, 222, 43], [184, 222, 41], [186, 222, 40], [189, 223, 38], [192, 223, 37],
    [194, 223, 35], [197, 224, 33], [200, 224, 32], [202, 225, 31], [205, 225, 29], [208, 225, 28], [210, 226, 27], [213, 226, 26],
    [216, 226, 25], [218, 227, 25], [221, 227, 24], [223, 227, 24], [226, 228, 24], [229, 228, 25], [231, 228, 25], [234, 229, 26],
    [236, 229, 27], [239, 229, 28], [241, 229, 29], [244, 230, 30], [246, 230, 32], [248, 230, 33], [251, 231, 35], [253, 231, 37],
];

/// The viridis colour at `t` in `[0, 1]` (clamped; NaN gives the 0 end): entry `round(255 t)`.
pub fn viridis(t: f32) -> [u8; 3] {
    let i = (t.clamp(0.0, 1.0) * 255.0 + 0.5) as usize; // NaN -> 0
    VIRIDIS[i.min(255)]
}

/// Per-pixel mean absolute RGB error of `b` against `a`, in 8-bit units `[0, 255]`, row-major.
///
/// # Errors
/// [`QualityError::SizeMismatch`].
pub fn error_map(a: &Image8, b: &Image8) -> Result<Vec<f32>, QualityError> {
    check_same(a.size(), b.size())?;
    Ok(a.pixels()
        .iter()
        .zip(b.pixels())
        .map(|(pa, pb)| {
            let s: u32 = (0..3).map(|c| u32::from(pa[c].abs_diff(pb[c]))).sum();
            s as f32 / 3.0
        })
        .collect())
}

/// The heat map of `b`'s error against `a`: [`error_map`] / `max_error` through [`viridis`] inside
/// `mask` (`None`: everywhere), [`OUTSIDE`] elsewhere. Opaque.
///
/// # Errors
/// [`QualityError::InvalidScale`] unless `max_error` is finite and > 0; size mismatches.
pub fn heat_map(
    a: &Image8,
    b: &Image8,
    mask: Option<&Mask>,
    max_error: f32,
) -> Result<Image8, QualityError> {
    if !(max_error.is_finite() && max_error > 0.0) {
        return Err(QualityError::InvalidScale(max_error));
    }
    check_mask(mask, a.size())?;
    let err = error_map(a, b)?;
    let px = err
        .iter()
        .enumerate()
        .map(|(i, &e)| {
            if mask.is_none_or(|m| m.bits()[i]) {
                let [r, g, b] = viridis(e / max_error);
                [r, g, b, 255]
            } else {
                OUTSIDE
            }
        })
        .collect();
    Image8::new(a.width(), a.height(), px)
}

/// A horizontal legend strip `width x height`: column `x` shows `viridis((x + 0.5) / width)`.
///
/// # Errors
/// Size errors of [`Image8::new`].
pub fn legend_image(width: u32, height: u32) -> Result<Image8, QualityError> {
    Image8::from_fn(width, height, |x, _| {
        let [r, g, b] = viridis((x as f32 + 0.5) / width as f32);
        [r, g, b, 255]
    })
}

/// A self-contained SVG legend, `width` pixels wide: the viridis ramp as a linear gradient with
/// 17 stops and tick labels at 0, 1/4, 1/2, 3/4 and 1 of `max_error` (8-bit error units), the last
/// one marked "≥". `max_error` should be finite and > 0 (others are drawn as 0..1).
pub fn legend_svg(max_error: f32, width: u32) -> String {
    let max = if max_error.is_finite() && max_error > 0.0 {
        max_error
    } else {
        1.0
    };
    let w = width.max(60);
    let bar = w - 20;
    let mut s = format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w}\" height=\"44\" viewBox=\"0 0 {w} 44\" role=\"img\" aria-label=\"error scale\">\n<defs><linearGradient id=\"viridis\" x1=\"0\" x2=\"1\" y1=\"0\" y2=\"0\">\n"
    );
    for k in 0..=16 {
        let t = k as f32 / 16.0;
        let [r, g, b] = viridis(t);
        s += &format!("<stop offset=\"{t:.4}\" stop-color=\"rgb({r},{g},{b})\"/>\n");
    }
    s += &format!("</linearGradient></defs>\n<rect x=\"10\" y=\"2\" width=\"{bar}\" height=\"16\" fill=\"url(#viridis)\" stroke=\"#444\"/>\n");
    for k in 0..=4 {
        let x = 10.0 + bar as f32 * k as f32 / 4.0;
        let v = max * k as f32 / 4.0;
        let label = if k == 4 {
            format!("\u{2265}{}", fmt_num(v))
        } else {
            fmt_num(v)
        };
        s += &format!(
            "<line x1=\"{x:.1}\" y1=\"18\" x2=\"{x:.1}\" y2=\"23\" stroke=\"#444\"/><text x=\"{x:.1}\" y=\"36\" font-size=\"11\" text-anchor=\"middle\" font-family=\"sans-serif\">{label}</text>\n"
        );
    }
    s += "</svg>\n";
    s
}

fn fmt_num(v: f32) -> String {
    if v.fract() == 0.0 {
        format!("{v:.0}")
    } else {
        format!("{v:.1}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn viridis_endpoints_and_known_entries() {
        assert_eq!(viridis(0.0), [68, 1, 84]);
        assert_eq!(viridis(1.0), [253, 231, 37]);
        assert_eq!(VIRIDIS[128], [33, 145, 140]);
        assert_eq!(viridis(f32::NAN), VIRIDIS[0]);
        assert_eq!(viridis(7.0), VIRIDIS[255]);
        // Perceptual ramp: luminance increases monotonically (checked on Rec. 709 luma).
        let luma = |c: [u8; 3]| {
            0.2126 * f64::from(c[0]) + 0.7152 * f64::from(c[1]) + 0.0722 * f64::from(c[2])
        };
        assert!(VIRIDIS.windows(2).all(|p| luma(p[1]) >= luma(p[0]) - 0.5));
        assert!(!VIRIDIS.contains(&[0, 0, 0]));
    }

    #[test]
    fn heat_map_values() {
        let a = Image8::filled(3, 1, [100, 100, 100, 255]).unwrap();
        let b = Image8::from_rgba_bytes(3, 1, &[100, 100, 100, 9, 116, 84, 100, 0, 0, 0, 0, 0])
            .unwrap();
        assert_eq!(error_map(&a, &b).unwrap(), vec![0.0, 32.0 / 3.0, 100.0]);
        let mask = Mask::from_fn(3, 1, |x, _| x < 2).unwrap();
        let h = heat_map(&a, &b, Some(&mask), 32.0).unwrap();
        assert_eq!(h.pixels()[0], [68, 1, 84, 255]);
        let [r, g, bl] = viridis(1.0 / 3.0);
        assert_eq!(h.pixels()[1], [r, g, bl, 255]);
        assert_eq!(h.pixels()[2], OUTSIDE);
        let full = heat_map(&a, &b, None, 32.0).unwrap();
        assert_eq!(full.pixels()[2], [253, 231, 37, 255]); // 100 > 32 saturates
        for bad in [0.0, -1.0, f32::NAN, f32::INFINITY] {
            assert!(matches!(
                heat_map(&a, &b, None, bad),
                Err(QualityError::InvalidScale(_))
            ));
        }
    }

    #[test]
    fn legend() {
        let img = legend_image(256, 2).unwrap();
        assert_eq!(img.pixel(0, 1).unwrap(), [68, 1, 84, 255]);
        assert_eq!(img.pixel(255, 0).unwrap(), [253, 231, 37, 255]);
        let svg = legend_svg(32.0, 300);
        assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"));
        assert_eq!(svg.matches("<stop ").count(), 17);
        assert!(svg.contains(">16<") && svg.contains(">\u{2265}32<"));
    }
}
