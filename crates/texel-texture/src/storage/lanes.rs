//! Explicit 8-lane kernels for the batched sampler's hottest step, the bilinear blend of a quad of
//! linear 8-bit texels, on AVX2 through [`pulp`]'s run-time tokens (safe: a token exists only on
//! a CPU that has the features, and its intrinsics are safe methods), with the four-lane `glam`
//! kernel as the fallback on every other CPU. The fixed-point blend of stored codes (`--precision
//! gpu`) has a sixteen-lane `u16` kernel as well, four quads at a time (below).
//!
//! Why. Written in plain Rust (`[f32; 16]` lanes, `Vec4` blends), LLVM's SLP vectoriser splits the
//! quad into four texels and three four-lane lerps: per texel a broadcast, a byte shuffle, a
//! conversion and the decode's two multiplies and add, then `3 x 3` four-lane operations, about 35
//! vector operations a quad. The explicit kernel reads the quad as its two rows of 8 bytes, widens
//! each row to eight `f32` lanes (`vpmovzxbd`, `vcvtdq2ps`), decodes both rows in eight lanes,
//! and blends the two rows' x-lerps in one eight-lane lerp: about 15 operations, and faster
//! stand-alone (a trilinear kernel over cache-resident samples; docs/decisions.md).
//!
//! Same bits. Each lane computes the scalar kernel's operations in its order: the decode
//! `b * hi + b * lo` ([`crate::storage::fetch`]'s `unorm8_lanes`: two multiplies and an add, never fused),
//! then [`crate::kernel::bilinear::blend`]'s `lerp(lerp(t00, t10, a), lerp(t01, t11, a), b)` with
//! `lerp(x, y, t) = x + (y - x) * t`. Only the grouping into registers differs, so the result is
//! bit for bit the scalar kernel's (unit test below; `tests/core.rs` compares whole batches). The
//! fixed-point kernels compute integers: in `f32` lanes each intermediate is exact, in `u16` lanes
//! each is exact modulo `2^16` and the result is its low byte, so both give
//! [`crate::kernel::fixed8`]'s codes (tested over every quad of a random level and every run
//! length's tail).
//!
//! Where it runs. The batched sampler's kernels run on [`crate::engine::dispatch`]'s instruction-set
//! copies; [`crate::Sampler::sample_batch`] takes the token of the copy it runs on
//! ([`crate::engine::dispatch::lanes`]: [`Lanes::detect`] on x86-64-v3 and -v4), and
//! [`crate::Sampler::sample_batch_lanes`] the caller's (the rasterizer's tiles pass their copy's).
//! The one-sample path keeps the scalar kernel: pulp's intrinsics carry `#[target_feature]`, so in
//! code compiled for the x86-64 baseline each would stay a call.

use glam::Vec4;

#[cfg(target_arch = "x86_64")]
use crate::base::color::{UNORM8_HI, UNORM8_LO};
#[cfg(target_arch = "x86_64")]
use crate::base::floor::{round_staged4, ROUND_F32};

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

/// Which quad kernel the batched sampler ([`crate::Sampler::sample_batch_lanes`]) uses for the
/// bilinear blend of a 2x2 quad of linear 8-bit texels (`Rgba8Unorm`, its staged path: minifying
/// and magnifying bilinear, mip-nearest, trilinear and the anisotropic probes): AVX2's eight
/// lanes (a `pulp` token proving the CPU has them) or the four-lane scalar kernel. Both give the
/// same bits. Ignored for other formats, for the one-sample path, and for textures above the
/// staged path's side limit (2^22 texels). `Default` is [`Lanes::scalar`]. `Copy` and free to
/// pass (a zero-sized token in an `Option`).
///
/// The eight-lane kernel reads each row of two texels as 8 bytes, widens and decodes them in
/// eight lanes (`b * hi + b * lo` with `1/255 = hi + lo`, two multiplies and an add per lane,
/// never fused), lerps both rows along x in one eight-lane step and the two halves along y:
/// per lane the four-lane kernel's operations in its order. Its intrinsics carry
/// `#[target_feature]`, so it is fast only in code compiled with AVX2 ([`crate::engine::dispatch`]'s
/// x86-64-v3 and -v4 copies); called from baseline code each intrinsic stays a call (correct,
/// slower).
#[derive(Clone, Copy, Debug, Default)]
pub struct Lanes {
    #[cfg(target_arch = "x86_64")]
    v3: Option<pulp::x86::V3>,
}

