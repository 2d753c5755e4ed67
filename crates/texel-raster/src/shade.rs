//! Colour shading: the texture's colour as the base colour, times the material's factor and the
//! interpolated vertex colour; under lights, [`crate::material`]'s model with the material's maps
//! read through the same footprint; and the footprint handed to the sampler.
//!
//! Attributes (normal, tangent, position) are the perspective-correct barycentric combinations of
//! the original triangle's vertices. Alpha is `texture.a * base_color.a * vertex.a`; there is no
//! blending (the nearest fragment replaces the pixel).
//!
//! Footprints: for periodic address modes the sampler's result does not change when a whole
//! period is subtracted, so `u` (`v`) is reduced modulo 1 (Repeat) or 2 (MirrorRepeat) before the
//! sampler sees it: far from the origin (the ground scene reaches `|u| = 250`, 256 000 texels) this
//! keeps the texel position to `f32` precision instead of losing 1/64 texel. Interpolated `uv`
//! comes from [`UvPlanes`] (`f32` planes from which whole periods were taken out at an anchor
//! pixel of the tile, in `f64`); sphere mappings and the reference compute `uv` in `f64` and
//! reduce it here ([`DrawContext::footprint`]) before the conversion to `f32`.

use glam::{DMat4, DVec2, DVec3, DVec4, Vec3, Vec4};
use texel_texture::base::floor::{floor_staged_f64, STAGED_F64_LIMIT};
use texel_texture::mapping::sphere::SurfaceProjection;
use texel_texture::{AddressMode, Footprint, Sampler, Texture};

use crate::draw::{DrawCall, UvEvaluation, Vertex};
use crate::environment::{self, Environment};
use crate::interp::UvPlanes;
use crate::layers::Needs;
use crate::material::{
    self, Displacement, Light, Material, SpecularAa, Surface, TextureInput, MAX_SHADING_SAMPLES,
    MIN_ROUGHNESS,
};
use crate::point::ShadingPoint;
use crate::relief::{self, Lobe};
use crate::settings::{Perspective, RenderSettings};
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
    /// The draw's material.
    pub material: Option<Material<'a>>,
    /// The eye's world position (the centre of projection of `clip_from_world`).
    pub eye: Vec3,
    /// The sphere mapping evaluated per pixel, with its centre ([`crate::UvMapping`]); `None`
    /// when the vertices' `uv` is interpolated.
    surface: Option<(SurfaceProjection, DVec3)>,
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

/// The centre of projection of `clip_from_world`: the world point that maps to clip-space
/// `(0, 0, z, 0)`, `M^-1 (0, 0, 1, 0)` divided by its `w` (in `f64`). The origin for a matrix
/// without one (not invertible, or orthographic).
fn eye_of(draw: &DrawCall) -> Vec3 {
    let m = DMat4::from_cols_array(&draw.clip_from_world.to_cols_array().map(f64::from));
    if m.determinant() == 0.0 {
        return Vec3::ZERO;
    }
    let h = m.inverse() * DVec4::new(0.0, 0.0, 1.0, 0.0);
    if h.w.abs() < 1e-300 {
        return Vec3::ZERO;
    }
    let p = (h.truncate() / h.w).as_vec3();
    if p.is_finite() {
        p
    } else {
        Vec3::ZERO
    }
}

impl<'a> DrawContext<'a> {
    pub(crate) fn new(draw: &DrawCall<'a>) -> Self {
        let d = draw.sampler.descriptor();
        DrawContext {
            texture: draw.texture,
            sampler: draw.sampler,
            vertices: draw.vertices,
            period: DVec2::new(period(d.address_mode_u), period(d.address_mode_v)),
            inv_period: DVec2::new(inv_period(d.address_mode_u), inv_period(d.address_mode_v)),
            colored: draw.vertices.iter().any(|v| v.color != Vec4::ONE),
            material: draw.material,
            eye: eye_of(draw),
            surface: draw
                .uv_mapping
                .filter(|m| m.evaluation == UvEvaluation::PerPixel)
                .map(|m| (m.projection, m.centre.as_dvec3())),
        }
    }

