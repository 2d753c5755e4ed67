//! A pixel's footprint in texture space: `uv` and its screen-space derivatives.
//!
//! As pbrt-v4's `TexCoord2D`, coordinates travel with their derivatives. In texels of level 0 the
//! Jacobian is `J = [[dudx * W, dudy * W], [dvdx * H, dvdy * H]]`, and the screen axes map to
//! `Px = J e_x = (dudx * W, dvdx * H)` and `Py = J e_y = (dudy * W, dvdy * H)`.
//!
//! Isotropic LOD (OpenGL 4.6 spec eq. 8.7 / Vulkan "Scale Factor Operation"):
//! `rho = max(|Px|, |Py|)`, `lod = log2(rho) + bias`, clamped to `[lod_min_clamp, lod_max_clamp]`.
//! Non-finite derivatives give `rho = inf` and select the coarsest level; zero derivatives give
//! `lod = -inf`, clamped to `lod_min_clamp` (level 0, magnification).

use glam::Vec2;

/// Texture coordinate `(u, v)` (normalised, 0..1 spans the texture once) with its derivatives with
/// respect to screen x and y (uv units per pixel).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Footprint {
    /// Normalised u (0 = left edge, 1 = right edge of the texture).
    pub u: f32,
    /// Normalised v (0 = top row of the image file, 1 = bottom).
    pub v: f32,
    /// du / dx: change of u per pixel to the right.
    pub dudx: f32,
    /// du / dy: change of u per pixel down.
    pub dudy: f32,
    /// dv / dx: change of v per pixel to the right.
    pub dvdx: f32,
    /// dv / dy: change of v per pixel down.
    pub dvdy: f32,
}

/// The footprint's two screen axes in texels of level 0, ordered by length.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Axes {
    /// The longer of `Px`, `Py` (texels of level 0).
    pub major: Vec2,
    /// The shorter of `Px`, `Py` (texels of level 0).
    pub minor: Vec2,
    /// The major axis in uv units (`(dudx, dvdx)` or `(dudy, dvdy)`).
    pub major_uv: Vec2,
}

impl Footprint {
    /// A footprint at `(u, v)` with zero derivatives (a point sample: level 0, magnification).
    pub fn point(u: f32, v: f32) -> Self {
        Footprint {
            u,
            v,
            ..Default::default()
        }
    }

    /// A footprint with an isotropic, axis-aligned derivative `d` (uv per pixel) in both directions.
    pub fn isotropic(u: f32, v: f32, d: f32) -> Self {
        Footprint {
            u,
            v,
            dudx: d,
            dudy: 0.0,
            dvdx: 0.0,
            dvdy: d,
        }
    }

    /// `(u, v)` as a vector.
    pub fn uv(&self) -> Vec2 {
        Vec2::new(self.u, self.v)
    }

    /// `Px` and `Py`, the screen axes in texels of a `width x height` level.
    #[inline]
    pub fn texel_axes(&self, width: u32, height: u32) -> (Vec2, Vec2) {
        let (w, h) = (width as f32, height as f32);
        (
            Vec2::new(self.dudx * w, self.dvdx * h),
            Vec2::new(self.dudy * w, self.dvdy * h),
        )
    }

    /// `rho = max(|Px|, |Py|)` in texels of a `width x height` level 0. `+inf` if any derivative is
    /// NaN or infinite.
    #[inline]
    pub fn rho(&self, width: u32, height: u32) -> f32 {
        let (px, py) = self.texel_axes(width, height);
        let (a, b) = (px.length_squared(), py.length_squared());
        // `f32::max` ignores NaN, so test both before combining.
        if a.is_finite() && b.is_finite() {
            a.max(b).sqrt()
        } else {
            f32::INFINITY
        }
    }

    /// The ordered axes of the footprint in texels of level 0, and the major one in uv units.
    ///
    /// Non-finite derivatives give infinite axes.
    #[inline]
    pub fn axes(&self, width: u32, height: u32) -> Axes {
        let (px, py) = self.texel_axes(width, height);
        let sane = |a: Vec2| {
            if a.is_finite() {
                a
            } else {
                Vec2::splat(f32::INFINITY)
            }
        };
        let (px, py) = (sane(px), sane(py));
        if px.length_squared() >= py.length_squared() {
            Axes {
                major: px,
                minor: py,
                major_uv: Vec2::new(self.dudx, self.dvdx),
            }
        } else {
            Axes {
                major: py,
                minor: px,
                major_uv: Vec2::new(self.dudy, self.dvdy),
            }
        }
    }

    /// Whether all six fields are finite.
    pub fn is_finite(&self) -> bool {
        [self.u, self.v, self.dudx, self.dudy, self.dvdx, self.dvdy]
            .iter()
            .all(|x| x.is_finite())
    }
}

/// Largest |u| or |v| honoured (2^24): coordinates beyond are clamped to it.
pub const UV_LIMIT: f32 = 16_777_216.0;

