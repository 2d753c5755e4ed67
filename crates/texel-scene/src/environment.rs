//! The scene's environment map (`[environment]`): an equirectangular, cube or octahedral map
//! ([`Mapping`]) from image files (PNG, JPEG, OpenEXR or Radiance HDR) or the built-in procedural
//! sky, with an intensity and whether it is seen as the background.
//!
//! A cube map comes as six files (`faces`, in Vulkan's layer order `+x, -x, +y, -y, +z, -z`, each
//! oriented as Vulkan's face table says, [`texel_texture::mapping::sphere`]) or as one cross image
//! ([`CubeCross`]): a horizontal cross 4 faces wide and 3 high (`+y` above `+z`; `-x, +z, +x, -z`
//! left to right; `-y` below `+z`), or a vertical cross 3 wide and 4 high (the same, with `-z`
//! below `-y`, turned 180 degrees so that its edge meets `-y`'s). Both layouts unfold the cube
//! without a cut between neighbours in a row or column.
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
//! not aliased. The sky can be made in any mapping (`size` is then an equirect map's width, or a
//! cube face's or the octahedral square's side), so the three can be compared on one scene.

use std::path::PathBuf;

use glam::{DVec2, DVec3, Vec3};
use texel_texture::mapping::sphere::Mapping;
use texel_texture::{ColorSpace, Format, Limits, Texture};

use crate::error::SceneError;

/// The sun's angular radius in radians (about 1.15 degrees, four times the real sun's, so that a
/// 1024-wide map resolves it over several texels).
pub(crate) const SUN_RADIUS: f64 = 0.02;

/// The sun disc's radiance (linear, per channel, times the sky's warm tint).
pub(crate) const SUN_RADIANCE: f64 = 30.0;

/// The largest sky width (its height is half), face side or square side.
pub const MAX_SKY_WIDTH: u32 = 8192;

/// Most texels (all layers) a procedural sky may have: 2^21, an equirect map of 2048 x 1024. The
/// environment's prefiltered pyramid and irradiance cost time in proportion.
pub const MAX_SKY_TEXELS: u64 = 1 << 21;

/// The largest sky `size` in `mapping` within [`MAX_SKY_TEXELS`] (and [`MAX_SKY_WIDTH`]).
pub fn max_sky_width(mapping: Mapping) -> u32 {
    let sky = |width| Sky {
        width,
        ..Sky::default()
    };
    let texels = |w: u32| {
        let (a, b) = sky(w).layer_size(mapping);
        u64::from(a) * u64::from(b) * mapping.layers() as u64
    };
    let (mut lo, mut hi) = (2u32, MAX_SKY_WIDTH);
    while lo < hi {
        let mid = (lo + hi).div_ceil(2);
        if texels(mid) <= MAX_SKY_TEXELS {
            lo = mid;
        } else {
            hi = mid - 1;
        }
    }
    lo
}

/// The procedural sky's default size per mapping: a 1024-wide equirect map, 256-texel cube faces
/// (a 1024 x 768 cross) and a 512-texel octahedral square, within a factor 1.3 of one another in
/// texel angle (`2 pi / 1024`, `2 / 256`, `sqrt(4 pi) / 512` radians).
pub fn default_sky_size(mapping: Mapping) -> u32 {
    match mapping {
        Mapping::Equirect => 1024,
        Mapping::Cube => 256,
        Mapping::Octahedral => 512,
    }
}

/// The scene's environment (`[environment]`).
#[derive(Clone, Debug, PartialEq)]
pub struct EnvironmentSpec {
    /// How directions map to the image (`mapping`, default `equirect`).
    pub mapping: Mapping,
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
    /// `path = "file"` (relative to the scene file): the equirect or octahedral image, or a cube
    /// map's cross ([`CubeCross`]). 8-bit images are decoded as sRGB; float images (EXR, HDR) are
    /// linear.
    File(PathBuf),
    /// `faces = ["+x", "-x", "+y", "-y", "+z", "-z"]` (files, relative to the scene file): a cube
    /// map's six square faces of one size.
    Faces(Box<[PathBuf; 6]>),
    /// `procedural = "sky"`.
    Sky(Sky),
}

