//! The rendered frame and its 8-bit encodings.

use rayon::prelude::*;
use texel_texture::color::{linear_to_srgb8, unorm8};
use texel_texture::Footprint;

use crate::settings::RenderSettings;

/// Elements per parallel chunk when clearing a buffer (large enough that rayon's overhead is noise).
const CLEAR_CHUNK: usize = 1 << 15;

/// Set every element of `buf` to `value`, in parallel on the current rayon pool.
fn fill<T: Copy + Send + Sync>(buf: &mut [T], value: T) {
    buf.par_chunks_mut(CLEAR_CHUNK).for_each(|c| c.fill(value));
}

/// Resize `buf` to `n` elements of `value` (`n = 0` frees nothing but empties it), reusing its
/// allocation when it is large enough.
fn reset_buffer<T: Copy + Send + Sync>(buf: &mut Vec<T>, n: usize, value: T) {
    if buf.len() == n {
        fill(buf, value);
    } else {
        buf.clear();
        buf.resize(n, value);
    }
}

/// A rendered image with its per-pixel side channels. Every buffer is row-major, row 0 at the top,
/// `width * height` long unless stated otherwise.
#[derive(Clone, Debug, PartialEq)]
pub struct Frame {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Linear RGBA colour. Debug views store the linear value whose sRGB encoding is the displayed
    /// value (see [`crate::views`]).
    pub color: Vec<[f32; 4]>,
    /// Texels the filter read for the pixel's visible fragment (0 for background). Filled when
    /// counting ([`crate::RenderSettings::counts_texels`]); empty otherwise and for reference frames.
    pub texels_read: Vec<u32>,
    /// Whether any triangle covers the pixel (its centre for `render`, any sample for the reference).
    pub coverage: Vec<bool>,
    /// NDC depth of the visible fragment, `+inf` where nothing is drawn. Empty for reference frames.
    pub depth: Vec<f32>,
    /// The footprint handed to the sampler for the visible fragment (zeroes for background). Filled
    /// when [`crate::RenderSettings::capture_footprints`] is on; empty otherwise.
    pub footprints: Vec<Footprint>,
}

impl Frame {
    /// A cleared frame for `settings` (see [`Frame::reset`]). The size is not validated here:
    /// [`crate::render`] and [`crate::render_into`] validate the settings before allocating.
    pub fn new(settings: &RenderSettings) -> Frame {
        let mut frame = Frame {
            width: 0,
            height: 0,
            color: Vec::new(),
            texels_read: Vec::new(),
            coverage: Vec::new(),
            depth: Vec::new(),
            footprints: Vec::new(),
        };
        frame.reset(settings);
        frame
    }

    /// Clear the frame for a render with `settings`, reusing its buffers when the size is unchanged:
    /// colour to the background, depth to `+inf`, coverage to `false`; the texel counts
    /// (when [`RenderSettings::counts_texels`]) and footprints (when
    /// [`RenderSettings::capture_footprints`]) to zero, and emptied otherwise. Runs on the current
    /// rayon pool. This is the "clear" of a GPU frame: [`crate::draw_into`] then draws on top.
    pub fn reset(&mut self, settings: &RenderSettings) {
        let n = settings.width as usize * settings.height as usize;
        self.width = settings.width;
        self.height = settings.height;
        reset_buffer(&mut self.color, n, settings.background);
        reset_buffer(&mut self.depth, n, f32::INFINITY);
        reset_buffer(&mut self.coverage, n, false);
        let counted = if settings.counts_texels() { n } else { 0 };
        reset_buffer(&mut self.texels_read, counted, 0);
        let captured = if settings.capture_footprints { n } else { 0 };
        reset_buffer(&mut self.footprints, captured, Footprint::default());
    }

    /// Whether the frame's buffers have the size and side channels a render with `settings` writes
    /// (what [`Frame::reset`] gives).
    pub fn matches(&self, settings: &RenderSettings) -> bool {
        let n = settings.width as usize * settings.height as usize;
        let side = |on: bool| if on { n } else { 0 };
        self.width == settings.width
            && self.height == settings.height
            && self.color.len() == n
            && self.depth.len() == n
            && self.coverage.len() == n
            && self.texels_read.len() == side(settings.counts_texels())
            && self.footprints.len() == side(settings.capture_footprints)
    }

    /// Index of pixel `(i, j)` in the buffers. No bounds check beyond the buffers' own.
    pub fn index(&self, i: u32, j: u32) -> usize {
        j as usize * self.width as usize + i as usize
    }

    /// The colour as 8-bit RGBA bytes with RGB sRGB-encoded and alpha linear (what a PNG viewer
    /// expects). Values are clamped to `[0, 1]`; NaN encodes as 0. `4 * width * height` bytes.
    pub fn to_srgb8(&self) -> Vec<u8> {
        self.color
            .iter()
            .flat_map(|c| {
                [
                    linear_to_srgb8(c[0]),
                    linear_to_srgb8(c[1]),
                    linear_to_srgb8(c[2]),
                    unorm8(c[3].clamp(0.0, 1.0)),
                ]
            })
            .collect()
    }

    /// The colour as raw 8-bit RGBA bytes, every channel `round(255 * clamp(c, 0, 1))` with no
    /// transfer function (a linear `*Unorm` render target).
    pub fn to_raw8(&self) -> Vec<u8> {
        self.color
            .iter()
            .flat_map(|c| c.map(|x| unorm8(x.clamp(0.0, 1.0))))
            .collect()
    }

    /// Number of pixels [`Frame::coverage`] marks as covered.
    pub fn covered_pixels(&self) -> usize {
        self.coverage.iter().filter(|&&c| c).count()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn encodings() {
        let f = Frame {
            width: 2,
            height: 1,
            color: vec![[0.0, 1.0, 0.2159, 0.5], [f32::NAN, 2.0, -1.0, 1.0]],
            texels_read: vec![],
            coverage: vec![true, false],
            depth: vec![],
            footprints: vec![],
        };
        assert_eq!(f.to_srgb8(), vec![0, 255, 128, 128, 0, 255, 0, 255]);
        assert_eq!(f.to_raw8(), vec![0, 255, 55, 128, 0, 255, 0, 255]);
        assert_eq!(f.covered_pixels(), 1);
        assert_eq!(f.index(1, 0), 1);
    }
}
