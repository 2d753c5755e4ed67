//! Environment maps: light from every direction, stored equirectangular (latitude-longitude), as
//! a cube or octahedral, seen as the background and reflected by surfaces.
//!
//! Directions become texture coordinates through [`texel_texture::mapping::sphere`] (the conventions'
//! conventions: equirect `u = 0.5 + atan2(d.x, -d.z) / (2 pi)`, `v = acos(d.y / |d|) / pi`;
//! Vulkan's cube faces; pbrt-v4's equal-area octahedral square).
//!
//! **Footprints come from analytic gradients** ([`MapLayout::footprint`]): the screen
//! derivatives of the direction (the camera ray's for the background; the reflected
//! direction's, differentiated as pbrt-v4 does with `dn/dx` and `dp/dx`, for reflections) are
//! mapped through the exact Jacobian of the mapping ([`texel_texture::mapping::sphere::equirect_duv`],
//! [`texel_texture::mapping::sphere::cube_dst`], [`texel_texture::mapping::sphere::octahedral_duv`]). Differencing
//! `u` itself would jump by about 1 across a seam and pick the coarsest level there (a visible
//! line). Near an equirect map's poles `du` grows as `1 / sin(theta)`: the footprint becomes long
//! in `u`, which is exactly the stretch the anisotropic and EWA filters are for.
//!
//! **Seamless cube and octahedral maps.** Each cube face, and the octahedral square, is stored
//! with a border of [`border`]`(N) = N / 8` texels (at least 1) on every side, filled from the
//! neighbouring faces (the face's plane extended: a border texel holds the map's radiance along
//! the direction through its centre, read bilinearly from the face that direction selects) or, for
//! the octahedral square, from the square's own continuation ([`texel_texture::mapping::sphere::octahedral_wrap`],
//! which maps border texel centres exactly onto texel centres). The box pyramid is built over the
//! bordered image, so every level's border continues its face. Any filter then reads across an
//! edge as if the neighbouring face were there: where Vulkan's seamless cube filtering fetches the
//! neighbour's edge texels for the 2x2 bilinear footprint only, the border also serves the
//! anisotropic probes, EWA's ellipse and the summed-area box, up to `N / 8` level-0 texels past the
//! edge (`N / 2^(k+3)` at level `k`; footprints reaching further are clamped to the border's last
//! texel). Each level's border halves with the face, so it covers the same angle at every level.
//!
//! **Glossy reflection** reads a GGX-prefiltered pyramid ([`EnvironmentMaps::glossy`], Karis 2013,
//! "Real Shading in Unreal Engine 4"): level 0 is the map itself and level `k >= 1` is the map
//! convolved with GGX of `alpha_k = min(1, theta_0 2^k)`, `theta_0` the angle of a level-0 texel
//! ([`MapLayout::texel_angle`]: `2 pi / W` for an equirect map, `2 / N` at a cube face's centre,
//! `sqrt(4 pi) / N` for the octahedral square), under Karis's `n = v = r` assumption, weighted by
//! `n.l`. The lobe's full width at half maximum is about `2.6 alpha` radians of reflected
//! direction, so level `k`'s lobe spans about 2.6 of its own texels: it is sampled without aliasing
//! at its resolution. A lookup with roughness `r` uses `lod_r = log2(r^2 / theta_0)` and reads at
//! `max(lod_r, lod_footprint)` (trilinear), where `lod_footprint` is the reflected direction's
//! footprint measured in angle ([`angular_lod`]: `log2` of the unit direction's larger change per
//! pixel over `theta_0`), the same for every mapping and every part of the sphere; the map's `uv`
//! footprint would pick levels far too coarse where the mapping stretches (the equirect poles,
//! where `du` grows as `1 / sin theta`), and the glossy pyramid is read isotropically anyway;
//! below `lod_r = 0` (perceptual roughness under
//! `sqrt(theta_0)`, 0.078 for a 1024-wide equirect map) the surface is a mirror and the frame's
//! filter reads the plain map with that footprint, like any texture. The convolution is
//! importance-sampled (64 Hammersley directions per texel) from the plain map's box pyramid at the
//! level whose texel matches each sample's share of the lobe (Colbert and Krivanek 2007, GPU Gems
//! 3 ch. 20, with Karis's +1 bias).
//!
//! **Split sum**: specular `= prefiltered(r) (F0 A + B)` with `(A, B)` the integrated GGX/Smith BRDF
//! for `(n.v, roughness)` ([`dfg`], a 32x32 table integrated at first use with the shading model's
//! own `D` and visibility, 256 samples per entry); diffuse `= c_diff E(n) / pi` with `E` the
//! irradiance of the map ([`EnvironmentMaps::irradiance`], an equirect map of 32x16 texels, each a
//! brute-force cosine-weighted sum over a 64x32 grid of directions read from the map at the
//! grid's resolution, whatever its layout). Both are scaled by the environment's intensity and
//! the surface's ambient occlusion.
//!
//! **The reference** (texel-raster's `reference`) reads the plain map bilinearly at level 0 for the
//! background and mirrors, and the glossy pyramid trilinearly at exactly `lod_r` (the lobe is the
//! material's, not a filter's): what it leaves out is every pixel footprint.