impl Lanes {
    /// The four-lane scalar kernel, on every CPU.
    pub fn scalar() -> Lanes {
        Lanes::default()
    }

    /// The eight-lane AVX2 kernel if the CPU has x86-64-v3's features (pulp's `V3`: AVX, AVX2,
    /// FMA, BMI1/2, LZCNT and SSE up to 4.2; detected once per process), else
    /// [`Lanes::scalar`]. Worth it only in code compiled with those features (see [`Lanes`]);
    /// the results are the same either way.
    pub fn detect() -> Lanes {
        Lanes {
            #[cfg(target_arch = "x86_64")]
            v3: pulp::x86::V3::try_new(),
        }
    }

    /// Whether the eight-lane kernel is used.
    pub fn is_wide(self) -> bool {
        #[cfg(target_arch = "x86_64")]
        return self.v3.is_some();
        #[cfg(not(target_arch = "x86_64"))]
        false
    }

    /// The bilinear blend of the linear 8-bit quad whose rows are `r0 = [T00, T10]` and
    /// `r1 = [T01, T11]`, with fractions `a` (along x) and `b` (along y), in eight lanes: each
    /// byte decoded to `b / 255` (exactly [`crate::storage::fetch`]'s `Unorm8`), then
    /// `lerp(lerp(T00, T10, a), lerp(T01, T11, a), b)`, bit for bit the four-lane kernel.
    /// `None` when this is [`Lanes::scalar`]: the caller then runs the four-lane kernel (an
    /// `Option`, not a fallback closure: closures can stay outlined, compiled for the baseline).
    #[inline(always)]
    pub(crate) fn bilinear_unorm8(
        self,
        (r0, r1): ([[u8; 4]; 2], [[u8; 4]; 2]),
        (a, b): (f32, f32),
    ) -> Option<Vec4> {
        #[cfg(target_arch = "x86_64")]
        if let Some(simd) = self.v3 {
            return Some(bilinear_unorm8_v3(simd, (r0, r1), (a, b)));
        }
        let _ = (r0, r1, a, b);
        None
    }

    /// [`Lanes::bilinear_unorm8`] of each sample of `run` (every quad inside the `width`-wide
    /// linear 8-bit level `texels`, read by [`crate::storage::fetch::quad_rows`]) into `out` (the run's
    /// length): `true`, or `false` with `out` untouched when this is [`Lanes::scalar`]. The
    /// token is tested once for the run, and the loop runs the eight-lane kernel alone. It is
    /// inlined into the batched sampler's instruction-set copies ([`crate::engine::dispatch`]), where
    /// the kernel's intrinsics inline on x86-64-v3 and -v4 (docs/decisions.md).
    #[inline(always)]
    pub(crate) fn bilinear_unorm8_run(
        self,
        texels: &[[u8; 4]],
        width: u32,
        run: Run<'_>,
        out: &mut [[f32; 4]],
    ) -> bool {
        #[cfg(target_arch = "x86_64")]
        if let Some(simd) = self.v3 {
            // Plain zips: no closure in the loop (a closure can stay an outlined call, compiled
            // for the baseline).
            let taps = run.i.iter().zip(run.j);
            let fractions = run.a.iter().zip(run.b);
            for (o, ((&i, &j), (&a, &b))) in out.iter_mut().zip(taps.zip(fractions)) {
                let rows = quad_rows(texels, width, i as u32, j as u32);
                *o = bilinear_unorm8_v3(simd, rows, (a, b)).to_array();
            }
            return true;
        }
        let _ = (texels, width, run, out);
        false
    }

