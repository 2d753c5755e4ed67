//! EWA from trilinear probes: the footprint's Gaussian approximated by Gaussian-weighted trilinear
//! samples along the ellipse's major axis, after Mavridis and Papaioannou ("High Quality
//! Elliptical Texture Filtering on GPU", I3D 2011).
//!
//! The target is the second moments of texel's reference, as EWA's kernel is
//! ([`crate::technique::ewa`]): the pixel square carried through the Jacobian `M = [Px Py]`
//! (texels of level 0) and level 0's bilinear tent, `C = (S + 2 I) / 12` with `S = M M^T`. Its
//! eigenvalues `lambda_1 >= lambda_2` and the major direction `e1` come from the same
//! eigen-decomposition as EWA's ellipse ([`Ellipse::from_axes`], with its eccentricity clamp).
//! Covariances add, so the filter is built as a sum of two parts:
//!
//! 1. **One probe's kernel carries the minor axis.** A bilinear sample of level `k`, in level-0
//!    terms, is a tent of `2 * 4^k / 12` per axis over texels that each average `2^k x 2^k`
//!    level-0 texels (spread `(4^k - 1) / 12`): variance `v_k = (3 * 4^k - 1) / 12` per axis,
//!    averaged over where the sample falls between texel centres. Trilinear at `lod = k + delta`
//!    mixes two levels, so its variance is `(1 - delta) v_k + delta v_(k+1)`. The lod whose
//!    variance is the minor eigenvalue `sigma^2 = lambda_2` is [`lod_of_variance`]; `v_0 = 1/6` is
//!    the tent alone and `lambda_2 >= 1/6` always, so it is never negative. The probes read
//!    [`LOD_OFFSET`] (a quarter of a level) coarser than that lod.
//! 2. **The probes' positions carry the rest of the major axis.** `N` probes at
//!    `x_i = s * u_i / sqrt(V_N)` texels along `e1`, with `u_i = ((i + 1/2) / N * 2 - 1) T`
//!    evenly spread over `[-T, T]` and weights `w_i = exp(-u_i^2 / 2) - exp(-T^2 / 2)` (the 1-D
//!    form of EWA's truncated Gaussian, `T` = [`TRUNCATION`] standard deviations), normalised.
//!    `V_N = sum w u^2 / sum w` is the discrete weights' own variance, so the positions have
//!    variance exactly `s^2 = lambda_1 - sigma^2` along `e1` and none across: with the probe
//!    kernel, the total is `C`.
//!
//! `N` is the fewest probes whose spacing `2 T s / (N sqrt(V_N))` is at most [`SPACING`] times
//! `sigma`; one probe when `lambda_1 <= (1 + ONE_PROBE) lambda_2` (a near-circle: trilinear).
//! At most [`MAX_PROBES`] (`A`): where more would be needed, the probes' kernel grows until `A`
//! probes fit, `sigma^2 = g^2 lambda_1 / (SPACING^2 + g^2)` with `g = 2 T / (A sqrt(V_A))`, which
//! blurs rather than aliases, as EWA's eccentricity clamp does.
//!
//! Why the constants are what they are. A trilinear probe's kernel is a tent over blocks of
//! `2^k x 2^k` level-0 texels, so its shape depends on where the sample falls: its variance runs
//! from `(4^k - 1) / 12` at a texel centre to `4^k / 4` more midway between two, and it is
//! `v_k` only on average. EWA evaluates its Gaussian at every texel centre and has no such
//! jitter; the probes' sum along the major axis averages it out there, not across it. Measured
//! against texel's reference and against the brute-force Gaussian of tests/aniso.rs, a flatter
//! weight (`T = 1`), a wider spacing (`3 sigma`) and the quarter level coarser score best for the
//! texels read; the figures and the alternatives are in docs/decisions.md ("EWA from trilinear
//! probes").
//!
//! Against EWA: the same covariance, each probe's kernel a trilinear tent rather than a Gaussian,
//! and `8 N` texels read (two bilinear levels) where EWA reads every texel of the ellipse in one
//! level. Against the hardware-style probes of [`crate::technique::aniso`]: those are evenly
//! weighted, spaced by the minor axis and each about a level coarser, so across the major axis
//! their kernel is wider than the reference's pixel.
//!
//! Decisions:
//! - `lod_bias` and the lod clamps apply to the probes' lod as to any other; magnification is the
//!   sampler's decision (the isotropic lod), as for EWA;
//! - degenerate footprints (non-finite derivatives) fall back to trilinear at the isotropic lod;
//!   probe positions that overflow are sampled at 0, as the sampler treats non-finite `uv`;
//! - the one-sample and batched paths run the same code (the batch reuses the probes' scratch),
//!   so they agree bit for bit.