use std::f64::consts::PI;
use std::sync::OnceLock;

use glam::{DMat4, DVec2, DVec3, DVec4, Mat4, Vec3};
use rayon::prelude::*;
pub use texel_texture::mapping::sphere::{equirect_direction, equirect_duv, equirect_uv, Mapping};
use texel_texture::{
    AddressMode, Filter, Footprint, Format, Limits, Sampler, SamplerDescriptor, Texture,
};

use crate::error::ShadeError;
use crate::material::{ggx_d, smith_visibility, MIN_ROUGHNESS};

/// Width of the irradiance map (its height is half).
pub const IRRADIANCE_WIDTH: u32 = 32;

/// Hammersley samples per texel of the glossy pyramid's levels.
pub const PREFILTER_SAMPLES: u32 = 64;

/// Width of the grid of directions the irradiance is summed over (its height is half).
const IRRADIANCE_SOURCES: u32 = 64;

/// The border in texels around each stored cube face or octahedral square of side `side`
/// (module docs): `side / 8`, at least 1.
pub fn border(side: u32) -> u32 {
    (side / 8).max(1)
}

/// The address modes of a mapping's stored layers: an equirect map wraps around in `u` and stops
/// at the poles in `v`; bordered cube faces and octahedral squares clamp to their border.
pub fn descriptor(mapping: Mapping, desc: SamplerDescriptor) -> SamplerDescriptor {
    let u = match mapping {
        Mapping::Equirect => AddressMode::Repeat,
        Mapping::Cube | Mapping::Octahedral => AddressMode::ClampToEdge,
    };
    SamplerDescriptor {
        address_mode_u: u,
        address_mode_v: AddressMode::ClampToEdge,
        ..desc
    }
}

/// How directions land in an environment's stored layers: the mapping, the side of a face (the
/// width of an equirect map) and the border around it (module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MapLayout {
    /// The mapping.
    pub mapping: Mapping,
    /// Texels across a cube face or the octahedral square; an equirect map's width.
    pub side: u32,
    /// An equirect map's height (a cube face's and the octahedral square's are `side`).
    pub height: u32,
    /// Border texels on each side of a stored face (0 for an equirect map).
    pub border: u32,
}

impl MapLayout {
    /// The layout of a map of `mapping` whose source faces are `width x height`.
    pub fn new(mapping: Mapping, width: u32, height: u32) -> Self {
        let border = match mapping {
            Mapping::Equirect => 0,
            Mapping::Cube | Mapping::Octahedral => border(width),
        };
        MapLayout {
            mapping,
            side: width,
            height,
            border,
        }
    }

