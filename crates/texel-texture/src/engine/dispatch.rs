//! Run-time instruction-set dispatch, and the non-temporal copies of streamed frames
//! ([`stream_copy`]): the one module of texel that uses `unsafe`.
//!
//! texel is compiled for the x86-64 baseline (SSE2), so one binary runs on every x86-64 CPU. Work
//! that implements [`Kernel`] gets two more copies: one compiled for x86-64-v3 (AVX2, FMA,
//! BMI1/2, F16C, LZCNT, MOVBE) and one for x86-64-v4 (v3 plus AVX-512 F, BW, CD, DQ and VL).
//! [`run`] runs the best copy whose every feature the CPU has ([`level`]), unless capped
//! ([`limit_level`]). The kernels are the batched sampler's (`Sampler::sample_batch` and its
//! stored-bytes and fixed-point forms: one per texel storage and within-level filter) and
//! texel-raster's tile rasterizer (coverage, interpolation, shading, encoding).
//!
//! Each copy is its own function (`#[inline(never)]`): a kernel that runs another kernel calls
//! that kernel's copy for the level, never inlines it. Why: the whole batched sampler inlined
//! into the tile rasterizer makes each of its three copies one very large function, nine tenths
//! of it the sampler's, and LLVM's time on a function grows faster than its size, so the release
//! build's time goes to texel-raster's one `rustc` (sizes and build times in docs/decisions.md).
//! A dispatch per sampled span of the rasterizer (up to 256
//! fragments; per 64-footprint chunk on the stored-codes paths) costs a few nanoseconds against
//! microseconds of filtering.
//!
//! Images are bit for bit the same on every copy: Rust never fuses a multiply and an add unless
//! asked (`mul_add`), and no code here asks, and without fast-math flags LLVM emits no
//! approximate instruction (AVX-512's `vrcp14`, `vrsqrt14`, `vgetexp` are not used for `/`,
//! `sqrt` or `log2`), so the wider instructions compute the same IEEE operations
//! (texel-raster's `tests/targets.rs` renders every view on every copy the CPU has and finds
//! them identical).
//!
//! The copies differ in one more way: `v3` and `v4` hand the kernel [`Lanes::detect`], the
//! sampler's eight-lane AVX2 quad kernel (safe intrinsics through `pulp`'s run-time token, bit for
//! bit the four-lane kernel), and the baseline copy [`Lanes::scalar`]: only inside a function
//! compiled with AVX2 do that kernel's intrinsics inline (in baseline code each would stay a
//! call).
//!
//! Safety argument: calling a `#[target_feature]` function is `unsafe` because running its
//! instructions on a CPU without the features is undefined behaviour. [`run`] calls `v3` only
//! when [`level`] is [`SimdLevel::X86_64V3`] and `v4` only when it is [`SimdLevel::X86_64V4`].
//! [`level`] is at most what `detect` found, and `detect` reports a level only when
//! `is_x86_feature_detected!` reported every feature that level's function enables (the lists in
//! `detect` are the ones the functions' attributes name; v4's includes v3's).
#![allow(unsafe_code)]

use std::sync::atomic::{AtomicU8, Ordering};
use std::sync::OnceLock;

use crate::storage::lanes::Lanes;

/// The instruction set the dispatched kernels (the sampler's batch kernels, the rasterizer's
/// tiles) run on, ordered from the least to the most.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum SimdLevel {
    /// The build's own target (x86-64: SSE2; other architectures: their baseline).
    Baseline,
    /// x86-64-v3: AVX2, FMA, BMI1, BMI2, F16C, LZCNT, MOVBE (and the v2 features below them).
    X86_64V3,
    /// x86-64-v4: x86-64-v3 plus AVX-512 F, BW, CD, DQ and VL.
    X86_64V4,
}

impl SimdLevel {
    /// Every level, from the least to the most.
    pub const ALL: [SimdLevel; 3] = [
        SimdLevel::Baseline,
        SimdLevel::X86_64V3,
        SimdLevel::X86_64V4,
    ];

