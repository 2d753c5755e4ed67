//! Decode and blend the four sRGB RGBA8 texels of 4096 coherent bilinear samples (a 64 x 64 block
//! walking a 1024^2 texture, as texel's sampler bench does), two ways, with every index and fraction
//! computed beforehand:
//!
//! - scalar: per sample four 32-bit texel loads, sixteen table loads (RGB through the sRGB table,
//!   alpha through `b / 255`) and three blends per channel — texel's `batch` texel stage;
//! - AVX2: eight samples at a time, the texels and the table entries fetched with
//!   `vpgatherdd`/`vgatherdps`, the blends eight lanes wide.
//!
//! Both perform the same IEEE operations per channel (no fused multiply-add), so their results are
//! compared bit for bit. Run: `cargo run --release --manifest-path experiments/avx2_gather/Cargo.toml`.

use std::arch::x86_64::*;
use std::time::Instant;

/// IEC 61966-2-1 sRGB to linear.
fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// Texel index of each sample's top-left texel and its bilinear fractions.
struct Quads {
    k: Vec<i32>,
    a: Vec<f32>,
    b: Vec<f32>,
}

fn scalar(
    texels: &[u32],
    w: usize,
    q: &Quads,
    table: &[f32; 256],
    alpha: &[f32; 256],
    out: &mut [[f32; 4]],
) {
    let dec = |t: u32| {
        [
            table[(t & 255) as usize],
            table[((t >> 8) & 255) as usize],
            table[((t >> 16) & 255) as usize],
            alpha[(t >> 24) as usize],
        ]
    };
    for (s, o) in out.iter_mut().enumerate() {
        let (k, a, b) = (q.k[s] as usize, q.a[s], q.b[s]);
        let (t00, t10, t01, t11) = (
            dec(texels[k]),
            dec(texels[k + 1]),
            dec(texels[k + w]),
            dec(texels[k + w + 1]),
        );
        for c in 0..4 {
            let top = t00[c] + (t10[c] - t00[c]) * a;
            let bottom = t01[c] + (t11[c] - t01[c]) * a;
            o[c] = top + (bottom - top) * b;
        }
    }
}

/// # Safety
/// The CPU supports AVX2, `out.len()` is a multiple of 8 and at most `q.k.len()`, and every
/// `q.k[s] + w + 1` indexes `texels`.
#[target_feature(enable = "avx2")]
unsafe fn avx2(
    texels: &[u32],
    w: usize,
    q: &Quads,
    table: &[f32; 256],
    alpha: &[f32; 256],
    out: &mut [[f32; 4]],
) {
    let base = texels.as_ptr() as *const i32;
    let byte = _mm256_set1_epi32(255);
    let (one, row) = (_mm256_set1_epi32(1), _mm256_set1_epi32(w as i32));
    for s in (0..out.len()).step_by(8) {
        let k = _mm256_loadu_si256(q.k.as_ptr().add(s) as *const __m256i);
        let a = _mm256_loadu_ps(q.a.as_ptr().add(s));
        let b = _mm256_loadu_ps(q.b.as_ptr().add(s));
        let kw = _mm256_add_epi32(k, row);
        let t = [k, _mm256_add_epi32(k, one), kw, _mm256_add_epi32(kw, one)]
            .map(|i| _mm256_i32gather_epi32::<4>(base, i));
        let mut lanes = [[0f32; 8]; 4];
        for (c, lane) in lanes.iter_mut().enumerate() {
            let shift = _mm_cvtsi32_si128(8 * c as i32);
            let tab = if c < 3 {
                table.as_ptr()
            } else {
                alpha.as_ptr()
            };
            let [x00, x10, x01, x11] = t.map(|t| {
                _mm256_i32gather_ps::<4>(tab, _mm256_and_si256(_mm256_srl_epi32(t, shift), byte))
            });
            let top = _mm256_add_ps(x00, _mm256_mul_ps(_mm256_sub_ps(x10, x00), a));
            let bottom = _mm256_add_ps(x01, _mm256_mul_ps(_mm256_sub_ps(x11, x01), a));
            let v = _mm256_add_ps(top, _mm256_mul_ps(_mm256_sub_ps(bottom, top), b));
            _mm256_storeu_ps(lane.as_mut_ptr(), v);
        }
        for l in 0..8 {
            out[s + l] = [lanes[0][l], lanes[1][l], lanes[2][l], lanes[3][l]];
        }
    }
}

fn main() {
    if !is_x86_feature_detected!("avx2") {
        println!("no AVX2 on this CPU: nothing to compare");
        return;
    }
    let w = 1024usize;
    // Pseudo-random texels: the decode's cost does not depend on the values.
    let texels: Vec<u32> = (0..w * w)
        .map(|k| (k.wrapping_mul(2_654_435_761) >> 7) as u32)
        .collect();
    let table: [f32; 256] = std::array::from_fn(|b| srgb_to_linear(b as f32 / 255.0));
    let alpha: [f32; 256] = std::array::from_fn(|b| b as f32 / 255.0);
    let mut q = Quads {
        k: Vec::new(),
        a: Vec::new(),
        b: Vec::new(),
    };
    for s in 0..4096 {
        let (x, y) = ((s % 64) as f32 + 100.8, (s / 64) as f32 + 201.2);
        let (i, j) = (x.floor(), y.floor());
        q.k.push((j as usize * w + i as usize) as i32);
        q.a.push(x - i);
        q.b.push(y - j);
    }
    let (mut o1, mut o2) = (vec![[0f32; 4]; 4096], vec![[0f32; 4]; 4096]);
    let reps = 2000;
    // Million samples per second of `reps` calls of `f`.
    let rate = |f: &mut dyn FnMut()| {
        let t = Instant::now();
        for _ in 0..reps {
            f();
        }
        (4096 * reps) as f64 / t.elapsed().as_secs_f64() / 1e6
    };
    for round in 1..=3 {
        let q = std::hint::black_box(&q);
        let scalar_rate = rate(&mut || {
            scalar(&texels, w, q, &table, &alpha, &mut o1);
            std::hint::black_box(&o1);
        });
        let avx2_rate = rate(&mut || {
            // SAFETY: AVX2 was detected above; 4096 is a multiple of 8; the samples' quads lie
            // inside the 1024^2 texture (x, y below 300).
            unsafe { avx2(&texels, w, q, &table, &alpha, &mut o2) };
            std::hint::black_box(&o2);
        });
        let same = o1
            .iter()
            .zip(&o2)
            .all(|(x, y)| x.map(f32::to_bits) == y.map(f32::to_bits));
        println!("round {round}: scalar {scalar_rate:.1} M samples/s, AVX2 gathers {avx2_rate:.1} M samples/s, bit-identical: {same}");
    }
}