    /// Stored layers: 6 for a cube, else 1.
    pub fn layers(&self) -> usize {
        self.mapping.layers()
    }

    /// A stored layer's size, border included.
    pub fn stored_size(&self) -> (u32, u32) {
        (self.side + 2 * self.border, self.height + 2 * self.border)
    }

    /// The angle in radians a level-0 texel spans (module docs: the glossy pyramid's scale).
    pub fn texel_angle(&self) -> f64 {
        let n = f64::from(self.side.max(1));
        match self.mapping {
            Mapping::Equirect => 2.0 * PI / n,
            Mapping::Cube => 2.0 / n,
            Mapping::Octahedral => (4.0 * PI).sqrt() / n,
        }
    }

    /// The stored uv of a face's own uv (the border shifts and shrinks it), per axis.
    fn scale_offset(&self) -> (DVec2, DVec2) {
        let (w, h) = self.stored_size();
        let (w, h) = (f64::from(w), f64::from(h));
        let b = f64::from(self.border);
        (
            DVec2::new(f64::from(self.side) / w, f64::from(self.height) / h),
            DVec2::new(b / w, b / h),
        )
    }

    /// The layer direction `d` (any length but 0) lands in and its stored uv; a zero or
    /// non-finite `d` gives layer 0 and NaN.
    pub fn locate(&self, d: DVec3) -> (usize, DVec2) {
        let (scale, offset) = self.scale_offset();
        let (layer, uv) = self.mapping.uv(d);
        (layer, uv * scale + offset)
    }

    /// The layer direction `d` lands in and its footprint there for screen derivatives `dd_dx`,
    /// `dd_dy` of `d` (analytic, module docs; zero derivatives give a zero footprint, level 0).
    pub fn footprint(&self, d: DVec3, dd_dx: DVec3, dd_dy: DVec3) -> (usize, Footprint) {
        let (layer, uv) = self.locate(d);
        let (scale, _) = self.scale_offset();
        let duv = |dd: DVec3| scale * self.mapping.duv(layer, d, dd);
        let (dx, dy) = (duv(dd_dx), duv(dd_dy));
        let fp = Footprint {
            u: uv.x as f32,
            v: uv.y as f32,
            dudx: dx.x as f32,
            dudy: dy.x as f32,
            dvdx: dx.y as f32,
            dvdy: dy.y as f32,
        };
        (layer, fp)
    }