use std::sync::OnceLock;

use glam::{DVec2, Vec2, Vec4};

use crate::base::footprint::Query;
use crate::kernel::bilinear::Bilinear;
use crate::storage::fetch::Fetch;
use crate::storage::view::Pyramid;
use crate::technique::aniso::Probes;
use crate::technique::ewa::Ellipse;
use crate::technique::mip::{linear_levels, trilinear};
use crate::technique::Params;

/// The most probes a sample takes.
pub const MAX_PROBES: usize = 16;

/// The largest distance between neighbouring probes, in standard deviations of one probe's
/// kernel.
pub const SPACING: f64 = 3.0;

/// Standard deviations of the major axis's Gaussian the probes cover on each side.
pub const TRUNCATION: f64 = 1.0;

/// Added to the lod whose trilinear variance matches the minor axis: the probes read a quarter
/// of a level coarser (see the module docs).
pub const LOD_OFFSET: f64 = 0.25;

/// A footprint whose eigenvalues differ by at most this share takes one probe.
pub const ONE_PROBE: f64 = 0.1;

/// The probe weights and positions for every probe count `n` in `1..=MAX_PROBES`.
#[derive(Debug)]
pub struct ProbeTable {
    /// `positions[n - 1][i]`: probe `i`'s offset along the major axis for a unit residual
    /// standard deviation, `u_i / sqrt(V_n)` (0 for `n = 1`).
    pub positions: [[f32; MAX_PROBES]; MAX_PROBES],
    /// `weights[n - 1][i]`: probe `i`'s weight, the weights of `n` probes summing to 1.
    pub weights: [[f32; MAX_PROBES]; MAX_PROBES],
    /// `spacing[n - 1]`: the distance between neighbouring probes for a unit residual standard
    /// deviation, `2 T / (n sqrt(V_n))` (infinite for `n = 1`).
    pub spacing: [f64; MAX_PROBES],
}

/// The [`ProbeTable`], computed on first use.
pub fn probe_table() -> &'static ProbeTable {
    static TABLE: OnceLock<ProbeTable> = OnceLock::new();
    TABLE.get_or_init(|| {
        let mut t = ProbeTable {
            positions: [[0.0; MAX_PROBES]; MAX_PROBES],
            weights: [[0.0; MAX_PROBES]; MAX_PROBES],
            spacing: [f64::INFINITY; MAX_PROBES],
        };
        t.weights[0][0] = 1.0;
        let floor = (-TRUNCATION * TRUNCATION / 2.0).exp();
        for n in 2..=MAX_PROBES {
            let u: Vec<f64> = (0..n)
                .map(|i| ((i as f64 + 0.5) / n as f64 * 2.0 - 1.0) * TRUNCATION)
                .collect();
            let w: Vec<f64> = u.iter().map(|u| (-u * u / 2.0).exp() - floor).collect();
            let sum: f64 = w.iter().sum();
            let var = u.iter().zip(&w).map(|(u, w)| w * u * u).sum::<f64>() / sum;
            let root = var.sqrt();
            for i in 0..n {
                t.positions[n - 1][i] = (u[i] / root) as f32;
                t.weights[n - 1][i] = (w[i] / sum) as f32;
            }
            t.spacing[n - 1] = 2.0 * TRUNCATION / (n as f64 * root);
        }
        t
    })
}

