//! The scene's environment map (`[environment]`): an equirectangular image from a file (PNG,
//! JPEG, OpenEXR or Radiance HDR) or the built-in procedural sky, with an intensity and whether
//! it is seen as the background.
//!
//! The procedural sky ([`Sky`]) is what tests and the demo light with (nothing is downloaded):
//! - above the horizon a gradient from a pale horizon to a blue zenith, with clouds: four
//!   octaves of value noise on a cloud layer 1 unit above the eye (so they crowd together
//!   towards the horizon, as real clouds do), thresholded softly;
//! - a sun disc of angular radius [`SUN_RADIUS`] radians and radiance [`SUN_RADIANCE`];
//! - below the horizon a ground plane 1 unit below the eye in checks of 1 unit, two browns,
//!   fading to the horizon colour over the last few degrees (haze).
//!
//! Each texel is the mean of 3 x 3 stratified directions inside it, so the map's own level 0 is
//! not aliased. Directions follow DESIGN.md's equirectangular convention (`v = 0` up, the
//! centre column looks along `-z`).

use std::f64::consts::PI;
use std::path::PathBuf;

use glam::{DVec3, Vec3};
use texel_texture::{ColorSpace, Limits, Texture};

use crate::error::SceneError;

/// The sun's angular radius in radians (about 1.15 degrees, four times the real sun's, so that a
/// 1024-wide map resolves it over several texels).
pub const SUN_RADIUS: f64 = 0.02;

/// The sun disc's radiance (linear, per channel, times the sky's warm tint).
pub const SUN_RADIANCE: f64 = 30.0;

/// The largest sky width (its height is half).
pub const MAX_SKY_WIDTH: u32 = 8192;

/// The scene's environment (`[environment]`).
#[derive(Clone, Debug, PartialEq)]
pub struct EnvironmentSpec {
    /// Where the map comes from.
    pub source: EnvironmentSource,
    /// Linear RGB scale of the map's radiance (finite, not negative; default 1).
    pub intensity: Vec3,
    /// Whether pixels no mesh covers show the environment (default true); otherwise they show
    /// `output.background`, and the environment only lights and is reflected.
    pub background: bool,
}

/// Where an environment map comes from.
#[derive(Clone, Debug, PartialEq)]
pub enum EnvironmentSource {
    /// `path = "file"` (relative to the scene file): an equirectangular image. 8-bit images are
    /// decoded as sRGB; float images (EXR, HDR) are linear.
    File(PathBuf),
    /// `procedural = "sky"`.
    Sky(Sky),
}

/// The procedural sky's parameters (module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sky {
    /// Width in texels, `2..=MAX_SKY_WIDTH` (`size`, default 1024); the height is half.
    pub width: u32,
    /// Direction towards the sun (`sun`, any length but 0; default `[-0.5, 0.7, -0.5]`).
    pub sun: Vec3,
    /// Seed of the clouds' noise (`seed`, default 0).
    pub seed: u32,
}

impl Default for Sky {
    fn default() -> Self {
        Sky {
            width: 1024,
            sun: Vec3::new(-0.5, 0.7, -0.5),
            seed: 0,
        }
    }
}

/// A hash of integer lattice point `(x, y)` and `seed` to `[0, 1)`.
fn lattice(x: i64, y: i64, seed: u32) -> f64 {
    let mut h = (x as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15)
        ^ (y as u64).wrapping_mul(0xC2B2_AE3D_27D4_EB4F)
        ^ u64::from(seed).wrapping_mul(0x1656_67B1_9E37_79F9);
    h ^= h >> 31;
    h = h.wrapping_mul(0xBF58_476D_1CE4_E5B9);
    h ^= h >> 29;
    (h >> 11) as f64 / (1u64 << 53) as f64
}