    /// The fixed-point bilinear blend of stored codes (`crate::kernel::fixed8`'s `bilinear8`)
    /// of the quad whose rows are `r0 = [T00, T10]` and `r1 = [T01, T11]`, with the 8-bit
    /// weights `wa`, `wb` (`0.0..=256.0`), in eight lanes; `None` when this is
    /// [`Lanes::scalar`].
    #[inline(always)]
    pub(crate) fn bilinear_codes8(
        self,
        (r0, r1): ([[u8; 4]; 2], [[u8; 4]; 2]),
        (wa, wb): (f32, f32),
    ) -> Option<Vec4> {
        #[cfg(target_arch = "x86_64")]
        if let Some(simd) = self.v3 {
            return Some(bilinear_codes8_v3(simd, (r0, r1), (wa, wb)));
        }
        let _ = (r0, r1, wa, wb);
        None
    }

    /// The fixed-point bilinear blend of stored codes (`crate::kernel::fixed8`'s `bilinear8`)
    /// for each sample of `weights` (every quad inside the `width`-wide level `texels`; its `a`
    /// and `b` are the 8-bit weights `round(256 a)`, `round(256 b)`, not the fractions) into
    /// `out` (the run's length), as codes `0.0..=255.0`: four quads at a time in sixteen `u16`
    /// lanes, the rest in `f32` lanes. `true`, or `false` with `out` untouched when this is
    /// [`Lanes::scalar`].
    #[inline(always)]
    pub(crate) fn bilinear_codes8_run(
        self,
        texels: &[[u8; 4]],
        width: u32,
        weights: Run<'_>,
        out: &mut [[f32; 4]],
    ) -> bool {
        #[cfg(target_arch = "x86_64")]
        if let Some(simd) = self.v3 {
            // Four samples at a time in sixteen `u16` lanes, the rest one by one in `f32` lanes
            // (the same integers).
            let n = out.len();
            let quads = n / 4 * 4;
            let (ws, taps) = (
                weights.a.iter().zip(weights.b),
                weights.i.iter().zip(weights.j),
            );
            let groups = out[..quads].chunks_exact_mut(4);
            for (k, o) in groups.enumerate() {
                let k = 4 * k;
                let rows: [_; 4] = std::array::from_fn(|s| {
                    let (i, j) = (weights.i[k + s], weights.j[k + s]);
                    quad_rows(texels, width, i as u32, j as u32)
                });
                let wa: [f32; 4] = std::array::from_fn(|s| weights.a[k + s]);
                let wb: [f32; 4] = std::array::from_fn(|s| weights.b[k + s]);
                let codes = bilinear_codes8_x4(simd, rows, (wa, wb));
                o.copy_from_slice(&codes);
            }
            let tail = taps.zip(ws).skip(quads);
            for (o, ((&i, &j), (&wa, &wb))) in out[quads..].iter_mut().zip(tail) {
                let rows = quad_rows(texels, width, i as u32, j as u32);
                *o = bilinear_codes8_v3(simd, rows, (wa, wb)).to_array();
            }
            return true;
        }
        let _ = (texels, width, weights, out);
        false
    }
}