    /// The unit direction through the centre of texel `(i, j)` of a stored `lw x lh` level of
    /// `layer` (border texels included: a cube face's plane extended, the octahedral square
    /// continued).
    pub fn texel_direction(&self, layer: usize, lw: u32, lh: u32, i: u32, j: u32) -> DVec3 {
        let (scale, offset) = self.scale_offset();
        let stored = DVec2::new(
            (f64::from(i) + 0.5) / f64::from(lw),
            (f64::from(j) + 0.5) / f64::from(lh),
        );
        self.mapping.direction(layer, (stored - offset) / scale)
    }
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

/// GGX's `alpha` that level `k` of the glossy pyramid holds, for level-0 texels of
/// `texel_angle` radians ([`MapLayout::texel_angle`]).
pub fn level_alpha(k: u32, texel_angle: f64) -> f64 {
    if k == 0 {
        return 0.0;
    }
    (texel_angle * f64::from(1u32 << k.min(31))).min(1.0)
}

/// The glossy pyramid's level for perceptual roughness `roughness` (`log2(r^2 / theta_0)`; `<= 0`
/// is a mirror), for level-0 texels of `texel_angle` radians.
pub fn roughness_lod(roughness: f32, texel_angle: f64) -> f32 {
    let alpha = f64::from(roughness.clamp(MIN_ROUGHNESS, 1.0)).powi(2);
    (alpha / texel_angle).log2() as f32
}

/// The glossy pyramid's level for a footprint of direction `d` (any length but 0) changing by
/// `dd[0]` and `dd[1]` per pixel: `log2(max(|dn/dx|, |dn/dy|) / theta_0)` with `dn` the change of
/// the unit direction (radians per pixel) and `theta_0 = texel_angle`, clamped to `[0, 64]`
/// (0 for a zero, NaN or degenerate footprint). At the equator of an equirect map it equals the
/// isotropic `uv` footprint's level; unlike that level it does not depend on where the mapping
/// stretches.
pub fn angular_lod(d: DVec3, dd: [DVec3; 2], texel_angle: f64) -> f32 {
    let len = d.length();
    if !(len > 0.0 && len.is_finite() && texel_angle > 0.0) {
        return 0.0;
    }
    let n = d / len;
    let rate = dd
        .iter()
        .map(|&v| ((v - n * n.dot(v)) / len).length())
        .fold(0.0, f64::max);
    let lod = (rate / texel_angle).log2();
    if lod.is_nan() {
        0.0
    } else {
        lod.clamp(0.0, 64.0) as f32
    }
}

/// The maps an environment is read through: the plain map with its box pyramid, its GGX
/// prefiltered pyramid and its irradiance (module docs), with the fixed samplers that read the
/// last two.
#[derive(Debug)]
pub struct EnvironmentMaps {
    /// Where directions land in the layers.
    pub layout: MapLayout,
    /// The stored layers ([`MapLayout::layers`]: the equirect map as given, else bordered
    /// linear float faces), each with its box pyramid: the background's and mirrors' lookups,
    /// through the frame's filter.
    pub radiance: Vec<Texture>,
    /// The GGX-prefiltered pyramids (module docs), one per layer, the same sizes as `radiance`.
    pub glossy: Vec<Texture>,
    /// Irradiance over pi, `E(n) / pi`, by the normal's equirectangular coordinates.
    pub irradiance: Texture,
    /// Trilinear, with the layout's address modes: reads `glossy` and `radiance` for the
    /// prefilter.
    trilinear: Sampler,
    /// Trilinear, equirect address modes: reads `irradiance`.
    irradiance_sampler: Sampler,
    /// Bilinear at level 0: the reference's reads of `radiance`.
    level0: Sampler,
}

impl EnvironmentMaps {
    /// The stored layers, prefiltered pyramid and irradiance of a map of `mapping` from its
    /// `faces` (one equirect or octahedral image; six cube faces in the order `+x, -x, +y, -y,
    /// +z, -z`, all square and of one size; any format, read through their pyramids), computed on
    /// the current rayon pool.
    ///
    /// # Errors
    /// [`ShadeError::Texture`] when a float pyramid does not fit `limits`;
    /// [`ShadeError::InvalidEnvironment`] for the wrong number of faces or faces of the wrong shape.
    pub fn new(mapping: Mapping, faces: Vec<Texture>, limits: &Limits) -> Result<Self, ShadeError> {
        let first = faces.first().ok_or(ShadeError::InvalidEnvironment(
            "an environment map needs an image",
        ))?;
        let layout = MapLayout::new(mapping, first.width(), first.height());
        if faces.len() != layout.layers() {
            return Err(ShadeError::InvalidEnvironment(
                "a cube map has six faces, other environment maps one image",
            ));
        }
        if mapping != Mapping::Equirect
            && faces
                .iter()
                .any(|f| f.width() != f.height() || f.width() != layout.side)
        {
            return Err(ShadeError::InvalidEnvironment(
                "cube faces and octahedral maps must be square, cube faces all of one size",
            ));
        }
        let trilinear = Sampler::new(descriptor(
            mapping,
            SamplerDescriptor::from(Filter::Trilinear),
        ))?;
        let level0 = Sampler::new(descriptor(
            mapping,
            SamplerDescriptor::from(Filter::Bilinear),
        ))?;
        let irradiance_sampler = Sampler::new(descriptor(
            Mapping::Equirect,
            SamplerDescriptor::from(Filter::Trilinear),
        ))?;
        let radiance = match mapping {
            Mapping::Equirect => faces,
            Mapping::Cube | Mapping::Octahedral => {
                let faces = MapFaces {
                    layout: MapLayout {
                        border: 0,
                        ..layout
                    },
                    faces: &faces,
                    sampler: &level0,
                };
                (0..layout.layers())
                    .map(|layer| faces.bordered(layout, layer, limits))
                    .collect::<Result<_, _>>()?
            }
        };
        let source = MapFaces {
            layout,
            faces: &radiance,
            sampler: &trilinear,
        };
        let glossy = (0..layout.layers())
            .map(|layer| source.prefilter_ggx(layer, limits))
            .collect::<Result<_, _>>()?;
        let irradiance = source.irradiance_map(limits)?;
        Ok(EnvironmentMaps {
            layout,
            radiance,
            glossy,
            irradiance,
            trilinear,
            irradiance_sampler,
            level0,
        })
    }