    /// Triangle `t` ready for its per-pixel sphere mapping ([`MappedTriangle`]); `None` when
    /// the draw interpolates the vertices' `uv`.
    #[inline(always)]
    pub(crate) fn mapped(&self, t: &TriangleSetup) -> Option<MappedTriangle> {
        let (projection, centre) = self.surface?;
        Some(MappedTriangle {
            projection,
            p: self.vertices(t).map(|v| v.position.as_dvec3() - centre),
        })
    }

    /// Whether an unlit fragment's colour is the texture sample unchanged: no material (no
    /// factor, no layers) and every vertex colour opaque white ([`shade`] without lighting then
    /// returns its `tex`).
    pub(crate) fn unshaded(&self) -> bool {
        !self.colored && self.material.is_none()
    }

    /// The triangle's vertices.
    #[inline(always)]
    pub(crate) fn vertices(&self, t: &TriangleSetup) -> [&'a Vertex; 3] {
        t.indices.map(|k| &self.vertices[k as usize])
    }

    /// The triangle's texture coordinates in `f64`.
    #[inline(always)]
    pub(crate) fn uvs(&self, t: &TriangleSetup) -> [DVec2; 3] {
        self.vertices(t).map(|v| v.uv.as_dvec2())
    }

    /// How triangle `t`'s fragments in the pixels `range` of one tile get their `uv`: its
    /// sphere mapping, or [`UvPlanes`] anchored there.
    #[inline(always)]
    pub(crate) fn uv_source(
        &self,
        t: &TriangleSetup,
        perspective: Perspective,
        range: [u32; 4],
    ) -> UvSource {
        match self.mapped(t) {
            Some(m) => UvSource::Mapped(m),
            None => UvSource::Planes(UvPlanes::new(
                t,
                self.uvs(t),
                perspective,
                range,
                self.period,
            )),
        }
    }

    /// The footprint for the sampler: `uv` reduced by whole periods, derivatives as given.
    #[inline(always)]
    pub(crate) fn footprint(&self, uv: DVec2, duv_dx: DVec2, duv_dy: DVec2) -> Footprint {
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

/// Where a triangle's fragments get their `uv` ([`DrawContext::uv_source`]).
#[derive(Clone, Copy, Debug)]
pub(crate) enum UvSource {
    /// A per-pixel sphere mapping of the interpolated position.
    Mapped(MappedTriangle),
    /// The vertices' `uv`, interpolated by `f32` planes re-anchored in the tile.
    Planes(UvPlanes),
}

/// One triangle of a draw with a per-pixel sphere mapping ([`crate::UvMapping`]): its vertices
/// relative to the sphere's centre, gathered once per triangle.
#[derive(Clone, Copy, Debug)]
pub(crate) struct MappedTriangle {
    projection: SurfaceProjection,
    p: [DVec3; 3],
}

impl MappedTriangle {
    /// `uv` at barycentrics `lambda`, the projection of the interpolated position's direction
    /// from the centre, and with `dlambda` (the barycentrics' derivatives per pixel right and
    /// down) its screen derivatives: the projection's Jacobian applied to the position's (zero
    /// without).
    #[inline(always)]
    pub(crate) fn uv(&self, lambda: DVec3, dlambda: Option<[DVec3; 2]>) -> (DVec2, DVec2, DVec2) {
        let p = &self.p;
        let at = |l: DVec3| p[0] * l.x + p[1] * l.y + p[2] * l.z;
        let d = at(lambda);
        let (dx, dy) = match dlambda {
            Some([x, y]) => (self.projection.duv(d, at(x)), self.projection.duv(d, at(y))),
            None => (DVec2::ZERO, DVec2::ZERO),
        };
        (self.projection.uv(d), dx, dy)
    }
}

/// The frame's lights and environment, gathered once.
#[derive(Clone, Debug)]
pub(crate) struct Lighting<'a> {
    lights: Vec<Light>,
    /// Some light is ambient, or there is an environment (only ambient light reads the
    /// occlusion map).
    ambient: bool,
    /// The environment's light ([`crate::environment`]).
    environment: Option<Environment<'a>>,
    /// The reference's point samples: the environment is read without footprints.
    reference: bool,
}

impl<'a> Lighting<'a> {
    /// The lights of `settings`, or `None` for an unlit frame; `reference` for the reference
    /// renderer's samples.
    pub(crate) fn of(settings: &RenderSettings<'a>, reference: bool) -> Option<Self> {
        settings.is_lit().then(|| {
            let lights: Vec<Light> = settings.active_lights().copied().collect();
            let ambient = settings.environment.is_some()
                || lights.iter().any(|l| matches!(l, Light::Ambient { .. }));
            Lighting {
                lights,
                ambient,
                environment: settings.environment,
                reference,
            }
        })
    }
}

/// What every fragment of a draw is shaded with: the draw, the frame's lights (`None` for an
/// unlit frame), and whether the texels the material's maps read are counted.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Shader<'c, 'a> {
    /// The draw's resolved state.
    pub draw: &'c DrawContext<'a>,
    /// The frame's lights and environment.
    pub lighting: Option<&'c Lighting<'a>>,
    /// Count the texels the maps read.
    pub count: bool,
}

