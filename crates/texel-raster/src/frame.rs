//! The rendered frame: its colour target, depth and optional side channels.

use std::borrow::Cow;

use rayon::prelude::*;
use texel_texture::engine::dispatch::{self, StreamElement};
use texel_texture::Footprint;

use crate::settings::{ColorTarget, RenderSettings};

/// Elements per parallel chunk when clearing a buffer (large enough that rayon's overhead is noise).
const CLEAR_CHUNK: usize = 1 << 15;

/// Set every element of `buf` to `value`, in parallel on the current rayon pool.
fn fill<T: Copy + Send + Sync>(buf: &mut [T], value: T) {
    buf.par_chunks_mut(CLEAR_CHUNK).for_each(|c| c.fill(value));
}

/// [`reset_buffer`] for the colour and depth buffers: a reused buffer is written with
/// non-temporal stores when `stream` (see [`crate::Streaming`]), each thread fencing its chunk.
fn reset_streamed<T: StreamElement + Send + Sync>(
    buf: &mut Vec<T>,
    n: usize,
    value: T,
    stream: bool,
) {
    if stream && buf.len() == n {
        buf.par_chunks_mut(CLEAR_CHUNK).for_each(|c| {
            dispatch::stream_fill(c, value);
            dispatch::stream_fence();
        });
    } else {
        reset_buffer(buf, n, value);
    }
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

/// A rendered image: its colour target, its depth and the side channels that were asked for.
/// Every buffer is row-major, row 0 at the top, `width * height` long unless stated otherwise.
///
/// As on a GPU, the frame holds colour in the target's format (8 bytes a pixel with depth for an
/// 8-bit target, 20 for a float one) and nothing else unless asked: coverage is implied by depth
/// ([`Frame::covered`]), texel counts and footprints are filled only when the settings ask.
#[derive(Clone, Debug, PartialEq)]
pub struct Frame {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// The colour target's format: which of [`Frame::color`] and [`Frame::color8`] holds the
    /// image.
    pub target: ColorTarget,
    /// Linear RGBA colour ([`ColorTarget::Float`]; empty for 8-bit targets). Debug views store the
    /// linear value whose sRGB encoding is the displayed value (see [`crate::views`]).
    pub color: Vec<[f32; 4]>,
    /// 8-bit RGBA colour in the target's encoding ([`ColorTarget::Srgb8`] or
    /// [`ColorTarget::Unorm8`]; empty for a float target).
    pub color8: Vec<[u8; 4]>,
    /// Texels the filter read for the pixel's visible fragment (0 for background). Filled when
    /// counting ([`crate::RenderSettings::counts_texels`]); empty otherwise and for reference frames.
    pub texels_read: Vec<u32>,
    /// NDC depth of the visible fragment, `+inf` where nothing is drawn (for the reference, the
    /// nearest depth among the pixel's sub-samples). A pixel is covered exactly when its depth is
    /// finite ([`Frame::covered`]): depth tests are strict (`z < depth`) and the setup skips
    /// non-finite triangles, so no drawn fragment has depth `+inf`.
    pub depth: Vec<f32>,
    /// The footprint handed to the sampler for the visible fragment (zeroes for background). Filled
    /// when [`crate::RenderSettings::capture_footprints`] is on; empty otherwise.
    pub footprints: Vec<Footprint>,
    /// Whether the buffers hold what [`Frame::reset`] wrote and nothing since (see
    /// [`Frame::forget_clear`]).
    pub(crate) cleared: ClearMark,
}

/// [`Frame`]'s record that its buffers hold the clear, and which: the load operation of its next
/// draw (clear, or load what is there), not part of the image, so every two marks compare equal.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct ClearMark(pub(crate) Option<Clear>);

/// What [`Frame::reset`] wrote in every pixel: the background as a float and in the 8-bit
/// target's encoding (the buffer the target keeps holds one of them), depth `+inf`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Clear {
    pub(crate) color: [f32; 4],
    pub(crate) color8: [u8; 4],
}

impl PartialEq for ClearMark {
    fn eq(&self, _: &ClearMark) -> bool {
        true
    }
}

impl Frame {
    /// A cleared frame for `settings` (see [`Frame::reset`]). The size is not validated here:
    /// [`crate::render`] and [`crate::render_into`] validate the settings before allocating.
    pub fn new(settings: &RenderSettings) -> Frame {
        let mut frame = Frame {
            width: 0,
            height: 0,
            target: settings.target,
            color: Vec::new(),
            color8: Vec::new(),
            texels_read: Vec::new(),
            depth: Vec::new(),
            footprints: Vec::new(),
            cleared: ClearMark(None),
        };
        frame.reset(settings);
        frame
    }

