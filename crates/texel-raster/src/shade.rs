//! Colour shading: the texture's colour as the diffuse colour, times the interpolated vertex colour,
//! optionally lit by one directional light (Lambert), and the footprint handed to the sampler.
//!
//! `colour = texture * vertex_colour * (ambient + light_colour * max(0, n . l))` in linear light, with
//! `n` the perspective-correct interpolated normal, normalised. Alpha is `texture.a * vertex.a`;
//! there is no blending (the nearest fragment replaces the pixel).
//!
//! Footprints: `uv` is interpolated in `f64`. For periodic address modes the sampler's result does
//! not change when a whole period is subtracted, so `u` (`v`) is reduced modulo 1 (Repeat) or 2
//! (MirrorRepeat) in `f64` before the conversion to `f32`: far from the origin (the ground scene
//! reaches `|u| = 250`, 256 000 texels) this keeps the texel position exact to `f32` precision
//! instead of losing 1/64 texel.

use glam::{DVec2, DVec3, Vec3, Vec4};
use texel_texture::floor::{floor_staged_f64, STAGED_F64_LIMIT};
use texel_texture::{AddressMode, Footprint, Sampler, Texture};

use crate::draw::{DrawCall, Vertex};
use crate::settings::DirectionalLight;
use crate::setup::TriangleSetup;

/// Per-draw state resolved once per frame.
#[derive(Clone, Copy, Debug)]
pub(crate) struct DrawContext<'a> {
    pub texture: &'a Texture,
    pub sampler: &'a Sampler,
    pub vertices: &'a [Vertex],
    /// Period of u and v under the sampler's address modes (0: not periodic).
    period: DVec2,
    /// `1 / period` (0 where not periodic).
    inv_period: DVec2,
    /// Whether any vertex colour differs from opaque white (skips the multiply when not).
    colored: bool,
}

fn period(mode: AddressMode) -> f64 {
    match mode {
        AddressMode::Repeat => 1.0,
        AddressMode::MirrorRepeat => 2.0,
        _ => 0.0,
    }
}

fn inv_period(mode: AddressMode) -> f64 {
    let p = period(mode);
    if p > 0.0 {
        1.0 / p
    } else {
        0.0
    }
}

/// `x - p * floor(x / p)` for a period `p > 0`; `x` unchanged for `p = 0`, non-finite `x` or
/// `|x / p| >=` [`STAGED_F64_LIMIT`] (`2^51`, where f64 has at most one fraction bit left to keep).
///
/// Branch-free so that [`crate::tile`]'s span loops vectorise: the floor is the staged one
/// ([`floor_staged_f64`]; `f64::floor` is a libm call without SSE4.1, and an integer-conversion
/// floor has no packed form before AVX-512).
///
/// `inv_p` is `1 / p` (0 for `p = 0`): the periods are 1 and 2, whose reciprocals are exact, so
/// `x * inv_p` equals `x / p` bit for bit without a division (a `divsd` per coordinate would sit on
/// every pixel's critical path).
#[inline(always)]
fn reduce(x: f64, p: f64, inv_p: f64) -> f64 {
    let t = x * inv_p;
    let q = floor_staged_f64(t);
    if p > 0.0 && t.abs() < STAGED_F64_LIMIT {
        x - p * q
    } else {
        x
    }
}

impl<'a> DrawContext<'a> {
    pub fn new(draw: &DrawCall<'a>) -> Self {
        let d = draw.sampler.descriptor();
        DrawContext {
            texture: draw.texture,
            sampler: draw.sampler,
            vertices: draw.vertices,
            period: DVec2::new(period(d.address_mode_u), period(d.address_mode_v)),
            inv_period: DVec2::new(inv_period(d.address_mode_u), inv_period(d.address_mode_v)),
            colored: draw.vertices.iter().any(|v| v.color != Vec4::ONE),
        }
    }

    /// The triangle's vertices.
    #[inline(always)]
    pub fn vertices(&self, t: &TriangleSetup) -> [&'a Vertex; 3] {
        t.indices.map(|k| &self.vertices[k as usize])
    }

