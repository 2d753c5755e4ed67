//! Lights, materials and the shading model: Lambert diffuse plus GGX specular with Smith masking,
//! as glTF 2.0's metallic-roughness model (glTF 2.0 specification, Appendix B "BRDF
//! Implementation"), with normal maps in glTF's tangent space and specular antialiasing.
//!
//! For a fragment with base colour `c` (the draw's texture times the material's factor times the
//! vertex colour), perceptual roughness `r` and metalness `m`, unit normal `n`, unit view direction
//! `v` (towards the eye) and a light from unit direction `l` giving illuminance `E` on a surface
//! facing it:
//!
//! - `alpha = r^2` (Burley 2012; `r` clamped to at least [`MIN_ROUGHNESS`]);
//! - `h = normalize(l + v)`, `F0 = mix(0.04, c, m)`, `F = F0 + (1 - F0)(1 - v.h)^5` (Schlick 1994);
//! - `D = alpha^2 / (pi ((n.h)^2 (alpha^2 - 1) + 1)^2)` (GGX, Walter et al. 2007);
//! - `Vis = 0.5 / (n.l sqrt((n.v)^2 (1 - alpha^2) + alpha^2) + n.v sqrt((n.l)^2 (1 - alpha^2) +
//!   alpha^2))`, the height-correlated Smith masking-shadowing term divided by `4 n.l n.v` (Heitz
//!   2014, eq. 99);
//! - `f = (1 - F) c_diff / pi + F D Vis` with `c_diff = c (1 - m)`;
//! - where specular antialiasing measured a spread of normals under the pixel
//!   ([`SlopeSpread`]), `D` is the GGX lobe convolved with that spread ([`SlopeSpread::d`]) and the
//!   diffuse `n.l` the mean clamped cosine over it ([`SlopeSpread::clamped_cosine`]);
//! - outgoing radiance `L = sum over lights of f E (n.l)` for `n.l > 0`, plus `A (c_diff + F0)` for
//!   ambient light `A`, times the ambient visibility [`Surface::occlusion`] (glTF's occlusion
//!   texture applies to ambient light only). The diffuse part's `n.l` uses [`Surface::diffuse_normal`] (the mean normal
//!   under the pixel where specular antialiasing keeps it; the shading normal otherwise).
//!
//! Units follow glTF's `KHR_lights_punctual`: a directional light's `intensity` is the illuminance
//! on a surface facing it; a point light's is its luminous intensity, giving `intensity / d^2` at
//! distance `d`. A white Lambertian surface facing a directional light of intensity `pi` therefore
//! shows radiance 1.
//!
//! Draws without a [`Material`] under lights are Lambertian: `L = c/pi sum E (n.l) + A c`, with the
//! interpolated vertex normal.

use glam::{Vec3, Vec4};
use texel_texture::{Footprint, Texture};

use crate::inputs::read_channel;
pub use crate::inputs::{ChannelInput, MomentMap, TextureInput};
use crate::layers::Layers;

/// The most lights a frame has (as fixed-function GPUs had 8).
pub const MAX_LIGHTS: usize = 8;

/// The smallest perceptual roughness used (`alpha = 0.045^2 = 0.002`): a perfect mirror's
/// highlight under a point light would be a Dirac pulse no pixel samples.
pub const MIN_ROUGHNESS: f32 = 0.045;

/// The most shading sub-samples per pixel axis that [`Material::shading_samples`] may ask for
/// (8 x 8 = 64 shadings of one pixel).
pub const MAX_SHADING_SAMPLES: u32 = 8;

/// One light, in world space, linear RGB.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Light {
    /// Parallel light from `direction` (pointing *towards* the light; need not be normalised):
    /// illuminance `intensity` on a surface facing it.
    Directional {
        /// Direction towards the light.
        direction: Vec3,
        /// Illuminance on a surface facing the light, linear RGB.
        intensity: Vec3,
    },
    /// A point light at `position`: illuminance `intensity / d^2` at distance `d` on a surface
    /// facing it.
    Point {
        /// World-space position.
        position: Vec3,
        /// Luminous intensity, linear RGB.
        intensity: Vec3,
    },
    /// Light from every direction, unoccluded: adds `intensity * (c_diff + F0)`.
    Ambient {
        /// Ambient radiance, linear RGB.
        intensity: Vec3,
    },
}

impl Light {
    /// Whether every number is finite.
    pub fn is_finite(&self) -> bool {
        match *self {
            Light::Directional {
                direction,
                intensity,
            } => direction.is_finite() && intensity.is_finite(),
            Light::Point {
                position,
                intensity,
            } => position.is_finite() && intensity.is_finite(),
            Light::Ambient { intensity } => intensity.is_finite(),
        }
    }
}

/// How the specular lobe is widened where the normal varies within a pixel.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum SpecularAa {
    /// None: the filtered normal is normalised and used as if it were exact (sparkles and aliases
    /// at a distance).
    #[default]
    #[cfg_attr(
        feature = "clap",
        value(help = "None: the filtered normal is normalised and used as if exact")
    )]
    None,
    /// Toksvig (2005): the filtered (averaged) tangent-space normal is shorter than 1 where the
    /// normals under the footprint disagree. With `|n|` its length and the Blinn-Phong exponent
    /// `s = 2 / alpha^2 - 2` equivalent to GGX's `alpha` (Walter et al. 2007), the exponent becomes
    /// `s' = s |n| / (|n| + s (1 - |n|))`, i.e. `alpha'^2 = 2 / (s' + 2)`. The widening is taken
    /// as an isotropic slope variance `(alpha'^2 - alpha^2) / 2` about the mean normal and shaped
    /// by [`SlopeSpread::d`].
    #[cfg_attr(
        feature = "clap",
        value(
            help = "Toksvig (2005): roughness widened by how much the filtered normal shortened"
        )
    )]
    Toksvig,
    /// LEAN mapping (Olano & Baker 2010): the map's slopes `b = (n_x, n_y) / n_z` and their second
    /// moments `(b_x^2, b_y^2, b_x b_y)` are stored in float textures ([`lean_map`]) and filtered
    /// by the same filter, which is exact for them because they are linear. The mean slope gives
    /// the normal `normalize(b_x, b_y, 1)`; `E[b b^T] - E[b] E[b]^T` is the slopes' covariance
    /// under the footprint. The lobe is the material's GGX lobe convolved with the Gaussian of
    /// that covariance ([`SlopeSpread::d`]: anisotropic, oriented by the cross moment), with the
    /// isotropic `alpha'^2 = alpha^2 + tr(cov)` for the masking term; the diffuse term takes the
    /// mean of the clamped cosine over the spread ([`SlopeSpread::clamped_cosine`]). Needs
    /// [`Material::lean`] for a normal map, or [`Material::height_moments`] for a height map
    /// (whose slopes are the height's gradient).
    #[cfg_attr(
        feature = "clap",
        value(
            help = "LEAN mapping (Olano & Baker 2010): slope moments filtered with the normals; the lobe convolved with their covariance (anisotropic)"
        )
    )]
    Lean,
    /// Projected-space NDF filtering (Tokuyoshi & Kaplanyan 2021, "Stable Geometric Specular
    /// Antialiasing with Projected-Space NDF Filtering", JCGT 10(2), eq. 14 and listing 5), what
    /// GPUs ship: the shading normal is also evaluated one pixel to the right and one below (the
    /// difference a fragment quad's `ddx`/`ddy` takes), and the lobe widens by the screen-space
    /// variance of the normal under a Gaussian pixel filter of variance `sigma^2 = 1 / (2 pi)`:
    /// `alpha'^2 = min(1, alpha^2 + min(sigma^2 (|dn/dx|^2 + |dn/dy|^2), kappa))` with the paper's
    /// clamp `kappa = 0.18`. Covers normal maps, bump maps and curved geometry alike, at the price
    /// of two more normal evaluations. The lobe stays the widened GGX, as the paper ships it.
    #[cfg_attr(
        feature = "clap",
        value(
            help = "Projected-space NDF filtering (Tokuyoshi & Kaplanyan 2021): roughness widened by the normal's change to the neighbouring pixels, as GPUs ship it"
        )
    )]
    Projected,
}

