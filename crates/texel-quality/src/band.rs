//! The horizon band: where minification and anisotropy are extreme.
//!
//! Rule (conventions.md asks for "the band just below the horizon"): in every column `x`, find the
//! topmost covered row `y0(x)` of the coverage mask; the band holds the covered pixels
//! `(x, y)` with `y0(x) <= y < y0(x) + rows`. Columns without coverage contribute nothing.
//! The default depth is [`default_band_rows`]: 10% of the image height, at least 8 rows (and never
//! more than the height).
//!
//! For the ground plane the topmost covered row of each column is the horizon, so the band is the
//! strip just below it. For a closed object (cube, sphere) it is the strip along the top of its
//! silhouette, which is where such objects are seen at grazing angles — the same stress case.
//! Rejected alternative: a fixed band of image rows around the projected horizon line needs the
//! camera, which a quality crate should not depend on, and is empty for objects that do not reach it.

use crate::mask::Mask;

/// The default band depth for an image `height` pixels tall: `max(8, round(0.1 * height))`,
/// capped at `height`. Examples: 720 -> 72, 64 -> 8, 5 -> 5.
pub fn default_band_rows(height: u32) -> u32 {
    let tenth = (u64::from(height) + 5) / 10;
    (tenth.max(8) as u32).min(height)
}

/// The band of `rows` covered pixels below the topmost covered pixel of each column of `coverage`
/// (see the module docs). `rows = 0` gives an empty band.
pub fn horizon_band(coverage: &Mask, rows: u32) -> Mask {
    let (w, h) = coverage.size();
    let mut bits = vec![false; w as usize * h as usize];
    for x in 0..w {
        if let Some(y0) = (0..h).find(|&y| coverage.get(x, y)) {
            let end = (u64::from(y0) + u64::from(rows)).min(u64::from(h)) as u32;
            for y in y0..end {
                if coverage.get(x, y) {
                    bits[y as usize * w as usize + x as usize] = true;
                }
            }
        }
    }
    Mask::new(w, h, bits).expect("same size as a valid mask")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_rows_examples() {
        assert_eq!(default_band_rows(720), 72);
        assert_eq!(default_band_rows(64), 8);
        assert_eq!(default_band_rows(5), 5);
        assert_eq!(default_band_rows(95), 10);
        assert_eq!(default_band_rows(94), 9);
    }

    #[test]
    fn band_follows_each_column_top() {
        // Coverage: column x starts at row x (a diagonal horizon), with a hole at (1, 3).
        let cov = Mask::from_fn(4, 8, |x, y| y >= x && !(x == 1 && y == 3)).unwrap();
        let band = horizon_band(&cov, 3);
        for x in 0..4 {
            for y in 0..8 {
                let want = y >= x && y < x + 3 && !(x == 1 && y == 3);
                assert_eq!(band.get(x, y), want, "({x}, {y})");
            }
        }
        assert_eq!(band.count(), 3 + 2 + 3 + 3);
    }

    #[test]
    fn empty_columns_and_zero_rows() {
        let cov = Mask::from_fn(3, 4, |x, _| x == 1).unwrap();
        assert_eq!(horizon_band(&cov, 2).count(), 2);
        assert_eq!(horizon_band(&cov, 0).count(), 0);
        assert_eq!(horizon_band(&cov, u32::MAX).count(), 4);
    }
}
