//! How filters read texels: per-level [`Fetch`] views ([`Level`], decoding 8-bit texels through a
//! table ([`Table8`]) or reading floats ([`Float`])), the whole-pyramid [`Pyramid`] view, and the [`Counted`]
//! wrapper that counts every texel read. This is the one home of texel reading; `texture.rs` owns
//! the storage.
//!
//! Every filter is generic over these traits, so the same code serves 8-bit and float textures and the
//! statistics mode: counting is a wrapper type, not a flag, and costs nothing when it is not used
//! (the plain views monomorphise to a bare load).

use std::cell::Cell;

use glam::Vec4;

use crate::base::color::{srgb_table, unorm8_table};
use crate::kernel::bilinear::{blend, wrapped_quad};
use crate::storage::lanes::Lanes;
use crate::storage::texture::{Format, LevelInfo, Storage, Texture};

/// How a stored texel becomes linear RGBA, per storage format: [`Table8`] for 8-bit texels,
/// [`Float`] for `f32` ones. The level and pyramid views below are generic over it, so the two
/// formats share one implementation and each monomorphises to a bare load (and table lookups).
pub(crate) trait Decode: Copy {
    /// The stored texel.
    type Texel: Copy + 'static;
    /// A 1x1 transparent-black image, for [`Pyramid::image`] on a storage of the other format.
    const BLACK: &'static [Self::Texel];
    /// The texel in linear RGBA.
    fn decode(&self, t: Self::Texel) -> Vec4;
    /// Four texels (a bilinear quad) in linear RGBA: [`Decode::decode`] of each, which a
    /// decoder may compute in lanes (the same bits).
    #[inline(always)]
    fn decode4(&self, t: [Self::Texel; 4]) -> [Vec4; 4] {
        t.map(|t| self.decode(t))
    }
    /// The bilinear blend ([`blend`]) of the quad whose rows are `r0 = [T00, T10]` and
    /// `r1 = [T01, T11]`, with fractions `a` (x) and `b` (y): [`Decode::decode4`] then [`blend`],
    /// which a decoder may compute in wider lanes (the same bits: [`crate::storage::lanes`]).
    #[inline(always)]
    fn bilinear_rows(&self, r0: [Self::Texel; 2], r1: [Self::Texel; 2], a: f32, b: f32) -> Vec4 {
        blend(self.decode4([r0[0], r0[1], r1[0], r1[1]]), a, b)
    }
    /// [`Decode::bilinear_rows`] of each sample of `run` (every quad inside the `width`-wide
    /// level `texels`) into `out` (the run's length), in one call: `true`, or `false` with `out`
    /// untouched where the decoder has no run kernel (the default) and the caller's per-sample
    /// loop runs instead. A `bool`, not a fallback loop here: the caller's loop is the fallback,
    /// not compiled twice (docs/decisions.md).
    #[inline(always)]
    fn bilinear_run(
        &self,
        texels: &[Self::Texel],
        width: u32,
        run: Run<'_>,
        out: &mut [[f32; 4]],
    ) -> bool {
        let _ = (texels, width, run, out);
        false
    }
    /// The texels of `storage` if it holds this format.
    fn texels(storage: &Storage) -> Option<&[Self::Texel]>;
}

/// 8-bit texels: one table load per channel (RGB through the colour table, sRGB or linear;
/// alpha always `b / 255`).
#[derive(Clone, Copy)]
pub(crate) struct Table8 {
    pub table: &'static [f32; 256],
    pub alpha: &'static [f32; 256],
}

impl Decode for Table8 {
    type Texel = [u8; 4];
    const BLACK: &'static [[u8; 4]] = &[[0; 4]];
    #[inline(always)]
    fn decode(&self, t: [u8; 4]) -> Vec4 {
        Vec4::new(
            self.table[t[0] as usize],
            self.table[t[1] as usize],
            self.table[t[2] as usize],
            self.alpha[t[3] as usize],
        )
    }
    fn texels(storage: &Storage) -> Option<&[[u8; 4]]> {
        match storage {
            Storage::U8(v) => Some(v),
            Storage::F32(_) => None,
        }
    }
}

