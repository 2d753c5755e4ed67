//! Maps between directions (points on the unit sphere) and texture coordinates, with their
//! analytic derivatives: the three environment-map layouts of conventions.md.
//!
//! - **Equirectangular** (latitude-longitude): `u = 0.5 + atan2(d.x, -d.z) / (2 pi)`,
//!   `v = acos(d.y / |d|) / pi` (`v = 0` straight up, `-z` at the centre column, the seam
//!   `u = 0 = 1` along `+z`).
//! - **Cube**: six square faces, Vulkan's face selection and orientation (Vulkan 1.3 spec,
//!   "Cube Map Face Selection and Transformations"): the face is the axis of the direction's
//!   largest magnitude `rc`, and `(s, t) = ((sc / |rc| + 1) / 2, (tc / |rc| + 1) / 2)` with `sc`,
//!   `tc` from the spec's table ([`CUBE_FACES`]). Faces are numbered `+x, -x, +y, -y, +z, -z`
//!   (Vulkan's layers 0-5). Where two magnitudes tie, `z` wins over `y` and `y` over `x` (the spec
//!   leaves ties to the implementation).
//! - **Octahedral**: pbrt-v4's equal-area octahedral mapping (Clarberg 2008, "Fast Equal-Area
//!   Mapping of the (Hemi)Sphere using SIMD"; pbrt-v4 `EqualAreaSphereToSquare`), with the exact
//!   `atan2` where pbrt uses a polynomial: `+z` at the centre of the square, `-z` at its corners,
//!   equal solid angle per texel. Its continuation outside the square is [`octahedral_wrap`].
//!
//! Every derivative is the Jacobian of the mapping applied to a change of direction, computed in
//! closed form ([`equirect_duv`], [`cube_dst`], [`octahedral_duv`]): conventions.md forbids
//! differencing `u` across a seam, which jumps by about one texture width.

use std::f64::consts::{FRAC_PI_2, PI};

use glam::{DVec2, DVec3};

/// The environment-map layouts.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum Mapping {
    /// Latitude-longitude, one image twice as wide as high.
    #[default]
    #[cfg_attr(
        feature = "clap",
        value(help = "Latitude-longitude, twice as wide as high")
    )]
    Equirect,
    /// Six square faces ([`cube_face`]).
    #[cfg_attr(
        feature = "clap",
        value(help = "Six faces with Vulkan's orientation, filtered across their edges")
    )]
    Cube,
    /// One square image ([`octahedral_uv`]).
    #[cfg_attr(
        feature = "clap",
        value(help = "pbrt-v4's equal-area octahedral square")
    )]
    Octahedral,
}

impl Mapping {
    /// The name a scene file uses: `equirect`, `cube` or `octahedral`.
    pub fn name(self) -> &'static str {
        match self {
            Mapping::Equirect => "equirect",
            Mapping::Cube => "cube",
            Mapping::Octahedral => "octahedral",
        }
    }

    /// Images the mapping stores: 6 cube faces (in [`CUBE_FACES`]' order), else 1.
    pub fn layers(self) -> usize {
        match self {
            Mapping::Cube => 6,
            Mapping::Equirect | Mapping::Octahedral => 1,
        }
    }

    /// The layer direction `d` (any length but 0) lands in and its coordinates there
    /// ([`equirect_uv`], [`cube_face`], [`octahedral_uv`]); a zero or non-finite `d` gives NaN
    /// (in layer 0).
    pub fn uv(self, d: DVec3) -> (usize, DVec2) {
        match self {
            Mapping::Equirect => (0, equirect_uv(d)),
            Mapping::Cube => cube_face(d).unwrap_or((0, DVec2::NAN)),
            Mapping::Octahedral => (0, octahedral_uv(d)),
        }
    }

    /// The change of the coordinates in `layer` (where `d` lands, [`Mapping::uv`]) for a small
    /// change `dd` of `d`: [`equirect_duv`], [`cube_dst`] or [`octahedral_duv`].
    pub fn duv(self, layer: usize, d: DVec3, dd: DVec3) -> DVec2 {
        match self {
            Mapping::Equirect => equirect_duv(d, dd),
            Mapping::Cube => cube_dst(layer, d, dd),
            Mapping::Octahedral => octahedral_duv(d, dd),
        }
    }

    /// The unit direction at coordinates `uv` of layer `layer` (the inverse of [`Mapping::uv`]).
    /// Past `[0, 1]^2` a cube face's plane extends and the octahedral square continues
    /// ([`octahedral_wrap`]), so border texels have directions too.
    pub fn direction(self, layer: usize, uv: DVec2) -> DVec3 {
        match self {
            Mapping::Equirect => equirect_direction(uv),
            Mapping::Cube => cube_direction(layer, uv).normalize(),
            Mapping::Octahedral => octahedral_direction(octahedral_wrap(uv)),
        }
    }
}

