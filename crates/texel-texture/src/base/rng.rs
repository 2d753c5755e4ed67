//! The project's one deterministic PRNG: SplitMix64 (Steele, Lea & Flood, "Fast splittable
//! pseudorandom number generators", OOPSLA 2014; the constants of Java's `SplittableRandom`).
//! The reference renderer seeds it per pixel from `(seed, i, j)` ([`SplitMix64::for_pixel`]), so
//! its jitter does not depend on the order pixels are rendered in, nor on the thread count; tests
//! and benchmarks seed it with [`SplitMix64::new`] for reproducible random inputs.

/// SplitMix64 state.
#[derive(Clone, Copy, Debug)]
pub struct SplitMix64(u64);

/// The SplitMix64 output function (a strong 64-bit mixer).
#[inline]
pub fn mix64(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

impl SplitMix64 {
    /// The generator seeded with `seed` (its first output is `mix64(seed + golden gamma)`).
    pub fn new(seed: u64) -> Self {
        SplitMix64(seed)
    }

    /// The generator for pixel `(i, j)` of a frame rendered with `seed`.
    pub fn for_pixel(seed: u64, i: u32, j: u32) -> Self {
        SplitMix64(mix64(seed ^ mix64((u64::from(j) << 32) | u64::from(i))))
    }

    /// The next 64 random bits.
    #[inline]
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        mix64(self.0)
    }

    /// A uniform number in `[0, 1)` with 53 random bits.
    #[inline]
    pub fn next_f64(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }

    /// A uniform number in `[0, 1)` with 24 random bits (every such `f32` is exact).
    #[inline]
    pub fn next_f32(&mut self) -> f32 {
        (self.next_u64() >> 40) as f32 * (1.0 / (1u64 << 24) as f32)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn known_sequence_and_range() {
        // SplitMix64 seeded with 0 (reference values of the published algorithm).
        let mut r = SplitMix64::new(0);
        assert_eq!(r.next_u64(), 0xE220_A839_7B1D_CDAF);
        assert_eq!(r.next_u64(), 0x6E78_9E6A_A1B9_65F4);
        let mut p = SplitMix64::for_pixel(7, 3, 4);
        let mean = (0..10_000).map(|_| p.next_f64()).sum::<f64>() / 10_000.0;
        assert!((mean - 0.5).abs() < 0.02, "{mean}");
        assert_ne!(
            SplitMix64::for_pixel(7, 3, 4).next_u64(),
            SplitMix64::for_pixel(7, 4, 3).next_u64()
        );
    }
}