/// Linear 8-bit (`Rgba8Unorm`) texels, `b / 255` per channel, by arithmetic in lanes (single
/// texels four channels wide, bilinear quads sixteen: [`unorm8_lanes`]), bit for bit the table
/// [`unorm8_table`]. A decoder of its own, not a flag on [`Table8`]: a branch in the shared
/// kernel slows sRGB trilinear frames. Single texels by arithmetic rather than four table
/// loads, which is faster on mip-nearest and trilinear frames (figures in docs/decisions.md).
/// Bilinear quads blend in eight lanes where `lanes` has them ([`crate::storage::lanes`]).
#[derive(Clone, Copy, Default)]
pub(crate) struct Unorm8 {
    pub lanes: Lanes,
}

/// `1 / 255` split into a high part of 12 significant bits, so that `b * UNORM8_HI` is exact for
/// every byte `b`, and the `f32` nearest to the rest.
pub(crate) const UNORM8_HI: f32 = f32::from_bits((1.0f32 / 255.0).to_bits() & !((1 << 12) - 1));
pub(crate) const UNORM8_LO: f32 = (1.0f64 / 255.0 - UNORM8_HI as f64) as f32;

/// `b / 255` for the sixteen bytes of a quad, as `b * hi + b * lo` with `1 / 255 = hi + lo`
/// (`hi` with 12 significant bits, so `b * hi` is exact and only the `b * lo` product and the sum
/// round): equal to the correctly rounded `b as f32 / 255.0` for all 256 bytes (checked
/// exhaustively by a test), and a multiply-add that runs in lanes where the table's sixteen
/// loads do not.
#[inline(always)]
pub(crate) fn unorm8_lanes(b: [u8; 16]) -> [f32; 16] {
    b.map(|b| unorm8_of(f32::from(b)))
}

/// `x / 255` for `x` a byte's value, as [`unorm8_lanes`] computes it (the lanes' one formula).
#[inline(always)]
fn unorm8_of<T: Copy + std::ops::Mul<f32, Output = T> + std::ops::Add<Output = T>>(x: T) -> T {
    x * UNORM8_HI + x * UNORM8_LO
}

/// A bilinear quad's four texels as sixteen lanes, each byte through `f`, back as four texels.
#[inline(always)]
fn quad_lanes(t: [[u8; 4]; 4], f: impl Fn([u8; 16]) -> [f32; 16]) -> [Vec4; 4] {
    let mut b = [0u8; 16];
    b.copy_from_slice(t.as_flattened());
    let f = f(b);
    [
        Vec4::from_slice(&f[0..4]),
        Vec4::from_slice(&f[4..8]),
        Vec4::from_slice(&f[8..12]),
        Vec4::from_slice(&f[12..16]),
    ]
}

impl Decode for Unorm8 {
    type Texel = [u8; 4];
    const BLACK: &'static [[u8; 4]] = &[[0; 4]];
    #[inline(always)]
    fn decode(&self, t: [u8; 4]) -> Vec4 {
        // `unorm8_lanes`' arithmetic, four lanes.
        unorm8_of(Codes8.decode(t))
    }
    #[inline(always)]
    fn decode4(&self, t: [[u8; 4]; 4]) -> [Vec4; 4] {
        quad_lanes(t, unorm8_lanes)
    }
    #[inline(always)]
    fn bilinear_rows(&self, r0: [[u8; 4]; 2], r1: [[u8; 4]; 2], a: f32, b: f32) -> Vec4 {
        match self.lanes.bilinear_unorm8((r0, r1), (a, b)) {
            Some(v) => v,
            None => blend(self.decode4([r0[0], r0[1], r1[0], r1[1]]), a, b),
        }
    }
    /// The eight-lane kernel over the whole run, the token tested once
    /// ([`Lanes::bilinear_unorm8_run`]); `false` on [`Lanes::scalar`].
    #[inline(always)]
    fn bilinear_run(
        &self,
        texels: &[[u8; 4]],
        width: u32,
        run: Run<'_>,
        out: &mut [[f32; 4]],
    ) -> bool {
        self.lanes.bilinear_unorm8_run(texels, width, run, out)
    }
    fn texels(storage: &Storage) -> Option<&[[u8; 4]]> {
        Table8::texels(storage)
    }
}