/// How a material's height map shapes the surface ([`Material::height_map`]). The mesh is the
/// top of the relief: height 1 lies on it and height 0 lies `height_scale` below it, along the
/// normal (so a displaced point is `p + height_scale (h - 1) n`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Displacement {
    /// The height map is not used.
    #[default]
    None,
    /// Bump mapping (Blinn 1978), as pbrt-v4's `BumpMap`: the normal of the displaced surface from
    /// forward differences of the filtered height, with a step that follows the pixel footprint
    /// (`du = (|du/dx| + |du/dy|) / 2`, likewise `dv`); the geometry stays flat.
    Bump,
    /// Parallax occlusion mapping (Tatarchuk 2006): the view ray is marched through the height
    /// field below the polygon (8 to 64 linear steps, more at grazing angles, then a secant step)
    /// and every map is read where it meets the relief; the normal is bump mapping's at that
    /// point. Silhouettes and self-shadowing are not modelled.
    Pom,
}

/// A draw's material. The base colour texture is the draw call's own texture; everything here
/// multiplies or perturbs it.
#[derive(Clone, Copy, Debug)]
pub struct Material<'a> {
    /// Linear RGBA factor multiplying the base colour texture.
    pub base_color: Vec4,
    /// Perceptual roughness factor in `[0, 1]` (multiplies `roughness_map`).
    pub roughness: f32,
    /// Metalness factor in `[0, 1]` (multiplies `metallic_map`).
    pub metallic: f32,
    /// Roughness from a texture channel (glTF: green of `metallicRoughnessTexture`).
    pub roughness_map: Option<ChannelInput<'a>>,
    /// Metalness from a texture channel (glTF: blue of `metallicRoughnessTexture`).
    pub metallic_map: Option<ChannelInput<'a>>,
    /// Tangent-space normal map (glTF: `normalTexture`, linear RGB, `+Y` up, `n = 2 rgb - 1`).
    pub normal_map: Option<TextureInput<'a>>,
    /// Scales the normal map's x and y (glTF `normalTexture.scale`).
    pub normal_scale: f32,
    /// Specular antialiasing.
    pub specular_aa: SpecularAa,
    /// Adaptive shading supersampling: at most this many shading sub-samples per pixel axis
    /// (`1` turns it off, [`MAX_SHADING_SAMPLES`] at most). Where the shading normal turns from
    /// one pixel to the next by more than half the specular lobe's width, one shading sample
    /// cannot stand for the pixel; such pixels are shaded on a grid of `ceil(2 |dn| / alpha)`
    /// sub-samples per axis (`dn` the normal's change to the next pixel along that axis, `alpha`
    /// the lobe's GGX width after `specular_aa`) and averaged in linear light. Lit frames only; the
    /// reference ignores it (its sub-samples resolve the pixel already).
    pub shading_samples: u32,
    /// The LEAN moment map of `normal_map` ([`lean_map`]), read through the normal map's
    /// sampler; required by [`SpecularAa::Lean`] on a normal map.
    pub lean: Option<&'a MomentMap>,
    /// Height map, one channel in `[0, 1]` (see [`Displacement`]); used when `displacement` is
    /// not [`Displacement::None`]. A normal map, when there is one, still gives the normal.
    pub height_map: Option<ChannelInput<'a>>,
    /// World units between heights 0 and 1; finite and at least 0.
    pub height_scale: f32,
    /// What the height map does.
    pub displacement: Displacement,
    /// The slope moment map of `height_map` ([`height_moments`]), read through the height map's
    /// sampler; used by [`SpecularAa::Lean`] and [`SpecularAa::Toksvig`] on bump-mapped
    /// surfaces without a normal map.
    pub height_moments: Option<&'a MomentMap>,
    /// Layers blended by a mask ([`crate::layers`]), filtered then blended. Their blended base
    /// colour multiplies the draw's texture and `base_color`, their roughness multiplies
    /// `roughness`; their normals (where some layer has a normal map) replace `normal_map`, and
    /// their blended height replaces `height_map` when a layer gives a height.
    pub layers: Option<Layers<'a>>,
    /// Ambient occlusion from a texture channel (glTF: red of `occlusionTexture`), `1`
    /// unoccluded; it dims ambient light only (glTF 2.0 5.19.4: occlusion applies to indirect
    /// lighting), by `1 + occlusion_strength (ao - 1)`.
    pub occlusion_map: Option<ChannelInput<'a>>,
    /// How much of `occlusion_map` applies, `[0, 1]` (glTF `occlusionTexture.strength`).
    pub occlusion_strength: f32,
}

impl Default for Material<'_> {
    /// A white dielectric of roughness 0.5 without maps.
    fn default() -> Self {
        Material {
            base_color: Vec4::ONE,
            roughness: 0.5,
            metallic: 0.0,
            roughness_map: None,
            metallic_map: None,
            normal_map: None,
            normal_scale: 1.0,
            specular_aa: SpecularAa::None,
            shading_samples: 1,
            lean: None,
            height_map: None,
            height_scale: 0.05,
            displacement: Displacement::None,
            height_moments: None,
            layers: None,
            occlusion_map: None,
            occlusion_strength: 1.0,
        }
    }
}

