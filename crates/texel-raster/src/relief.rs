//! Surface relief from textures: the shading normal from a normal map or a height map (bump
//! mapping), specular antialiasing of what they put under a pixel, and parallax occlusion
//! mapping. [`crate::shade`] calls these for lit draws with a [`Material`].
//!
//! Conventions (see [`Displacement`]): a height map's value `h` in `[0, 1]` places the surface at
//! `p + height_scale (h - 1) n`, so the mesh is the top of the relief. The surface's derivatives
//! `dp/du` and `dp/dv` are the triangle's own (constant over it), made orthogonal to the
//! interpolated normal `n`; a gradient `g = height_scale (dh/du, dh/dv)` then gives the displaced
//! surface's normal `normalize((dp/du + g_u n) x (dp/dv + g_v n))`, turned to `n`'s side
//! (pbrt-v4 `BumpMap`, without the `h dn/du` term, which is 0 on flat triangles).

use glam::{Vec2, Vec3};
use texel_texture::Footprint;

use crate::draw::Vertex;
use crate::layers::{read_normal, LayerSample};
use crate::material::{self, Material, SlopeSpread, SpecularAa};
use crate::point::ShadingPoint;

/// The fewest and the most linear steps of the parallax march (at normal incidence and at
/// grazing angles; Tatarchuk 2006 interpolates between them by `n.v`).
pub(crate) const POM_STEPS: (u32, u32) = (8, 64);

/// The specular lobe a shading normal is read for: the antialiasing method and the perceptual
/// roughness before it.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Lobe {
    /// How the spread of the normals under the footprint widens the lobe.
    pub aa: SpecularAa,
    /// Perceptual roughness before antialiasing.
    pub roughness: f32,
}

/// A fragment's shading normal and what specular antialiasing made of it.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Shading {
    /// Unit shading normal.
    pub normal: Vec3,
    /// The mean normal for the diffuse term, where the method keeps it.
    pub diffuse_normal: Option<Vec3>,
    /// Perceptual roughness after antialiasing.
    pub roughness: f32,
    /// The spread of the normals that antialiasing measured (the lobe's shape, see
    /// [`SlopeSpread::d`]); `None` without antialiasing.
    pub spread: Option<SlopeSpread>,
}

/// The barycentric interpolation of `f` over the triangle's vertices.
#[inline(always)]
pub(crate) fn interpolate(verts: [&Vertex; 3], l: Vec3, f: impl Fn(&Vertex) -> Vec3) -> Vec3 {
    f(verts[0]) * l.x + f(verts[1]) * l.y + f(verts[2]) * l.z
}

/// The interpolated unit normal at barycentrics `l`, or the face normal where the vertices'
/// normals cancel.
pub(crate) fn geometric_normal(verts: [&Vertex; 3], l: Vec3) -> Vec3 {
    let n = interpolate(verts, l, |v| v.normal).normalize_or_zero();
    if n != Vec3::ZERO {
        return n;
    }
    (verts[1].position - verts[0].position)
        .cross(verts[2].position - verts[0].position)
        .normalize_or(Vec3::Y)
}

/// `v` less its component along the unit `n`.
fn on_plane(v: Vec3, n: Vec3) -> Vec3 {
    v - n * n.dot(v)
}

/// The triangle's `dp/du` and `dp/dv` (world units per unit of `u`, `v`), made orthogonal to the
/// unit `n`; `None` where its texture coordinates are degenerate (zero uv area).
pub(crate) fn surface_derivatives(verts: [&Vertex; 3], n: Vec3) -> Option<(Vec3, Vec3)> {
    let e1 = verts[1].position - verts[0].position;
    let e2 = verts[2].position - verts[0].position;
    let d1 = verts[1].uv - verts[0].uv;
    let d2 = verts[2].uv - verts[0].uv;
    let det = d1.x * d2.y - d1.y * d2.x;
    if det == 0.0 || !det.is_finite() {
        return None;
    }
    let inv = 1.0 / det;
    let dpdu = on_plane((e1 * d2.y - e2 * d1.y) * inv, n);
    let dpdv = on_plane((e2 * d1.x - e1 * d2.x) * inv, n);
    (dpdu.is_finite() && dpdv.is_finite() && dpdu.cross(dpdv) != Vec3::ZERO).then_some((dpdu, dpdv))
}

/// The normal of the surface whose height has gradient `g` (world units per unit of u and v),
/// over tangent-plane derivatives `(a, b)` of the surface with unit normal `n` (module docs).
pub(crate) fn normal_from_gradient(a: Vec3, b: Vec3, n: Vec3, g: Vec2) -> Vec3 {
    let m = (a + n * g.x).cross(b + n * g.y);
    let m = if m.dot(n) < 0.0 { -m } else { m };
    m.normalize_or(n)
}

