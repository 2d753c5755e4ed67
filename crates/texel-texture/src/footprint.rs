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

/// `lod = log2(rho) + bias` clamped to `[lod_min, lod_max]`, with non-finite `rho` giving `lod_max`
/// (the coarsest allowed level) and `rho = 0` giving `lod_min`.
#[inline]
pub fn lod_from_rho(rho: f32, bias: f32, lod_min: f32, lod_max: f32) -> f32 {
    if rho.is_nan() || rho == f32::INFINITY {
        return lod_max;
    }
    // log2(0) = -inf clamps to lod_min.
    (rho.log2() + bias).clamp(lod_min, lod_max)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rho_and_axes() {
        let f = Footprint {
            u: 0.5,
            v: 0.5,
            dudx: 4.0 / 256.0,
            dudy: 0.0,
            dvdx: 0.0,
            dvdy: 1.0 / 128.0,
        };
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
}