/// The environment's light on `surface` (linear RGB) at `p`, adding the texels read to
/// `texels`: diffuse from the irradiance along the diffuse normal and, unless `lambert`,
/// specular from the direction the view reflects to ([`reflection`]) through the split sum (see
/// [`crate::environment`]). Scaled by the surface's occlusion.
fn environment_light(
    s: &Shader,
    lighting: &Lighting,
    p: &ShadingPoint,
    surface: &Surface,
    lambert: bool,
    texels: &mut u32,
) -> Vec3 {
    let Some(env) = &lighting.environment else {
        return Vec3::ZERO;
    };
    let nd = surface
        .diffuse_normal
        .as_dvec3()
        .normalize_or(surface.normal.as_dvec3());
    let (irr, k) = env.irradiance(nd, s.count);
    *texels += k;
    let mut out = surface.base * (1.0 - surface.metallic) * irr;
    if !lambert {
        let derivatives = !lighting.reference;
        let (r, dr, n_dot_v) = reflection(p, surface, s.draw.eye, derivatives);
        let (spec, k) = env.specular(r, dr, surface.roughness, lighting.reference, s.count);
        *texels += k;
        let f0 = Vec3::splat(0.04).lerp(surface.base, surface.metallic);
        let (a, b) = environment::dfg(n_dot_v.max(1e-4) as f32, surface.roughness);
        out += spec * (f0 * a + Vec3::splat(b));
    }
    out * surface.occlusion
}

/// The direction `r = 2 (n.v) n - v` the view reflects to about the surface's normal, its
/// screen derivatives when `derivatives` (zero otherwise), and `n.v`. The derivatives are
/// pbrt-v4's, `dr = 2 ((dn.v + n.dv) n + (n.v) dn) - dv`, with `dp` and `dn` (of the
/// interpolated vertex normals) from the barycentrics' derivatives at `p`, and `dv` from `dp`.
fn reflection(
    p: &ShadingPoint,
    surface: &Surface,
    eye: Vec3,
    derivatives: bool,
) -> (DVec3, [DVec3; 2], f64) {
    let n = surface.normal.as_dvec3();
    let to_eye = eye.as_dvec3() - surface.position.as_dvec3();
    let dist = to_eye.length().max(1e-30);
    let v = to_eye / dist;
    let n_dot_v = n.dot(v);
    let r = n * (2.0 * n_dot_v) - v;
    if !derivatives {
        return (r, [DVec3::ZERO; 2], n_dot_v);
    }
    let verts = p.verts;
    let m = lerp3(verts, p.lambda, |v| v.normal);
    let len = m.length();
    let ng = if len > 0.0 { m / len } else { DVec3::ZERO };
    let dr = p.dlambda.map(|dl| {
        let dp = lerp3(verts, dl, |v| v.position);
        let dm = lerp3(verts, dl, |v| v.normal);
        // Without vertex normals the normal does not turn.
        let dn = if len > 0.0 {
            (dm - ng * ng.dot(dm)) / len
        } else {
            DVec3::ZERO
        };
        let dv = -(dp - v * v.dot(dp)) / dist;
        (n * (dn.dot(v) + n.dot(dv)) + dn * n_dot_v) * 2.0 - dv
    });
    (r, dr, n_dot_v)
}