impl Material<'_> {
    /// Whether every factor is finite and in range (`roughness` and `metallic` in `[0, 1]`,
    /// channels `0..=3`, `height_scale >= 0`, `shading_samples` in `1..=`[`MAX_SHADING_SAMPLES`]),
    /// LEAN has its moment map for the map that gives the normal, and a displacement has a
    /// height map.
    pub fn is_valid(&self) -> bool {
        let channel_ok = |c: &Option<ChannelInput>| c.is_none_or(|c| c.channel < 4);
        let lean_ok = self.specular_aa != SpecularAa::Lean
            || match (self.normal_map, self.bumped()) {
                (Some(_), _) => self.lean.is_some(),
                (None, true) => self.height_moments.is_some(),
                (None, false) => true,
            };
        let height_ok = self.displacement == Displacement::None || self.has_height();
        lean_ok
            && height_ok
            && (1..=MAX_SHADING_SAMPLES).contains(&self.shading_samples)
            && self.layers.as_ref().is_none_or(Layers::is_valid)
            && self.height_scale.is_finite()
            && self.height_scale >= 0.0
            && channel_ok(&self.height_map)
            && self.base_color.is_finite()
            && (0.0..=1.0).contains(&self.roughness)
            && (0.0..=1.0).contains(&self.metallic)
            && self.normal_scale.is_finite()
            && channel_ok(&self.roughness_map)
            && channel_ok(&self.metallic_map)
    }

    /// Whether the height map gives the normal (a displacement is set and there is a height map
    /// or layers with heights).
    pub fn bumped(&self) -> bool {
        self.displacement != Displacement::None && self.has_height()
    }

    /// Whether there are heights: a height map, or layers that give heights.
    pub fn has_height(&self) -> bool {
        self.height_map.is_some() || self.layers.as_ref().is_some_and(|l| l.heights)
    }

    /// The height in `[0, 1]` at `fp`: the layers' blended height where they give heights, else
    /// the height map's; `None` without either. Adds the texels read to `texels` when `count`.
    pub fn height_at(&self, fp: &Footprint, count: bool, texels: &mut u32) -> Option<f32> {
        match (&self.layers, &self.height_map) {
            (Some(l), _) if l.heights => Some(l.height(fp, count, texels)),
            (_, Some(h)) => Some(read_channel(h, fp, count, texels)),
            _ => None,
        }
    }

    /// The width and height in texels of what gives the heights (bump mapping's fallback step).
    pub fn height_size(&self) -> (u32, u32) {
        match (&self.layers, &self.height_map) {
            (Some(l), _) if l.heights => l.height_size(),
            (_, Some(h)) => (h.input.texture.width(), h.input.texture.height()),
            _ => (1, 1),
        }
    }
}

/// Everything the BRDF needs at one fragment.
#[derive(Clone, Copy, Debug)]
pub struct Surface {
    /// Base colour, linear RGB.
    pub base: Vec3,
    /// Perceptual roughness after maps and antialiasing, `[MIN_ROUGHNESS, 1]`.
    pub roughness: f32,
    /// Metalness, `[0, 1]`.
    pub metallic: f32,
    /// Unit shading normal.
    pub normal: Vec3,
    /// The normal the diffuse term uses, length at most 1: the mean of the normals under the
    /// pixel where a filter averaged them (`E[max(0, n.l)] = E[n].l` while no normal under it
    /// faces away from the light), else `normal`.
    pub diffuse_normal: Vec3,
    /// World-space position.
    pub position: Vec3,
    /// Ambient visibility in `[0, 1]` (baked ambient occlusion; 1 unoccluded): multiplies the
    /// ambient lights only.
    pub occlusion: f32,
    /// The spread of the normals under the pixel that specular antialiasing measured, or `None`
    /// (exact normals, or no antialiasing): the lobe is then [`SlopeSpread::d`] instead of GGX
    /// at `roughness`.
    pub spread: Option<SlopeSpread>,
}

/// The normals under a pixel as specular antialiasing sees them: slopes (`b = (x, y) / z` of a
/// normal in `frame`) with mean `mean` and covariance `cov`, under the material's own GGX lobe of
/// perceptual roughness `base_roughness`. The reflectance of such a pixel is the convolution of
/// the GGX slope distribution `P_a(m) = 1 / (pi a^2 (1 + |m|^2 / a^2)^2)` with the Gaussian of the
/// slopes (Olano & Baker 2010 use Beckmann for both, so their convolution is Beckmann again; GGX
/// has no closed form). [`SlopeSpread::d`] approximates it by a mixture that is exact at both
/// ends and has the right tail.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SlopeSpread {
    /// `[tangent, bitangent, normal]`, orthonormal, world space: the slopes' frame.
    pub frame: [Vec3; 3],
    /// Mean slope along tangent and bitangent.
    pub mean: glam::Vec2,
    /// Covariance of the slopes `[xx, yy, xy]` (positive semi-definite; rounding is clamped).
    pub cov: [f32; 3],
    /// The material's perceptual roughness before antialiasing widened it.
    pub base_roughness: f32,
}

impl SlopeSpread {
    /// The isotropic spread about the unit `normal` (no mean slope) that turns perceptual
    /// roughness `base` into `widened` (`alpha^2 = alpha_0^2 + 2 sigma^2`, so
    /// `sigma^2 = (alpha^2 - alpha_0^2) / 2` per axis): how Toksvig's widening is shaped.
    pub fn isotropic(normal: Vec3, base: f32, widened: f32) -> SlopeSpread {
        let a0 = base.clamp(MIN_ROUGHNESS, 1.0).powi(4);
        let a1 = widened.clamp(MIN_ROUGHNESS, 1.0).powi(4);
        let var = (0.5 * (a1 - a0)).max(0.0);
        let (t, b) = normal.any_orthonormal_pair();
        SlopeSpread {
            frame: [t, b, normal],
            mean: glam::Vec2::ZERO,
            cov: [var, var, 0.0],
            base_roughness: base,
        }
    }

    /// `E[max(0, n.l)]` over the pixel's normals, for the unit light direction `l` and
    /// `mean = E[n].l`: to first order in the slopes, `n.l` is Gaussian with that mean and the
    /// variance `l_t^T cov l_t` (`l_t` the light's components along the frame's tangent and
    /// bitangent), and the mean of a clamped Gaussian is `m Phi(m / s) + s phi(m / s)`.
    pub fn clamped_cosine(&self, mean: f32, l: Vec3) -> f32 {
        let [t, b, _] = self.frame;
        let (x, y) = (l.dot(t), l.dot(b));
        let var = self.cov[0] * x * x + self.cov[1] * y * y + 2.0 * self.cov[2] * x * y;
        if var <= 1e-12 {
            return mean.max(0.0);
        }
        let sd = var.sqrt();
        let z = mean / sd;
        let phi = (-0.5 * z * z).exp() / (2.0 * std::f32::consts::PI).sqrt();
        let cdf = 0.5 * (1.0 + erf(z / std::f32::consts::SQRT_2));
        (mean * cdf + sd * phi).max(0.0)
    }