/// 8-bit texels as their stored code values, `0.0..=255.0` per channel (exact in `f32`), with
/// no transfer function: the stored-bytes path ([`crate::Sampler::sample_batch_stored`]) runs the
/// same single-texel kernels on these and converts the results back to bytes, bit for bit the
/// texels the decoding views read.
#[derive(Clone, Copy)]
pub(crate) struct Codes8;

impl Decode for Codes8 {
    type Texel = [u8; 4];
    const BLACK: &'static [[u8; 4]] = &[[0; 4]];
    #[inline(always)]
    fn decode(&self, t: [u8; 4]) -> Vec4 {
        Vec4::new(
            f32::from(t[0]),
            f32::from(t[1]),
            f32::from(t[2]),
            f32::from(t[3]),
        )
    }
    /// The sixteen conversions in lanes, as [`unorm8_lanes`] converts them.
    #[inline(always)]
    fn decode4(&self, t: [[u8; 4]; 4]) -> [Vec4; 4] {
        quad_lanes(t, |b| b.map(f32::from))
    }
    fn texels(storage: &Storage) -> Option<&[[u8; 4]]> {
        Table8::texels(storage)
    }
}

/// Linear `f32` texels, read as they are.
#[derive(Clone, Copy)]
pub(crate) struct Float;

impl Decode for Float {
    type Texel = [f32; 4];
    const BLACK: &'static [[f32; 4]] = &[[0.0; 4]];
    #[inline(always)]
    fn decode(&self, t: [f32; 4]) -> Vec4 {
        Vec4::from_array(t)
    }
    fn texels(storage: &Storage) -> Option<&[[f32; 4]]> {
        match storage {
            Storage::F32(v) => Some(v),
            Storage::U8(_) => None,
        }
    }
}

/// One mip level (or ripmap image) of stored texels, row-major, decoded by `D`.
#[derive(Clone, Copy)]
pub(crate) struct Level<'a, D: Decode> {
    pub width: u32,
    pub height: u32,
    pub texels: &'a [D::Texel],
    pub decode: D,
}

/// Read access to one mip level's texels by already-wrapped integer index.
pub(crate) trait Fetch: Copy {
    /// Level size in texels.
    fn size(&self) -> (u32, u32);
    /// Texel `(i, j)` in linear RGBA; `i < width`, `j < height`.
    fn texel(&self, i: u32, j: u32) -> Vec4;
    /// The bilinear blend of [`Fetch::quad`] with fractions `a` (x) and `b` (y) ([`blend`]).
    #[inline(always)]
    fn bilinear_quad(&self, i: u32, j: u32, a: f32, b: f32) -> Vec4 {
        blend(self.quad(i, j), a, b)
    }
    /// The bilinear blend of the texels at the already wrapped taps `i[0], i[1]` by `j[0], j[1]`
    /// (each inside the level) with fractions `a` and `b`: [`wrapped_quad`] then [`blend`].
    #[inline(always)]
    fn bilinear_wrapped(&self, i: [u32; 2], j: [u32; 2], a: f32, b: f32) -> Vec4 {
        blend(wrapped_quad(self, i, j), a, b)
    }
    /// [`Fetch::bilinear_quad`] of each sample of `run` (every first tap inside the level:
    /// `i + 1 < width`, `j + 1 < height`) into `out` (the run's length), in one call: `true`, or
    /// `false` with `out` untouched where the view has no run kernel (the default; the caller
    /// then runs its per-sample loop).
    #[inline(always)]
    fn bilinear_run(&self, run: Run<'_>, out: &mut [[f32; 4]]) -> bool {
        let _ = (run, out);
        false
    }
    /// The 2x2 texels `[(i, j), (i + 1, j), (i, j + 1), (i + 1, j + 1)]`; `i + 1 < width`,
    /// `j + 1 < height` (no wrapping). The storage views read them as two 2-texel rows of one
    /// range ([`quad_rows`]), so a bilinear lookup inside the level pays one bounds check instead
    /// of four.
    #[inline(always)]
    fn quad(&self, i: u32, j: u32) -> [Vec4; 4] {
        [
            self.texel(i, j),
            self.texel(i + 1, j),
            self.texel(i, j + 1),
            self.texel(i + 1, j + 1),
        ]
    }
}