/// Smoothly interpolated value noise at `(x, y)`, in `[0, 1)`.
fn value_noise(x: f64, y: f64, seed: u32) -> f64 {
    let (x0, y0) = (x.floor(), y.floor());
    let (fx, fy) = (x - x0, y - y0);
    let s = |t: f64| t * t * (3.0 - 2.0 * t);
    let (sx, sy) = (s(fx), s(fy));
    let (i, j) = (x0 as i64, y0 as i64);
    let a = lattice(i, j, seed) + (lattice(i + 1, j, seed) - lattice(i, j, seed)) * sx;
    let b = lattice(i, j + 1, seed) + (lattice(i + 1, j + 1, seed) - lattice(i, j + 1, seed)) * sx;
    a + (b - a) * sy
}

impl Sky {
    /// The sky's radiance (linear RGB) along unit direction `d`.
    pub fn radiance(&self, d: DVec3) -> DVec3 {
        let horizon = DVec3::new(0.85, 0.9, 1.0);
        let zenith = DVec3::new(0.18, 0.35, 0.85);
        let sun = self.sun.as_dvec3().normalize_or(DVec3::Y);
        if d.y >= 0.0 {
            let sky = horizon.lerp(zenith, d.y.sqrt());
            // Clouds on a layer one unit up: (x, z) / y, so they crowd towards the horizon.
            let (cx, cz) = (d.x / (d.y + 0.02), d.z / (d.y + 0.02));
            let n = (0..4)
                .map(|o| {
                    let f = f64::from(1u32 << o) * 3.0;
                    value_noise(cx * f, cz * f, self.seed.wrapping_add(o)) / f64::from(1u32 << o)
                })
                .sum::<f64>()
                / 1.875;
            let cover = ((n - 0.5) / 0.15).clamp(0.0, 1.0);
            let mut c = sky.lerp(DVec3::splat(1.1), cover);
            let angle = d.dot(sun).clamp(-1.0, 1.0).acos();
            if angle < SUN_RADIUS {
                c = DVec3::new(1.0, 0.95, 0.85) * SUN_RADIANCE;
            }
            c
        } else {
            // The ground one unit down, in checks of one unit, hazy towards the horizon.
            let (gx, gz) = (d.x / -d.y, d.z / -d.y);
            let dark = (gx.floor() as i64 + gz.floor() as i64).rem_euclid(2) == 0;
            let ground = if dark {
                DVec3::new(0.12, 0.1, 0.08)
            } else {
                DVec3::new(0.4, 0.34, 0.26)
            };
            let haze = (-(-d.y) * 12.0).exp();
            ground.lerp(horizon, haze)
        }
    }

    /// The map's texels, `width x width / 2`, row-major, linear RGBA (module docs).
    pub fn texels(&self) -> Vec<[f32; 4]> {
        let (w, h) = (self.width, (self.width / 2).max(1));
        let mut out = Vec::with_capacity(w as usize * h as usize);
        for j in 0..h {
            for i in 0..w {
                let mut sum = DVec3::ZERO;
                for s in 0..9 {
                    let u = (f64::from(i) + (f64::from(s % 3) + 0.5) / 3.0) / f64::from(w);
                    let v = (f64::from(j) + (f64::from(s / 3) + 0.5) / 3.0) / f64::from(h);
                    let (theta, phi) = (PI * v, 2.0 * PI * (u - 0.5));
                    let st = theta.sin();
                    let d = DVec3::new(st * phi.sin(), theta.cos(), -st * phi.cos());
                    sum += self.radiance(d);
                }
                let c = sum / 9.0;
                out.push([c.x as f32, c.y as f32, c.z as f32, 1.0]);
            }
        }
        out
    }
}