    /// Clear the frame for a render with `settings`, reusing its buffers when the size is unchanged:
    /// colour to the background (encoded once for an 8-bit target), depth to `+inf`; the texel
    /// counts (when [`RenderSettings::counts_texels`]) and footprints (when
    /// [`RenderSettings::capture_footprints`]) to zero, and emptied otherwise. Runs on the current
    /// rayon pool. This is the "clear" of a GPU frame: [`crate::draw_into`] then draws on top.
    ///
    /// Like a GPU's fast clear, the frame remembers that it holds the clear until the next draw,
    /// and that draw may then write a tile it reaches from the clear values rather than from the
    /// buffers (see [`crate::Streaming`]; large frames only). Writing the buffers by hand between
    /// `reset` and a draw therefore needs [`Frame::forget_clear`] first. The colour and depth of a
    /// frame larger than the last-level cache (under [`crate::Streaming::Auto`]) whose buffers
    /// are reused at their size are written with non-temporal stores, so the clear does not fill
    /// the cache with lines the draw would first have to write back (a new or resized buffer is
    /// filled as it is allocated).
    pub fn reset(&mut self, settings: &RenderSettings) {
        let n = settings.width as usize * settings.height as usize;
        self.width = settings.width;
        self.height = settings.height;
        self.target = settings.target;
        let stream = crate::stream::streams(self.bytes());
        let (n_float, n_8) = if settings.target.is_8bit() {
            (0, n)
        } else {
            (n, 0)
        };
        reset_streamed(&mut self.color, n_float, settings.background, stream);
        let background8 = settings.target.encode(settings.background);
        reset_streamed(&mut self.color8, n_8, background8, stream);
        reset_streamed(&mut self.depth, n, f32::INFINITY, stream);
        let counted = if settings.counts_texels() { n } else { 0 };
        reset_buffer(&mut self.texels_read, counted, 0);
        let captured = if settings.capture_footprints { n } else { 0 };
        reset_buffer(&mut self.footprints, captured, Footprint::default());
        self.cleared = ClearMark(Some(Clear {
            color: settings.background,
            color8: background8,
        }));
    }

    /// Forget that the frame holds its clear ([`Frame::reset`]): the next draw then loads every
    /// tile from the buffers, so hand-written pixels survive it. A draw does this itself.
    pub fn forget_clear(&mut self) {
        self.cleared = ClearMark(None);
    }

    /// Whether the frame holds what [`Frame::reset`] wrote, no draw having run since and
    /// [`Frame::forget_clear`] not called.
    pub fn holds_clear(&self) -> bool {
        self.cleared.0.is_some()
    }

    /// The clear the frame holds when its next draw streams ([`Frame::draw_streams`]).
    pub(crate) fn streamed_clear(&self) -> Option<Clear> {
        self.cleared.0.filter(|_| self.draw_streams())
    }

    /// Whether the next draw into this frame writes its tiles from per-thread scratch with
    /// non-temporal stores ([`crate::Streaming`]): the frame holds its clear, has no side
    /// channels (texel counts, footprints), and streaming applies to its size.
    pub fn draw_streams(&self) -> bool {
        self.holds_clear()
            && self.texels_read.is_empty()
            && self.footprints.is_empty()
            && crate::stream::streams(self.bytes())
    }

    /// Bytes of colour and depth in the frame's size and target (4 a pixel of depth, 4 or 16
    /// of colour), whether or not its buffers have been allocated yet.
    fn bytes(&self) -> usize {
        let colour = if self.target.is_8bit() { 4 } else { 16 };
        self.width as usize * self.height as usize * (colour + 4)
    }

    /// Whether the frame's buffers have the size, target and side channels a render with
    /// `settings` writes (what [`Frame::reset`] gives).
    pub fn matches(&self, settings: &RenderSettings) -> bool {
        let n = settings.width as usize * settings.height as usize;
        let side = |on: bool| if on { n } else { 0 };
        self.width == settings.width
            && self.height == settings.height
            && self.target == settings.target
            && self.color.len() == side(!settings.target.is_8bit())
            && self.color8.len() == side(settings.target.is_8bit())
            && self.depth.len() == n
            && self.texels_read.len() == side(settings.counts_texels())
            && self.footprints.len() == side(settings.capture_footprints)
    }

    /// Index of pixel `(i, j)` in the buffers. No bounds check beyond the buffers' own.
    pub fn index(&self, i: u32, j: u32) -> usize {
        j as usize * self.width as usize + i as usize
    }

    /// Whether any triangle covers pixel `k` (its centre for `render`, any sample for the
    /// reference): its depth is finite. Panics if `k` is out of range.
    pub fn covered(&self, k: usize) -> bool {
        self.depth[k] < f32::INFINITY
    }

    /// [`Frame::covered`] for every pixel.
    pub fn coverage(&self) -> Vec<bool> {
        self.depth.iter().map(|&z| z < f32::INFINITY).collect()
    }

    /// Number of covered pixels.
    pub fn covered_pixels(&self) -> usize {
        self.depth.iter().filter(|&&z| z < f32::INFINITY).count()
    }