/// The unit tangent and bitangent at barycentrics `l` for the unit shading `normal`: the
/// interpolated tangent made orthogonal to `normal` (Gram-Schmidt), and glTF's bitangent
/// `w cross(normal, tangent)`. `None` where the vertices carry no tangent (or it is parallel to
/// the normal): the normal map cannot be oriented.
fn tangent_frame(verts: [&Vertex; 3], l: Vec3, normal: Vec3) -> Option<(Vec3, Vec3)> {
    let tangent = verts[0].tangent * l.x + verts[1].tangent * l.y + verts[2].tangent * l.z;
    let t = (tangent.truncate() - normal * normal.dot(tangent.truncate())).try_normalize()?;
    let sign = if tangent.w < 0.0 { -1.0 } else { 1.0 };
    Some((t, normal.cross(t) * sign))
}

/// Bump mapping's step along one texture axis: half the footprint's extent along it (pbrt-v4
/// `BumpMap`: `du = (|du/dx| + |du/dy|) / 2`), or an eighth of a level-0 texel where the footprint
/// is a point (the reference's sub-samples), for a map `size` texels across.
fn bump_step(d_dx: f32, d_dy: f32, size: u32) -> f32 {
    let d = 0.5 * (d_dx.abs() + d_dy.abs());
    if d > 0.0 && d.is_finite() {
        d
    } else {
        0.125 / size.max(1) as f32
    }
}

/// The shading normal and roughness of material `m` at fragment `p` (its barycentrics and
/// footprint) with interpolated unit normal `n`, for the lobe's roughness and its specular
/// antialiasing `aa` (what
/// [`SpecularAa::Projected`] adds is the caller's: it needs the neighbours' normals). `layered`
/// is the fragment's [`LayerSample`] for a layered material (its blended normal, if any, is used
/// in place of the normal map).
pub(crate) fn shading_normal(
    m: &Material,
    layered: Option<&LayerSample>,
    p: &ShadingPoint,
    n: Vec3,
    Lobe { aa, roughness }: Lobe,
    count: bool,
    texels: &mut u32,
) -> Shading {
    let (verts, l, fp) = (p.verts, p.l(), &p.fp);
    let plain = Shading {
        normal: n,
        diffuse_normal: None,
        roughness,
        spread: None,
    };
    let layer_normal = layered.and_then(|s| s.normal);
    if layer_normal.is_some() || m.normal_map.is_some() {
        let Some((t, b)) = tangent_frame(verts, l, n) else {
            return plain;
        };
        let to_world = |v: Vec3| t * v.x + b * v.y + n * v.z;
        // The filtered map normal: the mean of the normals under the footprint.
        let mapped = match (layer_normal, &m.normal_map) {
            (Some(ln), _) => ln,
            (None, Some(map)) => {
                let lean = m.lean.filter(|_| aa == SpecularAa::Lean);
                read_normal(map, m.normal_scale, lean, fp, count, texels)
            }
            (None, None) => return plain,
        };
        let base = roughness;
        let mut roughness = roughness;
        let mut spread = None;
        let antialiased = match (aa, mapped.moments) {
            (SpecularAa::Lean, Some(moments)) => {
                let (mean, cov) = material::lean_mean_covariance(moments, 1.0);
                let (nt, r) = material::lean_normal_roughness(mean, cov, roughness);
                roughness = r;
                spread = Some(SlopeSpread {
                    frame: [t, b, n],
                    mean,
                    cov,
                    base_roughness: base,
                });
                Some(nt)
            }
            // Toksvig's rule, also LEAN's fallback where a layer has no moment map.
            (SpecularAa::Toksvig | SpecularAa::Lean, _) => {
                let len = (mapped.raw.length() + mapped.slack).min(1.0);
                roughness = material::toksvig_roughness(roughness, len);
                Some(mapped.mean)
            }
            _ => None,
        };
        let normal = to_world(antialiased.unwrap_or(mapped.mean)).normalize_or(n);
        if antialiased.is_some() && spread.is_none() {
            spread = Some(SlopeSpread::isotropic(normal, base, roughness));
        }
        return Shading {
            normal,
            // Antialiased methods light the diffuse term with the mean normal (no longer than 1:
            // scaling by `normal_scale` can lengthen it).
            diffuse_normal: antialiased.map(|_| to_world(mapped.mean).clamp_length_max(1.0)),
            roughness,
            spread,
        };
    }
    if !m.bumped() {
        return plain;
    }
    let Some((a, b)) = surface_derivatives(verts, n) else {
        return plain;
    };
    let (w, h) = m.height_size();
    let du = bump_step(fp.dudx, fp.dudy, w);
    let dv = bump_step(fp.dvdx, fp.dvdy, h);
    // Central differences: pbrt's forward ones are centred half a step away, which shifts
    // every slope (a bevel's shading) by a quarter of the footprint.
    let at = |du: f32, dv: f32, texels: &mut u32| {
        let fp = Footprint {
            u: fp.u + du,
            v: fp.v + dv,
            ..*fp
        };
        m.height_at(&fp, count, texels).unwrap_or(1.0)
    };
    let (hu0, hu1) = (at(-du / 2.0, 0.0, texels), at(du / 2.0, 0.0, texels));
    let (hv0, hv1) = (at(0.0, -dv / 2.0, texels), at(0.0, dv / 2.0, texels));
    let s = m.height_scale;
    let g = Vec2::new((hu1 - hu0) / du, (hv1 - hv0) / dv) * s;
    let normal = normal_from_gradient(a, b, n, g);
    let base = roughness;
    let mut roughness = roughness;
    let mut spread = None;
    let moments = m
        .height_moments
        .zip(m.height_map.filter(|_| m.layers.is_none()));
    if let (SpecularAa::Lean | SpecularAa::Toksvig, Some((moments, height))) = (aa, moments) {
        // Toksvig measures an averaged normal's length, which a height map does not have; its
        // moments carry the same information (the spread of the normals), so both use them.
        let e = moments.read(height.input.sampler, fp, count, texels);
        // Gradients per unit of u and v become slopes along dp/du and dp/dv by dividing by
        // their lengths (the axes are orthogonal for the usual, unsheared, uv).
        let (la, lb) = (a.length(), b.length());
        let s2 = s * s;
        let var_u = (e[2] - e[0] * e[0]) * s2 / (la * la);
        let var_v = (e[3] - e[1] * e[1]) * s2 / (lb * lb);
        let cov_uv = (e[4] - e[0] * e[1]) * s2 / (la * lb);
        roughness = material::slope_variance_roughness(roughness, var_u, var_v);
        let t = a / la;
        let bt = on_plane(b, t).normalize_or(n.cross(t));
        spread = Some(SlopeSpread {
            frame: [t, bt, n],
            // The bump normal's own slopes, so that the lobe is centred where it points.
            mean: Vec2::new(normal.dot(t), normal.dot(bt)) / normal.dot(n).max(1e-6),
            cov: [var_u.max(0.0), var_v.max(0.0), cov_uv],
            base_roughness: base,
        });
    }
    Shading {
        normal,
        diffuse_normal: None,
        roughness,
        spread,
    }
}