    /// Bytes [`EnvironmentMaps::new`] adds to a map of `mapping` from faces of `width x height`:
    /// the bordered float layers (cube and octahedral), the float glossy pyramids and the
    /// irradiance map.
    pub fn extra_bytes(mapping: Mapping, width: u32, height: u32) -> u64 {
        let f = Format::Rgba32Float.texel_bytes();
        let layout = MapLayout::new(mapping, width, height);
        let (w, h) = layout.stored_size();
        let layer = texel_texture::storage::pyramid::pyramid_texels(w, h);
        let copies = if mapping == Mapping::Equirect { 1 } else { 2 };
        let irr =
            texel_texture::storage::pyramid::pyramid_texels(IRRADIANCE_WIDTH, IRRADIANCE_WIDTH / 2);
        (layer * copies * layout.layers() as u64 + irr) * f
    }
}

/// A map's layers with their layout and the sampler that reads them, while the maps are built.
struct MapFaces<'a> {
    layout: MapLayout,
    faces: &'a [Texture],
    sampler: &'a Sampler,
}

impl MapFaces<'_> {
    /// The radiance along `d`, read at level `lod`.
    fn read(&self, d: DVec3, lod: f32) -> DVec3 {
        let (layer, uv) = self.layout.locate(d);
        let tex = &self.faces[layer];
        let fp = footprint_at_lod(uv, lod, tex.width(), tex.height());
        let c = self.sampler.sample(tex, &fp);
        DVec3::new(c[0].into(), c[1].into(), c[2].into())
    }

    /// Layer `layer` of `bordered` (a layout with a border) from these unbordered faces: the
    /// face's own texels inside, the radiance along each border texel's direction outside
    /// (module docs), as a linear float texture with its box pyramid.
    fn bordered(
        &self,
        bordered: MapLayout,
        layer: usize,
        limits: &Limits,
    ) -> Result<Texture, ShadeError> {
        let (w, h) = bordered.stored_size();
        let b = bordered.border;
        let face = &self.faces[layer];
        Ok(Texture::from_fn(
            w,
            h,
            Format::Rgba32Float,
            limits,
            |i, j| {
                let (fi, fj) = (i.wrapping_sub(b), j.wrapping_sub(b));
                if fi < bordered.side && fj < bordered.height {
                    face.texel(0, fi, fj).unwrap_or([0.0; 4])
                } else {
                    let c = self.read(bordered.texel_direction(layer, w, h, i, j), 0.0);
                    [c.x as f32, c.y as f32, c.z as f32, 1.0]
                }
            },
        )?)
    }

    /// The GGX-prefiltered pyramid of layer `layer` (module docs).
    fn prefilter_ggx(&self, layer: usize, limits: &Limits) -> Result<Texture, ShadeError> {
        let layout = self.layout;
        let radiance = &self.faces[layer];
        let (w, h) = (radiance.width(), radiance.height());
        limits.check(w, h, Format::Rgba32Float)?;
        let theta0 = layout.texel_angle();
        let texel_solid_angle = theta0 * theta0;
        let mut all: Vec<[f32; 4]> = Vec::new();
        let levels = texel_texture::storage::pyramid::level_count(w, h);
        for k in 0..levels {
            let (lw, lh) = texel_texture::storage::pyramid::level_size(w, h, k);
            if k == 0 {
                all.extend((0..lh).flat_map(|j| {
                    (0..lw).map(move |i| radiance.texel(0, i, j).unwrap_or([0.0; 4]))
                }));
                continue;
            }
            let alpha = level_alpha(k, theta0);
            let n = PREFILTER_SAMPLES;
            let level: Vec<[f32; 4]> = (0..lh)
                .into_par_iter()
                .flat_map_iter(|j| {
                    (0..lw).map(move |i| {
                        let r = layout.texel_direction(layer, lw, lh, i, j);
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
                            sum += self.read(l, lod as f32) * n_dot_l;
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

    /// `E(n) / pi` over the map's directions (module docs), as an [`IRRADIANCE_WIDTH`]-wide
    /// equirect map.
    fn irradiance_map(&self, limits: &Limits) -> Result<Texture, ShadeError> {
        let (sw, sh) = (IRRADIANCE_SOURCES, IRRADIANCE_SOURCES / 2);
        // The level whose texels match the grid's cells.
        let lod = ((2.0 * PI / f64::from(sw)) / self.layout.texel_angle())
            .log2()
            .max(0.0) as f32;
        let sources: Vec<(DVec3, DVec3)> = (0..sh)
            .into_par_iter()
            .flat_map_iter(|j| {
                let theta0 = PI * f64::from(j) / f64::from(sh);
                let theta1 = PI * f64::from(j + 1) / f64::from(sh);
                // The exact solid angle of the cell's share of its latitude band.
                let omega = (theta0.cos() - theta1.cos()) * 2.0 * PI / f64::from(sw);
                (0..sw).map(move |i| {
                    let d = equirect_direction(DVec2::new(
                        (f64::from(i) + 0.5) / f64::from(sw),
                        (f64::from(j) + 0.5) / f64::from(sh),
                    ));
                    (d, self.read(d, lod) * omega)
                })
            })
            .collect();
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
    /// The frame's filter with [`descriptor`]'s address modes for the maps' mapping: the
    /// background's and mirrors' lookups.
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

    /// The layer direction `d` lands in and its footprint for screen derivatives `dd`
    /// ([`MapLayout::footprint`]).
    pub fn footprint(&self, d: DVec3, dd: [DVec3; 2]) -> (usize, Footprint) {
        self.maps.layout.footprint(d, dd[0], dd[1])
    }

    /// The radiance arriving from direction `d` whose screen derivatives are `dd` (zero for the
    /// reference's point samples, which read level 0 bilinearly), as the background and mirrors
    /// see it.
    pub fn radiance(&self, d: DVec3, dd: [DVec3; 2], reference: bool, count: bool) -> Read {
        let (layer, fp) = self.footprint(d, dd);
        self.radiance_at(layer, &fp, reference, count)
    }

    /// The plain map's radiance over footprint `fp` in layer `layer` (the frame's filter;
    /// bilinear at level 0 for the `reference`).
    pub fn radiance_at(&self, layer: usize, fp: &Footprint, reference: bool, count: bool) -> Read {
        let sampler = if reference {
            &self.maps.level0
        } else {
            self.sampler
        };
        self.read(sampler, &self.maps.radiance[layer], fp, count)
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
        let lod_r = roughness_lod(roughness, maps.layout.texel_angle());
        if lod_r <= 0.0 {
            return self.radiance(r, dr, reference, count);
        }
        let (layer, fp) = self.footprint(r, if reference { [DVec3::ZERO; 2] } else { dr });
        let lod = if reference {
            lod_r
        } else {
            lod_r.max(angular_lod(r, dr, maps.layout.texel_angle()))
        };
        let glossy = &maps.glossy[layer];
        let uv = DVec2::new(fp.u.into(), fp.v.into());
        let fp = footprint_at_lod(uv, lod, glossy.width(), glossy.height());
        self.read(&maps.trilinear, glossy, &fp, count)
    }

    /// Irradiance over pi for unit normal `n` (bilinear).
    pub fn irradiance(&self, n: DVec3, count: bool) -> Read {
        let uv = equirect_uv(n);
        let fp = Footprint {
            u: uv.x as f32,
            v: uv.y as f32,
            ..Footprint::default()
        };
        self.read(
            &self.maps.irradiance_sampler,
            &self.maps.irradiance,
            &fp,
            count,
        )
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
    /// The unit direction of the ray through continuous pixel position `(x, y)` (the conventions'
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

    /// The ray through the centre of pixel `(i, j)` and its differences to the rays one pixel
    /// right and one down (unit directions, so the differences are angles): the background's
    /// direction and screen derivatives.
    pub fn differentials(&self, i: u32, j: u32) -> Option<(DVec3, [DVec3; 2])> {
        let (x, y) = (f64::from(i) + 0.5, f64::from(j) + 0.5);
        let d = self.direction(x, y)?;
        let dx = self.direction(x + 1.0, y)?;
        let dy = self.direction(x, y + 1.0)?;
        Some((d, [dx - d, dy - d]))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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

    #[test]
    fn the_angular_level_matches_the_uv_level_at_the_equator_and_not_the_poles_stretch() {
        // An equirect map 2048 x 1024: theta_0 = 2 pi / 2048, square texels at the equator.
        let (w, h) = (2048.0, 1024.0);
        let theta0 = 2.0 * PI / w;
        let uv_lod = |d: DVec3, dd: [DVec3; 2]| {
            let rho = dd
                .iter()
                .map(|&v| {
                    let duv = texel_texture::mapping::sphere::equirect_duv(d, v);
                    DVec2::new(duv.x * w, duv.y * h).length()
                })
                .fold(0.0, f64::max);
            rho.log2() as f32
        };
        // Two degrees per pixel (11.4 texels), east and down, at the equator.
        let step = 2f64.to_radians();
        let d = DVec3::new(1.0, 0.0, 0.0) * 3.0;
        let dd = [
            DVec3::new(0.0, 0.0, step * 3.0),
            DVec3::new(0.0, -step * 3.0, 0.0),
        ];
        let (a, u) = (angular_lod(d, dd, theta0), uv_lod(d, dd));
        assert!((a - u).abs() < 1e-3, "{a} {u}");
        assert!((a - (step / theta0).log2() as f32).abs() < 1e-4);
        // A degree from the pole, the same change of angle east: the same angular level, where
        // the uv footprint stretches by 1 / sin(1 degree) (almost 6 levels coarser).
        let t = 1f64.to_radians();
        let d = DVec3::new(t.sin(), t.cos(), 0.0);
        let east = [DVec3::new(0.0, 0.0, step), DVec3::ZERO];
        let (a, u) = (angular_lod(d, east, theta0), uv_lod(d, east));
        assert!((a - (step / theta0).log2() as f32).abs() < 1e-4, "{a}");
        assert!(u > a + 5.5, "{u} {a}");
        // Degenerate footprints read level 0; huge ones clamp.
        assert_eq!(angular_lod(DVec3::ZERO, east, theta0), 0.0);
        assert_eq!(angular_lod(d, [DVec3::ZERO; 2], theta0), 0.0);
        assert_eq!(angular_lod(d, [DVec3::splat(f64::NAN); 2], theta0), 0.0);
        assert_eq!(angular_lod(d, [DVec3::splat(1e300); 2], theta0), 64.0);
    }
}
