//! Environment maps: light from every direction, stored as an equirectangular (latitude-longitude)
//! image, seen as the background and reflected by surfaces.
//!
//! Directions to texture coordinates follow DESIGN.md: for a direction `d`,
//! `u = 0.5 + atan2(d.x, -d.z) / (2 pi)` and `v = acos(d.y / |d|) / pi` (`v = 0` straight up, `-z`
//! at the centre column). The seam `u = 0 = 1` lies along `+z`.
//!
//! **Footprints come from analytic gradients** ([`equirect_duv`]): the screen derivatives of the
//! direction (the camera ray's for the background; the reflected direction's, differentiated as
//! pbrt-v4 does with `dn/dx` and `dp/dx`, for reflections) are mapped through the exact Jacobian of
//! `(u, v)(d)`, `du = (x dz - z dx) / (2 pi (x^2 + z^2))`,
//! `dv = -(dy - y (d.dd) / |d|^2) / (pi sqrt(x^2 + z^2))`. Differencing `u` itself would jump by
//! about 1 across the seam and pick the coarsest level there (a visible line). Near the poles
//! `du` grows as `1 / sin(theta)`: the footprint becomes long in `u`, which is exactly the
//! stretch the anisotropic and EWA filters are for. Each derivative is clamped to 1 (one period;
//! any more selects the coarsest level anyway).
//!
//! **Glossy reflection** reads a GGX-prefiltered pyramid ([`EnvironmentMaps::glossy`], Karis 2013,
//! "Real Shading in Unreal Engine 4"): level 0 is the map itself and level `k >= 1` is the map
//! convolved with GGX of `alpha_k = min(1, 2 pi 2^k / W)` (`W` the map's width) under Karis's
//! `n = v = r` assumption, weighted by `n.l`. The lobe's full width at half maximum is about
//! `2.6 alpha` radians of reflected direction, so level `k`'s lobe spans about 2.6 of its own
//! texels: it is sampled without aliasing at its resolution. A lookup with roughness `r` uses
//! `lod_r = log2(r^2 W / (2 pi))` and reads at `max(lod_r, lod_footprint)` (trilinear), where
//! `lod_footprint` is the frame filter's level for the reflected direction's footprint; below
//! `lod_r = 0` (perceptual roughness under `sqrt(2 pi / W)`, 0.078 for a 1024-wide map) the
//! surface is a mirror and the frame's filter reads the plain map with that footprint, like any
//! texture. The convolution is importance-sampled (64 Hammersley directions per texel) from the
//! plain map's box pyramid at the level whose texel matches each sample's share of the lobe
//! (Colbert and Krivanek 2007, GPU Gems 3 ch. 20, with Karis's +1 bias).
//!
//! **Split sum**: specular `= prefiltered(r) (F0 A + B)` with `(A, B)` the integrated GGX/Smith BRDF
//! for `(n.v, roughness)` ([`dfg`], a 32x32 table integrated at first use with the shading model's
//! own `D` and visibility, 256 samples per entry); diffuse `= c_diff E(n) / pi` with `E` the
//! irradiance of the map ([`EnvironmentMaps::irradiance`], 32x16 texels, each a brute-force
//! cosine-weighted sum over the 64-wide level of the map). Both are scaled by the environment's
//! intensity and the surface's ambient occlusion.
//!
//! **The reference** ([`crate::reference`]) reads the plain map bilinearly at level 0 for the
//! background and mirrors, and the glossy pyramid trilinearly at exactly `lod_r` (the lobe is the
//! material's, not a filter's): what it leaves out is every pixel footprint.

use std::f64::consts::PI;
use std::sync::OnceLock;

use glam::{DMat4, DVec2, DVec3, DVec4, Mat4, Vec3};
use rayon::prelude::*;
use texel_texture::{AddressMode, Footprint, Format, Limits, Sampler, SamplerDescriptor, Texture};

use crate::error::RasterError;
use crate::material::{ggx_d, smith_visibility, MIN_ROUGHNESS};

/// Width of the irradiance map (its height is half).
pub const IRRADIANCE_WIDTH: u32 = 32;

/// Hammersley samples per texel of the glossy pyramid's levels.
pub const PREFILTER_SAMPLES: u32 = 64;