    /// A short name for reports: `"x86-64-v4 (avx512)"`, `"x86-64-v3 (avx2+fma)"` or
    /// `"baseline (sse2)"`.
    pub fn name(self) -> &'static str {
        match self {
            SimdLevel::X86_64V4 => "x86-64-v4 (avx512)",
            SimdLevel::X86_64V3 => "x86-64-v3 (avx2+fma)",
            SimdLevel::Baseline if cfg!(target_arch = "x86_64") => "baseline (sse2)",
            SimdLevel::Baseline => "baseline",
        }
    }
}

/// Set by [`limit_level`]: the highest level allowed, as its index in [`SimdLevel::ALL`].
static LIMIT: AtomicU8 = AtomicU8::new(u8::MAX);

/// What the CPU supports, detected once: the best level whose every feature it has.
fn detected() -> SimdLevel {
    static DETECTED: OnceLock<SimdLevel> = OnceLock::new();
    *DETECTED.get_or_init(detect)
}

#[cfg(target_arch = "x86_64")]
fn detect() -> SimdLevel {
    let v3 = is_x86_feature_detected!("avx")
        && is_x86_feature_detected!("avx2")
        && is_x86_feature_detected!("fma")
        && is_x86_feature_detected!("bmi1")
        && is_x86_feature_detected!("bmi2")
        && is_x86_feature_detected!("f16c")
        && is_x86_feature_detected!("lzcnt")
        && is_x86_feature_detected!("movbe")
        && is_x86_feature_detected!("popcnt")
        && is_x86_feature_detected!("sse3")
        && is_x86_feature_detected!("ssse3")
        && is_x86_feature_detected!("sse4.1")
        && is_x86_feature_detected!("sse4.2");
    let v4 = v3
        && is_x86_feature_detected!("avx512f")
        && is_x86_feature_detected!("avx512bw")
        && is_x86_feature_detected!("avx512cd")
        && is_x86_feature_detected!("avx512dq")
        && is_x86_feature_detected!("avx512vl");
    if v4 {
        SimdLevel::X86_64V4
    } else if v3 {
        SimdLevel::X86_64V3
    } else {
        SimdLevel::Baseline
    }
}

#[cfg(not(target_arch = "x86_64"))]
fn detect() -> SimdLevel {
    SimdLevel::Baseline
}

/// The level [`run`] picks: the best the CPU has (detected once), or the limit set by
/// [`limit_level`] when that is lower.
pub fn level() -> SimdLevel {
    let limit = LIMIT.load(Ordering::Relaxed) as usize;
    detected().min(SimdLevel::ALL[limit.min(SimdLevel::ALL.len() - 1)])
}

/// Run every later kernel (sampler batches, rasterizer tiles) on a copy no higher than `max`
/// (`SimdLevel::Baseline`: the baseline copy; the highest level: the CPU's best again), for
/// comparing the copies. A level above the CPU's runs the CPU's best. Process-wide; images do
/// not depend on it.
pub fn limit_level(max: SimdLevel) {
    LIMIT.store(max as u8, Ordering::Relaxed);
}

/// Work compiled once per instruction set ([`run`]). Implementations should mark
/// [`Kernel::run`] `#[inline(always)]`, and so everything it calls that should be compiled with
/// the copy's features: a function left out of line (a closure's body, often) stays compiled for
/// the baseline, and the copy merely calls it.
pub trait Kernel {
    /// What the work returns.
    type Output;
    /// Do the work, sampling with `lanes`: [`Lanes::detect`] on the copies compiled with AVX2
    /// (where its kernels' intrinsics inline), [`Lanes::scalar`] on the baseline copy.
    fn run(self, lanes: Lanes) -> Self::Output;
}

/// The sampler's quad kernel for the copy [`run`] picks: [`Lanes::detect`] on x86-64-v3 and
/// above, [`Lanes::scalar`] on the baseline copy.
pub fn lanes() -> Lanes {
    if level() >= SimdLevel::X86_64V3 {
        Lanes::detect()
    } else {
        Lanes::scalar()
    }
}

