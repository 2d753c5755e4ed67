//! How filters read texels: per-level [`Fetch`] views ([`Level`], decoding 8-bit texels through a
//! table ([`Table8`]) or reading floats ([`Float`])), the whole-pyramid [`Pyramid`] view, and the [`Counted`]
//! wrapper that counts every texel read. This is the one home of texel reading; `texture.rs` owns
//! the storage.
//!
//! Every filter is generic over these traits, so the same code serves 8-bit and float textures and the
//! statistics mode: counting is a wrapper type, not a flag, and costs nothing when it is not used
//! (the plain views monomorphise to a bare load).

use glam::Vec4;

use crate::base::color::{srgb_table, unorm8_table, UNORM8_HI, UNORM8_LO};
use crate::base::lerp::blend;
use crate::storage::format::{Format, Storage};
use crate::storage::lanes::{quad_rows, Lanes, Run};

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
    /// The fixed-point bilinear blend of stored codes ([`crate::kernel::fixed8`]'s `bilinear8`)
    /// of each sample of `weights` (every quad inside the `width`-wide level `texels`; `a` and
    /// `b` hold the 8-bit weights, not the fractions) into `out`: `true`, or `false` with `out`
    /// untouched where the decoder has no such kernel (the default; only [`Codes8`] with an AVX2
    /// token has one).
    #[inline(always)]
    fn bilinear_codes8_run(
        &self,
        texels: &[Self::Texel],
        width: u32,
        weights: Run<'_>,
        out: &mut [[f32; 4]],
    ) -> bool {
        let _ = (texels, width, weights, out);
        false
    }
    /// The fixed-point bilinear blend of stored codes of the quad whose rows are `r0` and `r1`
    /// with the 8-bit weights `wa`, `wb` ([`Decode::bilinear_codes8_run`] for one sample);
    /// `None` where the decoder has no such kernel (the default).
    #[inline(always)]
    fn bilinear_codes8_rows(
        &self,
        r0: [Self::Texel; 2],
        r1: [Self::Texel; 2],
        wa: f32,
        wb: f32,
    ) -> Option<Vec4> {
        let _ = (r0, r1, wa, wb);
        None
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
        unorm8_of(Codes8::default().decode(t))
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
/// no transfer function: the stored-bytes path ([`crate::SpanKind::Stored`]) runs the
/// same single-texel kernels on these and converts the results back to bytes, bit for bit the
/// texels the decoding views read. The fixed-point bilinear blend of [`crate::kernel::fixed8`]
/// runs in eight lanes where `lanes` has them ([`Lanes::bilinear_codes8_run`]).
#[derive(Clone, Copy, Default)]
pub(crate) struct Codes8 {
    pub lanes: Lanes,
}

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
    #[inline(always)]
    fn bilinear_codes8_run(
        &self,
        texels: &[[u8; 4]],
        width: u32,
        weights: Run<'_>,
        out: &mut [[f32; 4]],
    ) -> bool {
        self.lanes.bilinear_codes8_run(texels, width, weights, out)
    }
    #[inline(always)]
    fn bilinear_codes8_rows(
        &self,
        r0: [[u8; 4]; 2],
        r1: [[u8; 4]; 2],
        wa: f32,
        wb: f32,
    ) -> Option<Vec4> {
        self.lanes.bilinear_codes8((r0, r1), (wa, wb))
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
    /// The fixed-point bilinear blend of stored codes ([`Decode::bilinear_codes8_run`]) of each
    /// sample of `weights` (every first tap inside the level; `a`, `b` the 8-bit weights) into
    /// `out`: `true`, or `false` with `out` untouched where the view has no such kernel (the
    /// default).
    #[inline(always)]
    fn bilinear_codes8_run(&self, weights: Run<'_>, out: &mut [[f32; 4]]) -> bool {
        let _ = (weights, out);
        false
    }
    /// The fixed-point bilinear blend of stored codes of the quad at `(i, j)` (inside the level)
    /// with the 8-bit weights `wa`, `wb`, where the view has an eight-lane kernel for it
    /// ([`Decode::bilinear_codes8_rows`]); `None` otherwise (the default).
    #[inline(always)]
    fn bilinear_codes8(&self, i: u32, j: u32, wa: f32, wb: f32) -> Option<Vec4> {
        let _ = (i, j, wa, wb);
        None
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
    fn bilinear_codes8_run(&self, weights: Run<'_>, out: &mut [[f32; 4]]) -> bool {
        self.decode
            .bilinear_codes8_run(self.texels, self.width, weights, out)
    }
    #[inline(always)]
    fn bilinear_codes8(&self, i: u32, j: u32, wa: f32, wb: f32) -> Option<Vec4> {
        let (r0, r1) = quad_rows(self.texels, self.width, i, j);
        self.decode.bilinear_codes8_rows(r0, r1, wa, wb)
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

/// The 2x2 texels of taps `i`, `j` already wrapped into `level`, in [`Fetch::quad`]'s order: the
/// texels bilinear's taps read near an edge where no tap takes the border colour.
#[inline(always)]
pub(crate) fn wrapped_quad<F: Fetch>(level: &F, i: [u32; 2], j: [u32; 2]) -> [Vec4; 4] {
    [
        level.texel(i[0], j[0]),
        level.texel(i[1], j[0]),
        level.texel(i[0], j[1]),
        level.texel(i[1], j[1]),
    ]
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