    /// The microfacet distribution `D(h)` of the pixel for the half vector `h` (unit), with
    /// `alpha` the widened GGX alpha: [`SpreadLobe::d`] of [`SlopeSpread::lobe`].
    pub fn d(&self, h: Vec3, alpha: f32) -> f32 {
        self.lobe(alpha).d(h)
    }

    /// What [`SpreadLobe::d`] needs that does not depend on the light, for the widened GGX
    /// `alpha` (`alpha^2 = alpha_0^2 + tr(cov)`, as [`slope_variance_roughness`] gives): worked
    /// out once per pixel, before the lights.
    pub fn lobe(&self, alpha: f32) -> SpreadLobe {
        let [t, b, n] = self.frame;
        let a0 = self.base_roughness.clamp(MIN_ROUGHNESS, 1.0).powi(2);
        let lobe = 0.5 * a0 * a0;
        let (sxx, syy) = (self.cov[0].max(0.0) + lobe, self.cov[1].max(0.0) + lobe);
        // Keep the matrix positive definite whatever rounding did to the cross term.
        let sxy = self.cov[2].clamp(-0.999 * (sxx * syy).sqrt(), 0.999 * (sxx * syy).sqrt());
        let det = sxx * syy - sxy * sxy;
        SpreadLobe {
            frame: self.frame,
            mean: self.mean,
            alpha,
            w: (a0 * a0 / (alpha * alpha).max(1e-12)).min(1.0),
            mean_normal: (t * self.mean.x + b * self.mean.y + n).normalize(),
            sigma: [sxx, syy, sxy],
            det,
            gauss_norm: 2.0 * std::f32::consts::PI * det.sqrt(),
        }
    }
}

/// A pixel's [`SlopeSpread`] made ready for its lights ([`SlopeSpread::lobe`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpreadLobe {
    frame: [Vec3; 3],
    mean: glam::Vec2,
    /// The widened GGX alpha.
    alpha: f32,
    /// GGX's weight `alpha_0^2 / alpha^2`.
    w: f32,
    /// The unit normal of the mean slope.
    mean_normal: Vec3,
    /// The Gaussian's covariance `cov + alpha_0^2 / 2 I`, `[xx, yy, xy]`.
    sigma: [f32; 3],
    /// Its determinant.
    det: f32,
    /// `2 pi sqrt(det)`.
    gauss_norm: f32,
}

impl SpreadLobe {
    /// The microfacet distribution `D(h)` for the unit half vector `h`, with
    /// `w = alpha_0^2 / alpha^2`:
    ///
    /// `D = w D_GGX(n'.h; alpha) + (1 - w) N(m_h - mean; cov + alpha_0^2 / 2 I) / (h.n)^4`,
    ///
    /// where `n'` is the normal of the mean slope, `m_h` the slope of `h` in `frame` and `N` the
    /// bivariate Gaussian. Both parts integrate to 1 over projected area. Without spread
    /// (`cov = 0`, `w = 1`) it is the material's GGX lobe exactly; for a spread much wider than
    /// the lobe it is the Gaussian of the slopes widened by the lobe's own variance
    /// (`alpha_0^2 / 2` per axis, Beckmann's); and far from the mean its tail is
    /// `alpha_0^2 / (pi |m|^4)`, the base lobe's own (GGX's tail scales as `alpha^2`, and
    /// `w alpha^2 = alpha_0^2`), where a widened GGX alone (what Toksvig's and LEAN's GGX
    /// adaptations use) carries `alpha^2`: a highlight too wide and too bright in its tails.
    pub fn d(&self, h: Vec3) -> f32 {
        let [t, b, n] = self.frame;
        let c = h.dot(n);
        if c <= 0.0 {
            return 0.0;
        }
        let ggx = ggx_d(self.mean_normal.dot(h).max(0.0), self.alpha);
        if self.w >= 1.0 {
            return ggx;
        }
        let m = glam::Vec2::new(h.dot(t), h.dot(b)) / c - self.mean;
        let [sxx, syy, sxy] = self.sigma;
        let q = (syy * m.x * m.x - 2.0 * sxy * m.x * m.y + sxx * m.y * m.y) / self.det;
        let gauss = (-0.5 * q).exp() / self.gauss_norm;
        self.w * ggx + (1.0 - self.w) * gauss / (c * c * c * c)
    }
}

/// The error function, Abramowitz & Stegun 7.1.26 (absolute error below `1.5e-7` in exact
/// arithmetic, `1e-6` in `f32`).
pub fn erf(x: f32) -> f32 {
    let t = 1.0 / (1.0 + 0.327_591_1 * x.abs());
    let poly = t
        * (0.254_829_6
            + t * (-0.284_496_74 + t * (1.421_413_7 + t * (-1.453_152_1 + t * 1.061_405_4))));
    let y = 1.0 - poly * (-x * x).exp();
    y.copysign(x)
}

/// GGX's normal distribution `D(n.h)` for `alpha` (see the module docs).
pub fn ggx_d(n_dot_h: f32, alpha: f32) -> f32 {
    let a2 = alpha * alpha;
    let t = n_dot_h * n_dot_h * (a2 - 1.0) + 1.0;
    a2 / (std::f32::consts::PI * t * t)
}

/// The height-correlated Smith term divided by `4 n.l n.v` (Heitz 2014).
pub fn smith_visibility(n_dot_l: f32, n_dot_v: f32, alpha: f32) -> f32 {
    let a2 = alpha * alpha;
    let gv = n_dot_l * (n_dot_v * n_dot_v * (1.0 - a2) + a2).sqrt();
    let gl = n_dot_v * (n_dot_l * n_dot_l * (1.0 - a2) + a2).sqrt();
    0.5 / (gv + gl).max(1e-12)
}

/// Schlick's Fresnel approximation for reflectance `f0` at normal incidence.
pub fn fresnel(f0: Vec3, v_dot_h: f32) -> Vec3 {
    let k = (1.0 - v_dot_h.clamp(0.0, 1.0)).powi(5);
    f0 + (Vec3::ONE - f0) * k
}

/// The roughness that Toksvig's rule gives for `roughness` and a filtered normal of length
/// `length` (`(0, 1]`; 1 leaves it unchanged). See [`SpecularAa::Toksvig`].
pub fn toksvig_roughness(roughness: f32, length: f32) -> f32 {
    let r = roughness.max(MIN_ROUGHNESS);
    let len = length.clamp(1e-4, 1.0);
    let a2 = r.powi(4);
    let s = 2.0 / a2 - 2.0;
    let s2 = s * len / (len + s * (1.0 - len));
    let a2_new = 2.0 / (s2 + 2.0);
    a2_new.sqrt().sqrt().clamp(r, 1.0)
}