/// The address modes of an equirectangular map: `u` wraps around, `v` stops at the poles.
pub fn equirect_descriptor(desc: SamplerDescriptor) -> SamplerDescriptor {
    SamplerDescriptor {
        address_mode_u: AddressMode::Repeat,
        address_mode_v: AddressMode::ClampToEdge,
        ..desc
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

/// The change of [`equirect_uv`] for a small change `dd` of the direction `d` (the Jacobian
/// applied to `dd`, module docs), each component clamped to `[-1, 1]`. Continuous across the
/// seam; at the poles, where `u` is undefined, `du` is the clamp.
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

/// The footprint of direction `d` with screen derivatives `dd_dx`, `dd_dy` (zero derivatives
/// give a zero footprint: level 0).
pub fn equirect_footprint(d: DVec3, dd_dx: DVec3, dd_dy: DVec3) -> Footprint {
    let uv = equirect_uv(d);
    let dx = equirect_duv(d, dd_dx);
    let dy = equirect_duv(d, dd_dy);
    Footprint {
        u: uv.x as f32,
        v: uv.y as f32,
        dudx: dx.x as f32,
        dudy: dy.x as f32,
        dvdx: dx.y as f32,
        dvdy: dy.y as f32,
    }
}

/// GGX's `alpha` that level `k` of the glossy pyramid of a `width`-wide map holds.
pub fn level_alpha(k: u32, width: u32) -> f64 {
    if k == 0 {
        return 0.0;
    }
    (2.0 * PI * f64::from(1u32 << k.min(31)) / f64::from(width.max(1))).min(1.0)
}

/// The glossy pyramid's level for perceptual roughness `roughness` (`log2(r^2 W / (2 pi))`; `<= 0`
/// is a mirror).
pub fn roughness_lod(roughness: f32, width: u32) -> f32 {
    let alpha = f64::from(roughness.clamp(MIN_ROUGHNESS, 1.0)).powi(2);
    (alpha * f64::from(width) / (2.0 * PI)).log2() as f32
}

/// The `i`-th of `n` points of the Hammersley set in `[0, 1)^2`.
fn hammersley(i: u32, n: u32) -> (f64, f64) {
    (
        (f64::from(i) + 0.5) / f64::from(n),
        f64::from(i.reverse_bits()) / 4_294_967_296.0,
    )
}

/// A GGX-distributed half vector about `n` (unit) for `alpha` from the point `(xi1, xi2)` (Walter
/// et al. 2007, eq. 35-36), with `n.h`.
fn ggx_half(n: DVec3, alpha: f64, (xi1, xi2): (f64, f64)) -> (DVec3, f64) {
    let phi = 2.0 * PI * xi1;
    let a2 = alpha * alpha;
    let cos_t = ((1.0 - xi2) / (1.0 + (a2 - 1.0) * xi2)).sqrt();
    let sin_t = (1.0 - cos_t * cos_t).max(0.0).sqrt();
    let (t, b) = orthonormal_basis(n);
    (
        (t * (sin_t * phi.cos()) + b * (sin_t * phi.sin()) + n * cos_t).normalize(),
        cos_t,
    )
}

/// Two unit vectors completing unit `n` to an orthonormal basis (Duff et al. 2017).
fn orthonormal_basis(n: DVec3) -> (DVec3, DVec3) {
    let sign = 1f64.copysign(n.z);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    (
        DVec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x),
        DVec3::new(b, sign + n.y * n.y * a, -n.y),
    )
}

/// An isotropic footprint at `uv` whose level in a `w x h` texture is `lod`.
fn footprint_at_lod(uv: DVec2, lod: f32, w: u32, h: u32) -> Footprint {
    let s = lod.exp2();
    Footprint {
        u: uv.x as f32,
        v: uv.y as f32,
        dudx: s / w as f32,
        dudy: 0.0,
        dvdx: 0.0,
        dvdy: s / h as f32,
    }
}

/// The maps an environment is read through: the plain map with its box pyramid, its GGX
/// prefiltered pyramid and its irradiance (module docs), with the fixed samplers that read the
/// last two.
#[derive(Debug)]
pub struct EnvironmentMaps {
    /// The map as given (equirectangular, linear RGB), with its box pyramid: the background's
    /// and mirrors' lookups, through the frame's filter.
    pub radiance: Texture,
    /// The GGX-prefiltered pyramid (module docs), the same size as `radiance`.
    pub glossy: Texture,
    /// Irradiance over pi, `E(n) / pi`, by the normal's equirectangular coordinates.
    pub irradiance: Texture,
    /// Trilinear, Repeat in `u`, clamped in `v`: reads `glossy` and `irradiance`.
    trilinear: Sampler,
    /// Bilinear at level 0: the reference's reads of `radiance`.
    level0: Sampler,
}

impl EnvironmentMaps {
    /// The prefiltered pyramid and the irradiance of `radiance` (an equirectangular map, any
    /// format; it is read through its pyramid), computed on the current rayon pool.
    ///
    /// # Errors
    /// [`RasterError::Texture`] when the float pyramid does not fit `limits`.
    pub fn new(radiance: Texture, limits: &Limits) -> Result<Self, RasterError> {
        let trilinear = Sampler::new(equirect_descriptor(SamplerDescriptor::lab_mode(4)?))?;
        let level0 = Sampler::new(equirect_descriptor(SamplerDescriptor::lab_mode(2)?))?;
        let glossy = prefilter_ggx(&radiance, &trilinear, limits)?;
        let irradiance = irradiance_map(&radiance, limits)?;
        Ok(EnvironmentMaps {
            radiance,
            glossy,
            irradiance,
            trilinear,
            level0,
        })
    }

    /// Bytes [`EnvironmentMaps::new`] adds to a `width x height` map: the float glossy pyramid and
    /// the irradiance map.
    pub fn extra_bytes(width: u32, height: u32) -> u64 {
        let f = Format::Rgba32Float.texel_bytes();
        let irr = texel_texture::pyramid::pyramid_texels(IRRADIANCE_WIDTH, IRRADIANCE_WIDTH / 2);
        (texel_texture::pyramid::pyramid_texels(width, height) + irr) * f
    }
}

/// The GGX-prefiltered pyramid of `radiance` (module docs), read through `trilinear`.
fn prefilter_ggx(
    radiance: &Texture,
    trilinear: &Sampler,
    limits: &Limits,
) -> Result<Texture, RasterError> {
    let (w, h) = (radiance.width(), radiance.height());
    limits.check(w, h, Format::Rgba32Float)?;
    // The solid angle of a level-0 texel on the equator.
    let texel_solid_angle = (2.0 * PI / f64::from(w)) * (PI / f64::from(h));
    let mut all: Vec<[f32; 4]> = Vec::new();
    let levels = texel_texture::pyramid::level_count(w, h);
    for k in 0..levels {
        let (lw, lh) = texel_texture::pyramid::level_size(w, h, k);
        if k == 0 {
            all.extend(
                (0..lh).flat_map(|j| {
                    (0..lw).map(move |i| radiance.texel(0, i, j).unwrap_or([0.0; 4]))
                }),
            );
            continue;
        }
        let alpha = level_alpha(k, w);
        let n = PREFILTER_SAMPLES;
        let level: Vec<[f32; 4]> = (0..lh)
            .into_par_iter()
            .flat_map_iter(|j| {
                (0..lw).map(move |i| {
                    let uv = DVec2::new(
                        (f64::from(i) + 0.5) / f64::from(lw),
                        (f64::from(j) + 0.5) / f64::from(lh),
                    );
                    let r = equirect_direction(uv);
                    let mut sum = DVec3::ZERO;
                    let mut weight = 0.0;
                    for s in 0..n {
                        let (hv, n_dot_h) = ggx_half(r, alpha, hammersley(s, n));
                        let l = hv * (2.0 * r.dot(hv)) - r;
                        let n_dot_l = r.dot(l);
                        if n_dot_l <= 0.0 {
                            continue;
                        }
                        // pdf of l: D(n.h) n.h / (4 v.h), and v.h = n.h when v = n.
                        let pdf = f64::from(ggx_d(n_dot_h as f32, alpha as f32)) / 4.0;
                        let omega_s = 1.0 / (f64::from(n) * pdf.max(1e-30));
                        let lod = (0.5 * (omega_s / texel_solid_angle).log2() + 1.0).max(0.0);
                        let fp = footprint_at_lod(equirect_uv(l), lod as f32, w, h);
                        let c = trilinear.sample(radiance, &fp);
                        sum += DVec3::new(c[0].into(), c[1].into(), c[2].into()) * n_dot_l;
                        weight += n_dot_l;
                    }
                    let c = if weight > 0.0 { sum / weight } else { sum };
                    [c.x as f32, c.y as f32, c.z as f32, 1.0]
                })
            })
            .collect();
        all.extend(level);
    }
    Ok(Texture::from_rgba32f_levels(w, h, all, limits)?)
}

/// `E(n) / pi` over the map's directions (module docs), as an [`IRRADIANCE_WIDTH`]-wide map.
fn irradiance_map(radiance: &Texture, limits: &Limits) -> Result<Texture, RasterError> {
    // The finest level at most 64 texels wide: the cosine lobe is smooth, so it loses nothing.
    let level = radiance
        .levels()
        .iter()
        .position(|l| l.width <= 64)
        .unwrap_or(radiance.levels().len() - 1);
    let info = radiance.levels()[level];
    let (sw, sh) = (info.width, info.height);
    let mut sources = Vec::with_capacity((sw * sh) as usize);
    for j in 0..sh {
        let theta0 = PI * f64::from(j) / f64::from(sh);
        let theta1 = PI * f64::from(j + 1) / f64::from(sh);
        // The exact solid angle of the texel's latitude band share.
        let omega = (theta0.cos() - theta1.cos()) * 2.0 * PI / f64::from(sw);
        for i in 0..sw {
            let uv = DVec2::new(
                (f64::from(i) + 0.5) / f64::from(sw),
                (f64::from(j) + 0.5) / f64::from(sh),
            );
            let c = radiance.texel(level, i, j).unwrap_or([0.0; 4]);
            let l = DVec3::new(c[0].into(), c[1].into(), c[2].into());
            sources.push((equirect_direction(uv), l * omega));
        }
    }
    let (w, h) = (IRRADIANCE_WIDTH, IRRADIANCE_WIDTH / 2);
    Ok(Texture::from_fn(
        w,
        h,
        Format::Rgba32Float,
        limits,
        |i, j| {
            let n = equirect_direction(DVec2::new(
                (f64::from(i) + 0.5) / f64::from(w),
                (f64::from(j) + 0.5) / f64::from(h),
            ));
            let e: DVec3 = sources
                .iter()
                .map(|(d, l)| *l * n.dot(*d).max(0.0))
                .sum::<DVec3>()
                / PI;
            [e.x as f32, e.y as f32, e.z as f32, 1.0]
        },
    )?)
}

/// Side of the [`dfg`] table.
const DFG_SIZE: usize = 32;

/// Samples per [`dfg`] entry.
const DFG_SAMPLES: u32 = 256;

/// The split sum's `(A, B)` for `n.v` and perceptual roughness (module docs): specular reflectance
/// of a constant environment is `F0 A + B`. Bilinear in a table over `n.v` and roughness in
/// `[0, 1]`, integrated once per process with [`ggx_d`] and [`smith_visibility`] (Karis 2013).
pub fn dfg(n_dot_v: f32, roughness: f32) -> (f32, f32) {
    static TABLE: OnceLock<Vec<(f32, f32)>> = OnceLock::new();
    let table = TABLE.get_or_init(|| {
        (0..DFG_SIZE * DFG_SIZE)
            .map(|k| {
                let nv = ((k % DFG_SIZE) as f64 + 0.5) / DFG_SIZE as f64;
                let r = ((k / DFG_SIZE) as f64 + 0.5) / DFG_SIZE as f64;
                integrate_dfg(nv, r)
            })
            .collect()
    });
    let x = (n_dot_v.clamp(0.0, 1.0) * DFG_SIZE as f32 - 0.5).clamp(0.0, (DFG_SIZE - 1) as f32);
    let y = (roughness.clamp(0.0, 1.0) * DFG_SIZE as f32 - 0.5).clamp(0.0, (DFG_SIZE - 1) as f32);
    let (x0, y0) = (x.floor() as usize, y.floor() as usize);
    let (x1, y1) = ((x0 + 1).min(DFG_SIZE - 1), (y0 + 1).min(DFG_SIZE - 1));
    let (fx, fy) = (x - x0 as f32, y - y0 as f32);
    let at = |i: usize, j: usize| table[j * DFG_SIZE + i];
    let lerp =
        |a: (f32, f32), b: (f32, f32), t: f32| (a.0 + (b.0 - a.0) * t, a.1 + (b.1 - a.1) * t);
    lerp(
        lerp(at(x0, y0), at(x1, y0), fx),
        lerp(at(x0, y1), at(x1, y1), fx),
        fy,
    )
}

/// One [`dfg`] entry by importance sampling GGX's half vectors (`pdf(l) = D n.h / (4 v.h)`):
/// `A = mean((1 - Fc) w)`, `B = mean(Fc w)` with `Fc = (1 - v.h)^5` and
/// `w = Vis 4 (v.h) (n.l) / (n.h)`.
pub fn integrate_dfg(n_dot_v: f64, roughness: f64) -> (f32, f32) {
    let alpha = roughness.max(f64::from(MIN_ROUGHNESS)).powi(2);
    let n = DVec3::Z;
    let v = DVec3::new((1.0 - n_dot_v * n_dot_v).max(0.0).sqrt(), 0.0, n_dot_v);
    let (mut a, mut b) = (0.0, 0.0);
    for s in 0..DFG_SAMPLES {
        let (hv, n_dot_h) = ggx_half(n, alpha, hammersley(s, DFG_SAMPLES));
        let v_dot_h = v.dot(hv);
        let l = hv * (2.0 * v_dot_h) - v;
        let n_dot_l = l.z;
        if n_dot_l <= 0.0 || v_dot_h <= 0.0 {
            continue;
        }
        let vis = f64::from(smith_visibility(
            n_dot_l as f32,
            n_dot_v as f32,
            alpha as f32,
        ));
        let w = vis * 4.0 * v_dot_h * n_dot_l / n_dot_h.max(1e-12);
        let fc = (1.0 - v_dot_h).powi(5);
        a += (1.0 - fc) * w;
        b += fc * w;
    }
    let m = f64::from(DFG_SAMPLES);
    ((a / m) as f32, (b / m) as f32)
}

/// An environment as a frame sees it: its maps, the sampler of the frame's filter, its
/// intensity, whether it is the background, and the camera the background is seen through.
#[derive(Clone, Copy, Debug)]
pub struct Environment<'a> {
    /// The maps.
    pub maps: &'a EnvironmentMaps,
    /// The frame's filter with [`equirect_descriptor`]'s address modes: the background's and
    /// mirrors' lookups.
    pub sampler: &'a Sampler,
    /// Linear RGB scale of the map's radiance.
    pub intensity: Vec3,
    /// Whether pixels no triangle covers show the environment (else the settings' background).
    pub background: bool,
    /// The camera of the background (the draws' `clip_from_world`).
    pub clip_from_world: Mat4,
}