/// The equirectangular coordinates of direction `d` (any length but 0; see the module docs).
/// `u` is in `[0, 1]`, `v` in `[0, 1]`; a zero or non-finite `d` gives NaN.
pub fn equirect_uv(d: DVec3) -> DVec2 {
    let len = d.length();
    DVec2::new(
        0.5 + d.x.atan2(-d.z) / (2.0 * PI),
        (d.y / len).clamp(-1.0, 1.0).acos() / PI,
    )
}

/// The unit direction at equirectangular coordinates `uv` (the inverse of [`equirect_uv`]):
/// `theta = pi v`, `phi = 2 pi (u - 0.5)`, `d = (sin theta sin phi, cos theta, -sin theta cos phi)`.
pub fn equirect_direction(uv: DVec2) -> DVec3 {
    let theta = PI * uv.y;
    let phi = 2.0 * PI * (uv.x - 0.5);
    let s = theta.sin();
    DVec3::new(s * phi.sin(), theta.cos(), -s * phi.cos())
}

/// The change of [`equirect_uv`] for a small change `dd` of the direction `d`:
/// `du = (x dz - z dx) / (2 pi (x^2 + z^2))`, `dv = -(dy - y (d.dd) / |d|^2) / (pi sqrt(x^2 + z^2))`,
/// each component clamped to `[-1, 1]` (one period; any more selects the coarsest level anyway).
/// Continuous across the seam; at the poles, where `u` is undefined, `du` is the clamp.
pub fn equirect_duv(d: DVec3, dd: DVec3) -> DVec2 {
    let rho2 = d.x * d.x + d.z * d.z;
    let len2 = d.length_squared();
    if !(rho2 > 1e-300 && len2.is_finite()) {
        return DVec2::ONE;
    }
    let du = (d.x * dd.z - d.z * dd.x) / (2.0 * PI * rho2);
    let dv = -(dd.y - d.y * d.dot(dd) / len2) / (PI * rho2.sqrt());
    let c = |x: f64| if x.is_nan() { 1.0 } else { x.clamp(-1.0, 1.0) };
    DVec2::new(c(du), c(dv))
}

/// One cube face's axes: `sc = a.d`, `tc = b.d` and the major axis `rc = c.d` (positive on the
/// face), from the Vulkan spec's table "Cube map face selection".
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CubeFace {
    /// The direction whose dot product is `sc`.
    pub a: DVec3,
    /// The direction whose dot product is `tc`.
    pub b: DVec3,
    /// The face's outward axis: `|rc| = c.d` on the face.
    pub c: DVec3,
}

/// The six faces in Vulkan's layer order `+x, -x, +y, -y, +z, -z`.
pub const CUBE_FACES: [CubeFace; 6] = [
    // +x: sc = -rz, tc = -ry.
    CubeFace {
        a: DVec3::NEG_Z,
        b: DVec3::NEG_Y,
        c: DVec3::X,
    },
    // -x: sc = +rz, tc = -ry.
    CubeFace {
        a: DVec3::Z,
        b: DVec3::NEG_Y,
        c: DVec3::NEG_X,
    },
    // +y: sc = +rx, tc = +rz.
    CubeFace {
        a: DVec3::X,
        b: DVec3::Z,
        c: DVec3::Y,
    },
    // -y: sc = +rx, tc = -rz.
    CubeFace {
        a: DVec3::X,
        b: DVec3::NEG_Z,
        c: DVec3::NEG_Y,
    },
    // +z: sc = +rx, tc = -ry.
    CubeFace {
        a: DVec3::X,
        b: DVec3::NEG_Y,
        c: DVec3::Z,
    },
    // -z: sc = -rx, tc = -ry.
    CubeFace {
        a: DVec3::NEG_X,
        b: DVec3::NEG_Y,
        c: DVec3::NEG_Z,
    },
];

/// The face direction `d` selects (module docs: the largest magnitude, ties to `z`, then `y`);
/// `None` for a zero or non-finite `d`.
pub fn cube_face_of(d: DVec3) -> Option<usize> {
    if !d.is_finite() || d == DVec3::ZERO {
        return None;
    }
    let a = d.abs();
    let face = if a.z >= a.x && a.z >= a.y {
        if d.z >= 0.0 {
            4
        } else {
            5
        }
    } else if a.y >= a.x {
        if d.y >= 0.0 {
            2
        } else {
            3
        }
    } else if d.x >= 0.0 {
        0
    } else {
        1
    };
    Some(face)
}

/// The coordinates `(s, t)` of direction `d` on face `face` (`[0, 1]^2` on the face `d`
/// selects; outside it on the face's plane extended, for a `d` in front of the face, `c.d > 0`).
pub fn cube_st(face: usize, d: DVec3) -> DVec2 {
    let f = CUBE_FACES[face];
    let rc = f.c.dot(d);
    DVec2::new(0.5 * (f.a.dot(d) / rc + 1.0), 0.5 * (f.b.dot(d) / rc + 1.0))
}