/// `sum lambda_k f(vertex_k)` in `f64`.
#[inline(always)]
fn lerp3(verts: [&Vertex; 3], lambda: DVec3, f: impl Fn(&Vertex) -> Vec3) -> DVec3 {
    f(verts[0]).as_dvec3() * lambda.x
        + f(verts[1]).as_dvec3() * lambda.y
        + f(verts[2]).as_dvec3() * lambda.z
}

/// The shaded colour of the fragment at `p` with base texture colour `tex` (linear RGBA); also
/// the texels the maps read when `s.count`. The footprint `p.fp` reads the material's maps.
/// Unlit frames show `tex * base_color * vertex colour`; lit frames
/// [`crate::material::radiance`] with the normal and roughness of [`crate::relief`], averaged
/// over a grid of shading sub-samples where [`Material::shading_samples`] asks for one (see
/// [`shade_grid`]).
#[inline(always)]
pub(crate) fn shade(s: &Shader, p: &ShadingPoint, tex: [f32; 4]) -> ([f32; 4], u32) {
    let adaptive = s.lighting.is_some() && s.draw.material.is_some_and(|m| m.shading_samples > 1);
    let (c, texels, grid) = shade_once(s, p, tex, adaptive);
    if grid == [1, 1] {
        return (c, texels);
    }
    let (c, more) = shade_grid(s, p, grid);
    (c, texels + more)
}

/// The mean of [`shade_once`] over a `grid[0] x grid[1]` grid of sub-samples centred in the
/// pixel: sub-sample `(a, b)` sits at offset `o = ((a + 1/2) / kx - 1/2, (b + 1/2) / ky - 1/2)`
/// pixels from the centre, where barycentrics and footprint are moved to first order
/// (`lambda + dlambda . o`, `uv + J o`) and the footprint's derivatives shrink to the sub-sample's
/// spacing (`J / k` per axis), so every map, the base colour included, is filtered over the
/// sub-sample's own footprint. The sub-samples are averaged in linear light (as the reference
/// averages its own), and return the texels they read when counting. The sub-samples read the
/// base colour with the `f32` sampler even where the pixel's own sample took the `--precision gpu`
/// fixed-point route (`tile.rs`'s `Route::Fixed8`): sub-sampling is a quality feature, and the
/// fixed-point route exists for the plain filters' speed.
fn shade_grid(s: &Shader, p: &ShadingPoint, [kx, ky]: [u32; 2]) -> ([f32; 4], u32) {
    let base = TextureInput {
        texture: s.draw.texture,
        sampler: s.draw.sampler,
    };
    let (fp, dlambda) = (&p.fp, p.dlambda);
    let (sx, sy) = (1.0 / kx as f32, 1.0 / ky as f32);
    let dl = [dlambda[0] * f64::from(sx), dlambda[1] * f64::from(sy)];
    let mut texels = 0;
    let mut sum = Vec4::ZERO;
    for b in 0..ky {
        let oy = (b as f32 + 0.5) * sy - 0.5;
        for a in 0..kx {
            let ox = (a as f32 + 0.5) * sx - 0.5;
            let sub = ShadingPoint {
                verts: p.verts,
                lambda: p.lambda + dlambda[0] * f64::from(ox) + dlambda[1] * f64::from(oy),
                dlambda: dl,
                fp: Footprint {
                    u: fp.u + fp.dudx * ox + fp.dudy * oy,
                    v: fp.v + fp.dvdx * ox + fp.dvdy * oy,
                    dudx: fp.dudx * sx,
                    dvdx: fp.dvdx * sx,
                    dudy: fp.dudy * sy,
                    dvdy: fp.dvdy * sy,
                },
            };
            let tex = crate::inputs::read(&base, &sub.fp, s.count, &mut texels);
            let (c, t, _) = shade_once(s, &sub, tex, false);
            sum += Vec4::from_array(c);
            texels += t;
        }
    }
    ((sum / (kx * ky) as f32).to_array(), texels)
}