/// Per-axis variance of a trilinear sample at `lod` (level-0 texels^2, levels halving exactly):
/// `(1 - delta) v_k + delta v_(k+1)` with `v_k = (3 * 4^k - 1) / 12`.
pub fn variance_of_lod(lod: f64) -> f64 {
    let lod = lod.max(0.0);
    let k = lod.floor();
    let delta = lod - k;
    let v = |k: f64| (3.0 * 4f64.powf(k) - 1.0) / 12.0;
    (1.0 - delta) * v(k) + delta * v(k + 1.0)
}

/// The lod whose trilinear sample has per-axis variance `var` (level-0 texels^2), the inverse of
/// [`variance_of_lod`]; 0 for `var <= 1/6` (bilinear in level 0).
pub fn lod_of_variance(var: f64) -> f64 {
    if var.is_nan() || var <= 1.0 / 6.0 {
        return 0.0;
    }
    if !var.is_finite() {
        return f64::from(f32::MAX);
    }
    // `v_k <= var < v_(k+1)` for `4^k <= x = (12 var + 1) / 3`, `x > 1`: `k` is half of `x`'s
    // binary exponent, rounded down, and `4^k` is exact.
    let x = (12.0 * var + 1.0) / 3.0;
    let exponent = ((x.to_bits() >> 52) & 0x7ff) as i64 - 1023;
    let k = (exponent.max(0) / 2) as u64;
    let four_k = f64::from_bits((2 * k + 1023) << 52);
    let vk = (3.0 * four_k - 1.0) / 12.0;
    k as f64 + ((var - vk) / (0.75 * four_k)).clamp(0.0, 1.0)
}

/// What a sample's probes are: their count, their shared lod (before the bias and clamps), and
/// the offset between neighbouring probes per unit of [`ProbeTable::positions`] in uv units.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ProbePlan {
    /// Probe count `N` (1 to [`MAX_PROBES`]).
    pub n: usize,
    /// The probes' lod from their matched variance, before `lod_bias` and the clamps.
    pub lod: f64,
    /// The major axis's residual standard deviation `s` along `e1`, in uv units: probe `i` sits
    /// at `uv + positions[n - 1][i] * axis_uv`.
    pub axis_uv: DVec2,
    /// The same in texels of level 0.
    pub axis_texels: DVec2,
}

/// The [`ProbePlan`] of the footprint with screen axes `px`, `py` (texels of a `size` level 0)
/// under the eccentricity clamp `max_anisotropy`; `None` when an axis is not finite.
pub fn plan(px: Vec2, py: Vec2, size: (u32, u32), max_anisotropy: f32) -> Option<ProbePlan> {
    let e = Ellipse::from_axes(px, py, max_anisotropy)?;
    // The reference's covariance `C = (S + 2 I) / 12`: eigenvalues from the clamped semi-axes.
    let l1 = (e.major * e.major + 2.0) / 12.0;
    let l2 = (e.minor * e.minor + 2.0) / 12.0;
    let table = probe_table();
    let (n, var) = if l1 <= (1.0 + ONE_PROBE) * l2 {
        (1, l2)
    } else {
        // The largest spacing per unit residual standard deviation that fits.
        let limit = SPACING * l2.sqrt() / (l1 - l2).sqrt();
        match (2..=MAX_PROBES).find(|&n| table.spacing[n - 1] <= limit) {
            Some(n) => (n, l2),
            None => {
                let g2 = table.spacing[MAX_PROBES - 1].powi(2);
                (MAX_PROBES, (g2 * l1 / (SPACING * SPACING + g2)).max(l2))
            }
        }
    };
    let residual = if n == 1 {
        0.0
    } else {
        (l1 - var).max(0.0).sqrt()
    };
    let axis_texels = e.e1 * residual;
    let (w, h) = (f64::from(size.0), f64::from(size.1));
    Some(ProbePlan {
        n,
        lod: lod_of_variance(var) + LOD_OFFSET,
        axis_uv: DVec2::new(axis_texels.x / w, axis_texels.y / h),
        axis_texels,
    })
}