/// The face `d` selects and its coordinates there; `None` for a zero or non-finite `d`.
pub fn cube_face(d: DVec3) -> Option<(usize, DVec2)> {
    let face = cube_face_of(d)?;
    Some((face, cube_st(face, d)))
}

/// The direction (not normalised) through `(s, t)` on face `face`'s plane, any `(s, t)` (outside
/// `[0, 1]^2` the plane extends past the face): `c + a (2s - 1) + b (2t - 1)`.
pub fn cube_direction(face: usize, st: DVec2) -> DVec3 {
    let f = CUBE_FACES[face];
    f.c + f.a * (2.0 * st.x - 1.0) + f.b * (2.0 * st.y - 1.0)
}

/// The change of [`cube_st`]`(face, d)` for a small change `dd` of `d` (the quotient rule of the
/// spec's "Cube Map Derivative Transformation"): `ds = (a.dd (c.d) - (a.d) c.dd) / (2 (c.d)^2)`,
/// likewise `dt` with `b`; each clamped to `[-1, 1]`. Any scale of `d` gives the same result
/// (the projection divides it out).
pub fn cube_dst(face: usize, d: DVec3, dd: DVec3) -> DVec2 {
    let f = CUBE_FACES[face];
    let rc = f.c.dot(d);
    let drc = f.c.dot(dd);
    let q = 2.0 * rc * rc;
    let ds = (f.a.dot(dd) * rc - f.a.dot(d) * drc) / q;
    let dt = (f.b.dot(dd) * rc - f.b.dot(d) * drc) / q;
    let c = |x: f64| if x.is_nan() { 1.0 } else { x.clamp(-1.0, 1.0) };
    DVec2::new(c(ds), c(dt))
}

/// The equal-area octahedral coordinates of direction `d` (any length but 0; module docs),
/// in `[0, 1]^2`. A zero or non-finite `d` gives NaN.
pub fn octahedral_uv(d: DVec3) -> DVec2 {
    let d = d / d.length();
    let (x, y, z) = (d.x.abs(), d.y.abs(), d.z.abs());
    let r = (1.0 - z).max(0.0).sqrt();
    // pbrt's atan(min/max), mirrored when x < y, is atan2(y, x) on the quadrant.
    let phi = if x == 0.0 && y == 0.0 {
        0.0
    } else {
        y.atan2(x) / FRAC_PI_2
    };
    let mut v = phi * r;
    let mut u = r - v;
    if d.z < 0.0 {
        (u, v) = (1.0 - v, 1.0 - u);
    }
    u = u.copysign(d.x);
    v = v.copysign(d.y);
    DVec2::new(0.5 * (u + 1.0), 0.5 * (v + 1.0))
}

/// The unit direction at equal-area octahedral coordinates `uv` in `[0, 1]^2` (pbrt-v4's
/// `EqualAreaSquareToSphere`, the inverse of [`octahedral_uv`]).
pub fn octahedral_direction(uv: DVec2) -> DVec3 {
    let (u, v) = (2.0 * uv.x - 1.0, 2.0 * uv.y - 1.0);
    let (up, vp) = (u.abs(), v.abs());
    let signed_distance = 1.0 - (up + vp);
    let r = 1.0 - signed_distance.abs();
    let phi = if r == 0.0 { 1.0 } else { (vp - up) / r + 1.0 } * PI / 4.0;
    let z = (1.0 - r * r).copysign(signed_distance);
    let s = r * (2.0 - r * r).max(0.0).sqrt();
    DVec3::new(phi.cos().copysign(u) * s, phi.sin().copysign(v) * s, z)
}

/// The octahedral square's continuation past its edges (pbrt-v4's `WrapEqualAreaSquare`): a
/// point past an edge is the point mirrored back across it, reflected about the edge's midpoint
/// (`u < 0` becomes `(-u, 1 - v)`, `u > 1` becomes `(2 - u, 1 - v)`, likewise in `v`). For `uv`
/// within one width of the square, the result is in `[0, 1]^2`, and the direction there is
/// continuous across every edge.
pub fn octahedral_wrap(uv: DVec2) -> DVec2 {
    let (mut u, mut v) = (uv.x, uv.y);
    if u < 0.0 {
        u = -u;
        v = 1.0 - v;
    } else if u > 1.0 {
        u = 2.0 - u;
        v = 1.0 - v;
    }
    if v < 0.0 {
        u = 1.0 - u;
        v = -v;
    } else if v > 1.0 {
        u = 1.0 - u;
        v = 2.0 - v;
    }
    DVec2::new(u, v)
}

