//! Run-time instruction-set dispatch: the one module of texel that uses `unsafe`.
//!
//! texel is compiled for the x86-64 baseline (SSE2), so one binary runs on every x86-64 CPU. The
//! tile rasterizer (coverage, interpolation, sampling, shading, encoding: everything
//! `tile::raster_tile` inlines) gets a second copy compiled for x86-64-v3 (AVX2, FMA, BMI1/2,
//! F16C, LZCNT, MOVBE), chosen per tile when the CPU has every one of those features.
//!
//! Images are bit for bit the same on both copies: Rust never fuses a multiply and an add unless
//! asked (`mul_add`), and no code here asks, so the wider instructions compute the same IEEE
//! operations (`tests/targets.rs` renders every view both ways; `scripts/same_images.sh` compared
//! 134 images of a whole-program x86-64-v3 build with the baseline build, all identical).
//!
//! Safety argument: calling a `#[target_feature]` function is `unsafe` because running its
//! instructions on a CPU without the features is undefined behaviour. [`run`] calls [`v3`] only
//! when [`level`] is [`SimdLevel::X86_64V3`], which it is only when `is_x86_feature_detected!`
//! reported every feature `v3` enables (the list below is the one `v3`'s attribute names).
#![allow(unsafe_code)]

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::OnceLock;

/// The instruction set the rasterizer's tiles run on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SimdLevel {
    /// The build's own target (x86-64: SSE2; other architectures: their baseline).
    Baseline,
    /// x86-64-v3: AVX2, FMA, BMI1, BMI2, F16C, LZCNT, MOVBE (and the v2 features below them).
    X86_64V3,
}

impl SimdLevel {
    /// A short name for reports: `"x86-64-v3 (avx2+fma)"` or `"baseline (sse2)"`.
    pub fn name(self) -> &'static str {
        match self {
            SimdLevel::X86_64V3 => "x86-64-v3 (avx2+fma)",
            SimdLevel::Baseline if cfg!(target_arch = "x86_64") => "baseline (sse2)",
            SimdLevel::Baseline => "baseline",
        }
    }
}

/// Set by [`force_baseline`].
static FORCE_BASELINE: AtomicBool = AtomicBool::new(false);

/// What the CPU supports, detected once.
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
    if v3 {
        SimdLevel::X86_64V3
    } else {
        SimdLevel::Baseline
    }
}

#[cfg(not(target_arch = "x86_64"))]
fn detect() -> SimdLevel {
    SimdLevel::Baseline
}

/// The level tiles run on now: the CPU's, unless [`force_baseline`] is on.
pub fn level() -> SimdLevel {
    if FORCE_BASELINE.load(Ordering::Relaxed) {
        SimdLevel::Baseline
    } else {
        detected()
    }
}

/// Run every later tile on the baseline copy (`true`) or on the CPU's best again (`false`), for
/// comparing the two. Process-wide; images do not depend on it.
pub fn force_baseline(on: bool) {
    FORCE_BASELINE.store(on, Ordering::Relaxed);
}

/// Work compiled once per instruction set. `run` must be `#[inline(always)]` (a closure's body
/// would stay a separate function compiled for the baseline, which `v3` would merely call).
pub(crate) trait Kernel {
    /// What the work returns.
    type Output;
    /// Do the work.
    fn run(self) -> Self::Output;
}

/// Run `k` on the copy for [`level`]: its body (with everything it inlines) is compiled once for
/// the baseline and once inside [`v3`].
#[inline(always)]
pub(crate) fn run<K: Kernel>(k: K) -> K::Output {
    #[cfg(target_arch = "x86_64")]
    if level() == SimdLevel::X86_64V3 {
        // SAFETY: `level()` is `X86_64V3` only when `detect` saw every feature `v3` enables.
        return unsafe { v3(k) };
    }
    k.run()
}

/// `k.run()` compiled for x86-64-v3.
#[cfg(target_arch = "x86_64")]
#[target_feature(
    enable = "avx,avx2,fma,bmi1,bmi2,f16c,lzcnt,movbe,popcnt,sse3,ssse3,sse4.1,sse4.2"
)]
unsafe fn v3<K: Kernel>(k: K) -> K::Output {
    k.run()
}
