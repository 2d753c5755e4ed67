//! Mip pyramid construction by exact box reduction.
//!
//! Level `k` is `max(1, W >> k) x max(1, H >> k)` (Vulkan spec, "Image Mip Level Sizing"), down to
//! 1x1. Each destination texel is the exact box-filtered mean of the source area it covers: an axis of
//! `n` source texels reduced to `m = max(1, n / 2)` maps destination texel `k` to the source interval
//! `[k * n / m, (k + 1) * n / m)`, and every source texel is weighted by its overlap with that interval.
//! For even `n` this is the usual 2x2 average; for odd `n` the weights are fractional (e.g. `n = 5`:
//! destination 0 takes texels 0, 1 and half of 2), so no row or column is dropped and the mean of every
//! level equals the mean of level 0. Rejected: dropping the last row/column of odd levels (biases the
//! mean and shifts the image) and the 3-tap odd-size filter of some drivers (same result as ours for
//! `n = 2m + 1` only when `m = 1`).
//!
//! Reduction runs on linear `f32` values, one destination row per rayon task when the level is large.

use glam::Vec4;
use rayon::prelude::*;

use crate::storage::format::LevelInfo;

/// Size of level `level` of a `width x height` texture: `max(1, side >> level)`.
pub fn level_size(width: u32, height: u32, level: u32) -> (u32, u32) {
    let s = |x: u32| x.checked_shr(level).unwrap_or(0).max(1);
    (s(width), s(height))
}

/// Number of levels of a full chain: `floor(log2(max(W, H))) + 1`.
pub fn level_count(width: u32, height: u32) -> u32 {
    32 - width.max(height).max(1).leading_zeros()
}

/// Texels in the whole pyramid of a `width x height` texture (about 4/3 of level 0); saturates
/// at `u64::MAX`.
pub fn pyramid_texels(width: u32, height: u32) -> u64 {
    (0..level_count(width, height))
        .map(|k| {
            let (w, h) = level_size(width, height, k);
            u64::from(w) * u64::from(h)
        })
        .fold(0, u64::saturating_add)
}

/// Box-reduction taps of one axis: for each destination texel, the first source index and the weights.
pub(crate) fn axis_taps(n: u32, m: u32) -> Vec<(u32, Vec<f32>)> {
    let scale = f64::from(n) / f64::from(m);
    (0..m)
        .map(|k| {
            let lo = f64::from(k) * scale;
            let hi = (f64::from(k) + 1.0) * scale;
            let first = lo.floor() as u32;
            let last = (hi.ceil() as u32).min(n);
            let weights = (first..last)
                .map(|i| {
                    let overlap = (hi.min(f64::from(i) + 1.0) - lo.max(f64::from(i))).max(0.0);
                    (overlap / scale) as f32
                })
                .collect();
            (first, weights)
        })
        .collect()
}

/// Reduce a `sw x sh` image given by `src(i, j)` to the next level.
fn reduce(sw: u32, sh: u32, src: impl Fn(u32, u32) -> Vec4 + Sync) -> (u32, u32, Vec<Vec4>) {
    let (dw, dh) = ((sw / 2).max(1), (sh / 2).max(1));
    let xt = axis_taps(sw, dw);
    let yt = axis_taps(sh, dh);
    let row = |y: usize| -> Vec<Vec4> {
        let (j0, wy) = &yt[y];
        xt.iter()
            .map(|(i0, wx)| {
                let mut acc = Vec4::ZERO;
                for (dj, &wj) in wy.iter().enumerate() {
                    let mut racc = Vec4::ZERO;
                    for (di, &wi) in wx.iter().enumerate() {
                        racc += src(i0 + di as u32, j0 + dj as u32) * wi;
                    }
                    acc += racc * wj;
                }
                acc
            })
            .collect()
    };
    let out: Vec<Vec4> = if u64::from(dw) * u64::from(dh) >= 64 * 64 {
        (0..dh as usize)
            .into_par_iter()
            .flat_map_iter(row)
            .collect()
    } else {
        (0..dh as usize).flat_map(row).collect()
    };
    (dw, dh, out)
}

/// Build the level table and the linear texels of levels 1.. (concatenated) from level 0.
pub(crate) fn build(
    width: u32,
    height: u32,
    level0: impl Fn(u32, u32) -> Vec4 + Sync,
) -> (Vec<LevelInfo>, Vec<Vec4>) {
    let count = level_count(width, height);
    let mut levels = vec![LevelInfo {
        width,
        height,
        offset: 0,
    }];
    let mut below: Vec<Vec4> = Vec::with_capacity(
        (pyramid_texels(width, height) - u64::from(width) * u64::from(height)) as usize,
    );
    let mut offset = width as usize * height as usize;
    let (mut w, mut h) = (width, height);
    // Start of the previous level inside `below` (level 1 onwards).
    let mut prev_start = 0usize;
    for k in 1..count {
        let (dw, dh, texels) = if k == 1 {
            reduce(w, h, &level0)
        } else {
            let prev = &below[prev_start..];
            let pw = w as usize;
            reduce(w, h, |i, j| prev[j as usize * pw + i as usize])
        };
        debug_assert_eq!((dw, dh), level_size(width, height, k));
        prev_start = below.len();
        below.extend_from_slice(&texels);
        levels.push(LevelInfo {
            width: dw,
            height: dh,
            offset,
        });
        offset += dw as usize * dh as usize;
        (w, h) = (dw, dh);
    }
    (levels, below)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_follow_vulkan_rule() {
        assert_eq!(level_count(1, 1), 1);
        assert_eq!(level_count(1024, 1024), 11);
        assert_eq!(level_count(5, 3), 3);
        assert_eq!(level_size(5, 3, 1), (2, 1));
        assert_eq!(level_size(5, 3, 2), (1, 1));
        assert_eq!(level_size(1, 300, 4), (1, 18));
        assert_eq!(pyramid_texels(4, 4), 16 + 4 + 1);
    }

    #[test]
    fn taps_partition_unity() {
        for n in 1..40u32 {
            let m = (n / 2).max(1);
            let taps = axis_taps(n, m);
            // every destination sums to one; every source texel contributes n/m... in total exactly m/n*..
            let mut per_src = vec![0f64; n as usize];
            for (first, w) in &taps {
                let s: f32 = w.iter().sum();
                assert!((s - 1.0).abs() < 1e-6, "n={n} sum={s}");
                for (d, &x) in w.iter().enumerate() {
                    per_src[*first as usize + d] += f64::from(x);
                }
            }
            // each source texel is used with total weight m/n
            for &p in &per_src {
                assert!((p - f64::from(m) / f64::from(n)).abs() < 1e-6, "n={n}");
            }
        }
    }

    #[test]
    fn odd_five_uses_fractional_weights() {
        let taps = axis_taps(5, 2);
        assert_eq!(taps[0].0, 0);
        assert_eq!(taps[0].1, vec![0.4, 0.4, 0.2]);
        assert_eq!(taps[1].0, 2);
        assert_eq!(taps[1].1, vec![0.2, 0.4, 0.4]);
    }
}