/// The fixed-point bilinear blend (`crate::kernel::fixed8`'s `bilinear8`) of one quad of stored
/// codes with the 8-bit weights `wa`, `wb` (`0.0..=256.0`) in `f32` lanes: both rows' x-blends
/// `round_staged((x (256 - A) + y A + 1/2) / 256)` in eight lanes, the y-blend in four. Every
/// intermediate is an integer (or one plus a half) below `2^24`, exact in `f32`, so the lanes'
/// grouping gives the four-lane kernel's bits.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
fn bilinear_codes8_v3(
    simd: pulp::x86::V3,
    (r0, r1): ([[u8; 4]; 2], [[u8; 4]; 2]),
    (wa, wb): (f32, f32),
) -> Vec4 {
    let (avx, sse) = (simd.avx, simd.sse);
    let (row0, row1) = (codes_v3(simd, r0), codes_v3(simd, r1));
    // [T00 | T01] and [T10 | T11].
    let left = avx._mm256_permute2f128_ps::<0x20>(row0, row1);
    let right = avx._mm256_permute2f128_ps::<0x31>(row0, row1);
    let sum = avx._mm256_add_ps(
        avx._mm256_mul_ps(left, avx._mm256_set1_ps(256.0 - wa)),
        avx._mm256_mul_ps(right, avx._mm256_set1_ps(wa)),
    );
    let half = avx._mm256_add_ps(sum, avx._mm256_set1_ps(0.5));
    let scaled = avx._mm256_mul_ps(half, avx._mm256_set1_ps(1.0 / 256.0));
    let r = avx._mm256_set1_ps(ROUND_F32);
    let x = avx._mm256_sub_ps(avx._mm256_add_ps(scaled, r), r);
    let (x0, x1) = (
        avx._mm256_castps256_ps128(x),
        avx._mm256_extractf128_ps::<1>(x),
    );
    let y = sse._mm_add_ps(
        sse._mm_mul_ps(x0, sse._mm_set1_ps(256.0 - wb)),
        sse._mm_mul_ps(x1, sse._mm_set1_ps(wb)),
    );
    let y = sse._mm_add_ps(y, sse._mm_set1_ps(0.5));
    round_staged4(Vec4::from(sse._mm_mul_ps(y, sse._mm_set1_ps(1.0 / 256.0))))
}

/// A quad of 8-bit texels as [`quad_rows`] reads it: `([T00, T10], [T01, T11])`.
#[cfg(target_arch = "x86_64")]
type QuadRows = ([[u8; 4]; 2], [[u8; 4]; 2]);

/// The fixed-point blend of codes `x` and `y` by the weights `w` (all in `0..=256`, per `u16`
/// lane): `floor((x (256 - w) + y w + 128) / 256)`, as `x + ((y - x) w + 128) >> 8` in wrapping
/// 16-bit arithmetic, masked to its low byte. The true value is a code, and every step is exact
/// modulo `2^16` and the logical shift exact modulo `2^8`, so the low byte is the value.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
fn lerp8_u16(
    simd: pulp::x86::V3,
    x: std::arch::x86_64::__m256i,
    y: std::arch::x86_64::__m256i,
    w: std::arch::x86_64::__m256i,
) -> std::arch::x86_64::__m256i {
    let (avx, avx2) = (simd.avx, simd.avx2);
    let p = avx2._mm256_mullo_epi16(avx2._mm256_sub_epi16(y, x), w);
    let q = avx2._mm256_srli_epi16::<8>(avx2._mm256_add_epi16(p, avx._mm256_set1_epi16(128)));
    avx2._mm256_and_si256(avx2._mm256_add_epi16(x, q), avx._mm256_set1_epi16(0xff))
}