/// One shading sample: [`shade`] without the sub-sample grid. When `measure`, also the grid the
/// pixel needs (`[1, 1]` otherwise): per screen axis `ceil(2 |n' - n| / alpha)`, at most
/// [`Material::shading_samples`], where `n'` is the shading normal one pixel along that axis
/// (read as the projected method reads it) and `alpha` the GGX width of the lobe after
/// texture-space antialiasing. Neighbouring sub-samples' normals then differ by at most
/// `alpha / 2` (in slope, to first order), about 2.6 sub-samples across the GGX lobe's full
/// width at half maximum (`2 alpha sqrt(sqrt(2) - 1) = 1.29 alpha`), so the pixel's mean
/// highlight is integrated rather than point-sampled.
#[inline(always)]
fn shade_once(
    s: &Shader,
    p: &ShadingPoint,
    tex: [f32; 4],
    measure: bool,
) -> ([f32; 4], u32, [u32; 2]) {
    let ctx = s.draw;
    let (verts, l, count) = (p.verts, p.l(), s.count);
    let mut texels = 0;
    let Some(lighting) = s.lighting else {
        let c = unlit(ctx, p, tex, count, &mut texels);
        return (c.to_array(), texels, [1, 1]);
    };
    let mut position = relief::interpolate(verts, l, |v| v.position);
    let normal = relief::geometric_normal(verts, l);
    let Some(m) = &ctx.material else {
        let c = base_color(ctx, verts, l, tex);
        let surface = Surface {
            base: c.truncate(),
            roughness: 1.0,
            metallic: 0.0,
            normal,
            diffuse_normal: normal,
            position,
            occlusion: 1.0,
            spread: None,
        };
        let rgb = radiance(s, lighting, p, &surface, true, &mut texels);
        return (rgb.extend(c.w).to_array(), texels, [1, 1]);
    };
    // Parallax occlusion mapping moves every read to where the view ray meets the relief.
    let mut at = *p;
    let mut tex = tex;
    if m.displacement == Displacement::Pom && m.has_height() {
        let hit = relief::parallax(m, &at, normal, position, ctx.eye, count, &mut texels);
        if let Some(hit) = hit {
            at.fp = hit.footprint;
            position = hit.position;
            let base = TextureInput {
                texture: ctx.texture,
                sampler: ctx.sampler,
            };
            tex = crate::inputs::read(&base, &at.fp, count, &mut texels);
        }
    }
    let fp = &at.fp;
    let needs = Needs {
        color: true,
        normal: true,
        moments: m.specular_aa == SpecularAa::Lean,
    };
    let layered = m
        .layers
        .as_ref()
        .map(|layers| layers.sample(fp, needs, count, &mut texels));
    let mut c = base_color(ctx, verts, l, tex);
    let mut roughness = m.roughness;
    if let Some(s) = &layered {
        c *= s.base;
        roughness *= s.roughness;
    }
    let (roughness, metallic, occlusion) =
        scalar_maps(m, fp, roughness, lighting.ambient, count, &mut texels);
    let lobe = Lobe {
        aa: m.specular_aa,
        roughness,
    };
    let mut shading =
        relief::shading_normal(m, layered.as_ref(), &at, normal, lobe, count, &mut texels);
    let mut grid = [1, 1];
    let projected = m.specular_aa == SpecularAa::Projected;
    if projected || measure {
        let (dn_dx, dn_dy) = normal_differences(s, m, &at, shading.normal, roughness, &mut texels);
        if measure {
            let alpha = shading.roughness.clamp(MIN_ROUGHNESS, 1.0).powi(2);
            let most = m.shading_samples.clamp(1, MAX_SHADING_SAMPLES);
            // NaN (a degenerate normal) casts to 0 and is clamped to one sample.
            let k = |dn: Vec3| ((2.0 * dn.length() / alpha).ceil() as u32).clamp(1, most);
            grid = [k(dn_dx), k(dn_dy)];
        }
        if projected {
            shading.roughness = material::projected_roughness(roughness, dn_dx, dn_dy);
        }
    }
    let surface = Surface {
        base: c.truncate(),
        roughness: shading.roughness.clamp(MIN_ROUGHNESS, 1.0),
        metallic: metallic.clamp(0.0, 1.0),
        normal: shading.normal,
        diffuse_normal: shading.diffuse_normal.unwrap_or(shading.normal),
        position,
        occlusion,
        spread: shading.spread,
    };
    let rgb = radiance(s, lighting, &at, &surface, false, &mut texels);
    (rgb.extend(c.w).to_array(), texels, grid)
}