/// Run `k` on the copy for [`level`]: its body (with everything it inlines) is compiled once
/// inside `baseline`, once inside `v3` and once inside `v4`, each a function of its own.
/// Costs a call, an atomic load and a `OnceLock` read; the result does not depend on the copy.
#[inline(always)]
pub fn run<K: Kernel>(k: K) -> K::Output {
    #[cfg(target_arch = "x86_64")]
    match level() {
        // SAFETY: `level()` is `X86_64V4` only when `detect` saw every feature `v4` enables.
        SimdLevel::X86_64V4 => return unsafe { v4(k) },
        // SAFETY: `level()` is at least `X86_64V3` only when `detect` saw every feature `v3`
        // enables.
        SimdLevel::X86_64V3 => return unsafe { v3(k) },
        SimdLevel::Baseline => {}
    }
    baseline(k)
}

/// `k.run(Lanes::scalar())` compiled for the build's target, as a function of its own.
#[inline(never)]
fn baseline<K: Kernel>(k: K) -> K::Output {
    k.run(Lanes::scalar())
}

/// `k.run(Lanes::detect())` compiled for x86-64-v3.
#[cfg(target_arch = "x86_64")]
#[target_feature(
    enable = "avx,avx2,fma,bmi1,bmi2,f16c,lzcnt,movbe,popcnt,sse3,ssse3,sse4.1,sse4.2"
)]
#[inline(never)]
unsafe fn v3<K: Kernel>(k: K) -> K::Output {
    k.run(Lanes::detect())
}

/// `k.run(Lanes::detect())` compiled for x86-64-v4.
#[cfg(target_arch = "x86_64")]
#[target_feature(
    enable = "avx,avx2,fma,bmi1,bmi2,f16c,lzcnt,movbe,popcnt,sse3,ssse3,sse4.1,sse4.2,avx512f,avx512bw,avx512cd,avx512dq,avx512vl"
)]
#[inline(never)]
unsafe fn v4<K: Kernel>(k: K) -> K::Output {
    k.run(Lanes::detect())
}

/// Element types [`stream_copy`] and [`stream_fill`] accept: plain data whose every byte is
/// initialised (no padding), so reading them as 16-byte vectors is defined. Sealed: `u8`, `u32`,
/// `f32`, `[u8; 4]` (an RGBA8 pixel) and `[f32; 4]` (an RGBA32F pixel).
pub trait StreamElement: Copy + sealed::Sealed {}

mod sealed {
    /// Keeps [`super::StreamElement`] to the types listed there.
    pub trait Sealed {}
}

macro_rules! stream_elements {
    ($($t:ty),*) => {$(
        impl sealed::Sealed for $t {}
        impl StreamElement for $t {}
    )*};
}
stream_elements!(u8, u32, f32, [u8; 4], [f32; 4]);