/// One environment read's result: linear RGB and the texels read.
type Read = (Vec3, u32);

impl Environment<'_> {
    /// Whether every number is finite and the intensity is not negative.
    pub fn is_valid(&self) -> bool {
        self.intensity.is_finite()
            && self.intensity.min_element() >= 0.0
            && self.clip_from_world.is_finite()
    }

    /// Read `texture` through `sampler` at `fp`, counting texels when `count`.
    fn read(&self, sampler: &Sampler, texture: &Texture, fp: &Footprint, count: bool) -> Read {
        let (c, n) = if count {
            sampler.sample_counted(texture, fp)
        } else {
            (sampler.sample(texture, fp), 0)
        };
        (Vec3::new(c[0], c[1], c[2]) * self.intensity, n)
    }

    /// The radiance arriving from direction `d` whose screen derivatives are `dd` (zero for the
    /// reference's point samples, which read level 0 bilinearly), as the background and mirrors
    /// see it.
    pub fn radiance(&self, d: DVec3, dd: [DVec3; 2], reference: bool, count: bool) -> Read {
        self.radiance_at(&equirect_footprint(d, dd[0], dd[1]), reference, count)
    }

    /// The plain map's radiance over footprint `fp` (the frame's filter; bilinear at level 0 for
    /// the `reference`).
    pub fn radiance_at(&self, fp: &Footprint, reference: bool, count: bool) -> Read {
        let sampler = if reference {
            &self.maps.level0
        } else {
            self.sampler
        };
        self.read(sampler, &self.maps.radiance, fp, count)
    }

    /// The prefiltered radiance reflected about direction `r` (derivatives `dr`) for perceptual
    /// `roughness`: the mirror lookup below `lod_r = 0`, else the glossy pyramid at
    /// `max(lod_r, lod_footprint)` (module docs; the reference at `lod_r`).
    pub fn specular(
        &self,
        r: DVec3,
        dr: [DVec3; 2],
        roughness: f32,
        reference: bool,
        count: bool,
    ) -> Read {
        let maps = self.maps;
        let (w, h) = (maps.radiance.width(), maps.radiance.height());
        let lod_r = roughness_lod(roughness, w);
        if lod_r <= 0.0 {
            return self.radiance(r, dr, reference, count);
        }
        let (uv, lod) = if reference {
            (equirect_uv(r), lod_r)
        } else {
            let fp = equirect_footprint(r, dr[0], dr[1]);
            let uv = DVec2::new(fp.u.into(), fp.v.into());
            (uv, lod_r.max(self.sampler.lod(&maps.radiance, &fp)))
        };
        let fp = footprint_at_lod(uv, lod, w, h);
        self.read(&maps.trilinear, &maps.glossy, &fp, count)
    }

    /// Irradiance over pi for unit normal `n` (bilinear).
    pub fn irradiance(&self, n: DVec3, count: bool) -> Read {
        let uv = equirect_uv(n);
        let fp = Footprint {
            u: uv.x as f32,
            v: uv.y as f32,
            ..Footprint::default()
        };
        self.read(&self.maps.trilinear, &self.maps.irradiance, &fp, count)
    }

    /// The camera rays of the background for a `width x height` frame: `None` where the
    /// environment is not the background, or the camera has no rays (a singular matrix).
    pub fn background_rays(&self, width: u32, height: u32) -> Option<ViewRays> {
        let m = DMat4::from_cols_array(&self.clip_from_world.to_cols_array().map(f64::from));
        (self.background && m.determinant() != 0.0).then(|| ViewRays {
            world_from_clip: m.inverse(),
            width: f64::from(width),
            height: f64::from(height),
        })
    }
}