/// [`bilinear_codes8_v3`] for four quads at once, in sixteen `u16` lanes (llvmpipe's and
/// tiny-skia's form): each quad's 16 bytes widened to `[T00 T10 | T01 T11]`, two quads' texels
/// regrouped into `[T00 T00' | T01 T01']` and `[T10 T10' | T11 T11']` so that one [`lerp8_u16`]
/// blends both rows of two quads along x, then the four quads' rows along y in one more. The
/// integer definition's own arithmetic, so the same codes as the `f32` lanes.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
fn bilinear_codes8_x4(
    simd: pulp::x86::V3,
    rows: [QuadRows; 4],
    (wa, wb): ([f32; 4], [f32; 4]),
) -> [[f32; 4]; 4] {
    use pulp::bytemuck::cast;
    let (avx, avx2, sse2, ssse3) = (simd.avx, simd.avx2, simd.sse2, simd.ssse3);
    let word = |r: [[u8; 4]; 2]| {
        u64::from(u32::from_le_bytes(r[0])) | u64::from(u32::from_le_bytes(r[1])) << 32
    };
    // Per quad: [T00 T10 | T01 T11], each texel four u16 lanes.
    let q = rows.map(|(r0, r1)| {
        avx2._mm256_cvtepu8_epi16(sse2._mm_set_epi64x(word(r1) as i64, word(r0) as i64))
    });
    // The weights as integers (they are exact), each quad's spread over four u16 lanes: `AB`
    // picks quads 0 and 1's low halves, `CD` quads 2 and 3's.
    let ab = sse2._mm_setr_epi8(0, 1, 0, 1, 0, 1, 0, 1, 4, 5, 4, 5, 4, 5, 4, 5);
    let cd = sse2._mm_setr_epi8(8, 9, 8, 9, 8, 9, 8, 9, 12, 13, 12, 13, 12, 13, 12, 13);
    let wa = sse2._mm_cvtps_epi32(cast(wa));
    let wb = sse2._mm_cvtps_epi32(cast(wb));
    let wa_ab = avx2._mm256_broadcastsi128_si256(ssse3._mm_shuffle_epi8(wa, ab));
    let wa_cd = avx2._mm256_broadcastsi128_si256(ssse3._mm_shuffle_epi8(wa, cd));
    let wb = avx._mm256_set_m128i(
        ssse3._mm_shuffle_epi8(wb, cd),
        ssse3._mm_shuffle_epi8(wb, ab),
    );
    // x-blends: [x0 x0' | x1 x1'] for quads (0, 1) and (2, 3).
    let x01 = lerp8_u16(
        simd,
        avx2._mm256_unpacklo_epi64(q[0], q[1]),
        avx2._mm256_unpackhi_epi64(q[0], q[1]),
        wa_ab,
    );
    let x23 = lerp8_u16(
        simd,
        avx2._mm256_unpacklo_epi64(q[2], q[3]),
        avx2._mm256_unpackhi_epi64(q[2], q[3]),
        wa_cd,
    );
    // y-blend of [x0 of quads 0..4] and [x1 of quads 0..4].
    let top = avx2._mm256_permute2x128_si256::<0x20>(x01, x23);
    let bottom = avx2._mm256_permute2x128_si256::<0x31>(x01, x23);
    let y = lerp8_u16(simd, top, bottom, wb);
    let lo = avx._mm256_cvtepi32_ps(avx2._mm256_cvtepu16_epi32(avx._mm256_castsi256_si128(y)));
    let hi =
        avx._mm256_cvtepi32_ps(avx2._mm256_cvtepu16_epi32(avx2._mm256_extracti128_si256::<1>(y)));
    let (lo, hi): ([[f32; 4]; 2], [[f32; 4]; 2]) = (cast(lo), cast(hi));
    [lo[0], lo[1], hi[0], hi[1]]
}

/// A row of two 8-bit texels as eight `f32` lanes of their codes (`0.0..=255.0`).
#[cfg(target_arch = "x86_64")]
#[inline(always)]
fn codes_v3(simd: pulp::x86::V3, r: [[u8; 4]; 2]) -> std::arch::x86_64::__m256 {
    let (avx, avx2, sse2) = (simd.avx, simd.avx2, simd.sse2);
    let bytes = u64::from(u32::from_le_bytes(r[0])) | u64::from(u32::from_le_bytes(r[1])) << 32;
    let x = sse2._mm_set_epi64x(0, bytes as i64);
    avx._mm256_cvtepi32_ps(avx2._mm256_cvtepu8_epi32(x))
}