    /// The triangle's texture coordinates in `f64`.
    #[inline(always)]
    pub fn uvs(&self, t: &TriangleSetup) -> [DVec2; 3] {
        self.vertices(t).map(|v| v.uv.as_dvec2())
    }

    /// The footprint for the sampler: `uv` reduced by whole periods, derivatives as given.
    #[inline(always)]
    pub fn footprint(&self, uv: DVec2, duv_dx: DVec2, duv_dy: DVec2) -> Footprint {
        Footprint {
            u: reduce(uv.x, self.period.x, self.inv_period.x) as f32,
            v: reduce(uv.y, self.period.y, self.inv_period.y) as f32,
            dudx: duv_dx.x as f32,
            dudy: duv_dy.x as f32,
            dvdx: duv_dx.y as f32,
            dvdy: duv_dy.y as f32,
        }
    }
}

/// A [`DirectionalLight`] with its direction normalised once.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Lighting {
    to_light: Vec3,
    color: Vec3,
    ambient: Vec3,
}

impl Lighting {
    pub fn new(light: &DirectionalLight) -> Self {
        Lighting {
            to_light: light.direction.normalize_or_zero(),
            color: light.color,
            ambient: light.ambient,
        }
    }
}

/// The shaded colour of a fragment with texture colour `tex` (linear RGBA) and barycentrics `lambda`.
#[inline(always)]
pub(crate) fn shade(
    ctx: &DrawContext,
    verts: [&Vertex; 3],
    lambda: DVec3,
    tex: [f32; 4],
    light: Option<&Lighting>,
) -> [f32; 4] {
    let l = lambda.as_vec3();
    let mut c = Vec4::from_array(tex);
    if ctx.colored {
        c *= verts[0].color * l.x + verts[1].color * l.y + verts[2].color * l.z;
    }
    if let Some(light) = light {
        let n = (verts[0].normal * l.x + verts[1].normal * l.y + verts[2].normal * l.z)
            .normalize_or_zero();
        let k = light.ambient + light.color * n.dot(light.to_light).max(0.0);
        c = (c.truncate() * k).extend(c.w);
    }
    c.to_array()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn periodic_reduction() {
        assert_eq!(reduce(250.25, 1.0, 1.0), 0.25);
        assert_eq!(reduce(-0.25, 1.0, 1.0), 0.75);
        assert_eq!(reduce(-0.25, 2.0, 0.5), 1.75);
        assert_eq!(reduce(3.5, 0.0, 0.0), 3.5);
        assert_eq!(reduce(-2.0, 1.0, 1.0), 0.0);
        assert_eq!(reduce(1e300, 1.0, 1.0), 1e300);
        assert_eq!(reduce(-0.0, 1.0, 1.0), 0.0);
        assert_eq!(reduce(-1e-300, 1.0, 1.0), 1.0);
        assert_eq!(reduce(2.5, 2.0, 0.5), 0.5);
        assert_eq!(reduce(-3.0, 2.0, 0.5), 1.0);
        // The rounding floor against the library floor, near and far from the origin.
        for k in -20_000..20_000 {
            let x = k as f64 * 0.377_777_7 + (k as f64).powi(3) * 1e-3;
            for (p, ip) in [(1.0, 1.0), (2.0, 0.5)] {
                assert_eq!(reduce(x, p, ip), x - p * (x / p).floor(), "{x} mod {p}");
            }
        }
        let big = 2f64.powi(51) - 0.5;
        assert_eq!(reduce(big, 1.0, 1.0), 0.5);
        assert_eq!(reduce(2f64.powi(51), 1.0, 1.0), 2f64.powi(51));
        assert!(reduce(f64::NAN, 1.0, 1.0).is_nan());
        assert_eq!(inv_period(AddressMode::MirrorRepeat), 0.5);
        assert_eq!(inv_period(AddressMode::ClampToEdge), 0.0);
        // Multiplying by the exact reciprocal is the division, bit for bit.
        for k in -1000..1000 {
            let x = k as f64 * 0.123_456_789_1;
            for p in [1.0, 2.0] {
                assert_eq!(x * (1.0 / p), x / p);
            }
        }
    }
}