/// The change of [`octahedral_uv`] for a small change `dd` of `d`, differentiating the branch
/// `d` lies in (its quadrant and hemisphere): with `x, y, z` the magnitudes of the unit
/// direction's components, `r = sqrt(1 - z)` and `phi = atan2(y, x) / (pi / 2)`,
/// `dr = -dz / (2r)`, `dphi = (x dy - y dx) / ((pi / 2) (x^2 + y^2))`, `v = phi r`, `u = r - v`,
/// then the lower hemisphere's swap and the quadrant's signs. Each component is clamped to
/// `[-1, 1]`. At the poles, where `phi` is undefined, the mapping stretches a change of angle
/// `|dd|` by at most `1 / (2 sqrt 2)` in each coordinate, which is returned.
pub fn octahedral_duv(d: DVec3, dd: DVec3) -> DVec2 {
    let len = d.length();
    if !(len > 0.0 && len.is_finite()) {
        return DVec2::ONE;
    }
    let n = d / len;
    // The change of the unit direction.
    let dn = (dd - n * n.dot(dd)) / len;
    let (sx, sy, sz) = (1f64.copysign(n.x), 1f64.copysign(n.y), 1f64.copysign(n.z));
    let (x, y, z) = (n.x.abs(), n.y.abs(), n.z.abs());
    let (dx, dy, dz) = (sx * dn.x, sy * dn.y, sz * dn.z);
    let rho2 = x * x + y * y;
    let r = (1.0 - z).max(0.0).sqrt();
    if rho2 < 1e-24 || r < 1e-12 {
        return DVec2::splat((dn.length() / (2.0 * 2f64.sqrt())).min(1.0));
    }
    let phi = y.atan2(x) / FRAC_PI_2;
    let dr = -dz / (2.0 * r);
    let dphi = (x * dy - y * dx) / (FRAC_PI_2 * rho2);
    let mut dv = dphi * r + phi * dr;
    let mut du = dr - dv;
    if n.z < 0.0 {
        (du, dv) = (-dv, -du);
    }
    let c = |x: f64| if x.is_nan() { 1.0 } else { x.clamp(-1.0, 1.0) };
    DVec2::new(c(0.5 * sx * du), c(0.5 * sy * dv))
}

/// The latitude, in radians, at which Web Mercator cuts a square map: `2 atan(e^pi) - pi / 2`
/// (about 85.0511 degrees), where `ln tan(pi / 4 + phi / 2) = pi`, so the square spans
/// `y` in `[-pi, pi]` like `x`.
pub const MERCATOR_WEB_CUT: f64 = 1.484_422_229_745_332_4;

/// How a texture wraps a sphere seen from outside (a globe): the projections of the lecture's
/// "spherical mappings", applied to the direction `d` of a surface point from the sphere's centre.
///
/// Both share `u`: longitude 0 faces `+z` at `u = 0` (and 1), longitudes increase eastwards
/// towards `+x` (`u = 1/4`), so `u = atan2(d.x, d.z) / (2 pi)` reduced to `[0, 1)`; the seam
/// `u = 0 = 1` is the meridian through `+z`. `v = 0` is the north (`+y`) edge of the image.
/// - **Equirect**: `v = acos(d.y / |d|) / pi`, the colatitude; the poles are the image's top and
///   bottom rows, where `u` is undefined.
/// - **Mercator**: `v = 1/2 - ln tan(pi/4 + phi/2) / (2 Y)`, `Y = ln tan(pi/4 + cut/2)`, with
///   `phi` the latitude (`ln tan(pi/4 + phi/2) = atanh(sin phi)`; Snyder 1987, "Map Projections:
///   A Working Manual", eq. 7-2). The projection is conformal and reaches infinity at the poles,
///   so it is cut at latitude `cut` (Web Mercator's [`MERCATOR_WEB_CUT`] for a square map): past
///   it `v` clamps to the edge row (the polar caps take that row's colour) and stops changing.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SurfaceProjection {
    /// Latitude-longitude.
    Equirect,
    /// Mercator, cut at latitude `cut` radians, in `(0, pi/2)`.
    Mercator {
        /// The latitude (radians) mapped to the image's top edge; `-cut` maps to the bottom.
        cut: f64,
    },
}

/// `d` mirrored in `x`: the surface mappings' `u` runs the other way round from the environment's
/// (a globe is seen from outside, an environment from inside).
fn mirror_x(d: DVec3) -> DVec3 {
    DVec3::new(-d.x, d.y, d.z)
}

impl SurfaceProjection {
    /// Mercator with Web Mercator's cut ([`MERCATOR_WEB_CUT`]).
    pub const MERCATOR: SurfaceProjection = SurfaceProjection::Mercator {
        cut: MERCATOR_WEB_CUT,
    };