/// [`Lanes::bilinear_unorm8`] in AVX2's eight lanes. A row of two texels (8 bytes) becomes eight
/// `f32` lanes `[t.r, t.g, t.b, t.a, t'.r, ..]`; the decode runs on both rows; the rows are
/// regrouped into `[T00 | T01]` and `[T10 | T11]` so that one eight-lane lerp by `a` gives both
/// rows' x-lerps, whose halves the final four-lane lerp by `b` blends.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
fn bilinear_unorm8_v3(
    simd: pulp::x86::V3,
    (r0, r1): ([[u8; 4]; 2], [[u8; 4]; 2]),
    (a, b): (f32, f32),
) -> Vec4 {
    let (avx, sse) = (simd.avx, simd.sse);
    let (row0, row1) = (row_v3(simd, r0), row_v3(simd, r1));
    // [T00 | T01] and [T10 | T11].
    let left = avx._mm256_permute2f128_ps::<0x20>(row0, row1);
    let right = avx._mm256_permute2f128_ps::<0x31>(row0, row1);
    let x = avx._mm256_add_ps(
        left,
        avx._mm256_mul_ps(avx._mm256_sub_ps(right, left), avx._mm256_set1_ps(a)),
    );
    let (x0, x1) = (
        avx._mm256_castps256_ps128(x),
        avx._mm256_extractf128_ps::<1>(x),
    );
    let y = sse._mm_add_ps(
        x0,
        sse._mm_mul_ps(sse._mm_sub_ps(x1, x0), sse._mm_set1_ps(b)),
    );
    Vec4::from(y)
}

