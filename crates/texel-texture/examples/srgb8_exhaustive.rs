//! Check the table sRGB encoder (`color::linear_to_srgb8`) against its `powf` definition
//! (`color::linear_to_srgb8_exact`) for every `f32` in `[0, 1]` (1 065 353 217 values), and that
//! the definition is non-decreasing there (what makes the table exact). Takes about ten seconds
//! per core.
//!
//! ```text
//! cargo run --release -p texel-texture --example srgb8_exhaustive
//! ```

use texel_texture::base::color::{linear_to_srgb8, linear_to_srgb8_exact};

fn main() {
    const END: u32 = 0x3F80_0000; // 1.0
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get()) as u32;
    let chunk = END / threads + 1;
    let results: Vec<(u64, u64)> = std::thread::scope(|s| {
        let handles: Vec<_> = (0..threads)
            .map(|t| {
                s.spawn(move || {
                    let (lo, hi) = (t * chunk, ((t + 1) * chunk).min(END + 1));
                    let (mut differ, mut decreasing) = (0u64, 0u64);
                    let mut prev = linear_to_srgb8_exact(f32::from_bits(lo.saturating_sub(1)));
                    for bits in lo..hi {
                        let l = f32::from_bits(bits);
                        let exact = linear_to_srgb8_exact(l);
                        differ += u64::from(linear_to_srgb8(l) != exact);
                        decreasing += u64::from(exact < prev);
                        prev = exact;
                    }
                    (differ, decreasing)
                })
            })
            .collect();
        handles.into_iter().map(|h| h.join().unwrap()).collect()
    });
    let differ: u64 = results.iter().map(|r| r.0).sum();
    let decreasing: u64 = results.iter().map(|r| r.1).sum();
    println!(
        "{} floats in [0, 1]: {differ} encode differently, {decreasing} steps down",
        u64::from(END) + 1
    );
    if differ + decreasing > 0 {
        std::process::exit(1);
    }
}