    /// Texels read per covered pixel ([`Frame::texels_read`], filled when counting): the mean
    /// and the largest; `(0.0, 0)` when nothing is covered or nothing was counted.
    pub fn texels_per_pixel(&self) -> (f64, u64) {
        let (mut sum, mut n, mut max) = (0u64, 0u64, 0u64);
        for (k, &t) in self.texels_read.iter().enumerate() {
            if self.covered(k) {
                sum += u64::from(t);
                n += 1;
                max = max.max(u64::from(t));
            }
        }
        (if n == 0 { 0.0 } else { sum as f64 / n as f64 }, max)
    }

    /// The colour as linear RGBA floats: borrowed from a float target; decoded from an 8-bit one
    /// ([`ColorTarget::decode`], so re-encoding gives the stored bytes back).
    pub fn linear(&self) -> Cow<'_, [[f32; 4]]> {
        if self.target.is_8bit() {
            Cow::Owned(self.color8.iter().map(|&b| self.target.decode(b)).collect())
        } else {
            Cow::Borrowed(&self.color)
        }
    }

    /// The colour as 8-bit bytes of `target`'s encoding: a float frame is encoded
    /// ([`ColorTarget::encode`]), an 8-bit frame of that encoding copied, one of the other encoding
    /// decoded and re-encoded. `4 * width * height` bytes.
    pub fn to_8bit(&self, target: ColorTarget) -> Vec<u8> {
        let target = if target.is_8bit() {
            target
        } else {
            ColorTarget::Srgb8
        };
        if self.target == target {
            return self.color8.iter().flatten().copied().collect();
        }
        if self.target.is_8bit() {
            return self
                .color8
                .iter()
                .flat_map(|&b| target.encode(self.target.decode(b)))
                .collect();
        }
        self.color.iter().flat_map(|&c| target.encode(c)).collect()
    }

    /// The colour as 8-bit RGBA bytes with RGB sRGB-encoded and alpha linear (what a PNG viewer
    /// expects). Values are clamped to `[0, 1]`; NaN encodes as 0. `4 * width * height` bytes.
    pub fn to_srgb8(&self) -> Vec<u8> {
        self.to_8bit(ColorTarget::Srgb8)
    }

    /// The colour as raw 8-bit RGBA bytes, every channel `round(255 * clamp(c, 0, 1))` with no
    /// transfer function (a linear `*Unorm` render target).
    pub fn to_raw8(&self) -> Vec<u8> {
        self.to_8bit(ColorTarget::Unorm8)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn float_frame() -> Frame {
        Frame {
            width: 2,
            height: 1,
            target: ColorTarget::Float,
            color: vec![[0.0, 1.0, 0.2159, 0.5], [f32::NAN, 2.0, -1.0, 1.0]],
            color8: vec![],
            texels_read: vec![],
            depth: vec![0.5, f32::INFINITY],
            footprints: vec![],
            cleared: ClearMark(None),
        }
    }

    #[test]
    fn encodings() {
        let f = float_frame();
        assert_eq!(f.to_srgb8(), vec![0, 255, 128, 128, 0, 255, 0, 255]);
        assert_eq!(f.to_raw8(), vec![0, 255, 55, 128, 0, 255, 0, 255]);
        assert_eq!(f.covered_pixels(), 1);
        assert_eq!(f.coverage(), vec![true, false]);
        assert_eq!(f.index(1, 0), 1);
    }

    #[test]
    fn eight_bit_frames_convert_through_linear() {
        let f = float_frame();
        for target in [ColorTarget::Srgb8, ColorTarget::Unorm8] {
            let bytes = f.to_8bit(target);
            let g = Frame {
                target,
                color: vec![],
                color8: bytes
                    .chunks_exact(4)
                    .map(|c| [c[0], c[1], c[2], c[3]])
                    .collect(),
                ..f.clone()
            };
            // Its own encoding is a copy; the other goes through linear: sRGB code 128 is linear
            // 0.21586, unorm code 55 (55.04); unorm 55 is linear 0.21569, sRGB code 128 (127.95).
            assert_eq!(g.to_8bit(target), bytes);
            assert_eq!(g.to_srgb8(), vec![0, 255, 128, 128, 0, 255, 0, 255]);
            assert_eq!(g.to_raw8(), vec![0, 255, 55, 128, 0, 255, 0, 255]);
        }
        let srgb = Frame {
            target: ColorTarget::Srgb8,
            color: vec![],
            color8: vec![[0, 255, 128, 128], [0, 255, 0, 255]],
            ..f
        };
        let linear = srgb.linear();
        assert_eq!(linear[0][..2], [0.0, 1.0]);
        assert!((linear[0][2] - 0.215_860_5).abs() < 1e-6);
        assert_eq!(linear[0][3], 128.0 / 255.0);
    }

    #[test]
    fn decode_inverts_encode_for_every_byte() {
        for target in [ColorTarget::Srgb8, ColorTarget::Unorm8] {
            for b in 0..=255u8 {
                let px = [b, b, b, b];
                assert_eq!(target.encode(target.decode(px)), px, "{target:?} {b}");
            }
        }
    }
}