/// Where a parallax-occlusion-mapped view ray meets the relief.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Parallax {
    /// The fragment's footprint moved to the hit (derivatives unchanged, as Tatarchuk's
    /// `tex2Dgrad` keeps the pixel's).
    pub footprint: Footprint,
    /// The hit's world position.
    pub position: Vec3,
}

/// Parallax occlusion mapping (Tatarchuk 2006) of material `m` (which has heights) for the
/// fragment `p` at `position` with unit normal `n`, read through `p`'s footprint, seen from
/// `eye`: march the view
/// ray below the polygon in [`POM_STEPS`] linear steps of depth, reading the height through the
/// footprint, until it passes below the relief, then intersect the last segment with the relief
/// by the secant rule. `None` where the ray is parallel to or leaving the surface, the relief is
/// flat (`height_scale` 0) or the texture coordinates are degenerate.
pub(crate) fn parallax(
    m: &Material,
    p: &ShadingPoint,
    n: Vec3,
    position: Vec3,
    eye: Vec3,
    count: bool,
    texels: &mut u32,
) -> Option<Parallax> {
    let (verts, fp) = (p.verts, &p.fp);
    let s = m.height_scale;
    if s <= 0.0 {
        return None;
    }
    let (a, b) = surface_derivatives(verts, n)?;
    let dir = (position - eye).normalize_or_zero();
    let cos = -dir.dot(n);
    if cos <= 1e-4 {
        return None;
    }
    // The ray's motion along the surface per unit of depth below it, in texture coordinates:
    // solve a du + b dv = its tangential part (least squares through the 2x2 Gram matrix).
    let t = on_plane(dir, n) / cos;
    let (g11, g12, g22) = (
        f64::from(a.dot(a)),
        f64::from(a.dot(b)),
        f64::from(b.dot(b)),
    );
    let (ra, rb) = (f64::from(a.dot(t)), f64::from(b.dot(t)));
    let det = g11 * g22 - g12 * g12;
    if det <= 0.0 {
        return None;
    }
    let per_depth = Vec2::new(
        ((g22 * ra - g12 * rb) / det) as f32,
        ((g11 * rb - g12 * ra) / det) as f32,
    );
    let (lo, hi) = POM_STEPS;
    let steps = (hi as f32 + (lo as f32 - hi as f32) * cos).round().max(1.0) as u32;
    let at = |depth: f32, texels: &mut u32| {
        let fp = Footprint {
            u: fp.u + per_depth.x * depth,
            v: fp.v + per_depth.y * depth,
            ..*fp
        };
        // How far the relief lies below the ray: positive while the ray is above it.
        s * (1.0 - m.height_at(&fp, count, texels).unwrap_or(1.0)) - depth
    };
    let mut prev = (0.0f32, at(0.0, texels));
    let mut hit = 0.0;
    if prev.1 > 0.0 {
        hit = s;
        for k in 1..=steps {
            let depth = s * k as f32 / steps as f32;
            let gap = at(depth, texels);
            if gap <= 0.0 {
                let w = prev.1 / (prev.1 - gap);
                hit = prev.0 + w * (depth - prev.0);
                break;
            }
            prev = (depth, gap);
        }
    }
    Some(Parallax {
        footprint: Footprint {
            u: fp.u + per_depth.x * hit,
            v: fp.v + per_depth.y * hit,
            ..*fp
        },
        position: position + dir * (hit / cos),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec4;

    fn quad_vertex(p: Vec3, uv: Vec2) -> Vertex {
        Vertex {
            position: p,
            uv,
            color: Vec4::ONE,
            normal: Vec3::Y,
            tangent: Vec4::new(1.0, 0.0, 0.0, 1.0),
        }
    }

    /// A triangle in the y = 0 plane, 4 world units per unit of u along x and 2 per unit of v
    /// along z.
    fn triangle() -> [Vertex; 3] {
        [
            quad_vertex(Vec3::ZERO, Vec2::ZERO),
            quad_vertex(Vec3::new(4.0, 0.0, 0.0), Vec2::new(1.0, 0.0)),
            quad_vertex(Vec3::new(0.0, 0.0, 2.0), Vec2::new(0.0, 1.0)),
        ]
    }

    #[test]
    fn surface_derivatives_are_the_triangles_own() {
        let t = triangle();
        let (a, b) = surface_derivatives([&t[0], &t[1], &t[2]], Vec3::Y).unwrap();
        assert!((a - Vec3::new(4.0, 0.0, 0.0)).length() < 1e-6, "{a}");
        assert!((b - Vec3::new(0.0, 0.0, 2.0)).length() < 1e-6, "{b}");
        // Degenerate texture coordinates give none.
        let mut d = triangle();
        d[2].uv = Vec2::new(2.0, 0.0);
        assert!(surface_derivatives([&d[0], &d[1], &d[2]], Vec3::Y).is_none());
    }

    /// A height rising by 1 world unit per unit of u (4 world units along x) tilts the normal
    /// by atan(1/4) away from +x; a flat one leaves it alone.
    #[test]
    fn the_normal_of_a_gradient_is_the_displaced_surfaces() {
        let (a, b) = (Vec3::new(4.0, 0.0, 0.0), Vec3::new(0.0, 0.0, 2.0));
        assert_eq!(normal_from_gradient(a, b, Vec3::Y, Vec2::ZERO), Vec3::Y);
        let m = normal_from_gradient(a, b, Vec3::Y, Vec2::new(1.0, 0.0));
        assert!(
            (m - Vec3::new(-1.0, 4.0, 0.0).normalize()).length() < 1e-6,
            "{m}"
        );
        let m = normal_from_gradient(a, b, Vec3::Y, Vec2::new(0.0, -1.0));
        assert!(
            (m - Vec3::new(0.0, 2.0, 1.0).normalize()).length() < 1e-6,
            "{m}"
        );
    }

    #[test]
    fn bump_steps_follow_the_footprint() {
        assert_eq!(bump_step(0.01, -0.03, 256), 0.02);
        assert_eq!(bump_step(0.0, 0.0, 256), 0.125 / 256.0);
        assert_eq!(bump_step(f32::NAN, 0.0, 64), 0.125 / 64.0);
    }
}
