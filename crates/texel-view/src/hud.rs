//! Text and lines drawn over the frame: the heads-up display, the key table and the split-screen
//! divider, on a `0x00RRGGBB` buffer (softbuffer's pixel format). Glyphs are the public-domain
//! 8x8 bitmap font of the `font8x8` crate (basic Latin), scaled by a whole factor.

use font8x8::legacy::BASIC_LEGACY;

/// A `0x00RRGGBB` pixel buffer of `width x height`, row-major.
pub(crate) struct Canvas<'a> {
    /// Pixels.
    pub pixels: &'a mut [u32],
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
}

/// Glyph cell side before scaling, pixels.
pub(crate) const GLYPH: u32 = 8;

impl Canvas<'_> {
    /// Darken the rectangle `[x0, x0 + w) x [y0, y0 + h)` (clipped to the canvas) to a quarter of
    /// its brightness, so text over it reads on any image.
    pub(crate) fn shade(&mut self, x0: u32, y0: u32, w: u32, h: u32) {
        for y in y0..(y0 + h).min(self.height) {
            for x in x0..(x0 + w).min(self.width) {
                let p = &mut self.pixels[(y * self.width + x) as usize];
                *p = (*p >> 2) & 0x003f_3f3f;
            }
        }
    }

    /// Draw `text` with its top-left corner at `(x, y)`, each glyph pixel `scale x scale`, in
    /// `color`; characters outside basic Latin show as `?`. Clipped to the canvas.
    pub(crate) fn text(&mut self, x: u32, y: u32, text: &str, color: u32, scale: u32) {
        let mut cx = x;
        for ch in text.chars() {
            let code = if ch.is_ascii() {
                ch as usize
            } else {
                '?' as usize
            };
            let glyph = BASIC_LEGACY[code];
            for (row, bits) in glyph.iter().enumerate() {
                for col in 0..GLYPH {
                    if bits & (1 << col) == 0 {
                        continue;
                    }
                    for sy in 0..scale {
                        for sx in 0..scale {
                            let px = cx + col * scale + sx;
                            let py = y + row as u32 * scale + sy;
                            if px < self.width && py < self.height {
                                self.pixels[(py * self.width + px) as usize] = color;
                            }
                        }
                    }
                }
            }
            cx += GLYPH * scale;
        }
    }

    /// Draw `lines` in a shaded box at `(x, y)`; returns the box's height.
    pub(crate) fn panel(&mut self, x: u32, y: u32, lines: &[String], scale: u32) -> u32 {
        let pad = 4 * scale;
        let line_h = (GLYPH + 2) * scale;
        let chars = lines.iter().map(|l| l.chars().count()).max().unwrap_or(0) as u32;
        let (w, h) = (
            chars * GLYPH * scale + 2 * pad,
            lines.len() as u32 * line_h + 2 * pad,
        );
        self.shade(x, y, w, h);
        for (k, line) in lines.iter().enumerate() {
            self.text(
                x + pad,
                y + pad + k as u32 * line_h,
                line,
                0x00ff_ffff,
                scale,
            );
        }
        h
    }

    /// A vertical line at column `x`, `color`.
    pub(crate) fn vline(&mut self, x: u32, color: u32) {
        if x < self.width {
            for y in 0..self.height {
                self.pixels[(y * self.width + x) as usize] = color;
            }
        }
    }
}

/// The text scale for a window `height` pixels tall: 1 below 900 pixels, then 2.
pub(crate) fn scale_for(height: u32) -> u32 {
    if height >= 900 {
        2
    } else {
        1
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn text_sets_the_glyph_bits_and_clips() {
        let (w, h) = (20u32, 10u32);
        let mut px = vec![0u32; (w * h) as usize];
        let mut c = Canvas {
            pixels: &mut px,
            width: w,
            height: h,
        };
        c.text(0, 0, "H", 0xffffff, 1);
        let glyph = BASIC_LEGACY['H' as usize];
        for y in 0..8 {
            for x in 0..8 {
                let on = glyph[y as usize] & (1 << x) != 0;
                assert_eq!(px[(y * w + x) as usize] == 0xffffff, on, "({x}, {y})");
            }
        }
        // Clipped at the right edge without panicking.
        let mut c = Canvas {
            pixels: &mut px,
            width: w,
            height: h,
        };
        c.text(15, 5, "HH", 0xff, 3);
        // 'H' at scale 3 from column 15: glyph column 1 (bit 1 of row 0) covers pixels 18-20,
        // rows 5-7; the rest of the glyph falls outside the 20x10 canvas.
        assert_eq!(glyph[0] & 0b10, 0b10);
        assert_eq!(px[(5 * w + 18) as usize], 0xff);
        panel_clips_at_the_edge(&mut px, w, h);
    }

    fn panel_clips_at_the_edge(px: &mut [u32], w: u32, h: u32) {
        // A panel wider than the canvas shades and writes up to its edge.
        let before = px[(9 * w + 19) as usize];
        let mut c = Canvas {
            pixels: px,
            width: w,
            height: h,
        };
        let height = c.panel(10, 2, &["a long line".into()], 2);
        assert_eq!(height, 2 * (GLYPH + 2) + 2 * 8);
        assert_eq!(px[(9 * w + 19) as usize], (before >> 2) & 0x003f_3f3f);
    }

    #[test]
    fn shade_quarters_each_channel() {
        let mut px = vec![0x00ff_8040u32; 4];
        let mut c = Canvas {
            pixels: &mut px,
            width: 2,
            height: 2,
        };
        c.shade(1, 0, 5, 5);
        assert_eq!(px, vec![0x00ff_8040, 0x003f_2010, 0x00ff_8040, 0x003f_2010]);
    }
}