    /// The name a scene file uses: `equirect` or `mercator`.
    pub fn name(self) -> &'static str {
        match self {
            SurfaceProjection::Equirect => "equirect",
            SurfaceProjection::Mercator { .. } => "mercator",
        }
    }

    /// `Y`: Mercator's `ln tan(pi/4 + cut/2)`, the half-height of the map in `x`'s units (1 for
    /// Equirect, where it is not used).
    fn half_height(self) -> f64 {
        match self {
            SurfaceProjection::Equirect => 1.0,
            SurfaceProjection::Mercator { cut } => cut.sin().atanh(),
        }
    }

    /// The texture coordinates of surface direction `d` (any length but 0): `u` in `[0, 1]`,
    /// `v` in `[0, 1]` (see the type's docs). A zero or non-finite `d` gives NaN.
    pub fn uv(self, d: DVec3) -> DVec2 {
        match self {
            SurfaceProjection::Equirect => equirect_uv(mirror_x(d)),
            SurfaceProjection::Mercator { .. } => {
                // equirect_uv's u of the mirrored direction, without its acos.
                let u = 0.5 + (-d.x).atan2(-d.z) / (2.0 * PI);
                let y = (d.y / d.length()).clamp(-1.0, 1.0).atanh();
                DVec2::new(u, (0.5 - y / (2.0 * self.half_height())).clamp(0.0, 1.0))
            }
        }
    }

    /// The change of [`SurfaceProjection::uv`] for a small change `dd` of `d`, in closed form, so
    /// continuous across the seam (conventions.md: `u` is never differenced). `du` is
    /// [`equirect_duv`]'s, mirrored; Mercator's `dv = -(dy - y (d.dd) / |d|^2) |d| / (2 Y rho^2)`
    /// with `rho^2 = x^2 + z^2` (the derivative of `atanh(y / |d|)`), and 0 past the cut, where
    /// `v` is clamped. Each component is clamped to `[-1, 1]`; at the poles `du` is the clamp.
    pub fn duv(self, d: DVec3, dd: DVec3) -> DVec2 {
        let duv = equirect_duv(mirror_x(d), mirror_x(dd));
        match self {
            SurfaceProjection::Equirect => duv,
            SurfaceProjection::Mercator { .. } => {
                let (len2, rho2) = (d.length_squared(), d.x * d.x + d.z * d.z);
                let big_y = self.half_height();
                let y = (d.y / len2.sqrt()).clamp(-1.0, 1.0).atanh();
                let dv = if !(rho2 > 1e-300 && len2.is_finite()) || y.abs() >= big_y {
                    0.0
                } else {
                    -(dd.y - d.y * d.dot(dd) / len2) * len2.sqrt() / (2.0 * big_y * rho2)
                };
                let dv = if dv.is_nan() {
                    0.0
                } else {
                    dv.clamp(-1.0, 1.0)
                };
                DVec2::new(duv.x, dv)
            }
        }
    }

    /// The unit direction at texture coordinates `uv` (the inverse of
    /// [`SurfaceProjection::uv`] inside the cut).
    pub fn direction(self, uv: DVec2) -> DVec3 {
        let v = match self {
            SurfaceProjection::Equirect => uv.y,
            SurfaceProjection::Mercator { .. } => {
                let lat = ((1.0 - 2.0 * uv.y) * self.half_height()).tanh().asin();
                0.5 - lat / PI
            }
        };
        mirror_x(equirect_direction(DVec2::new(uv.x, v)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Directions spread over the sphere (a Fibonacci lattice), scaled to varying lengths.
    fn directions(n: usize) -> impl Iterator<Item = DVec3> {
        (0..n).map(move |k| {
            let z = 1.0 - 2.0 * (k as f64 + 0.5) / n as f64;
            let phi = k as f64 * PI * (3.0 - 5f64.sqrt());
            let s = (1.0 - z * z).sqrt();
            DVec3::new(s * phi.cos(), s * phi.sin(), z) * (0.5 + (k % 7) as f64)
        })
    }

    #[test]
    fn equirect_round_trips_and_follows_the_design_axes() {
        // -z is the centre column, +y the top row, +x a quarter turn right of -z.
        let uv = equirect_uv(DVec3::NEG_Z);
        assert!((uv - DVec2::new(0.5, 0.5)).length() < 1e-12);
        assert!(equirect_uv(DVec3::Y).y.abs() < 1e-12);
        assert!((equirect_uv(DVec3::NEG_Y).y - 1.0).abs() < 1e-12);
        assert!((equirect_uv(DVec3::X).x - 0.75).abs() < 1e-12);
        for k in 0..200 {
            let uv = DVec2::new(
                (k as f64 * 0.137) % 1.0,
                0.01 + 0.98 * (k as f64 * 0.291) % 0.98,
            );
            let back = equirect_uv(equirect_direction(uv) * 3.0);
            assert!((back - uv).length() < 1e-9, "{uv} -> {back}");
        }
    }

    #[test]
    fn the_equirect_jacobian_matches_differences_away_from_the_seam() {
        for k in 0..100 {
            let uv = DVec2::new(
                0.1 + 0.8 * ((k as f64 * 0.37) % 1.0),
                0.05 + 0.9 * ((k as f64 * 0.61) % 1.0),
            );
            let d = equirect_direction(uv) * (1.0 + k as f64 * 0.1);
            let dd = DVec3::new(0.3, -0.2, 0.5) * 1e-6;
            let num = (equirect_uv(d + dd) - equirect_uv(d - dd)) / 2.0;
            let ana = equirect_duv(d, dd);
            assert!(
                (num - ana).length() < 1e-9 * (1.0 + num.length() * 1e6),
                "{num} {ana}"
            );
        }
    }

    #[test]
    fn the_equirect_jacobian_is_continuous_across_the_seam() {
        // Either side of +z (u = 0 and u = 1): the same du, where differencing u jumps by 1.
        let dd = DVec3::new(1e-3, 0.0, 0.0);
        let a = equirect_duv(DVec3::new(-1e-9, 0.0, 1.0), dd);
        let b = equirect_duv(DVec3::new(1e-9, 0.0, 1.0), dd);
        assert!((a - b).length() < 1e-9);
        assert!((a.x - (-1e-3 / (2.0 * PI))).abs() < 1e-9, "{a}");
        let jump =
            equirect_uv(DVec3::new(1e-9, 0.0, 1.0)).x - equirect_uv(DVec3::new(-1e-9, 0.0, 1.0)).x;
        assert!(jump.abs() > 0.99);
        // At a pole u is undefined: the clamp.
        assert_eq!(equirect_duv(DVec3::Y, dd), DVec2::ONE);
    }

    #[test]
    fn cube_faces_follow_the_vulkan_table() {
        // The face centres, and the spec's orientation: on +z, s grows with +x and t with -y.
        for (face, axis) in [
            DVec3::X,
            DVec3::NEG_X,
            DVec3::Y,
            DVec3::NEG_Y,
            DVec3::Z,
            DVec3::NEG_Z,
        ]
        .into_iter()
        .enumerate()
        {
            let (f, st) = cube_face(axis * 2.0).unwrap();
            assert_eq!(f, face);
            assert!((st - DVec2::splat(0.5)).length() < 1e-12);
        }
        let (f, st) = cube_face(DVec3::new(0.5, -0.25, 1.0)).unwrap();
        assert_eq!(f, 4);
        assert!((st - DVec2::new(0.75, 0.625)).length() < 1e-12, "{st}");
        // +x: sc = -rz, tc = -ry.
        let (f, st) = cube_face(DVec3::new(1.0, 0.5, 0.5)).unwrap();
        assert_eq!(f, 0);
        assert!((st - DVec2::new(0.25, 0.25)).length() < 1e-12, "{st}");
        // -y: sc = +rx, tc = -rz.
        let (f, st) = cube_face(DVec3::new(0.5, -1.0, 0.5)).unwrap();
        assert_eq!(f, 3);
        assert!((st - DVec2::new(0.75, 0.25)).length() < 1e-12, "{st}");
        assert_eq!(cube_face(DVec3::ZERO), None);
        assert_eq!(cube_face(DVec3::new(f64::NAN, 0.0, 1.0)), None);
    }

    #[test]
    fn cube_coordinates_round_trip_and_the_jacobian_matches_differences() {
        for d in directions(500) {
            let (face, st) = cube_face(d).unwrap();
            assert!((0.0..=1.0).contains(&st.x) && (0.0..=1.0).contains(&st.y));
            let back = cube_direction(face, st).normalize();
            assert!((back - d.normalize()).length() < 1e-12, "{d}");
            let dd = DVec3::new(0.3, -0.2, 0.5) * 1e-6;
            let num = (cube_st(face, d + dd) - cube_st(face, d - dd)) / 2.0;
            let ana = cube_dst(face, d, dd);
            assert!(
                (num - ana).length() < 1e-12 + 1e-6 * ana.length(),
                "{num} {ana}"
            );
        }
    }

    #[test]
    fn a_cube_face_plane_continues_onto_its_neighbours() {
        // Past a face's edge its extended plane points into the neighbouring face: the
        // coordinates there are the neighbour's, continuously (no fold at the edge).
        for face in 0..6 {
            for k in 0..=20 {
                let t = k as f64 / 20.0;
                for st in [
                    DVec2::new(1.0 + 1e-9, t),
                    DVec2::new(-1e-9, t),
                    DVec2::new(t, 1.0 + 1e-9),
                    DVec2::new(t, -1e-9),
                ] {
                    let inside = cube_direction(face, st.clamp(DVec2::ZERO, DVec2::ONE));
                    let (nf, nst) = cube_face(cube_direction(face, st)).unwrap();
                    assert_ne!(nf, face);
                    // On the neighbour's edge, at the same direction.
                    let edge = nst.x.min(1.0 - nst.x).min(nst.y).min(1.0 - nst.y);
                    assert!(edge.abs() < 1e-8, "{face} {st}: {nf} {nst}");
                    let back = cube_direction(nf, nst).normalize();
                    assert!((back - inside.normalize()).length() < 1e-8);
                }
            }
        }
    }

    #[test]
    fn octahedral_round_trips_and_puts_z_at_the_centre() {
        assert!((octahedral_uv(DVec3::Z) - DVec2::splat(0.5)).length() < 1e-12);
        let corner = octahedral_uv(DVec3::NEG_Z);
        assert!(corner.x.min(1.0 - corner.x) < 1e-12 && corner.y.min(1.0 - corner.y) < 1e-12);
        // +x on the equator: the right corner of the inner diamond.
        assert!((octahedral_uv(DVec3::X) - DVec2::new(1.0, 0.5)).length() < 1e-12);
        assert!((octahedral_uv(DVec3::Y) - DVec2::new(0.5, 1.0)).length() < 1e-12);
        for d in directions(500) {
            let uv = octahedral_uv(d);
            let back = octahedral_direction(uv);
            assert!((back - d.normalize()).length() < 1e-9, "{d} {uv} {back}");
        }
    }

    #[test]
    fn octahedral_texels_have_equal_solid_angle() {
        // Area preservation: the Jacobian determinant of uv(d) is the same everywhere,
        // 1 / (4 pi) of the square per steradian.
        for d in directions(300) {
            let n = d.normalize();
            let t = n
                .cross(if n.x.abs() < 0.9 { DVec3::X } else { DVec3::Y })
                .normalize();
            let b = n.cross(t);
            let h = 1e-6;
            let du = octahedral_duv(n, t * h);
            let dv = octahedral_duv(n, b * h);
            let det = (du.x * dv.y - du.y * dv.x).abs() / (h * h);
            // Skip the folds (the axis planes), where one side's branch is differentiated.
            if n.x.abs() < 1e-3 || n.y.abs() < 1e-3 || n.z.abs() < 1e-3 {
                continue;
            }
            assert!((det - 1.0 / (4.0 * PI)).abs() < 1e-6, "{n}: {det}");
        }
    }

    #[test]
    fn the_octahedral_jacobian_matches_differences() {
        for d in directions(500) {
            let dd = DVec3::new(0.3, -0.2, 0.5) * 1e-7;
            let (a, b) = (octahedral_uv(d + dd), octahedral_uv(d - dd));
            let n = d.normalize();
            // Away from the folds, where both samples are on one branch.
            if n.x.abs() < 1e-4 || n.y.abs() < 1e-4 || n.z.abs() < 1e-4 {
                continue;
            }
            let num = (a - b) / 2.0;
            let ana = octahedral_duv(d, dd);
            assert!((num - ana).length() < 1e-12, "{d}: {num} {ana}");
        }
    }

    #[test]
    fn the_octahedral_wrap_is_continuous_across_every_edge() {
        for k in 0..=40 {
            let t = k as f64 / 40.0;
            for (inside, outside) in [
                (DVec2::new(1e-7, t), DVec2::new(-1e-7, t)),
                (DVec2::new(1.0 - 1e-7, t), DVec2::new(1.0 + 1e-7, t)),
                (DVec2::new(t, 1e-7), DVec2::new(t, -1e-7)),
                (DVec2::new(t, 1.0 - 1e-7), DVec2::new(t, 1.0 + 1e-7)),
            ] {
                let a = octahedral_direction(inside);
                let b = octahedral_direction(octahedral_wrap(outside));
                assert!((a - b).length() < 1e-5, "{inside} {outside}: {a} {b}");
            }
        }
        // A texel centre past the edge wraps onto a texel centre.
        let n = 8.0;
        let w = octahedral_wrap(DVec2::new(-0.5 / n, 2.5 / n));
        assert!((w * n - DVec2::new(0.5, 5.5)).length() < 1e-12, "{w}");
    }

    #[test]
    fn surface_projections_follow_the_globe_axes_and_round_trip() {
        for proj in [SurfaceProjection::Equirect, SurfaceProjection::MERCATOR] {
            // Longitude 0 faces +z, +x is a quarter turn east, -z half a turn; the equator is
            // the middle row.
            let at = |d: DVec3| proj.uv(d);
            assert!((at(DVec3::X) - DVec2::new(0.25, 0.5)).length() < 1e-12);
            assert!((at(DVec3::NEG_Z) - DVec2::new(0.5, 0.5)).length() < 1e-12);
            assert!((at(DVec3::NEG_X) - DVec2::new(0.75, 0.5)).length() < 1e-12);
            assert!(at(DVec3::new(0.0, 1.0, 0.5)).y < 0.5, "north is up");
            for k in 0..300 {
                let uv = DVec2::new(
                    (k as f64 * 0.137) % 1.0,
                    0.01 + 0.98 * ((k as f64 * 0.291) % 1.0),
                );
                let back = proj.uv(proj.direction(uv) * (0.5 + k as f64 * 0.01));
                let du = (back.x - uv.x).abs();
                assert!(
                    du.min(1.0 - du) < 1e-9 && (back.y - uv.y).abs() < 1e-9,
                    "{uv} {back}"
                );
            }
        }
        // Web Mercator's cut makes the square map's height equal its width: y = +-pi.
        assert!((MERCATOR_WEB_CUT.sin().atanh() - PI).abs() < 1e-12);
        assert!((MERCATOR_WEB_CUT.to_degrees() - 85.051_128_78).abs() < 1e-8);
    }

    #[test]
    fn mercator_is_cut_at_its_latitude_and_conformal_inside() {
        let cut = 60f64.to_radians();
        let m = SurfaceProjection::Mercator { cut };
        let at_lat = |lat: f64, lon: f64| {
            DVec3::new(lat.cos() * lon.sin(), lat.sin(), lat.cos() * lon.cos())
        };
        // The cut latitude is the top edge; past it v stays there and stops changing.
        assert!(m.uv(at_lat(cut, 1.0)).y.abs() < 1e-12);
        assert!((m.uv(at_lat(-cut, 1.0)).y - 1.0).abs() < 1e-12);
        for lat in [61f64, 75.0, 89.0, 90.0] {
            let d = at_lat(lat.to_radians(), 0.3);
            assert_eq!(m.uv(d).y, 0.0);
            assert_eq!(m.duv(d, DVec3::new(0.0, 1e-3, -1e-3)).y, 0.0);
            assert_eq!(m.uv(-d).y, 1.0);
        }
        // Conformal: with Web Mercator's cut a small step north moves v (down the image, so
        // negative) by as much as the same step east moves u, at every latitude inside the cut.
        let w = SurfaceProjection::MERCATOR;
        for lat in [-80.0f64, -45.0, 0.0, 30.0, 70.0, 85.0] {
            let (lat, lon) = (lat.to_radians(), 0.7);
            let d = at_lat(lat, lon);
            let east = DVec3::new(lon.cos(), 0.0, -lon.sin()) * 1e-4;
            let north =
                DVec3::new(-lat.sin() * lon.sin(), lat.cos(), -lat.sin() * lon.cos()) * 1e-4;
            let (e, n) = (w.duv(d, east), w.duv(d, north));
            assert!(e.y.abs() < 1e-15 && n.x.abs() < 1e-15, "{e} {n}");
            assert!((e.x + n.y).abs() < 1e-9 * e.x.abs(), "{lat}: {e} {n}");
            // And equirect stretches east by 1 / cos(lat) against north, halved by the 2:1 image.
            let q = SurfaceProjection::Equirect;
            let (e, n) = (q.duv(d, east), q.duv(d, north));
            assert!((e.x * lat.cos() * 2.0 + n.y).abs() < 1e-9, "{lat}: {e} {n}");
        }
    }

    #[test]
    fn surface_jacobians_match_differences_and_cross_the_seam() {
        for proj in [
            SurfaceProjection::Equirect,
            SurfaceProjection::MERCATOR,
            SurfaceProjection::Mercator { cut: 1.0 },
        ] {
            for d in directions(400) {
                let n = d.normalize();
                let uv = proj.uv(d);
                // Away from the seam, the poles and the cut (where v has a kink).
                let near_cut = matches!(proj, SurfaceProjection::Mercator { cut }
                    if (n.y.asin().abs() - cut).abs() < 1e-3);
                if !(0.01..0.99).contains(&uv.x) || n.y.abs() > 0.999 || near_cut {
                    continue;
                }
                let dd = DVec3::new(0.3, -0.2, 0.5) * 1e-6 * d.length();
                let num = (proj.uv(d + dd) - proj.uv(d - dd)) / 2.0;
                let ana = proj.duv(d, dd);
                assert!((num - ana).length() < 1e-9, "{proj:?} {d}: {num} {ana}");
            }
            // Either side of +z: u jumps by 1, its derivative does not.
            let dd = DVec3::new(1e-3, 0.0, 0.0);
            let (a, b) = (DVec3::new(-1e-9, 0.2, 1.0), DVec3::new(1e-9, 0.2, 1.0));
            assert!((proj.uv(a).x - proj.uv(b).x).abs() > 0.99);
            assert!((proj.duv(a, dd) - proj.duv(b, dd)).length() < 1e-9);
            assert!(proj.duv(a, dd).x > 0.0, "east is +u");
        }
    }
}
