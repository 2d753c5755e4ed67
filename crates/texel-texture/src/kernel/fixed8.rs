//! GPU-style fixed-point filtering of 8-bit unorm textures (the CLI's `--precision gpu`).
//!
//! texel filters in `f32` by default: every texel decoded to a float, weights and blends in
//! single precision, the result encoded once at the end. Hardware samplers (and llvmpipe, which
//! blends unorm8 texels in 16-bit lanes) work on the stored 8-bit codes with weights of a few
//! bits: Vulkan exposes them as `subTexelPrecisionBits` (at least 4; 8 is common on desktop GPUs)
//! and `mipmapPrecisionBits` (at least 4). This module defines texel's version, with 8 bits for
//! both and round-to-nearest wherever a result is narrowed:
//!
//! - **sub-texel weight**: a fraction `a` in `[0, 1)` becomes `A = round(256 a)` in `0..=256`
//!   ([`weight8`]);
//! - **blend**: two codes `x`, `y` with weight `W` on `y` become
//!   `floor((x (256 - W) + y W + 128) / 256)`, their mean under the 8-bit weight rounded to the
//!   nearest code, halves up ([`lerp8`]): in integer lanes a multiply, an addition of 128 and a
//!   shift by 8, as llvmpipe's and tiny-skia's 16-bit blends compute it;
//! - **bilinear**: the blend along x of each row of the quad by `A`, then the blend of the two
//!   rows along y by `B` ([`bilinear8`]), each rounded to a code;
//! - **mip blend**: `D = round(256 delta)`, the blend of the two levels' codes by `D` ([`mix8`]).
//!
//! The weights round halves to even (IEEE's default, so `round(256 a)` costs an addition and a
//! subtraction: [`crate::base::floor::round_staged`]); a blend's rounding never meets a tie in
//! that form, since `(n + 1/2) / 256` is never a half-integer, so `floor((n + 128) / 256)` is
//! `round_staged((n + 1/2) / 256)` (hardware documents only its precision, not its tie rule).
//!
//! Level selection (the lod) is the `f32` path's, so both read the same texels. Every value is an
//! integer below `2^24`, so `f32` holds it exactly: the one-sample kernels run in the `f32` lanes
//! the other filters use, on codes as floats (`0.0..=255.0`), and equal the integer definitions
//! bit for bit (tested against them). On AVX2 a run of quads inside one level blends in sixteen
//! `u16` lanes, four samples at a time (`storage::lanes`), with the integer definitions' own
//! arithmetic.
//!
//! Only unorm textures: an sRGB texture must be decoded to linear before it is filtered
//! (Vulkan spec, "Texel Filtering"), so hardware decodes sRGB texels to more than 8 bits first,
//! and texel keeps its `f32` path for them. Against the `f32` path a fixed-point sample differs
//! by the weights' quantisation (at most `255 / 512` of a code per weight), plus the one
//! rounding per stage; the images' differences are measured in docs/decisions.md.

use glam::{Vec2, Vec4};

use crate::base::address::Address;
use crate::base::floor::{round_staged, round_staged4};
use crate::kernel::bilinear;
use crate::kernel::nearest;
use crate::kernel::staged::{Taps, CHUNK};
use crate::kernel::LevelFilter;
use crate::storage::fetch::Fetch;
use crate::storage::lanes::Run;

/// The 8-bit weight of a fraction `a` in `[0, 1]`: `round(256 a)` (halves to even), in
/// `0..=256`. A fraction outside `[0, 1]` is clamped first; NaN gives 0.
#[inline(always)]
pub fn weight8(a: f32) -> f32 {
    // `max` returns the non-NaN operand, so NaN becomes 0 (`clamp` would keep NaN).
    #[allow(clippy::manual_clamp)]
    let a = a.max(0.0).min(1.0);
    round_staged(a * 256.0)
}