/// Outgoing radiance (linear RGB) of `surface` seen from `eye` under `lights`; `lambert` drops
/// the specular lobe (draws without a material). See the module docs.
pub fn radiance(surface: &Surface, eye: Vec3, lights: &[Light], lambert: bool) -> Vec3 {
    let n = surface.normal;
    let v = (eye - surface.position).normalize_or_zero();
    let n_dot_v = n.dot(v).max(1e-4);
    let alpha = surface.roughness.clamp(MIN_ROUGHNESS, 1.0).powi(2);
    let c_diff = surface.base * (1.0 - surface.metallic);
    let f0 = if lambert {
        Vec3::ZERO
    } else {
        Vec3::splat(0.04).lerp(surface.base, surface.metallic)
    };
    // The spread's lobe does not depend on the light: once per pixel.
    let lobe = surface.spread.as_ref().map(|s| s.lobe(alpha));
    let mut out = Vec3::ZERO;
    for light in lights {
        let (l, e) = match *light {
            Light::Directional {
                direction,
                intensity,
            } => (direction.normalize_or_zero(), intensity),
            Light::Point {
                position,
                intensity,
            } => {
                let d = position - surface.position;
                let d2 = d.length_squared();
                if d2 <= 0.0 {
                    continue;
                }
                (d / d2.sqrt(), intensity / d2)
            }
            Light::Ambient { intensity } => {
                out += intensity * (c_diff + f0) * surface.occlusion;
                continue;
            }
        };
        let n_dot_l = n.dot(l);
        let cosine = match &surface.spread {
            Some(spread) => spread.clamped_cosine(surface.diffuse_normal.dot(l), l),
            _ => surface.diffuse_normal.dot(l).max(0.0),
        };
        let diffuse = c_diff * std::f32::consts::FRAC_1_PI * cosine;
        if lambert {
            out += diffuse * e;
            continue;
        }
        if n_dot_l <= 0.0 {
            out += diffuse * e;
            continue;
        }
        let h = (l + v).normalize_or_zero();
        let fr = fresnel(f0, v.dot(h));
        let d = match &lobe {
            Some(lobe) => lobe.d(h),
            None => ggx_d(n.dot(h).max(0.0), alpha),
        };
        let spec = fr * (d * smith_visibility(n_dot_l, n_dot_v, alpha));
        out += ((Vec3::ONE - fr) * diffuse + spec * n_dot_l) * e;
    }
    out
}

/// The steepest slope LEAN stores (`n_z` at least `1 / sqrt(1 + 16^2)`, 86 degrees from the
/// surface normal): grazing map normals would make the moments explode.
pub const LEAN_MAX_SLOPE: f32 = 16.0;

/// The LEAN moment map of a tangent-space normal map (Olano & Baker 2010): the moments of
/// `b = (n_x, n_y) / n_z` for each level-0 texel's normal `n = normalize(2 rgb - 1)` (slopes
/// clamped to [`LEAN_MAX_SLOPE`]).
///
/// # Errors
/// The size errors of `Texture::from_fn` for a float texture of the map's size.
pub fn lean_map(
    normal_map: &Texture,
    limits: &texel_texture::Limits,
) -> Result<MomentMap, texel_texture::TextureError> {
    let (w, h) = (normal_map.width(), normal_map.height());
    MomentMap::from_slopes(w, h, limits, |i, j| {
        let c = normal_map.texel(0, i, j).unwrap_or([0.5, 0.5, 1.0, 1.0]);
        let n = (Vec3::new(c[0], c[1], c[2]) * 2.0 - Vec3::ONE).normalize_or(Vec3::Z);
        let z =
            n.z.max(1.0 / (1.0 + LEAN_MAX_SLOPE * LEAN_MAX_SLOPE).sqrt());
        (n.truncate() / z).clamp_length_max(LEAN_MAX_SLOPE)
    })
}

/// LEAN's tangent-space normal (unit) and widened roughness for base `roughness`, from the mean
/// slope and slope covariance [`lean_mean_covariance`] gives. See [`SpecularAa::Lean`].
pub fn lean_normal_roughness(mean: glam::Vec2, cov: [f32; 3], roughness: f32) -> (Vec3, f32) {
    (
        mean.extend(1.0).normalize(),
        slope_variance_roughness(roughness, cov[0], cov[1]),
    )
}

/// LEAN's mean slope and slope covariance `[xx, yy, xy]` from the filtered moments
/// `[b_x, b_y, b_x^2, b_y^2, b_x b_y]` of a normal map scaled by `scale` (variances below 0,
/// from rounding, are 0).
pub fn lean_mean_covariance(moments: [f32; 5], scale: f32) -> (glam::Vec2, [f32; 3]) {
    let b = glam::Vec2::new(moments[0], moments[1]) * scale;
    let s2 = scale * scale;
    let var_x = (moments[2] * s2 - b.x * b.x).max(0.0);
    let var_y = (moments[3] * s2 - b.y * b.y).max(0.0);
    (b, [var_x, var_y, moments[4] * s2 - b.x * b.y])
}

/// The perceptual roughness whose lobe also covers normals with slope variances `var_x` and
/// `var_y` along two orthogonal directions: `alpha'^2 = alpha^2 + 2 sigma^2` with `sigma^2` their
/// mean (negative variances, from rounding, count as 0). See [`SpecularAa::Lean`].
pub fn slope_variance_roughness(roughness: f32, var_x: f32, var_y: f32) -> f32 {
    let sigma2 = (0.5 * (var_x + var_y)).max(0.0);
    let alpha = roughness.clamp(MIN_ROUGHNESS, 1.0).powi(2);
    let alpha2 = (alpha * alpha + 2.0 * sigma2).min(1.0);
    alpha2.sqrt().sqrt()
}

/// The variance of the pixel filter in projected-space NDF filtering, `1 / (2 pi)`.
pub const PROJECTED_SIGMA2: f32 = 0.159_154_94;

/// The clamp of the kernel's `alpha^2` in projected-space NDF filtering (the paper's `kappa`).
pub const PROJECTED_KAPPA: f32 = 0.18;

/// Projected-space NDF filtering's roughness for `roughness` and the screen-space differences
/// `dn_dx`, `dn_dy` of the unit shading normal (see [`SpecularAa::Projected`]).
pub fn projected_roughness(roughness: f32, dn_dx: Vec3, dn_dy: Vec3) -> f32 {
    let kernel = PROJECTED_SIGMA2 * (dn_dx.length_squared() + dn_dy.length_squared());
    let alpha = roughness.clamp(MIN_ROUGHNESS, 1.0).powi(2);
    let alpha2 = (alpha * alpha + kernel.min(PROJECTED_KAPPA)).min(1.0);
    alpha2.sqrt().sqrt()
}