/// EWA from trilinear probes of query `q` (whose isotropic lod is `> 0`) under `s`, with the
/// eccentricity clamp `max`: the module's formula, [`plan`] then the weighted probes.
#[inline(always)]
pub(crate) fn ewa_probes<P: Pyramid>(
    p: &P,
    s: &Params,
    q: &Query,
    max: f32,
    probes: &mut Probes,
) -> Vec4 {
    let size = p.level(0).size();
    let (px, py) = q.fp.texel_axes(size.0, size.1);
    let Some(plan) = plan(px, py, size, max) else {
        return trilinear(p, Bilinear, &s.addr, q);
    };
    let lod = (plan.lod as f32 + s.lod_bias)
        .max(s.lod_min_clamp)
        .min(s.lod_max_clamp);
    let levels = linear_levels(lod, p.level_count() - 1);
    let table = probe_table();
    let n = plan.n;
    let finite = |x: f64| if x.is_finite() { x as f32 } else { 0.0 };
    let at = &mut probes.at;
    at.n = n;
    let (u, v) = (f64::from(q.fp.u), f64::from(q.fp.v));
    for (i, (pu, pv)) in at.u[..n].iter_mut().zip(&mut at.v[..n]).enumerate() {
        let t = f64::from(table.positions[n - 1][i]);
        *pu = finite(u + t * plan.axis_uv.x);
        *pv = finite(v + t * plan.axis_uv.y);
    }
    probes.trilinear_weighted_sum(p, levels, &table.weights[n - 1][..n])
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The lod rule inverts the trilinear variance, and level 0's bilinear is the tent alone.
    #[test]
    fn lod_inverts_the_trilinear_variance() {
        assert_eq!(variance_of_lod(0.0), 1.0 / 6.0);
        assert!((variance_of_lod(1.0) - 11.0 / 12.0).abs() < 1e-15);
        for i in 0..400 {
            let lod = f64::from(i) * 0.03;
            let back = lod_of_variance(variance_of_lod(lod));
            assert!((back - lod).abs() < 1e-9, "{lod} -> {back}");
        }
        assert_eq!(lod_of_variance(0.1), 0.0);
        assert_eq!(lod_of_variance(f64::NAN), 0.0);
    }

    /// Each row of the table has unit weight, zero mean and unit variance, and is symmetric.
    #[test]
    fn probe_table_rows_have_unit_variance() {
        let t = probe_table();
        for n in 1..=MAX_PROBES {
            let (w, x) = (&t.weights[n - 1][..n], &t.positions[n - 1][..n]);
            let sum: f64 = w.iter().map(|&w| f64::from(w)).sum();
            let mean: f64 = w.iter().zip(x).map(|(&w, &x)| f64::from(w * x)).sum();
            let var: f64 = w
                .iter()
                .zip(x)
                .map(|(&w, &x)| f64::from(w) * f64::from(x).powi(2))
                .sum();
            assert!((sum - 1.0).abs() < 1e-6, "{n}: {sum}");
            assert!(mean.abs() < 1e-6, "{n}: {mean}");
            if n > 1 {
                assert!((var - 1.0).abs() < 1e-5, "{n}: {var}");
                let gap = f64::from(x[1] - x[0]);
                assert!((gap - t.spacing[n - 1]).abs() < 1e-5, "{n}: {gap}");
            }
            for i in 0..n {
                assert!((w[i] - w[n - 1 - i]).abs() < 1e-7);
                assert!((x[i] + x[n - 1 - i]).abs() < 1e-5);
            }
        }
    }
}