/// The procedural sky's parameters (module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sky {
    /// An equirect map's width (its height is half), a cube face's or the octahedral square's
    /// side, `2..=MAX_SKY_WIDTH` (`size`, default [`default_sky_size`]).
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

    /// The size of each of the sky's layers in `mapping`.
    pub fn layer_size(&self, mapping: Mapping) -> (u32, u32) {
        match mapping {
            Mapping::Equirect => (self.width, (self.width / 2).max(1)),
            Mapping::Cube | Mapping::Octahedral => (self.width, self.width),
        }
    }

    /// The texels of layer `layer` (a cube face `0..6`; else 0) of the sky in `mapping`,
    /// [`Sky::layer_size`], row-major, linear RGBA (module docs).
    pub fn texels(&self, mapping: Mapping, layer: usize) -> Vec<[f32; 4]> {
        let (w, h) = self.layer_size(mapping);
        let mut out = Vec::with_capacity(w as usize * h as usize);
        for j in 0..h {
            for i in 0..w {
                let mut sum = DVec3::ZERO;
                for s in 0..9 {
                    let uv = DVec2::new(
                        (f64::from(i) + (f64::from(s % 3) + 0.5) / 3.0) / f64::from(w),
                        (f64::from(j) + (f64::from(s / 3) + 0.5) / 3.0) / f64::from(h),
                    );
                    sum += self.radiance(mapping.direction(layer, uv));
                }
                let c = sum / 9.0;
                out.push([c.x as f32, c.y as f32, c.z as f32, 1.0]);
            }
        }
        out
    }
}

/// The two cube-map cross layouts (module docs).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CubeCross {
    /// 4 faces wide, 3 high.
    Horizontal,
    /// 3 faces wide, 4 high, `-z` turned 180 degrees.
    Vertical,
}

impl CubeCross {
    /// The layout of a `width x height` image and its face side; `None` unless the image is 4 x 3
    /// or 3 x 4 square faces.
    pub fn of(width: u32, height: u32) -> Option<(CubeCross, u32)> {
        let (w, h) = (u64::from(width), u64::from(height));
        if width > 0 && width.is_multiple_of(4) && 3 * w == 4 * h {
            Some((CubeCross::Horizontal, width / 4))
        } else if width > 0 && width.is_multiple_of(3) && 4 * w == 3 * h {
            Some((CubeCross::Vertical, width / 3))
        } else {
            None
        }
    }

    /// Where face `face` (`+x, -x, +y, -y, +z, -z`) lies: its column and row in faces, and
    /// whether it is turned 180 degrees.
    pub fn cell(self, face: usize) -> (u32, u32, bool) {
        match (self, face) {
            (_, 0) => (2, 1, false),
            (_, 1) => (0, 1, false),
            (_, 2) => (1, 0, false),
            (_, 3) => (1, 2, false),
            (_, 4) => (1, 1, false),
            (CubeCross::Horizontal, _) => (3, 1, false),
            (CubeCross::Vertical, _) => (1, 3, true),
        }
    }

    /// The six faces of `cross` (laid out as `self`, faces of side `n`), each in the cross's
    /// format.
    ///
    /// # Errors
    /// A face does not fit `limits`.
    pub fn split(
        self,
        cross: &Texture,
        n: u32,
        limits: &Limits,
    ) -> Result<Vec<Texture>, texel_texture::TextureError> {
        (0..6)
            .map(|face| {
                let (col, row, turned) = self.cell(face);
                let (x0, y0) = (col * n, row * n);
                Texture::from_fn(n, n, cross.format(), limits, |i, j| {
                    let (i, j) = if turned {
                        (n - 1 - i, n - 1 - j)
                    } else {
                        (i, j)
                    };
                    cross.texel(0, x0 + i, y0 + j).unwrap_or([0.0; 4])
                })
            })
            .collect()
    }
}

impl EnvironmentSpec {
    /// The map's layers (the equirect or octahedral image; a cube map's six faces in the order
    /// `+x, -x, +y, -y, +z, -z`), each with its box pyramid, within `limits`.
    ///
    /// # Errors
    /// [`SceneError::Texture`] (named `environment`) when a file cannot be read or decoded, or
    /// the map does not fit `limits`; [`SceneError::Environment`] when the images do not have
    /// the mapping's shape (a 2:1 equirect map is not required; a square octahedral map, a 4:3
    /// or 3:4 cross, six square faces of one size are).
    pub fn load(&self, limits: &Limits) -> Result<Vec<Texture>, SceneError> {
        self.load_with(limits, false).map(|(faces, _)| faces)
    }