/// A sample coordinate made usable: NaN and infinities sample at 0; beyond `+-2^24`
/// ([`UV_LIMIT`]) an `f32` has no fractional bits left, so clamping there changes nothing a caller
/// could rely on and keeps `u * W` finite for every level.
#[inline(always)]
pub(crate) fn finite_uv(x: f32) -> f32 {
    if x.is_finite() {
        x.clamp(-UV_LIMIT, UV_LIMIT)
    } else {
        0.0
    }
}

/// One sample as every filter receives it, made once by the sampler (`Sampler::query`, or
/// `batch::queries` for a chunk): the footprint with its `u, v` made finite ([`finite_uv`]) and the
/// isotropic lod. Filters read `uv` from here only; the derivatives are as the caller gave them,
/// and each filter's documented fallback handles non-finite ones (they also make `lod` the
/// coarsest allowed level).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct Query {
    /// The footprint; `u` and `v` are finite and within [`UV_LIMIT`].
    pub fp: Footprint,
    /// `log2(rho) + lod_bias` clamped to the sampler's lod range ([`lod_from_rho_squared`]); 0 for a
    /// sampler whose result does not depend on it (no mipmapping, `mag_filter == min_filter`).
    pub lod: f32,
}

impl Query {
    /// The sample point, normalised (finite).
    #[inline(always)]
    pub(crate) fn uv(&self) -> Vec2 {
        Vec2::new(self.fp.u, self.fp.v)
    }
}

/// `lod = log2(rho) + bias` clamped to `[lod_min, lod_max]`, with non-finite `rho` giving `lod_max`
/// (the coarsest allowed level) and `rho = 0` giving `lod_min`. `log2` is [`fast_log2`], as for
/// the isotropic lod ([`lod_from_rho_squared`]).
#[inline]
pub fn lod_from_rho(rho: f32, bias: f32, lod_min: f32, lod_max: f32) -> f32 {
    if rho.is_nan() || rho == f32::INFINITY {
        return lod_max;
    }
    // log2(0) = -inf clamps to lod_min.
    (fast_log2(rho) + bias).clamp(lod_min, lod_max)
}

/// `rho^2 = max(|Px|^2, |Py|^2)` in texels of a `width x height` level 0 (no square root);
/// `+inf` if any derivative is NaN or infinite, or the square overflows.
#[inline]
pub fn rho_squared(fp: &Footprint, width: u32, height: u32) -> f32 {
    let (px, py) = fp.texel_axes(width, height);
    let (a, b) = (px.length_squared(), py.length_squared());
    if a.is_finite() && b.is_finite() {
        a.max(b)
    } else {
        f32::INFINITY
    }
}

/// The sampler's lod from `rho^2` ([`rho_squared`]): `0.5 * log2(rho^2) + bias` clamped to
/// `[lod_min, lod_max]`, which is [`lod_from_rho`]'s `log2(rho) + bias` without the square root.
/// Non-finite `rho^2` gives `lod_max`, `0` gives `lod_min`.
///
/// `log2` is [`fast_log2`]: exact on powers of two (so integer lods stay integer), within 1.2 units
/// in the last place of the exact value elsewhere (`1.4e-7` absolute for lods below 1), so a
/// trilinear blend weight moves by at most that much against `f32::log2`.
#[inline]
pub fn lod_from_rho_squared(rho2: f32, bias: f32, lod_min: f32, lod_max: f32) -> f32 {
    if rho2.is_nan() || rho2 == f32::INFINITY {
        return lod_max;
    }
    (0.5 * fast_log2(rho2) + bias).clamp(lod_min, lod_max)
}

/// `log2(x)` without a libm call, for the per-sample lod.
///
/// The exponent comes from the bits; the mantissa `m`, moved into `[sqrt(1/2), sqrt(2))`, goes
/// through `ln m = 2 atanh(s)`, `s = (m - 1) / (m + 1)` (`|s| <= 0.172`), summed to `s^9`
/// (Abramowitz & Stegun 4.1.28; the first omitted term is below `3e-9`). Exact for powers of two;
/// measured within 1.11 units in the last place of the exact (f64) value for normal `x` (unit
/// test; `f32::log2` itself is within 0.5 plus libm's error). Zero, subnormal,
/// infinite, negative and NaN inputs fall back to `f32::log2` (`-inf`, exact, `inf`, NaN, NaN).
#[inline]
pub fn fast_log2(x: f32) -> f32 {
    if !(f32::MIN_POSITIVE..f32::INFINITY).contains(&x) {
        return x.log2();
    }
    log2_normal(x)
}