/// The two 2-texel rows starting at `(i, j)` and `(i, j + 1)` of a row-major `width`-wide level
/// (`i + 1 < width`, `j + 1` below the height; out of bounds panics), by one range check: the
/// rows lie in the `width + 2` texels from `(i, j)`, whose elements then need none.
#[inline(always)]
pub(crate) fn quad_rows<T: Copy>(texels: &[T], width: u32, i: u32, j: u32) -> ([T; 2], [T; 2]) {
    let w = width as usize;
    let k = j as usize * w + i as usize;
    let q = &texels[k..k + w + 2];
    ([q[0], q[1]], [q[w], q[w + 1]])
}

/// Stage 2's results for a run of samples whose taps all lie inside one level (the batched
/// sampler's inside route, `batch.rs`): per sample its first tap `(i[k], j[k])` (non-negative)
/// and fractions `a[k]`, `b[k]`. The four slices have the run's length.
#[derive(Clone, Copy)]
#[cfg_attr(not(target_arch = "x86_64"), allow(dead_code))] // read by the AVX2 run kernel
pub(crate) struct Run<'r> {
    pub i: &'r [i32],
    pub j: &'r [i32],
    pub a: &'r [f32],
    pub b: &'r [f32],
}

impl<D: Decode> Fetch for Level<'_, D> {
    #[inline(always)]
    fn size(&self) -> (u32, u32) {
        (self.width, self.height)
    }
    #[inline(always)]
    fn texel(&self, i: u32, j: u32) -> Vec4 {
        self.decode
            .decode(self.texels[j as usize * self.width as usize + i as usize])
    }
    #[inline(always)]
    fn quad(&self, i: u32, j: u32) -> [Vec4; 4] {
        let (r0, r1) = quad_rows(self.texels, self.width, i, j);
        self.decode.decode4([r0[0], r0[1], r1[0], r1[1]])
    }
    #[inline(always)]
    fn bilinear_quad(&self, i: u32, j: u32, a: f32, b: f32) -> Vec4 {
        let (r0, r1) = quad_rows(self.texels, self.width, i, j);
        self.decode.bilinear_rows(r0, r1, a, b)
    }
    #[inline(always)]
    fn bilinear_run(&self, run: Run<'_>, out: &mut [[f32; 4]]) -> bool {
        self.decode.bilinear_run(self.texels, self.width, run, out)
    }
    #[inline(always)]
    fn bilinear_wrapped(&self, i: [u32; 2], j: [u32; 2], a: f32, b: f32) -> Vec4 {
        let w = self.width as usize;
        let (row0, row1) = (j[0] as usize * w, j[1] as usize * w);
        let (i0, i1) = (i[0] as usize, i[1] as usize);
        let r0 = [self.texels[row0 + i0], self.texels[row0 + i1]];
        let r1 = [self.texels[row1 + i0], self.texels[row1 + i1]];
        self.decode.bilinear_rows(r0, r1, a, b)
    }
}

/// All mip levels of a texture.
pub(crate) trait Pyramid {
    /// One level's view.
    type Level<'a>: Fetch
    where
        Self: 'a;
    /// Number of levels (at least 1).
    fn level_count(&self) -> usize;
    /// Level `k < level_count()`.
    fn level(&self, k: usize) -> Self::Level<'_>;
    /// The texture these levels belong to (for its lazily built ripmap and summed-area table).
    fn texture(&self) -> &Texture;
    /// A view of another image stored in the same format as these levels (a ripmap image), decoded
    /// and counted exactly as the levels are. `info` locates the image inside `storage`.
    ///
    /// A storage of the other format (impossible for structures built from this texture) gives a
    /// 1x1 transparent-black view instead of a panic.
    fn image<'s>(&'s self, info: &LevelInfo, storage: &'s Storage) -> Self::Level<'s>;
    /// Record `n` reads of a structure that is not made of texels (summed-area table entries).
    /// Free for the plain views; [`Counted`] adds `n` to its counter.
    #[inline(always)]
    fn note_reads(&self, _n: u32) {}
}