/// The fixed-point blend of codes `x` and `y` (per channel, `0.0..=255.0`) with the 8-bit weight
/// `w` (`0.0..=256.0`) on `y`: `floor((x (256 - w) + y w + 128) / 256)`, computed as
/// `round_staged((x (256 - w) + y w + 1/2) / 256)` (every value exact in `f32`, and never a tie).
#[inline(always)]
pub fn lerp8(x: Vec4, y: Vec4, w: f32) -> Vec4 {
    round_staged4((x * (256.0 - w) + y * w + Vec4::splat(0.5)) * (1.0 / 256.0))
}

/// The fixed-point bilinear blend of four codes `[T00, T10, T01, T11]` (each `0.0..=255.0`, one
/// vector per texel, per channel) with fractions `a` (along x) and `b` (along y): each row
/// blended along x by the 8-bit weight [`weight8`] of `a`, then the rows along y by that of `b`,
/// each blend rounded to a code ([`lerp8`]).
#[inline(always)]
pub fn bilinear8(quad: [Vec4; 4], a: f32, b: f32) -> Vec4 {
    bilinear8_weighted(quad, weight8(a), weight8(b))
}

/// [`bilinear8`] with the 8-bit weights `wa`, `wb` (`0.0..=256.0`) already made.
#[inline(always)]
fn bilinear8_weighted([t00, t10, t01, t11]: [Vec4; 4], wa: f32, wb: f32) -> Vec4 {
    lerp8(lerp8(t00, t10, wa), lerp8(t01, t11, wa), wb)
}

/// The fixed-point blend of two codes `a` and `b` (per channel, `0.0..=255.0`) with weight
/// `delta` on `b`: [`lerp8`] by `D = weight8(delta)`.
#[inline(always)]
pub fn mix8(a: Vec4, b: Vec4, delta: f32) -> Vec4 {
    lerp8(a, b, weight8(delta))
}

/// Nearest on codes with [`mix8`] between levels (a nearest sample itself has no arithmetic).
#[derive(Clone, Copy)]
pub(crate) struct Point8;

impl LevelFilter for Point8 {
    #[inline(always)]
    fn filter<F: Fetch>(self, level: &F, addr: &Address, uv: Vec2) -> Vec4 {
        nearest::nearest(level, addr, uv)
    }
}

impl Taps for Point8 {
    const HALF: f32 = nearest::HALF;
    const REACH: f32 = 0.0;
    #[inline(always)]
    fn inside<F: Fetch>(level: &F, i: u32, j: u32, _: (f32, f32)) -> Vec4 {
        level.texel(i, j)
    }
    #[inline(always)]
    fn wrapped<F: Fetch>(level: &F, i: [u32; 2], j: [u32; 2], _: (f32, f32)) -> Vec4 {
        level.texel(i[0], j[0])
    }
    #[inline(always)]
    fn mix(a: Vec4, b: Vec4, t: f32) -> Vec4 {
        mix8(a, b, t)
    }
}

/// Bilinear on codes: [`bilinear8`] of the taps [`crate::kernel::bilinear`] reads, [`mix8`] between
/// levels.
#[derive(Clone, Copy)]
pub(crate) struct Bilinear8;

impl LevelFilter for Bilinear8 {
    #[inline(always)]
    fn filter<F: Fetch>(self, level: &F, addr: &Address, uv: Vec2) -> Vec4 {
        let (quad, a, b) = bilinear::taps(level, addr, uv);
        bilinear8(quad, a, b)
    }
}