    /// As [`EnvironmentSpec::load`]; with `replace_non_finite`, NaN, infinite and out-of-range texels of the
    /// map's files are replaced ([`texel_texture::replace_non_finite`]) instead of refused, and
    /// their count is returned beside the layers.
    ///
    /// # Errors
    /// As [`EnvironmentSpec::load`].
    pub fn load_with(
        &self,
        limits: &Limits,
        replace_non_finite: bool,
    ) -> Result<(Vec<Texture>, u64), SceneError> {
        let replaced = std::cell::Cell::new(0u64);
        let err = |path: Option<PathBuf>| {
            move |source| SceneError::Texture {
                name: "environment".into(),
                path,
                source,
            }
        };
        let options = texel_texture::LoadOptions {
            replace_non_finite,
            ..texel_texture::LoadOptions::new(ColorSpace::Srgb, *limits)
        };
        let load = |path: &PathBuf| {
            let loaded = Texture::load_with(path, &options).map_err(err(Some(path.clone())))?;
            replaced.set(replaced.get() + loaded.replaced);
            Ok::<_, SceneError>(loaded.texture)
        };
        let bad = |s: String| Err(SceneError::Environment(s));
        let faces = match &self.source {
            EnvironmentSource::File(path) => {
                let image = load(path)?;
                let (w, h) = (image.width(), image.height());
                match self.mapping {
                    Mapping::Equirect => vec![image],
                    Mapping::Octahedral if w == h => vec![image],
                    Mapping::Octahedral => {
                        return bad(format!(
                            "{}: an octahedral map is square, this image is {w}x{h}",
                            path.display()
                        ))
                    }
                    Mapping::Cube => {
                        let Some((cross, n)) = CubeCross::of(w, h) else {
                            return bad(format!(
                                "{}: a cube map in one image is a cross of 4x3 or 3x4 square \
                         faces; this image is {w}x{h} (or give faces = [six files])",
                                path.display()
                            ));
                        };
                        cross
                            .split(&image, n, limits)
                            .map_err(err(Some(path.clone())))?
                    }
                }
            }
            EnvironmentSource::Faces(paths) => {
                let faces = paths.iter().map(load).collect::<Result<Vec<_>, _>>()?;
                let (n, first) = (faces[0].width(), &paths[0]);
                if let Some((p, f)) = paths
                    .iter()
                    .zip(&faces)
                    .find(|(_, f)| f.width() != f.height())
                {
                    return bad(format!(
                        "{}: cube faces are square, but this one is {}x{}",
                        p.display(),
                        f.width(),
                        f.height()
                    ));
                }
                if let Some((p, f)) = paths.iter().zip(&faces).find(|(_, f)| f.width() != n) {
                    return bad(format!(
                        "{}: cube faces are all of one size, {n}x{n} as the first ({}); this \
                         one is {}x{}",
                        p.display(),
                        first.display(),
                        f.width(),
                        f.height()
                    ));
                }
                faces
            }
            EnvironmentSource::Sky(sky) => {
                let (w, h) = sky.layer_size(self.mapping);
                (0..self.mapping.layers())
                    .map(|layer| {
                        limits.check(w, h, Format::Rgba32Float)?;
                        Texture::from_rgba32f(w, h, sky.texels(self.mapping, layer), limits)
                    })
                    .collect::<Result<_, _>>()
                    .map_err(err(None))?
            }
        };
        Ok((faces, replaced.get()))
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
            let max = max_sky_width(self.mapping);
            if sky.width > max {
                let (w, h) = sky.layer_size(self.mapping);
                return bad(format!(
                    "size {} makes a {:?} sky of {} texels ({w}x{h} a layer), over texel's bound \
                     of {MAX_SKY_TEXELS} (its prefiltering takes about 20 s on 2 cores at the \
                     bound): use size {max} or less",
                    sky.width,
                    self.mapping,
                    u64::from(w) * u64::from(h) * self.mapping.layers() as u64
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
        let small = Sky { width: 64, ..sky };
        for (mapping, len) in [
            (Mapping::Equirect, 64 * 32),
            (Mapping::Cube, 64 * 64),
            (Mapping::Octahedral, 64 * 64),
        ] {
            let texels = small.texels(mapping, 5);
            assert_eq!(texels.len(), len);
            assert!(texels
                .iter()
                .all(|t| t.iter().all(|c| c.is_finite() && *c >= 0.0)));
        }
        // The cube's -y face (layer 3) is ground; its +y face (2) is sky.
        let mean = |layer| {
            let t = small.texels(Mapping::Cube, layer);
            t.iter().map(|c| f64::from(c[2])).sum::<f64>() / t.len() as f64
        };
        assert!(mean(2) > 0.5 && mean(3) < 0.4, "{} {}", mean(2), mean(3));
    }

    #[test]
    fn validation_refuses_bad_numbers() {
        let ok = EnvironmentSpec {
            mapping: Mapping::Equirect,
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

#[cfg(test)]
mod cross_tests {
    use super::*;
    use texel_texture::mapping::sphere::cube_direction;

    #[test]
    fn crosses_are_recognised_by_shape_and_split_into_faces() {
        assert_eq!(CubeCross::of(400, 300), Some((CubeCross::Horizontal, 100)));
        assert_eq!(CubeCross::of(300, 400), Some((CubeCross::Vertical, 100)));
        for (w, h) in [(400, 301), (0, 0), (401, 300), (100, 100), (200, 100)] {
            assert_eq!(CubeCross::of(w, h), None, "{w}x{h}");
        }
        // Each cell of a 3x4 cross holds its face's index; -z comes back turned upright.
        let n = 4;
        let cross = Texture::from_fn(
            3 * n,
            4 * n,
            Format::Rgba32Float,
            &Limits::default(),
            |i, j| {
                [
                    (i / n) as f32,
                    (j / n) as f32,
                    (i % n) as f32,
                    (j % n) as f32,
                ]
            },
        )
        .unwrap();
        let faces = CubeCross::Vertical
            .split(&cross, n, &Limits::default())
            .unwrap();
        assert_eq!(faces[4].texel(0, 1, 2).unwrap(), [1.0, 1.0, 1.0, 2.0]);
        assert_eq!(faces[0].texel(0, 0, 0).unwrap(), [2.0, 1.0, 0.0, 0.0]);
        assert_eq!(faces[5].texel(0, 0, 0).unwrap(), [1.0, 3.0, 3.0, 3.0]);
    }

    #[test]
    fn both_crosses_are_continuous_across_their_cuts() {
        // Neighbouring cells meet without a jump: the texels either side of every internal edge
        // hold nearby directions.
        let n = 32;
        for cross in [CubeCross::Horizontal, CubeCross::Vertical] {
            let at = |x: u32, y: u32| {
                (0..6).find_map(|face| {
                    let (c, r, turned) = cross.cell(face);
                    let (i, j) = (x % n, y % n);
                    let (i, j) = if turned {
                        (n - 1 - i, n - 1 - j)
                    } else {
                        (i, j)
                    };
                    let uv = DVec2::new(
                        (f64::from(i) + 0.5) / f64::from(n),
                        (f64::from(j) + 0.5) / f64::from(n),
                    );
                    (x / n == c && y / n == r).then(|| cube_direction(face, uv).normalize())
                })
            };
            let (cols, rows) = match cross {
                CubeCross::Horizontal => (4, 3),
                CubeCross::Vertical => (3, 4),
            };
            let mut edges = 0;
            for y in 0..rows * n {
                for x in 0..cols * n {
                    for (x1, y1) in [(x + 1, y), (x, y + 1)] {
                        if let (Some(a), Some(b)) = (at(x, y), at(x1, y1)) {
                            assert!(
                                (a - b).length() < 3.0 / f64::from(n),
                                "{cross:?} ({x}, {y})"
                            );
                            edges += 1;
                        }
                    }
                }
            }
            // The pairs inside the six cells, and more across the cuts.
            assert!(edges > 6 * 2 * n * (n - 1), "{edges}");
        }
    }
}