/// The pyramid of a texture whose storage `D` decodes.
pub(crate) struct Stored<'a, D: Decode> {
    pub tex: &'a Texture,
    pub levels: &'a [LevelInfo],
    pub texels: &'a [D::Texel],
    pub decode: D,
}

fn level_slice<'t, T>(info: &LevelInfo, all: &'t [T]) -> &'t [T] {
    &all[info.offset..info.offset + info.width as usize * info.height as usize]
}

impl<D: Decode> Pyramid for Stored<'_, D> {
    type Level<'b>
        = Level<'b, D>
    where
        Self: 'b;
    #[inline(always)]
    fn level_count(&self) -> usize {
        self.levels.len()
    }
    #[inline(always)]
    fn level(&self, k: usize) -> Level<'_, D> {
        let info = &self.levels[k];
        Level {
            width: info.width,
            height: info.height,
            texels: level_slice(info, self.texels),
            decode: self.decode,
        }
    }
    #[inline(always)]
    fn texture(&self) -> &Texture {
        self.tex
    }
    #[inline]
    fn image<'s>(&'s self, info: &LevelInfo, storage: &'s Storage) -> Level<'s, D> {
        let (width, height, texels) = match D::texels(storage) {
            Some(v) => (info.width, info.height, level_slice(info, v)),
            None => (1, 1, D::BLACK),
        };
        Level {
            width,
            height,
            texels,
            decode: self.decode,
        }
    }
}

/// A pyramid view that counts texel reads.
pub(crate) struct Counted<P> {
    pub inner: P,
    pub count: Cell<u32>,
}

/// A level view that counts texel reads into its pyramid's counter.
#[derive(Clone, Copy)]
pub(crate) struct CountedLevel<'a, L> {
    inner: L,
    count: &'a Cell<u32>,
}

impl<L: Fetch> Fetch for CountedLevel<'_, L> {
    #[inline(always)]
    fn size(&self) -> (u32, u32) {
        self.inner.size()
    }
    #[inline(always)]
    fn texel(&self, i: u32, j: u32) -> Vec4 {
        self.count.set(self.count.get().saturating_add(1));
        self.inner.texel(i, j)
    }
    #[inline(always)]
    fn quad(&self, i: u32, j: u32) -> [Vec4; 4] {
        self.count.set(self.count.get().saturating_add(4));
        self.inner.quad(i, j)
    }
}

impl<P: Pyramid> Pyramid for Counted<P> {
    type Level<'b>
        = CountedLevel<'b, P::Level<'b>>
    where
        Self: 'b;
    fn level_count(&self) -> usize {
        self.inner.level_count()
    }
    fn level(&self, k: usize) -> Self::Level<'_> {
        CountedLevel {
            inner: self.inner.level(k),
            count: &self.count,
        }
    }
    fn texture(&self) -> &Texture {
        self.inner.texture()
    }
    fn image<'s>(&'s self, info: &LevelInfo, storage: &'s Storage) -> Self::Level<'s> {
        CountedLevel {
            inner: self.inner.image(info, storage),
            count: &self.count,
        }
    }
    fn note_reads(&self, n: u32) {
        self.count.set(self.count.get().saturating_add(n));
    }
}