/// The slope moment map of a height map (one channel, `channel`): the moments of `g`, the
/// height's gradient per unit of `u` and `v` from forward differences between level-0 texels
/// (wrapping at the edges, as height maps tile): `g_u = (h(i + 1, j) - h(i, j)) w`,
/// `g_v = (h(i, j + 1) - h(i, j)) h_px`. Averaged over a footprint they give the covariance of
/// the gradient under it, which [`SpecularAa::Lean`] turns into roughness after scaling by
/// `height_scale` and the surface's size per unit of `u` and `v`.
///
/// # Errors
/// The size errors of `Texture::from_fn` for a float texture of the map's size.
pub fn height_moments(
    height_map: &Texture,
    channel: usize,
    limits: &texel_texture::Limits,
) -> Result<MomentMap, texel_texture::TextureError> {
    let (w, h) = (height_map.width(), height_map.height());
    let at = |i: u32, j: u32| {
        height_map
            .texel(0, i % w, j % h)
            .map_or(0.0, |t| t[channel.min(3)])
    };
    MomentMap::from_slopes(w, h, limits, |i, j| {
        let h0 = at(i, j);
        glam::Vec2::new(
            (at(i + 1, j) - h0) * w as f32,
            (at(i, j + 1) - h0) * h as f32,
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f32::consts::PI;

    /// `integral over the hemisphere of D(n.h) (n.h) dw = 1`, by the midpoint rule in theta.
    #[test]
    fn ggx_is_normalised() {
        for alpha in [0.05f32, 0.2, 0.5, 1.0] {
            let n = 200_000;
            let mut sum = 0.0f64;
            for k in 0..n {
                let theta = (k as f64 + 0.5) / n as f64 * std::f64::consts::FRAC_PI_2;
                let c = theta.cos() as f32;
                sum += f64::from(ggx_d(c, alpha))
                    * f64::from(c)
                    * theta.sin()
                    * 2.0
                    * std::f64::consts::PI
                    * (std::f64::consts::FRAC_PI_2 / n as f64);
            }
            assert!((sum - 1.0).abs() < 2e-3, "alpha {alpha}: {sum}");
        }
    }

    #[test]
    fn smith_and_fresnel_limits() {
        // alpha = 1, n.l = n.v = 1: V = 0.5 / (1 + 1) = 0.25 (G = 1 over 4).
        assert!((smith_visibility(1.0, 1.0, 1.0) - 0.25).abs() < 1e-6);
        // Symmetric in l and v.
        assert_eq!(
            smith_visibility(0.3, 0.8, 0.4),
            smith_visibility(0.8, 0.3, 0.4)
        );
        let f0 = Vec3::new(0.04, 0.5, 1.0);
        assert!((fresnel(f0, 1.0) - f0).length() < 1e-6);
        assert!((fresnel(f0, 0.0) - Vec3::ONE).length() < 1e-6);
    }

    #[test]
    fn lambert_white_under_pi_is_one_and_point_lights_fall_off() {
        let s = Surface {
            base: Vec3::ONE,
            roughness: 1.0,
            metallic: 0.0,
            normal: Vec3::Y,
            diffuse_normal: Vec3::Y,
            position: Vec3::ZERO,
            occlusion: 1.0,
            spread: None,
        };
        let sun = [Light::Directional {
            direction: Vec3::Y,
            intensity: Vec3::splat(PI),
        }];
        let l = radiance(&s, Vec3::new(0.0, 5.0, 5.0), &sun, true);
        assert!((l - Vec3::ONE).length() < 1e-5, "{l}");
        // 60 degrees: half. Ambient adds c.
        let tilted = [
            Light::Directional {
                direction: Vec3::new(3f32.sqrt(), 1.0, 0.0),
                intensity: Vec3::splat(PI),
            },
            Light::Ambient {
                intensity: Vec3::splat(0.25),
            },
        ];
        let l = radiance(&s, Vec3::Y, &tilted, true);
        assert!((l - Vec3::splat(0.75)).length() < 1e-5, "{l}");
        // A point light at distance 2 gives a quarter of its intensity.
        let point = [Light::Point {
            position: Vec3::new(0.0, 2.0, 0.0),
            intensity: Vec3::splat(4.0 * PI),
        }];
        let l = radiance(&s, Vec3::Y, &point, true);
        assert!((l - Vec3::ONE).length() < 1e-5, "{l}");
        // Lights behind the surface give nothing.
        let below = [Light::Directional {
            direction: -Vec3::Y,
            intensity: Vec3::splat(PI),
        }];
        assert_eq!(radiance(&s, Vec3::Y, &below, false), Vec3::ZERO);
    }

    /// The full model's energy stays below the incoming light's (white furnace, one direction):
    /// directional-hemispherical reflectance of a white rough dielectric under uniform light is at
    /// most 1, estimated by integrating over light directions.
    #[test]
    fn a_white_surface_reflects_at_most_what_arrives() {
        for (roughness, metallic) in [(0.1f32, 0.0f32), (0.5, 0.0), (1.0, 0.0), (0.3, 1.0)] {
            let s = Surface {
                base: Vec3::ONE,
                roughness,
                metallic,
                normal: Vec3::Z,
                diffuse_normal: Vec3::Z,
                position: Vec3::ZERO,
                occlusion: 1.0,
                spread: None,
            };
            let eye = Vec3::new(0.5, 0.0, 1.0) * 10.0;
            let (nt, np) = (400, 400);
            let mut sum = 0.0f64;
            for i in 0..nt {
                let theta = (i as f32 + 0.5) / nt as f32 * PI / 2.0;
                for j in 0..np {
                    let phi = (j as f32 + 0.5) / np as f32 * 2.0 * PI;
                    let l = Vec3::new(
                        theta.sin() * phi.cos(),
                        theta.sin() * phi.sin(),
                        theta.cos(),
                    );
                    // Radiance 1 from direction l over solid angle dw: E = dw.
                    let dw = theta.sin() * (PI / 2.0 / nt as f32) * (2.0 * PI / np as f32);
                    let light = [Light::Directional {
                        direction: l,
                        intensity: Vec3::splat(dw),
                    }];
                    sum += f64::from(radiance(&s, eye, &light, false).x);
                }
            }
            assert!(
                sum <= 1.0 + 1e-3 && sum > 0.5,
                "r {roughness} m {metallic}: {sum}"
            );
        }
    }

    #[test]
    fn lean_moments_give_the_mean_normal_and_the_slope_variance() {
        // One flat texel: the normal is z and nothing widens.
        let lean = |m: [f32; 5], scale: f32, r: f32| {
            let (mean, cov) = lean_mean_covariance(m, scale);
            lean_normal_roughness(mean, cov, r)
        };
        let flat = lean([0.0; 5], 1.0, 0.3);
        assert!((flat.0 - Vec3::Z).length() < 1e-6 && (flat.1 - 0.3).abs() < 1e-6);
        // Two slopes (+0.5, 0) and (-0.5, 0) averaged: mean 0, variance 0.25 along x, 0 along y:
        // sigma^2 = 0.125, alpha'^2 = alpha^2 + 0.25.
        let (n, r) = lean([0.0, 0.0, 0.25, 0.0, 0.0], 1.0, 0.3);
        assert!((n - Vec3::Z).length() < 1e-6);
        let want = (0.3f32.powi(4) + 0.25).sqrt().sqrt();
        assert!((r - want).abs() < 1e-6, "{r} vs {want}");
        // A constant slope (0.5, 0.25): the normal tilts, no variance. Scale 2 doubles the slope.
        let m = [0.5, 0.25, 0.25, 0.0625, 0.125];
        let (n, r) = lean(m, 2.0, 0.3);
        assert!(
            (n - Vec3::new(1.0, 0.5, 1.0).normalize()).length() < 1e-6,
            "{n}"
        );
        assert!((r - 0.3).abs() < 1e-5, "{r}");
        let (mean, cov) = lean_mean_covariance(m, 2.0);
        assert_eq!(mean, glam::Vec2::new(1.0, 0.5));
        assert!(cov.iter().all(|c| c.abs() < 1e-6), "{cov:?}");
        // Slopes (0.5, 0.5) and (-0.5, -0.5): the variance lies along the diagonal, which only
        // the cross moment tells from (0.5, -0.5) and (-0.5, 0.5).
        let (_, cov) = lean_mean_covariance([0.0, 0.0, 0.25, 0.25, 0.25], 1.0);
        assert_eq!(cov, [0.25, 0.25, 0.25]);
        let (_, cov) = lean_mean_covariance([0.0, 0.0, 0.25, 0.25, -0.25], 1.0);
        assert_eq!(cov, [0.25, 0.25, -0.25]);
    }

    #[test]
    fn the_lean_map_holds_the_slope_moments_and_its_pyramid_their_covariance() {
        let normals = [
            Vec3::new(0.3, -0.2, 0.9),
            Vec3::new(-0.4, 0.1, 0.8),
            Vec3::new(0.1, 0.5, 0.85),
            Vec3::new(0.0, 0.0, 1.0),
        ]
        .map(Vec3::normalize);
        let code = |c: f32| ((c + 1.0) / 2.0 * 255.0).round() as u8;
        let t = Texture::from_rgba8(
            2,
            2,
            normals
                .iter()
                .map(|n| [code(n.x), code(n.y), code(n.z), 255])
                .collect(),
            texel_texture::ColorSpace::Linear,
            &texel_texture::Limits::default(),
        )
        .unwrap();
        let a = lean_map(&t, &texel_texture::Limits::default()).unwrap();
        let slope = |k: usize| {
            let (i, j) = (k as u32 % 2, k as u32 / 2);
            let c = t.texel(0, i, j).unwrap();
            let d = (Vec3::new(c[0], c[1], c[2]) * 2.0 - Vec3::ONE).normalize();
            glam::Vec2::new(d.x / d.z, d.y / d.z)
        };
        let moments = |level: usize, i: u32, j: u32| {
            let m = a.moments.texel(level, i, j).unwrap();
            let c = a.cross.texel(level, i, j).unwrap();
            [m[0], m[1], m[2], m[3], c[0]]
        };
        for k in 0..4 {
            let b = slope(k);
            let got = moments(0, k as u32 % 2, k as u32 / 2);
            for (g, w) in got.iter().zip([b.x, b.y, b.x * b.x, b.y * b.y, b.x * b.y]) {
                assert!((g - w).abs() < 1e-6, "{k}: {got:?}");
            }
        }
        // Level 1 averages the four texels: its moments give their mean and covariance exactly.
        let (mean, cov) = lean_mean_covariance(moments(1, 0, 0), 1.0);
        let bs: Vec<glam::Vec2> = (0..4).map(slope).collect();
        let want_mean = bs.iter().copied().sum::<glam::Vec2>() / 4.0;
        let d: Vec<glam::Vec2> = bs.iter().map(|b| *b - want_mean).collect();
        let want = [
            d.iter().map(|d| d.x * d.x).sum::<f32>() / 4.0,
            d.iter().map(|d| d.y * d.y).sum::<f32>() / 4.0,
            d.iter().map(|d| d.x * d.y).sum::<f32>() / 4.0,
        ];
        assert!((mean - want_mean).length() < 1e-6, "{mean} vs {want_mean}");
        for (g, w) in cov.iter().zip(want) {
            assert!((g - w).abs() < 1e-5, "{cov:?} vs {want:?}");
        }
        assert!(want[2].abs() > 0.01, "the cross term is exercised");
    }

    #[test]
    fn toksvig_widens_only_short_normals() {
        assert!((toksvig_roughness(0.3, 1.0) - 0.3).abs() < 1e-4);
        let mut last = 0.3;
        for len in [0.99f32, 0.95, 0.8, 0.5] {
            let r = toksvig_roughness(0.3, len);
            assert!(r > last && r <= 1.0, "{len}: {r}");
            last = r;
        }
        // Check one value against the formula by hand: r = 0.5, |n| = 0.9.
        let s = 2.0 / 0.5f32.powi(4) - 2.0; // 30
        let s2 = s * 0.9 / (0.9 + s * 0.1); // 6.75
        let want = (2.0 / (s2 + 2.0)).powf(0.25);
        assert!((toksvig_roughness(0.5, 0.9) - want).abs() < 1e-5);
    }

    #[test]
    fn projected_filtering_follows_eq_14() {
        // No change across the pixel: unchanged.
        assert!((projected_roughness(0.3, Vec3::ZERO, Vec3::ZERO) - 0.3).abs() < 1e-6);
        // |dn/dx|^2 + |dn/dy|^2 = 0.5: kernel alpha^2 = 0.5 / (2 pi).
        let (dx, dy) = (Vec3::new(0.5, 0.0, 0.0), Vec3::new(0.0, 0.5, 0.0));
        let want = (0.3f32.powi(4) + 0.5 / (2.0 * PI)).powf(0.25);
        assert!((projected_roughness(0.3, dx, dy) - want).abs() < 1e-6);
        // Large changes clamp at kappa.
        let big = Vec3::new(2.0, 0.0, 0.0);
        let want = (0.3f32.powi(4) + PROJECTED_KAPPA).powf(0.25);
        assert!((projected_roughness(0.3, big, big) - want).abs() < 1e-6);
    }

    #[test]
    fn height_moments_hold_forward_differences_and_their_products() {
        let limits = texel_texture::Limits::default();
        // h = (i^2 + 3 j) / 64 over 8 x 4 texels.
        let t = Texture::from_fn(8, 4, texel_texture::Format::Rgba32Float, &limits, |i, j| {
            let h = (i * i + 3 * j) as f32 / 64.0;
            [h, 0.0, 0.0, 1.0]
        })
        .unwrap();
        let m = height_moments(&t, 0, &limits).unwrap();
        let got = m.moments.texel(0, 2, 1).unwrap();
        let gu = (9.0 - 4.0) / 64.0 * 8.0;
        let gv = 3.0 / 64.0 * 4.0;
        assert_eq!(got, [gu, gv, gu * gu, gv * gv]);
        assert_eq!(m.cross.texel(0, 2, 1).unwrap()[0], gu * gv);
        // The last column wraps to the first.
        let got = m.moments.texel(0, 7, 0).unwrap();
        assert_eq!(got[0], (0.0 - 49.0 / 64.0) * 8.0);
    }

    /// `int D(h) (h.n) dw` over the hemisphere, by the midpoint rule in `(theta, phi)`.
    fn projected_integral(d: impl Fn(Vec3) -> f32) -> f64 {
        let (nt, np) = (2000, 256);
        let mut sum = 0.0f64;
        for i in 0..nt {
            let theta = (i as f64 + 0.5) / nt as f64 * std::f64::consts::FRAC_PI_2;
            for j in 0..np {
                let phi = (j as f64 + 0.5) / np as f64 * std::f64::consts::TAU;
                let h = Vec3::new(
                    (theta.sin() * phi.cos()) as f32,
                    (theta.sin() * phi.sin()) as f32,
                    theta.cos() as f32,
                );
                let dw = theta.sin()
                    * (std::f64::consts::FRAC_PI_2 / nt as f64)
                    * (std::f64::consts::TAU / np as f64);
                sum += f64::from(d(h)) * theta.cos() * dw;
            }
        }
        sum
    }

    fn spread(cov: [f32; 3], mean: glam::Vec2, base: f32) -> SlopeSpread {
        SlopeSpread {
            frame: [Vec3::X, Vec3::Y, Vec3::Z],
            mean,
            cov,
            base_roughness: base,
        }
    }

    #[test]
    fn the_spread_lobe_is_ggx_without_spread_and_normalised_with_it() {
        // No spread: the material's own GGX lobe about the mean slope's normal, exactly.
        let s = spread([0.0; 3], glam::Vec2::new(0.2, -0.1), 0.4);
        let n = Vec3::new(0.2, -0.1, 1.0).normalize();
        for h in [Vec3::Z, Vec3::new(0.3, 0.1, 1.0), Vec3::new(-0.5, 0.4, 0.6)] {
            let h = h.normalize();
            assert_eq!(s.d(h, 0.16), ggx_d(n.dot(h), 0.16));
        }
        // With spread (anisotropic, correlated), both parts keep unit projected area.
        for (cov, base) in [
            ([0.02f32, 0.005, 0.004], 0.3f32),
            ([0.09, 0.09, 0.0], 0.25),
            ([0.01, 0.04, -0.015], 0.5),
        ] {
            let s = spread(cov, glam::Vec2::ZERO, base);
            let a0 = base * base;
            let alpha = (a0 * a0 + cov[0] + cov[1]).sqrt();
            let total = projected_integral(|h| s.d(h, alpha));
            assert!((total - 1.0).abs() < 5e-3, "{cov:?}: {total}");
        }
    }

    #[test]
    fn a_wide_spread_is_the_slopes_gaussian_with_the_base_lobes_tail() {
        let base = 0.2f32;
        let a0 = base * base;
        let cov = [0.09f32, 0.04, 0.02];
        let alpha = (a0 * a0 + cov[0] + cov[1]).sqrt();
        let s = spread(cov, glam::Vec2::ZERO, base);
        // Near the mean: the bivariate Gaussian of covariance cov + a0^2 / 2, over cos^4.
        let (sxx, syy, sxy) = (cov[0] + a0 * a0 / 2.0, cov[1] + a0 * a0 / 2.0, cov[2]);
        let det = sxx * syy - sxy * sxy;
        for m in [
            glam::Vec2::ZERO,
            glam::Vec2::new(0.2, 0.1),
            glam::Vec2::new(-0.1, 0.3),
        ] {
            let h = m.extend(1.0).normalize();
            let q = (syy * m.x * m.x - 2.0 * sxy * m.x * m.y + sxx * m.y * m.y) / det;
            let c = h.z;
            let gauss = (-0.5 * q).exp() / (std::f32::consts::TAU * det.sqrt()) / c.powi(4);
            let got = s.d(h, alpha);
            assert!((got / gauss - 1.0).abs() < 0.01, "{m}: {got} vs {gauss}");
        }
        // Far out (|m| = 12): the base lobe's tail a0^2 / (pi |m|^4), not the widened GGX's.
        let m = glam::Vec2::new(12.0, 0.0);
        let h = m.extend(1.0).normalize();
        let tail = a0 * a0 / (std::f32::consts::PI * m.length().powi(4)) / h.z.powi(4);
        let got = s.d(h, alpha);
        assert!((got / tail - 1.0).abs() < 0.05, "{got} vs {tail}");
        assert!(
            ggx_d(h.z, alpha) > 10.0 * tail,
            "the widened GGX alone is far brighter"
        );
    }

    #[test]
    fn the_clamped_cosine_is_the_mean_of_a_clamped_gaussian() {
        assert!((erf(0.5) - 0.520_499_9).abs() < 1e-6);
        assert!((erf(1.0) - 0.842_700_8).abs() < 1e-6);
        assert!((erf(-2.0) + 0.995_322_3).abs() < 1e-6);
        let s = spread([0.04, 0.01, 0.01], glam::Vec2::ZERO, 0.3);
        let l = Vec3::new(0.6, 0.3, 0.2).normalize();
        // n.l's variance to first order: l_t^T cov l_t.
        let var = 0.04 * l.x * l.x + 0.01 * l.y * l.y + 2.0 * 0.01 * l.x * l.y;
        for mean in [-0.3f32, -0.05, 0.0, 0.1, 0.5] {
            // E[max(0, X)], X ~ N(mean, var), by the midpoint rule over +-8 sd.
            let sd = var.sqrt() as f64;
            let k = 20_000;
            let mut want = 0.0f64;
            for i in 0..k {
                let z = -8.0 + 16.0 * (i as f64 + 0.5) / k as f64;
                let x = f64::from(mean) + sd * z;
                want += x.max(0.0) * (-0.5 * z * z).exp() / (std::f64::consts::TAU).sqrt()
                    * (16.0 / k as f64);
            }
            let got = f64::from(s.clamped_cosine(mean, l));
            assert!((got - want).abs() < 1e-5, "{mean}: {got} vs {want}");
        }
        // No spread: the plain clamped cosine.
        let flat = spread([0.0; 3], glam::Vec2::ZERO, 0.3);
        assert_eq!(flat.clamped_cosine(0.4, l), 0.4);
        assert_eq!(flat.clamped_cosine(-0.4, l), 0.0);
    }
}