impl EnvironmentSpec {
    /// The map as a texture (with its box pyramid) within `limits`.
    ///
    /// # Errors
    /// [`SceneError::Texture`] (named `environment`) when the file cannot be read or decoded, or
    /// the map does not fit `limits`.
    pub fn load(&self, limits: &Limits) -> Result<Texture, SceneError> {
        let err = |path: Option<PathBuf>| {
            move |source| SceneError::Texture {
                name: "environment".into(),
                path,
                source,
            }
        };
        match &self.source {
            EnvironmentSource::File(path) => {
                Texture::load(path, ColorSpace::Srgb, limits).map_err(err(Some(path.clone())))
            }
            EnvironmentSource::Sky(sky) => {
                let (w, h) = (sky.width, (sky.width / 2).max(1));
                limits
                    .check(w, h, texel_texture::Format::Rgba32Float)
                    .map_err(err(None))?;
                Texture::from_rgba32f(w, h, sky.texels(), limits).map_err(err(None))
            }
        }
    }

    /// Check the numbers: a finite, non-negative intensity; a sky of a valid width and a non-zero,
    /// finite sun direction.
    ///
    /// # Errors
    /// [`SceneError::Environment`] saying what is wrong.
    pub fn validate(&self) -> Result<(), SceneError> {
        let bad = |s: String| Err(SceneError::Environment(s));
        if !self.intensity.is_finite() || self.intensity.min_element() < 0.0 {
            return bad(format!(
                "intensity {:?} must be finite and not negative",
                self.intensity.to_array()
            ));
        }
        if let EnvironmentSource::Sky(sky) = &self.source {
            if !(2..=MAX_SKY_WIDTH).contains(&sky.width) {
                return bad(format!(
                    "size {} is out of range: the sky is 2 to {MAX_SKY_WIDTH} texels wide",
                    sky.width
                ));
            }
            if !sky.sun.is_finite() || sky.sun.length() == 0.0 {
                return bad(format!(
                    "sun {:?} must be a finite, non-zero direction (towards the sun)",
                    sky.sun.to_array()
                ));
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_sky_has_its_sun_ground_and_gradient() {
        let sky = Sky::default();
        let sun = sky.sun.as_dvec3().normalize();
        assert!(sky.radiance(sun).x > 20.0);
        // Straight down is a check of ground; straight up is the zenith's blue (or cloud).
        let down = sky.radiance(DVec3::NEG_Y);
        assert!(down.x < 0.45 && down.z < 0.3, "{down}");
        let up = sky.radiance(DVec3::Y);
        assert!(up.z >= up.x, "{up}");
        // The checks alternate along the ground.
        let a = sky.radiance(DVec3::new(0.5, -1.0, 0.5).normalize());
        let b = sky.radiance(DVec3::new(1.5, -1.0, 0.5).normalize());
        assert!((a - b).length() > 0.2, "{a} {b}");
        let texels = Sky { width: 64, ..sky }.texels();
        assert_eq!(texels.len(), 64 * 32);
        assert!(texels
            .iter()
            .all(|t| t.iter().all(|c| c.is_finite() && *c >= 0.0)));
    }

    #[test]
    fn validation_refuses_bad_numbers() {
        let ok = EnvironmentSpec {
            source: EnvironmentSource::Sky(Sky::default()),
            intensity: Vec3::ONE,
            background: true,
        };
        assert!(ok.validate().is_ok());
        let with = |f: &dyn Fn(&mut EnvironmentSpec)| {
            let mut e = ok.clone();
            f(&mut e);
            e.validate().unwrap_err().to_string()
        };
        assert!(with(&|e| e.intensity = Vec3::splat(f32::NAN)).contains("intensity"));
        assert!(with(&|e| e.intensity = Vec3::new(1.0, -1.0, 1.0)).contains("negative"));
        let sky = |s: Sky| move |e: &mut EnvironmentSpec| e.source = EnvironmentSource::Sky(s);
        let zero_sun = Sky {
            sun: Vec3::ZERO,
            ..Sky::default()
        };
        assert!(with(&sky(zero_sun)).contains("sun"));
        let huge = Sky {
            width: MAX_SKY_WIDTH + 1,
            ..Sky::default()
        };
        assert!(with(&sky(huge)).contains("size"));
    }
}