impl Taps for Bilinear8 {
    const HALF: f32 = bilinear::HALF;
    const REACH: f32 = 1.0;
    /// [`bilinear8`], in the view's eight lanes where it has them ([`Fetch::bilinear_codes8`]:
    /// the same bits).
    #[inline(always)]
    fn inside<F: Fetch>(level: &F, i: u32, j: u32, (a, b): (f32, f32)) -> Vec4 {
        let (wa, wb) = (weight8(a), weight8(b));
        match level.bilinear_codes8(i, j, wa, wb) {
            Some(v) => v,
            None => bilinear8_weighted(level.quad(i, j), wa, wb),
        }
    }
    /// The run's 8-bit weights ([`weight8`]) in one loop, then the view's run kernel
    /// ([`Fetch::bilinear_codes8_run`]), which equals [`bilinear8`] bit for bit.
    #[inline(always)]
    fn inside_run<F: Fetch>(level: &F, run: Run<'_>, out: &mut [[f32; 4]]) -> bool {
        let n = run.a.len();
        if n > CHUNK {
            return false;
        }
        let (mut wa, mut wb) = ([0.0f32; CHUNK], [0.0f32; CHUNK]);
        for k in 0..n {
            wa[k] = weight8(run.a[k]);
            wb[k] = weight8(run.b[k]);
        }
        let weights = Run {
            a: &wa[..n],
            b: &wb[..n],
            ..run
        };
        level.bilinear_codes8_run(weights, out)
    }
    #[inline(always)]
    fn wrapped<F: Fetch>(level: &F, i: [u32; 2], j: [u32; 2], (a, b): (f32, f32)) -> Vec4 {
        bilinear8(crate::storage::fetch::wrapped_quad(level, i, j), a, b)
    }
    #[inline(always)]
    fn mix(a: Vec4, b: Vec4, t: f32) -> Vec4 {
        mix8(a, b, t)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The integer definitions the module documents.
    fn weight_int(a: f32) -> u64 {
        (f64::from(a) * 256.0).round_ties_even() as u64
    }

    fn lerp_int(x: u64, y: u64, w: u64) -> u64 {
        (x * (256 - w) + y * w + 128) >> 8
    }

    fn bilinear_int(t: [u64; 4], a: f32, b: f32) -> u64 {
        let (wa, wb) = (weight_int(a), weight_int(b));
        lerp_int(lerp_int(t[0], t[1], wa), lerp_int(t[2], t[3], wa), wb)
    }

    fn mix_int(a: u64, b: u64, delta: f32) -> u64 {
        lerp_int(a, b, weight_int(delta))
    }

    #[test]
    fn weights_round_to_nearest_256th() {
        assert_eq!(weight8(0.0), 0.0);
        assert_eq!(weight8(1.0), 256.0);
        assert_eq!(weight8(0.5), 128.0);
        assert_eq!(weight8(1.0 / 512.0), 0.0); // halves to even
        assert_eq!(weight8(3.0 / 512.0), 2.0);
        assert_eq!(weight8(0.999), 256.0);
        assert_eq!(weight8(-3.0), 0.0);
        assert_eq!(weight8(f32::NAN), 0.0);
        for k in 0..=256 {
            assert_eq!(weight8(k as f32 / 256.0), k as f32);
        }
    }

    /// Every fraction step of 1/4096 and a spread of code quads: the `f32` kernels equal the
    /// integer definitions, and the result lies within the quad's codes.
    #[test]
    fn bilinear8_equals_the_integer_definition() {
        let quads = [
            [0, 0, 0, 0],
            [255, 255, 255, 255],
            [0, 255, 255, 0],
            [255, 0, 0, 255],
            [12, 200, 97, 31],
            [1, 2, 3, 4],
            [254, 255, 0, 1],
        ];
        for q in quads {
            let t = q.map(|c| Vec4::splat(c as f32));
            let (lo, hi) = (*q.iter().min().unwrap(), *q.iter().max().unwrap());
            for i in 0..=64 {
                for j in 0..=64 {
                    let (a, b) = (i as f32 / 64.0 * 0.999, j as f32 / 64.0 * 0.999);
                    let got = bilinear8(t, a, b).x;
                    let want = bilinear_int(q, a, b);
                    assert_eq!(got, want as f32, "{q:?} {a} {b}");
                    assert!((lo..=hi).contains(&want));
                }
            }
        }
        // Every code pair along one axis, every weight.
        for c0 in (0..256).step_by(5) {
            for c1 in (0..256).step_by(3) {
                for w in 0..=256 {
                    let a = w as f32 / 256.0;
                    let t = [c0, c1, c0, c1].map(|c| Vec4::splat(c as f32));
                    assert_eq!(
                        bilinear8(t, a, 0.0).x,
                        bilinear_int([c0, c1, c0, c1], a, 0.0) as f32
                    );
                    let (x, y) = (Vec4::splat(c0 as f32), Vec4::splat(c1 as f32));
                    assert_eq!(mix8(x, y, a).x, mix_int(c0, c1, a) as f32);
                }
            }
        }
    }

    /// The run kernel ([`Fetch::bilinear_codes8_run`] on a level of codes with an AVX2 token:
    /// groups of four in `u16` lanes, the tail in `f32` lanes) equals [`bilinear8`] bit for bit
    /// over every quad of a random level and every length of tail, with fractions at 0, at the
    /// weights' rounding ties and near 1; the scalar token declines.
    #[test]
    fn the_run_kernel_equals_bilinear8() {
        use crate::base::rng::SplitMix64;
        use crate::storage::fetch::{Codes8, Level};
        use crate::storage::lanes::Lanes;
        let mut rng = SplitMix64::new(5);
        let (w, h) = (9u32, 7u32);
        let texels: Vec<[u8; 4]> = (0..w * h)
            .map(|_| {
                let x = rng.next_u64().to_le_bytes();
                [x[0], x[1], x[2], x[3]]
            })
            .collect();
        let level = |lanes| Level {
            width: w,
            height: h,
            texels: &texels,
            decode: Codes8 { lanes },
        };
        let (mut i, mut j, mut a, mut b) = (vec![], vec![], vec![], vec![]);
        let ends = [0.0, 1.0 / 512.0, 3.0 / 512.0, 0.5, 0.999_999];
        for (k, (ii, jj)) in (0..h - 1)
            .flat_map(|jj| (0..w - 1).map(move |ii| (ii, jj)))
            .enumerate()
        {
            i.push(ii as i32);
            j.push(jj as i32);
            a.push(if k < ends.len() {
                ends[k]
            } else {
                rng.next_f32()
            });
            b.push(if k < ends.len() {
                ends[ends.len() - 1 - k]
            } else {
                rng.next_f32()
            });
        }
        let run = Run {
            i: &i,
            j: &j,
            a: &a,
            b: &b,
        };
        let mut out = vec![[f32::NAN; 4]; i.len()];
        assert!(!Bilinear8::inside_run(
            &level(Lanes::scalar()),
            run,
            &mut out
        ));
        let wide = Lanes::detect();
        if !wide.is_wide() {
            println!("skipped: this CPU has no AVX2 (x86-64-v3); only the scalar kernel runs");
            return;
        }
        let scalar = level(Lanes::scalar());
        // Whole groups of four and every length of tail.
        for n in [i.len(), i.len() - 1, i.len() - 2, i.len() - 3, 3, 1] {
            let run = Run {
                i: &i[..n],
                j: &j[..n],
                a: &a[..n],
                b: &b[..n],
            };
            let out = &mut out[..n];
            assert!(Bilinear8::inside_run(&level(wide), run, out));
            for k in 0..n {
                let want = bilinear8(scalar.quad(i[k] as u32, j[k] as u32), a[k], b[k]);
                assert_eq!(out[k], want.to_array(), "{n}: quad {} {}", i[k], j[k]);
            }
        }
    }

    /// Against the exact blend of the codes: within half a code per blend plus the weights'
    /// quantisation.
    #[test]
    fn bilinear8_is_near_the_exact_blend() {
        let q = [12.0f32, 200.0, 97.0, 31.0];
        let t = q.map(Vec4::splat);
        for i in 0..100 {
            for j in 0..100 {
                let (a, b) = (i as f32 / 100.0, j as f32 / 100.0);
                let exact =
                    (q[0] * (1.0 - a) + q[1] * a) * (1.0 - b) + (q[2] * (1.0 - a) + q[3] * a) * b;
                // Each weight moves by at most 1/512, the result by at most 255/512 per weight;
                // the row blends and the blend of the rows each round by at most half a code.
                let bound = 1.0 + 2.0 * 255.0 / 512.0;
                assert!((bilinear8(t, a, b).x - exact).abs() <= bound, "{a} {b}");
            }
        }
    }
}