/// The world-space rays through a frame's pixels, for the background.
#[derive(Clone, Copy, Debug)]
pub struct ViewRays {
    world_from_clip: DMat4,
    width: f64,
    height: f64,
}

impl ViewRays {
    /// The unit direction of the ray through continuous pixel position `(x, y)` (DESIGN.md's
    /// viewport: `x_ndc = 2x / W - 1`, `y_ndc = 1 - 2y / H`), from the point at NDC depth 0 to the
    /// one at depth 1; `None` where they coincide or are not finite.
    pub fn direction(&self, x: f64, y: f64) -> Option<DVec3> {
        let ndc_x = 2.0 * x / self.width - 1.0;
        let ndc_y = 1.0 - 2.0 * y / self.height;
        let point = |z: f64| {
            let p = self.world_from_clip * DVec4::new(ndc_x, ndc_y, z, 1.0);
            p.truncate() / p.w
        };
        let d = (point(1.0) - point(0.0)).normalize_or_zero();
        (d.is_finite() && d != DVec3::ZERO).then_some(d)
    }

    /// The background's footprint at the centre of pixel `(i, j)`: the ray's direction with the
    /// differences to the rays one pixel right and one down (unit directions, so the differences
    /// are angles) through [`equirect_duv`].
    pub fn footprint(&self, i: u32, j: u32) -> Option<Footprint> {
        let (x, y) = (f64::from(i) + 0.5, f64::from(j) + 0.5);
        let d = self.direction(x, y)?;
        let dx = self.direction(x + 1.0, y)?;
        let dy = self.direction(x, y + 1.0)?;
        Some(equirect_footprint(d, dx - d, dy - d))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
    fn the_jacobian_matches_differences_away_from_the_seam() {
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
    fn the_jacobian_is_continuous_across_the_seam() {
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
    fn dfg_of_a_smooth_surface_at_normal_incidence_is_f0() {
        let (a, b) = integrate_dfg(1.0, f64::from(MIN_ROUGHNESS));
        assert!((a - 1.0).abs() < 0.02 && b.abs() < 0.01, "{a} {b}");
        // A + B (a white surface's reflectance) never exceeds 1 and falls with roughness
        // (single-scattering GGX loses energy).
        for nv in [0.1, 0.5, 0.9] {
            let mut last = f32::INFINITY;
            for r in [0.1, 0.4, 0.7, 1.0] {
                let (a, b) = integrate_dfg(nv, r);
                assert!(a + b <= 1.001 && a >= 0.0 && b >= 0.0, "{nv} {r}: {a} {b}");
                assert!(a + b <= last + 1e-3, "{nv} {r}");
                last = a + b;
            }
        }
    }

    #[test]
    fn hammersley_ggx_samples_follow_the_distribution() {
        // The mean of n.h under GGX sampling equals the integral of D (n.h)^2 over the hemisphere.
        let alpha = 0.3;
        let n = 4096;
        let mean: f64 = (0..n)
            .map(|i| ggx_half(DVec3::Z, alpha, hammersley(i, n)).1)
            .sum::<f64>()
            / f64::from(n);
        let steps = 200_000;
        let exact: f64 = (0..steps)
            .map(|k| {
                let t = (k as f64 + 0.5) / steps as f64 * PI / 2.0;
                let c = t.cos();
                f64::from(ggx_d(c as f32, alpha as f32)) * c * c * t.sin() * 2.0 * PI
            })
            .sum::<f64>()
            * (PI / 2.0 / steps as f64);
        assert!((mean - exact).abs() < 2e-3, "{mean} {exact}");
    }
}