/// An unlit fragment's colour: [`base_color`] times its layers' blended colour.
#[inline(always)]
fn unlit(
    ctx: &DrawContext,
    p: &ShadingPoint,
    tex: [f32; 4],
    count: bool,
    texels: &mut u32,
) -> Vec4 {
    let mut c = base_color(ctx, p.verts, p.l(), tex);
    if let Some(layers) = ctx.material.as_ref().and_then(|m| m.layers.as_ref()) {
        let needs = Needs {
            color: true,
            ..Needs::default()
        };
        c *= layers.sample(&p.fp, needs, count, texels).base;
    }
    c
}

/// The material's scalar maps read through `fp`: `roughness` times the roughness map, the
/// metallic factor times the metallic map, and the occlusion (read only under `ambient` light;
/// 1 without a map).
#[inline(always)]
fn scalar_maps(
    m: &Material,
    fp: &Footprint,
    mut roughness: f32,
    ambient: bool,
    count: bool,
    texels: &mut u32,
) -> (f32, f32, f32) {
    let mut metallic = m.metallic;
    if let Some(map) = &m.roughness_map {
        roughness *= crate::inputs::read_channel(map, fp, count, texels);
    }
    if let Some(map) = &m.metallic_map {
        metallic *= crate::inputs::read_channel(map, fp, count, texels);
    }
    let mut occlusion = 1.0;
    if let Some(map) = m.occlusion_map.as_ref().filter(|_| ambient) {
        let ao = crate::inputs::read_channel(map, fp, count, texels);
        occlusion = (1.0 + m.occlusion_strength * (ao - 1.0)).clamp(0.0, 1.0);
    }
    (roughness, metallic, occlusion)
}

/// The lights' and the environment's radiance on `surface` at `p`; `lambert` drops the
/// specular lobe.
#[inline(always)]
fn radiance(
    s: &Shader,
    lighting: &Lighting,
    p: &ShadingPoint,
    surface: &Surface,
    lambert: bool,
    texels: &mut u32,
) -> Vec3 {
    material::radiance(surface, s.draw.eye, &lighting.lights, lambert)
        + environment_light(s, lighting, p, surface, lambert, texels)
}

/// How the shading normal changes one pixel right and one down from `p` (where it is `normal`),
/// as a fragment quad's `ddx` and `ddy` see it: the normals there, read without antialiasing
/// under the lobe's `roughness`, less `normal`.
fn normal_differences(
    s: &Shader,
    m: &Material,
    p: &ShadingPoint,
    normal: Vec3,
    roughness: f32,
    texels: &mut u32,
) -> (Vec3, Vec3) {
    let fp = p.fp;
    let mut neighbour = |dl: DVec3, duv: [f32; 2]| {
        let at = ShadingPoint {
            lambda: p.lambda + dl,
            fp: Footprint {
                u: fp.u + duv[0],
                v: fp.v + duv[1],
                ..fp
            },
            ..*p
        };
        let n = relief::geometric_normal(at.verts, at.l());
        let needs = Needs {
            normal: true,
            ..Needs::default()
        };
        let layered = m
            .layers
            .as_ref()
            .map(|ly| ly.sample(&at.fp, needs, s.count, texels));
        let lobe = Lobe {
            aa: SpecularAa::None,
            roughness,
        };
        relief::shading_normal(m, layered.as_ref(), &at, n, lobe, s.count, texels).normal
    };
    let nx = neighbour(p.dlambda[0], [fp.dudx, fp.dvdx]);
    let ny = neighbour(p.dlambda[1], [fp.dudy, fp.dvdy]);
    (nx - normal, ny - normal)
}

/// The unlit colour: texture times vertex colour times the material's factor.
#[inline(always)]
fn base_color(ctx: &DrawContext, verts: [&Vertex; 3], l: Vec3, tex: [f32; 4]) -> Vec4 {
    let mut c = Vec4::from_array(tex);
    if ctx.colored {
        c *= verts[0].color * l.x + verts[1].color * l.y + verts[2].color * l.z;
    }
    if let Some(m) = &ctx.material {
        c *= m.base_color;
    }
    c
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