/// Call `$body` with `$p` bound to the texture's pyramid view (8-bit or float), monomorphising once
/// per storage format; with `$lanes`, the linear 8-bit view blends bilinear quads with that
/// kernel ([`crate::storage::lanes`]), else with the scalar one.
macro_rules! with_pyramid {
    ($tex:expr, |$p:ident| $body:expr) => {
        $crate::storage::fetch::with_pyramid!($tex, $crate::storage::lanes::Lanes::scalar(), |$p| {
            $body
        })
    };
    ($tex:expr, $lanes:expr, |$p:ident| $body:expr) => {
        match $crate::storage::fetch::pyramid_with($tex, $lanes) {
            $crate::storage::fetch::AnyPyramid::U8($p) => $body,
            $crate::storage::fetch::AnyPyramid::Unorm8($p) => $body,
            $crate::storage::fetch::AnyPyramid::F32($p) => $body,
        }
    };
}
pub(crate) use with_pyramid;

pub(crate) enum AnyPyramid<'a> {
    /// 8-bit sRGB texels.
    U8(Stored<'a, Table8>),
    /// 8-bit linear texels.
    Unorm8(Stored<'a, Unorm8>),
    F32(Stored<'a, Float>),
}

/// The decoding of an 8-bit texture's texels in `format` (sRGB or linear colour table).
pub(crate) fn table8(format: Format) -> Table8 {
    Table8 {
        table: if format == Format::Rgba8Srgb {
            srgb_table()
        } else {
            unorm8_table()
        },
        alpha: unorm8_table(),
    }
}

/// The pyramid of an 8-bit texture read as stored codes ([`Codes8`]); `None` for float storage.
pub(crate) fn codes_of(tex: &Texture) -> Option<Stored<'_, Codes8>> {
    Some(Stored {
        tex,
        levels: tex.levels(),
        texels: Codes8::texels(tex.storage())?,
        decode: Codes8,
    })
}

/// The texture's pyramid view (8-bit sRGB, linear 8-bit or float), whose linear 8-bit view
/// blends bilinear quads with `lanes`' kernel.
pub(crate) fn pyramid_with(tex: &Texture, lanes: Lanes) -> AnyPyramid<'_> {
    match tex.storage() {
        Storage::U8(v) if tex.format() == Format::Rgba8Unorm => AnyPyramid::Unorm8(Stored {
            tex,
            levels: tex.levels(),
            texels: v,
            decode: Unorm8 { lanes },
        }),
        Storage::U8(v) => AnyPyramid::U8(Stored {
            tex,
            levels: tex.levels(),
            texels: v,
            decode: table8(tex.format()),
        }),
        Storage::F32(v) => AnyPyramid::F32(Stored {
            tex,
            levels: tex.levels(),
            texels: v,
            decode: Float,
        }),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The lanes' `b * hi + b * lo` is the table's correctly rounded `b / 255`, for every byte
    /// in every position of a quad; `hi` has at most 12 significant bits (so `b * hi` is exact);
    /// the quads decode as their texels one by one, and single texels equal the table per channel.
    #[test]
    fn unorm8_lanes_equal_the_table() {
        assert_eq!(UNORM8_HI.to_bits() & ((1 << 12) - 1), 0);
        let table = unorm8_table();
        for b in 0..=255u8 {
            for k in 0..16 {
                let mut bytes = [0u8; 16];
                bytes[k] = b;
                let f = unorm8_lanes(bytes);
                assert_eq!(f[k].to_bits(), table[b as usize].to_bits(), "byte {b}");
                assert_eq!(f[k].to_bits(), (f32::from(b) / 255.0).to_bits());
            }
        }
        let lin = Unorm8::default();
        for b in 0..=255u8 {
            for k in 0..4 {
                let mut t = [0u8; 4];
                t[k] = b;
                let want = table[b as usize].to_bits();
                assert_eq!(lin.decode(t).to_array()[k].to_bits(), want, "byte {b}");
            }
        }
        let t = [
            [1, 2, 3, 4],
            [250, 251, 252, 253],
            [0, 128, 255, 7],
            [9, 99, 199, 254],
        ];
        let quad = lin.decode4(t);
        for (q, t) in quad.iter().zip(t) {
            assert_eq!(*q, lin.decode(t));
            assert_eq!(*q, table8(Format::Rgba8Unorm).decode(t));
        }
    }
}