/// A row of two linear 8-bit texels as eight decoded `f32` lanes, `b * hi + b * lo` per byte
/// ([`crate::storage::fetch`]'s `unorm8_lanes`). A function, not a closure: a closure stays an outlined
/// function compiled for the baseline, where every intrinsic is a call (docs/decisions.md).
#[cfg(target_arch = "x86_64")]
#[inline(always)]
fn row_v3(simd: pulp::x86::V3, r: [[u8; 4]; 2]) -> std::arch::x86_64::__m256 {
    let avx = simd.avx;
    let x = codes_v3(simd, r);
    avx._mm256_add_ps(
        avx._mm256_mul_ps(x, avx._mm256_set1_ps(UNORM8_HI)),
        avx._mm256_mul_ps(x, avx._mm256_set1_ps(UNORM8_LO)),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::base::lerp::blend;
    use crate::base::rng::SplitMix64;
    use crate::storage::fetch::{Decode, Unorm8};

    /// The eight-lane kernel equals the four-lane one bit for bit: random quads (every byte value
    /// reached), fractions at the ends of `[0, 1)`, at halves, near 1, and random; both kernels
    /// from the same bytes.
    #[test]
    fn wide_kernel_equals_the_scalar_one() {
        let wide = Lanes::detect();
        if !wide.is_wide() {
            println!("skipped: this CPU has no AVX2 (x86-64-v3); only the scalar kernel runs");
            return;
        }
        let scalar = Unorm8::default();
        let mut rng = SplitMix64::new(7);
        let mut fractions = vec![0.0, 0.5, 0.25, 1.0 - f32::EPSILON / 2.0, 1e-7, 0.999];
        fractions.extend((0..26).map(|_| rng.next_f32()));
        let mut compared = 0;
        for q in 0..2000u32 {
            let mut bytes = [0u8; 16];
            for (k, b) in bytes.iter_mut().enumerate() {
                // The first quads cover every byte value in every lane.
                *b = if q < 256 {
                    (q as usize + 17 * k) as u8
                } else {
                    rng.next_u64() as u8
                };
            }
            let t: [[u8; 4]; 4] =
                std::array::from_fn(|k| std::array::from_fn(|c| bytes[4 * k + c]));
            for &a in &fractions {
                for &b in fractions.iter().step_by(3) {
                    let want = blend(scalar.decode4(t), a, b);
                    let got = wide
                        .bilinear_unorm8(([t[0], t[1]], [t[2], t[3]]), (a, b))
                        .expect("the wide kernel");
                    assert_eq!(
                        got.to_array().map(f32::to_bits),
                        want.to_array().map(f32::to_bits)
                    );
                    compared += 1;
                }
            }
        }
        assert_eq!(compared, 2000 * 32 * 11);
    }

    /// The wrapping `u16` blend equals its integer definition
    /// `floor((x (256 - w) + y w + 128) / 256)` for every pair of codes and every 8-bit weight,
    /// sixteen cases a call (the lanes differ in `y`, so every lane is checked).
    #[cfg(target_arch = "x86_64")]
    #[test]
    fn u16_blend_equals_the_integer_definition() {
        use pulp::bytemuck::cast;
        let Some(simd) = Lanes::detect().v3 else {
            println!("skipped: this CPU has no AVX2 (x86-64-v3); only the scalar kernel runs");
            return;
        };
        let mut compared = 0u32;
        for w in 0..=256u16 {
            for x in 0..256u16 {
                for y0 in (0..256u16).step_by(16) {
                    let ys: [u16; 16] = std::array::from_fn(|k| y0 + k as u16);
                    let got: [u16; 16] =
                        cast(lerp8_u16(simd, cast([x; 16]), cast(ys), cast([w; 16])));
                    for (g, y) in got.iter().zip(ys) {
                        let (x, y, w) = (u32::from(x), u32::from(y), u32::from(w));
                        let want = (x * (256 - w) + y * w + 128) / 256;
                        assert_eq!(u32::from(*g), want, "{x} {y} {w}");
                        compared += 1;
                    }
                }
            }
        }
        assert_eq!(compared, 257 * 256 * 256);
    }

    /// The run kernel ([`Lanes::bilinear_unorm8_run`]) equals the four-lane kernel sample by
    /// sample over every quad of small levels, random texels and fractions; the last quad of each
    /// level ends at its last texel (the edge of `quad_rows`' one range check). On
    /// [`Lanes::scalar`] it declines and leaves the output untouched.
    #[test]
    fn run_kernel_equals_the_scalar_one() {
        let mut rng = SplitMix64::new(11);
        let scalar = Unorm8::default();
        for (w, h) in [(2u32, 2u32), (7, 5), (3, 9), (16, 2)] {
            let texels: Vec<[u8; 4]> = (0..w * h)
                .map(|_| {
                    let x = rng.next_u64().to_le_bytes();
                    [x[0], x[1], x[2], x[3]]
                })
                .collect();
            let (mut i, mut j, mut a, mut b) = (vec![], vec![], vec![], vec![]);
            for jj in 0..h - 1 {
                for ii in 0..w - 1 {
                    i.push(ii as i32);
                    j.push(jj as i32);
                    a.push(rng.next_f32());
                    b.push(rng.next_f32());
                }
            }
            // The fraction ends, once each.
            (a[0], b[0]) = (0.0, 1.0 - f32::EPSILON / 2.0);
            let run = Run {
                i: &i,
                j: &j,
                a: &a,
                b: &b,
            };
            let mut out = vec![[f32::NAN; 4]; i.len()];
            assert!(!Lanes::scalar().bilinear_unorm8_run(&texels, w, run, &mut out));
            assert!(out.iter().flatten().all(|x| x.is_nan()));
            let wide = Lanes::detect();
            if !wide.is_wide() {
                println!("skipped: this CPU has no AVX2 (x86-64-v3); only the scalar kernel runs");
                return;
            }
            assert!(wide.bilinear_unorm8_run(&texels, w, run, &mut out));
            for k in 0..i.len() {
                let at = |di: i32, dj: i32| texels[((j[k] + dj) * w as i32 + i[k] + di) as usize];
                let quad = [at(0, 0), at(1, 0), at(0, 1), at(1, 1)];
                let want = blend(scalar.decode4(quad), a[k], b[k]);
                let (got, want) = (out[k].map(f32::to_bits), want.to_array().map(f32::to_bits));
                assert_eq!(got, want, "{w}x{h} quad {} {}", i[k], j[k]);
            }
        }
    }
}