/// Copy `src` into `dst` (equal lengths) with non-temporal stores where the CPU has them
/// (x86-64: SSE2's `movntdq`, 64 bytes a step, then 16; plain copies for the bytes before `dst`'s
/// first 16-byte boundary and after its last): the destination's cache lines are written
/// without first being read from memory, and are not kept in the cache. For writing out a frame
/// larger than the cache, which nothing reads again soon. Elsewhere a plain copy.
///
/// The stores are weakly ordered: call [`stream_fence`] on the same thread before another
/// thread may read `dst` (before the work that wrote it is joined).
///
/// # Panics
/// If the lengths differ.
pub fn stream_copy<T: StreamElement>(dst: &mut [T], src: &[T]) {
    assert_eq!(dst.len(), src.len(), "stream_copy: lengths differ");
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::{__m128i, _mm_loadu_si128, _mm_stream_si128};
        let bytes = std::mem::size_of_val(src);
        let d = dst.as_mut_ptr().cast::<u8>();
        let s = src.as_ptr().cast::<u8>();
        let head = d.align_offset(16).min(bytes);
        let end = head + (bytes - head) / 16 * 16;
        // SAFETY: `dst` and `src` do not overlap (one is borrowed mutably) and both span `bytes`
        // bytes; every access below lies in `[0, bytes)`: the head `[0, head)`, 16-byte blocks
        // in `[head, end)` with `end <= bytes`, the tail `[k, bytes)`. Each `_mm_stream_si128`
        // address is `d + head + 16 m`, 16-byte aligned as it requires (`align_offset`);
        // `_mm_loadu_si128` takes any alignment. SSE2 is part of the x86-64 baseline. Every byte
        // of `src` is initialised (`StreamElement` types have no padding), so its 16-byte loads
        // read defined values; and any bytes of a `StreamElement` form a valid one (integers,
        // floats and arrays of them), so `dst` holds valid `T`s, the same as `copy_from_slice`.
        unsafe {
            // The head and tail are empty for rows of 16-byte multiples on 16-byte boundaries
            // (most frame rows): skip `memcpy`'s call and size dispatch.
            if head > 0 {
                std::ptr::copy_nonoverlapping(s, d, head);
            }
            let block = |k: usize| {
                let v = _mm_loadu_si128(s.add(k).cast::<__m128i>());
                _mm_stream_si128(d.add(k).cast::<__m128i>(), v);
            };
            let mut k = head;
            while k + 64 <= end {
                block(k);
                block(k + 16);
                block(k + 32);
                block(k + 48);
                k += 64;
            }
            while k < end {
                block(k);
                k += 16;
            }
            if k < bytes {
                std::ptr::copy_nonoverlapping(s.add(k), d.add(k), bytes - k);
            }
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    dst.copy_from_slice(src);
}

/// Set every element of `dst` to `value` with non-temporal stores ([`stream_copy`] from a
/// 4 KiB buffer of copies of `value`). Call [`stream_fence`] as after [`stream_copy`].
pub fn stream_fill<T: StreamElement>(dst: &mut [T], value: T) {
    let n = (4096 / std::mem::size_of::<T>().max(1)).clamp(1, dst.len().max(1));
    let src = vec![value; n];
    for c in dst.chunks_mut(n) {
        stream_copy(c, &src[..c.len()]);
    }
}

/// Order this thread's earlier [`stream_copy`] and [`stream_fill`] stores before its later
/// stores (`sfence` on x86-64; nothing elsewhere, where those are plain copies), so a thread
/// that sees the later stores (through a join or a lock) sees the streamed data too.
pub fn stream_fence() {
    #[cfg(target_arch = "x86_64")]
    // SAFETY: `sfence` takes no operands and touches no memory; SSE is part of the x86-64
    // baseline.
    unsafe {
        std::arch::x86_64::_mm_sfence();
    }
}

#[cfg(test)]
mod stream_tests {
    use super::*;

    /// Every length and alignment of the head, body and tail copies what `copy_from_slice` does.
    #[test]
    fn stream_copy_equals_a_plain_copy() {
        let src: Vec<u8> = (0..300u32).map(|i| (i * 37 % 251) as u8).collect();
        for off in 0..20 {
            for len in 0..(src.len() - off).min(200) {
                let mut dst = vec![0xAAu8; 300];
                stream_copy(&mut dst[off..off + len], &src[..len]);
                stream_fence();
                assert_eq!(
                    &dst[off..off + len],
                    &src[..len],
                    "offset {off}, length {len}"
                );
                assert!(dst[..off].iter().all(|&b| b == 0xAA));
                assert!(dst[off + len..].iter().all(|&b| b == 0xAA));
            }
        }
    }

    #[test]
    fn stream_fill_sets_every_element() {
        for len in [0, 1, 3, 1023, 1024, 1025, 5000] {
            let mut f = vec![0f32; len + 1];
            stream_fill(&mut f[1..], f32::INFINITY);
            stream_fence();
            assert_eq!(f[0], 0.0);
            assert!(f[1..].iter().all(|&z| z == f32::INFINITY), "length {len}");
            let mut c = vec![[0u8; 4]; len];
            stream_fill(&mut c, [1, 2, 3, 4]);
            stream_fence();
            assert!(c.iter().all(|&p| p == [1, 2, 3, 4]));
        }
    }
}