/// [`fast_log2`] for normal, finite, positive `x` only, branch-free (selects, no calls), so that a
/// loop over many inputs vectorises; other inputs give meaningless results, which the batch
/// stages recompute with [`fast_log2`].
#[inline(always)]
pub(crate) fn log2_normal(x: f32) -> f32 {
    let bits = x.to_bits();
    let m = f32::from_bits((bits & 0x007f_ffff) | 0x3f80_0000);
    let big = m > std::f32::consts::SQRT_2;
    let e = (((bits >> 23) & 0xff) as i32 - 127) + i32::from(big);
    let m = if big { m * 0.5 } else { m };
    let s = (m - 1.0) / (m + 1.0);
    let s2 = s * s;
    let series = 1.0 + s2 * (1.0 / 3.0 + s2 * (1.0 / 5.0 + s2 * (1.0 / 7.0 + s2 * (1.0 / 9.0))));
    e as f32 + (2.0 * std::f32::consts::LOG2_E) * s * series
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Axes of 4 and 2 texels on a 256 x 256 texture, along x and y.
    const AXES_4_BY_2: Footprint = Footprint {
        u: 0.5,
        v: 0.5,
        dudx: 4.0 / 256.0,
        dudy: 0.0,
        dvdx: 0.0,
        dvdy: 1.0 / 128.0,
    };

    #[test]
    fn rho_and_axes() {
        let f = AXES_4_BY_2;
        assert_eq!(f.rho(256, 256), 4.0);
        let a = f.axes(256, 256);
        assert_eq!(a.major, Vec2::new(4.0, 0.0));
        assert_eq!(a.minor, Vec2::new(0.0, 2.0));
        assert_eq!(a.major_uv, Vec2::new(4.0 / 256.0, 0.0));
        assert_eq!(lod_from_rho(f.rho(256, 256), 0.0, 0.0, 32.0), 2.0);
        assert_eq!(lod_from_rho(4.0, 0.5, 0.0, 32.0), 2.5);
        assert_eq!(lod_from_rho(4.0, 0.0, 0.0, 1.5), 1.5);
    }

    #[test]
    fn degenerate_derivatives() {
        assert_eq!(
            lod_from_rho(Footprint::point(0.3, 0.2).rho(64, 64), 0.0, 0.0, 32.0),
            0.0
        );
        let nan = Footprint {
            dudx: f32::NAN,
            ..Footprint::point(0.0, 0.0)
        };
        assert_eq!(nan.rho(64, 64), f32::INFINITY);
        assert_eq!(lod_from_rho(nan.rho(64, 64), 0.0, 0.0, 32.0), 32.0);
        let inf = Footprint {
            dvdy: f32::NEG_INFINITY,
            ..Footprint::point(0.0, 0.0)
        };
        assert_eq!(lod_from_rho(inf.rho(64, 64), 0.0, 0.0, 6.0), 6.0);
        assert!(inf.axes(64, 64).major.x.is_infinite());
    }

    #[test]
    fn fast_log2_accuracy() {
        // Powers of two are exact.
        for k in -126..128 {
            let x = 2f32.powi(k);
            assert_eq!(fast_log2(x), k as f32, "2^{k}");
        }
        // A dense sweep of mantissas over several exponents.
        let mut worst = 0f64;
        for k in 0..200_000u32 {
            let x = f32::from_bits(0x3f80_0000 + k * 41)
                * [1e-20, 0.37, 1.0, 3.0, 1e20][k as usize % 5];
            let want = f64::from(x).log2();
            // Measured against the exact value, in units of the result's own f32 spacing
            // (at least 2^-23, the spacing just below 1): rounding to f32 alone costs 0.5.
            let spacing = (want.abs().max(1.0) as f32).to_bits();
            let ulp = f64::from(f32::from_bits(spacing + 1) - f32::from_bits(spacing));
            worst = worst.max((f64::from(fast_log2(x)) - want).abs() / ulp);
        }
        // Measured: 1.11.
        assert!(worst < 1.5, "worst {worst} ulp");
        assert_eq!(fast_log2(0.0), f32::NEG_INFINITY);
        assert!(fast_log2(-1.0).is_nan());
        assert!(fast_log2(f32::NAN).is_nan());
        assert_eq!(fast_log2(f32::INFINITY), f32::INFINITY);
        assert_eq!(fast_log2(1e-40), 1e-40f32.log2());
    }

    #[test]
    fn squared_lod_matches_rho_lod() {
        let f = AXES_4_BY_2;
        assert_eq!(rho_squared(&f, 256, 256), 16.0);
        assert_eq!(lod_from_rho_squared(16.0, 0.0, 0.0, 32.0), 2.0);
        assert_eq!(lod_from_rho_squared(16.0, 0.5, 0.0, 32.0), 2.5);
        assert_eq!(lod_from_rho_squared(0.0, 0.0, 0.0, 32.0), 0.0);
        assert_eq!(lod_from_rho_squared(f32::INFINITY, 0.0, 0.0, 7.0), 7.0);
        assert_eq!(lod_from_rho_squared(f32::NAN, 0.0, 0.0, 7.0), 7.0);
        for k in 1..1000 {
            let rho = k as f32 * 0.37;
            let a = lod_from_rho(rho, 0.0, 0.0, 32.0);
            let b = lod_from_rho_squared(rho * rho, 0.0, 0.0, 32.0);
            assert!((a - b).abs() < 1e-6, "rho {rho}: {a} vs {b}");
        }
    }
}
