//! Procedural textures: checker, zone plate, grid, uv, solid, a globe's map, and the bump and
//! wave normal and height maps.
//!
//! Each generator gives the 8-bit code of every texel (`code(i, j)`, row 0 at the top); the texture
//! is then made with `Texture::from_rgba8` and the spec's colour space, so `color = "srgb"` decodes
//! the codes through the sRGB curve and `color = "linear"` reads them as `code / 255`. Grey levels
//! in the formulas below are codes in `[0, 255]`; alpha is 255.

use texel_texture::{ColorSpace, Format, Limits, Texture, TextureError};

/// A generated texture and its parameters (the TOML keys have the same names).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Procedural {
    /// Black and white squares of side `width / checks` texels: texel `(i, j)` is black when
    /// `floor(i / s) + floor(j / s)` is even, with `s = width / checks` (real), so texel (0, 0)
    /// lies in a black check. `width = height = size = 1024`, `checks = 8` by default
    /// (8 x 8 checks of 128 texels).
    Checker {
        /// Width in texels.
        width: u32,
        /// Height in texels.
        height: u32,
        /// Number of checks along the width (`>= 1`).
        checks: u32,
    },
    /// The zone plate `code = round(255 * (0.5 + 0.5 cos(pi r^2 / size)))`, `r` the distance in
    /// texels from the texture centre to the texel centre:
    /// `r^2 = (i + 0.5 - size/2)^2 + (j + 0.5 - size/2)^2`. Its local frequency `r / size` cycles
    /// per texel grows linearly from 0 at the centre to 0.5 (Nyquist) at the middle of each edge.
    /// Square; `size = 1024` by default.
    ZonePlate {
        /// Side in texels.
        size: u32,
    },
    /// Black lines `line_width` texels wide on white, one every `width / cells` texels
    /// (real) in both directions: texel `(i, j)` is black when `i mod p < line_width` or
    /// `j mod p < line_width`, `p = width / cells`. Defaults: `size = 1024`, `cells = 8`,
    /// `line_width = 2`.
    Grid {
        /// Width in texels.
        width: u32,
        /// Height in texels.
        height: u32,
        /// Number of cells along the width (`>= 1`).
        cells: u32,
        /// Line width in texels (`>= 0`, finite).
        line_width: f32,
    },
    /// Texture coordinates as colour: `R = round(255 (i + 0.5) / width)`,
    /// `G = round(255 (j + 0.5) / height)`, `B = 0`. `size = 256` by default.
    Uv {
        /// Width in texels.
        width: u32,
        /// Height in texels.
        height: u32,
    },
    /// A tangent-space normal map (use with `color = "linear"`) of the egg-crate height field
    /// `h(x, y) = A sin(2 pi c x / W) sin(2 pi c y / H)` in texels, `x = i + 0.5`, `y = j + 0.5`,
    /// `c = cells` bumps along each side, `A` chosen so the steepest slope is `slope`
    /// (`A = slope W / (2 pi c)` for a square map). With `y` up the image (glTF's `+Y`), the normal
    /// is `normalize(-dh/dx, dh/dj, 1)` and the code `round(255 (n + 1) / 2)`. Square;
    /// `size = 512`, `cells = 32`, `slope = 0.5` by default.
    Bumps {
        /// Side in texels.
        size: u32,
        /// Bumps along each side (`>= 1`).
        cells: u32,
        /// Steepest slope (rise over run, `>= 0`, finite).
        slope: f32,
    },
    /// Random waves (use with `color = "linear"`): the height field
    /// `h(x, y) = sum_k a_k sin(2 pi (m_k x + n_k y) / size + phi_k)` of `waves` sinusoids, with
    /// integer wave numbers `(m_k, n_k)` (so it tiles) drawn uniformly from the ring
    /// `cells / 2 <= |(m, n)| <= cells` and phases `phi_k` uniform, from a SplitMix64 stream
    /// seeded by `seed`; `a_k = 1 / |(m_k, n_k)|` gives every wave the same steepest slope, and
    /// the whole is scaled so the root-mean-square slope `sqrt(E[|grad h|^2])` (per texel) is
    /// `slope`. Being a sum of many independent waves, its slopes are close to Gaussian, the
    /// distribution LEAN and Toksvig assume, and it has no period shorter than the texture to
    /// beat against the pixel grid. `heights = false` (`"waves"`): the tangent-space normal map,
    /// coded as [`Procedural::Bumps`]'s; `heights = true` (`"wave-heights"`): the heights,
    /// `code = round(255 (0.5 + h / (8 sigma)))` clamped, `sigma` the heights' standard
    /// deviation (so +-4 sigma fill the range; the slope of the coded map is then
    /// `slope / (8 sigma)` per texel in map units). Square; `size = 512`, `waves = 64`,
    /// `cells = 32`, `slope = 0.3`, `seed = 1` by default.
    Waves {
        /// Side in texels.
        size: u32,
        /// Number of sinusoids (`>= 1`).
        waves: u32,
        /// Largest wave number, cycles per texture side (`>= 1`).
        cells: u32,
        /// Root-mean-square slope (rise over run, `>= 0`, finite).
        slope: f32,
        /// Seed of the random waves.
        seed: u32,
        /// Heights instead of normals.
        heights: bool,
    },
    /// A running-bond brick wall, `rows` courses of `columns` bricks each, odd courses shifted by
    /// half a brick (so `rows` even tiles vertically), with mortar joints `mortar` texels wide.
    /// Texel `(i, j)` lies at `d` texels inside its brick's edge (negative in the mortar).
    /// `heights = false` (`"bricks"`, sRGB): mortar `[176, 170, 160]`, bricks
    /// `[150, 62, 46]` scaled by a per-brick factor in `[0.8, 1.1]` (a hash of the brick's course
    /// and column); `heights = true` (`"brick-heights"`, use `color = "linear"`): 0 in the
    /// mortar rising to 255 over `bevel` texels, `code = round(255 smoothstep(0, bevel, d))`.
    /// `width = 1024`, `height = 512`, `rows = 14`, `columns = 9`, `mortar = 4`, `bevel = 3` by
    /// default.
    Bricks {
        /// Width in texels.
        width: u32,
        /// Height in texels.
        height: u32,
        /// Courses (`>= 1`).
        rows: u32,
        /// Bricks per course (`>= 1`).
        columns: u32,
        /// Mortar joint width in texels (`>= 0`, finite).
        mortar: f32,
        /// Bevel width in texels (`>= 0`, finite).
        bevel: f32,
        /// Heights instead of colours.
        heights: bool,
    },
    /// Tiling fractal value noise: `v = sum_o 2^-o n(2^o cells x / size, ...) / sum_o 2^-o` over
    /// `NOISE_OCTAVES` octaves, `n` value noise on an integer lattice of `cells` (doubled per
    /// octave) cells per side, wrapping so the texture tiles, with quintic interpolation
    /// (`6t^5 - 15t^4 + 10t^3`, Perlin 2002) between lattice values hashed from `seed`; `v` lies in
    /// `[0, 1]`. `kind = Color` (`"noise"`): the colour `rgba` scaled by `0.4 + 0.6 v` (alpha
    /// `rgba`'s); `Heights` (`"noise-heights"`, use `color = "linear"`): grey `round(255 v)`;
    /// `Splat` (`"splat"`, use `color = "linear"`): a layer mask, one independent noise `v_k`
    /// per channel (seeds `seed + k`) turned into weights summing to 1 by a softmax,
    /// `w_k = exp(24 v_k) / sum exp(24 v)` over the first `layers` channels (the rest 0), coded
    /// `round(255 w_k)`. Square; `size = 512`, `cells = 8`, `seed = 1`,
    /// `rgba = [255, 255, 255, 255]`, `layers = 4` by default.
    Noise {
        /// Side in texels.
        size: u32,
        /// Lattice cells along each side at the coarsest octave (`>= 1`).
        cells: u32,
        /// Seed of the lattice values.
        seed: u32,
        /// What is made of the noise.
        kind: NoiseKind,
    },
    /// A globe's map for the spherical mappings ([`texel_texture::mapping::sphere::SurfaceProjection`]):
    /// texel `(i, j)` is coloured by the point of the sphere it shows, `d = direction(u, v)` at its
    /// centre, latitude `phi`, longitude `lambda` (east from `+z`). Ocean `[28, 64, 128]`;
    /// Tissot's indicatrix, discs of `GLOBE_DISC_DEG` radius on the sphere centred every 30
    /// degrees of longitude at latitudes -60 to 60, in `[240, 150, 40]`; parallels and meridians
    /// every 15 degrees (`GLOBE_LINE_DEG` wide on the sphere; meridians end at 75 degrees of
    /// latitude except every 90th) in white; the prime meridian (the seam `u = 0 = 1`) in
    /// `[220, 40, 40]`. Every line and disc has the same size on the sphere, so on a correctly
    /// mapped globe they all look alike. Edges are antialiased with the texel's own angular size
    /// (coverage `clamp((r - dist) / s + 1/2, 0, 1)`, `s` the texel's extent on the sphere across
    /// the edge). `mercator = false` (`"globe"`): equirect, `2048 x 1024` by default;
    /// `mercator = true` (`"globe-mercator"`): Mercator whose cut follows the aspect
    /// (`ln tan(pi/4 + cut/2) = pi height / width`; a square, the default `2048 x 2048`, is Web
    /// Mercator).
    Globe {
        /// Width in texels.
        width: u32,
        /// Height in texels.
        height: u32,
        /// Mercator instead of equirect.
        mercator: bool,
    },
    /// One colour everywhere (8-bit codes, `rgba = [255, 255, 255, 255]` and `size = 1` by default).
    Solid {
        /// Width in texels.
        width: u32,
        /// Height in texels.
        height: u32,
        /// The colour's 8-bit codes.
        rgba: [u8; 4],
    },
}

impl Procedural {
    /// Width and height in texels.
    pub fn size(&self) -> (u32, u32) {
        match *self {
            Procedural::Checker { width, height, .. }
            | Procedural::Grid { width, height, .. }
            | Procedural::Uv { width, height }
            | Procedural::Bricks { width, height, .. }
            | Procedural::Globe { width, height, .. }
            | Procedural::Solid { width, height, .. } => (width, height),
            Procedural::ZonePlate { size }
            | Procedural::Bumps { size, .. }
            | Procedural::Waves { size, .. }
            | Procedural::Noise { size, .. } => (size, size),
        }
    }

    /// The 8-bit code of texel `(i, j)` (formulas in the variant docs). For
    /// [`Procedural::Waves`] each call draws the wave set again; [`Procedural::generate`] draws it
    /// once for the whole texture.
    pub fn code(&self, i: u32, j: u32) -> [u8; 4] {
        match *self {
            Procedural::Checker { width, checks, .. } => {
                let s = f64::from(width) / f64::from(checks);
                let a = (f64::from(i) / s).floor() as u64 + (f64::from(j) / s).floor() as u64;
                grey(if a.is_multiple_of(2) { 0 } else { 255 })
            }
            Procedural::ZonePlate { size } => {
                let c = f64::from(size) / 2.0;
                let (x, y) = (f64::from(i) + 0.5 - c, f64::from(j) + 0.5 - c);
                let v =
                    0.5 + 0.5 * (std::f64::consts::PI * (x * x + y * y) / f64::from(size)).cos();
                grey((255.0 * v).round() as u8)
            }
            Procedural::Grid {
                width,
                cells,
                line_width,
                ..
            } => {
                let p = f64::from(width) / f64::from(cells);
                let lw = f64::from(line_width);
                let on = f64::from(i) % p < lw || f64::from(j) % p < lw;
                grey(if on { 0 } else { 255 })
            }
            Procedural::Globe {
                width,
                height,
                mercator,
            } => globe(
                globe_projection(width, height, mercator),
                width,
                height,
                i,
                j,
            ),
            Procedural::Uv { width, height } => {
                let r = (255.0 * (f64::from(i) + 0.5) / f64::from(width)).round() as u8;
                let g = (255.0 * (f64::from(j) + 0.5) / f64::from(height)).round() as u8;
                [r, g, 0, 255]
            }
            Procedural::Bumps { size, cells, slope } => {
                let n = Self::bump_normal(size, cells, slope, i, j);
                let enc = |c: f64| (255.0 * (c + 1.0) / 2.0).round().clamp(0.0, 255.0) as u8;
                [enc(n[0]), enc(n[1]), enc(n[2]), 255]
            }
            Procedural::Waves { .. } => (self.coder())(i, j),
            Procedural::Bricks {
                width,
                height,
                rows,
                columns,
                mortar,
                bevel,
                heights,
            } => {
                let (d, row, col) = brick_at(width, height, rows, columns, mortar, i, j);
                if heights {
                    brick_height_code(d, bevel)
                } else if d < 0.0 {
                    [176, 170, 160, 255]
                } else {
                    brick_shade_code(row, col, columns)
                }
            }
            Procedural::Solid { rgba, .. } => rgba,
            Procedural::Noise {
                size,
                cells,
                seed,
                kind,
            } => noise_code(size, cells, seed, kind, i, j),
        }
    }

    /// The code of every texel as a function: [`Procedural::code`], with the wave set of
    /// [`Procedural::Waves`] drawn once instead of per texel.
    fn coder(&self) -> Box<dyn Fn(u32, u32) -> [u8; 4] + '_> {
        if let Procedural::Globe {
            width,
            height,
            mercator,
        } = *self
        {
            // The projection once, not per texel.
            let projection = globe_projection(width, height, mercator);
            return Box::new(move |i, j| globe(projection, width, height, i, j));
        }
        let Procedural::Waves {
            size,
            waves,
            cells,
            slope,
            seed,
            heights,
        } = *self
        else {
            return Box::new(|i, j| self.code(i, j));
        };
        let set = wave_set(size, waves, cells, slope, seed);
        let enc = |c: f64| (255.0 * (c + 1.0) / 2.0).round().clamp(0.0, 255.0) as u8;
        Box::new(move |i, j| {
            let (x, y) = (f64::from(i) + 0.5, f64::from(j) + 0.5);
            let (mut h, mut gx, mut gy) = (0.0, 0.0, 0.0);
            for w in &set.waves {
                let t = w.kx * x + w.ky * y + w.phase;
                h += w.amplitude * t.sin();
                let c = w.amplitude * t.cos();
                gx += c * w.kx;
                gy += c * w.ky;
            }
            if heights {
                let v = (255.0 * (0.5 + h / (8.0 * set.sigma)))
                    .round()
                    .clamp(0.0, 255.0) as u8;
                [v, v, v, 255]
            } else {
                let n = [-gx, gy, 1.0];
                let len = (gx * gx + gy * gy + 1.0).sqrt();
                [enc(n[0] / len), enc(n[1] / len), enc(n[2] / len), 255]
            }
        })
    }

    /// The unit tangent-space normal of [`Procedural::Bumps`] at texel `(i, j)` (`+y` up the image).
    pub fn bump_normal(size: u32, cells: u32, slope: f32, i: u32, j: u32) -> [f64; 3] {
        use std::f64::consts::PI;
        let k = 2.0 * PI * f64::from(cells) / f64::from(size);
        let a = f64::from(slope) / k;
        let (x, y) = (f64::from(i) + 0.5, f64::from(j) + 0.5);
        let hx = a * k * (k * x).cos() * (k * y).sin();
        let hj = a * k * (k * x).sin() * (k * y).cos();
        let v = [-hx, hj, 1.0];
        let len = (v[0] * v[0] + v[1] * v[1] + 1.0).sqrt();
        v.map(|c| c / len)
    }

    /// Generate the texture (with its mip pyramid) in colour space `color`. The size is checked
    /// against `limits` before anything is allocated.
    ///
    /// # Errors
    /// The size errors of [`Limits::check`].
    pub fn generate(&self, color: ColorSpace, limits: &Limits) -> Result<Texture, TextureError> {
        let (w, h) = self.size();
        let format = match color {
            ColorSpace::Srgb => Format::Rgba8Srgb,
            ColorSpace::Linear => Format::Rgba8Unorm,
        };
        limits.check(w, h, format)?;
        let code = self.coder();
        let texels = (0..h)
            .flat_map(|j| (0..w).map(move |i| (i, j)))
            .map(|(i, j)| code(i, j))
            .collect();
        Texture::from_rgba8(w, h, texels, color, limits)
    }
}

/// Most sinusoids a [`Procedural::Waves`] texture may sum.
pub const MAX_WAVES: u32 = 4096;

/// Most wave terms (texels x waves) a [`Procedural::Waves`] texture may evaluate: 2^31, about 30 s
/// on one core. The default (512 x 512 texels, 64 waves) is 2^24.
pub const MAX_WAVE_TERMS: u64 = 1 << 31;

impl Procedural {
    /// Check the work a texture's parameters ask for before any of it is done: the number of
    /// waves ([`MAX_WAVES`]), the wave terms ([`MAX_WAVE_TERMS`]), and the ring of wave numbers
    /// (`cells`, at most half the size: finer waves than two texels alias).
    ///
    /// # Errors
    /// A message naming the parameter, the bound and what to change.
    pub fn check_work(&self) -> Result<(), String> {
        if let Procedural::Waves {
            size, waves, cells, ..
        } = *self
        {
            if waves > MAX_WAVES {
                return Err(format!(
                    "waves = {waves} is over texel's bound of {MAX_WAVES} sinusoids a texture \
                     (their slopes are already close to Gaussian at 64)"
                ));
            }
            if cells > (size / 2).max(1) {
                return Err(format!(
                    "cells = {cells} is over half the size ({}): waves finer than two texels \
                     alias",
                    (size / 2).max(1)
                ));
            }
            let terms = u64::from(size) * u64::from(size) * u64::from(waves);
            if terms > MAX_WAVE_TERMS {
                return Err(format!(
                    "size = {size} with waves = {waves} is {terms} wave terms (texels x waves), \
                     over texel's bound of {MAX_WAVE_TERMS} (about 30 s of work): use fewer \
                     waves or a smaller size"
                ));
            }
        }
        Ok(())
    }
}

/// Radius, degrees on the sphere, of [`Procedural::Globe`]'s discs.
pub(crate) const GLOBE_DISC_DEG: f64 = 6.0;
/// Width, degrees on the sphere, of [`Procedural::Globe`]'s lines.
pub(crate) const GLOBE_LINE_DEG: f64 = 0.5;

impl Procedural {
    /// The projection a [`Procedural::Globe`] map is drawn in (`None` for other kinds): equirect,
    /// or Mercator cut where `ln tan(pi/4 + cut/2) = pi height / width`.
    pub fn globe_projection(&self) -> Option<texel_texture::mapping::sphere::SurfaceProjection> {
        match *self {
            Procedural::Globe {
                width,
                height,
                mercator,
            } => Some(globe_projection(width, height, mercator)),
            _ => None,
        }
    }
}

/// The grey code of value `v`, opaque.
fn grey(v: u8) -> [u8; 4] {
    [v, v, v, 255]
}

/// Where texel `(i, j)` of a [`Procedural::Bricks`] texture lies: its distance inside its brick's
/// edge less half the mortar (negative in the mortar), and the brick's row and column (odd rows
/// shifted by half a brick).
fn brick_at(
    width: u32,
    height: u32,
    rows: u32,
    columns: u32,
    mortar: f32,
    i: u32,
    j: u32,
) -> (f64, f64, f64) {
    let bh = f64::from(height) / f64::from(rows.max(1));
    let bw = f64::from(width) / f64::from(columns.max(1));
    let (x, y) = (f64::from(i) + 0.5, f64::from(j) + 0.5);
    let row = (y / bh).floor();
    let shifted = if row as u64 % 2 == 1 { x + bw / 2.0 } else { x };
    let col = (shifted / bw).floor();
    let (lx, ly) = (shifted - col * bw, y - row * bh);
    let d = lx.min(bw - lx).min(ly).min(bh - ly) - f64::from(mortar) / 2.0;
    (d, row, col)
}

/// The height code of a brick texel at distance `d` inside its edge: a smoothstep over `bevel`
/// texels, or a step where `bevel` is zero.
fn brick_height_code(d: f64, bevel: f32) -> [u8; 4] {
    let b = f64::from(bevel);
    let t = if b > 0.0 {
        (d / b).clamp(0.0, 1.0)
    } else {
        f64::from(u8::from(d >= 0.0))
    };
    grey((255.0 * t * t * (3.0 - 2.0 * t)).round() as u8)
}

/// The colour code of the brick at `row` and `col` of a texture `columns` bricks wide: one shade
/// per brick.
fn brick_shade_code(row: f64, col: f64, columns: u32) -> [u8; 4] {
    // Per-brick shade; the column wraps so the texture tiles.
    let c = (col as i64).rem_euclid(i64::from(columns.max(1))) as u64;
    let h = texel_texture::base::rng::mix64((row as u64) << 32 | c);
    let f = 0.8 + 0.3 * (h >> 11) as f64 / (1u64 << 53) as f64;
    let s = |v: f64| (v * f).round().clamp(0.0, 255.0) as u8;
    [s(150.0), s(62.0), s(46.0), 255]
}

/// The code of texel `(i, j)` of a [`Procedural::Noise`] texture of `kind`.
fn noise_code(size: u32, cells: u32, seed: u32, kind: NoiseKind, i: u32, j: u32) -> [u8; 4] {
    let v = |seed: u32| noise(size, cells, seed, i, j);
    let code = |x: f64| (255.0 * x).round().clamp(0.0, 255.0) as u8;
    match kind {
        NoiseKind::Color { rgba } => {
            let f = 0.4 + 0.6 * v(seed);
            let c = |k: usize| (f64::from(rgba[k]) * f).round() as u8;
            [c(0), c(1), c(2), rgba[3]]
        }
        NoiseKind::Heights => grey(code(v(seed))),
        NoiseKind::Splat { layers } => {
            let n = layers.clamp(1, 4) as usize;
            let mut e = [0.0f64; 4];
            for (k, e) in e.iter_mut().enumerate().take(n) {
                *e = (24.0 * v(seed.wrapping_add(k as u32))).exp();
            }
            let sum: f64 = e.iter().sum();
            e.map(|x| code(x / sum))
        }
    }
}

/// [`Procedural::globe_projection`] of a globe map `width x height`.
fn globe_projection(
    width: u32,
    height: u32,
    mercator: bool,
) -> texel_texture::mapping::sphere::SurfaceProjection {
    use texel_texture::mapping::sphere::SurfaceProjection;
    if mercator && width == height {
        SurfaceProjection::MERCATOR
    } else if mercator {
        let y = std::f64::consts::PI * f64::from(height) / f64::from(width.max(1));
        SurfaceProjection::Mercator {
            cut: y.tanh().asin(),
        }
    } else {
        SurfaceProjection::Equirect
    }
}

/// [`Procedural::Globe`]'s texel `(i, j)` of a `width x height` map in `projection`.
fn globe(
    projection: texel_texture::mapping::sphere::SurfaceProjection,
    width: u32,
    height: u32,
    i: u32,
    j: u32,
) -> [u8; 4] {
    use glam::{DVec2, DVec3};
    use std::f64::consts::PI;
    use texel_texture::mapping::sphere::SurfaceProjection;
    let (w, h) = (f64::from(width.max(1)), f64::from(height.max(1)));
    let uv = DVec2::new((f64::from(i) + 0.5) / w, (f64::from(j) + 0.5) / h);
    let d = projection.direction(uv);
    let lat = d.y.clamp(-1.0, 1.0).asin();
    let lon = 2.0 * PI * uv.x;
    let cos = lat.cos().max(1e-9);
    // A texel's extent on the sphere, radians: east-west, and north-south (equirect pi / H;
    // Mercator 2 Y cos(lat) / H, the same as east-west for a square map: conformal).
    let s_east = 2.0 * PI * cos / w;
    let s_north = match projection {
        SurfaceProjection::Equirect => PI / h,
        SurfaceProjection::Mercator { .. } => 2.0 * PI * cos / w,
    };
    let cover = |r: f64, dist: f64, s: f64| ((r - dist) / s + 0.5).clamp(0.0, 1.0);
    let deg = PI / 180.0;
    let nearest = |x: f64, step: f64| x - (x / step).round() * step;
    let half = 0.5 * GLOBE_LINE_DEG * deg;
    let parallel = cover(half, nearest(lat, 15.0 * deg).abs(), s_north);
    // Meridians: the distance on the sphere is |delta lon| cos(lat).
    let dlon = nearest(lon, 15.0 * deg).abs();
    let every_90th = ((lon / (15.0 * deg)).round() as i64).rem_euclid(6) == 0;
    let meridian = if lat.abs() > 75.0 * deg && !every_90th {
        0.0
    } else {
        cover(half, dlon * cos, s_east)
    };
    let prime = cover(half, nearest(lon, 2.0 * PI).abs() * cos, s_east);
    // Tissot's disc nearest the texel: its great-circle distance.
    let lat_c = ((lat / (30.0 * deg)).round().clamp(-2.0, 2.0)) * 30.0 * deg;
    let lon_c = (lon / (30.0 * deg)).round() * 30.0 * deg;
    let centre = DVec3::new(
        lat_c.cos() * lon_c.sin(),
        lat_c.sin(),
        lat_c.cos() * lon_c.cos(),
    );
    let here = DVec3::new(cos * lon.sin(), lat.sin(), cos * lon.cos());
    let dist = here.cross(centre).length().atan2(here.dot(centre));
    let disc = cover(GLOBE_DISC_DEG * deg, dist, (s_east * s_north).sqrt());
    let mix = |a: [f64; 3], b: [f64; 3], t: f64| std::array::from_fn(|k| a[k] + (b[k] - a[k]) * t);
    let mut c = mix([28.0, 64.0, 128.0], [240.0, 150.0, 40.0], disc);
    c = mix(c, [255.0; 3], parallel.max(meridian));
    c = mix(c, [220.0, 40.0, 40.0], prime);
    let code = |x: f64| x.round().clamp(0.0, 255.0) as u8;
    [code(c[0]), code(c[1]), code(c[2]), 255]
}

/// What [`Procedural::Noise`] makes of its noise.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum NoiseKind {
    /// `"noise"`: a colour texture, `rgba` scaled by the noise.
    Color {
        /// The brightest colour's 8-bit codes.
        rgba: [u8; 4],
    },
    /// `"noise-heights"`: a height map.
    Heights,
    /// `"splat"`: a mask of `layers` (1 to 4) weights.
    Splat {
        /// Channels holding weights.
        layers: u32,
    },
}

/// The octaves of [`Procedural::Noise`].
pub(crate) const NOISE_OCTAVES: u32 = 5;

/// [`Procedural::Noise`]'s fractal value noise at texel `(i, j)` of a `size`-texel square.
fn noise(size: u32, cells: u32, seed: u32, i: u32, j: u32) -> f64 {
    let (x, y) = (
        (f64::from(i) + 0.5) / f64::from(size.max(1)),
        (f64::from(j) + 0.5) / f64::from(size.max(1)),
    );
    let (mut sum, mut norm) = (0.0, 0.0);
    for o in 0..NOISE_OCTAVES {
        let n = u64::from(cells.max(1)) << o;
        let lattice = |a: u64, b: u64| {
            let key = (u64::from(seed) << 40) ^ (u64::from(o) << 56) ^ ((a % n) << 20) ^ (b % n);
            (texel_texture::base::rng::mix64(key) >> 11) as f64 / (1u64 << 53) as f64
        };
        let (fx, fy) = (x * n as f64, y * n as f64);
        let (a, b) = (fx.floor(), fy.floor());
        let fade = |t: f64| t * t * t * (t * (t * 6.0 - 15.0) + 10.0);
        let (tx, ty) = (fade(fx - a), fade(fy - b));
        let (a, b) = (a as u64, b as u64);
        let top = lattice(a, b) + tx * (lattice(a + 1, b) - lattice(a, b));
        let bottom = lattice(a, b + 1) + tx * (lattice(a + 1, b + 1) - lattice(a, b + 1));
        let w = 0.5f64.powi(o as i32);
        sum += w * (top + ty * (bottom - top));
        norm += w;
    }
    sum / norm
}

/// One sinusoid of [`Procedural::Waves`], in texel units: `amplitude sin(kx x + ky y + phase)`.
#[derive(Clone, Copy, Debug)]
struct Wave {
    kx: f64,
    ky: f64,
    phase: f64,
    amplitude: f64,
}

/// The waves of [`Procedural::Waves`], scaled to the slope asked, and the heights' standard
/// deviation.
struct WaveSet {
    waves: Vec<Wave>,
    sigma: f64,
}

fn wave_set(size: u32, count: u32, cells: u32, slope: f32, seed: u32) -> WaveSet {
    use std::f64::consts::TAU;
    let mut rng = texel_texture::base::rng::SplitMix64::new(u64::from(seed));
    let (lo, hi) = (f64::from(cells) / 2.0, f64::from(cells).max(1.0));
    let span = hi.ceil() as i64;
    let mut waves = Vec::with_capacity(count as usize);
    while waves.len() < count as usize {
        // Uniform over the ring's integer points by rejection from the bounding square.
        let m = (rng.next_f64() * (2 * span + 1) as f64).floor() as i64 - span;
        let n = (rng.next_f64() * (2 * span + 1) as f64).floor() as i64 - span;
        let r = ((m * m + n * n) as f64).sqrt();
        if r == 0.0 || r < lo || r > hi {
            continue;
        }
        let k = TAU / f64::from(size);
        waves.push(Wave {
            kx: k * m as f64,
            ky: k * n as f64,
            phase: rng.next_f64() * TAU,
            amplitude: 1.0 / r,
        });
    }
    // Each wave's gradient has mean square (a |k|)^2 / 2; the waves are independent.
    let mean_square: f64 = waves
        .iter()
        .map(|w| w.amplitude * w.amplitude * (w.kx * w.kx + w.ky * w.ky) / 2.0)
        .sum();
    let scale = f64::from(slope) / mean_square.sqrt();
    for w in &mut waves {
        w.amplitude *= scale;
    }
    let sigma = waves
        .iter()
        .map(|w| w.amplitude * w.amplitude / 2.0)
        .sum::<f64>()
        .sqrt()
        .max(f64::MIN_POSITIVE);
    WaveSet { waves, sigma }
}

#[cfg(test)]
mod tests {
    use super::*;
    use texel_texture::base::color::srgb_table;

    #[test]
    fn checker_layout() {
        let c = Procedural::Checker {
            width: 1024,
            height: 1024,
            checks: 8,
        };
        assert_eq!(c.code(0, 0), [0, 0, 0, 255]);
        assert_eq!(c.code(127, 127), [0, 0, 0, 255]);
        assert_eq!(c.code(128, 0), [255, 255, 255, 255]);
        assert_eq!(c.code(0, 128), [255, 255, 255, 255]);
        assert_eq!(c.code(128, 128), [0, 0, 0, 255]);
        assert_eq!(c.code(1023, 1023), [0, 0, 0, 255]); // (7 + 7) even
                                                        // Non-divisible: 10 texels, 3 checks of 3.33 texels.
        let odd = Procedural::Checker {
            width: 10,
            height: 10,
            checks: 3,
        };
        let row: Vec<u8> = (0..10).map(|i| odd.code(i, 0)[0]).collect();
        assert_eq!(row, vec![0, 0, 0, 0, 255, 255, 255, 0, 0, 0]);
    }

    #[test]
    fn zone_plate_formula() {
        let z = Procedural::ZonePlate { size: 64 };
        // Centre texel (32, 32): r^2 = 0.5, 0.5 + 0.5 cos(pi * 0.5 / 64) = 0.99985 -> 255.
        assert_eq!(z.code(32, 32)[0], 255);
        // (40, 32): r^2 = 8.5^2 + 0.5^2 = 72.5; 0.5 + 0.5 cos(pi * 72.5 / 64) = 0.042895 -> 11.
        let v = 0.5 + 0.5 * (std::f64::consts::PI * 72.5 / 64.0).cos();
        assert!((v - 0.042_895_12).abs() < 1e-8);
        assert_eq!(z.code(40, 32)[0], 11);
        // Corner (0, 0): r^2 = 2 * 31.5^2 = 1984.5; 1984.5 / 64 = 31.0078 -> cos(31.0078 pi) ~ -1 -> 0.
        assert_eq!(z.code(0, 0)[0], 0);
        // Local frequency at the edge: phase step between (63, 32) and (62, 32) is about pi.
        let phase = |i: f64| std::f64::consts::PI * ((i + 0.5 - 32.0).powi(2) + 0.25) / 64.0;
        assert!((phase(63.0) - phase(62.0) - std::f64::consts::PI * 62.0 / 64.0).abs() < 1e-12);
    }

    /// The waves' slopes have the root-mean-square asked (measured over the texels, from the
    /// decoded normals), the map tiles, and the heights use the range as documented.
    #[test]
    fn waves_have_the_slope_asked_and_tile() {
        use std::f64::consts::TAU;
        let p = Procedural::Waves {
            size: 128,
            waves: 48,
            cells: 12,
            slope: 0.3,
            seed: 7,
            heights: false,
        };
        let code = p.coder();
        let mut sum = 0.0;
        for j in 0..128 {
            for i in 0..128 {
                let c = code(i, j).map(|c| f64::from(c) / 255.0 * 2.0 - 1.0);
                let (sx, sy) = (c[0] / c[2], c[1] / c[2]);
                sum += sx * sx + sy * sy;
            }
        }
        let rms = (sum / (128.0 * 128.0)).sqrt();
        // Quantisation and the finite texel sample: within 5%.
        assert!((rms - 0.3).abs() < 0.015, "rms slope {rms}");
        let set = wave_set(128, 48, 12, 0.3, 7);
        // Integer wave numbers (a whole texture later the phase is the same) in the ring.
        for w in &set.waves {
            let (m, n) = (w.kx * 128.0 / TAU, w.ky * 128.0 / TAU);
            assert!((m - m.round()).abs() < 1e-9 && (n - n.round()).abs() < 1e-9);
            assert!((6.0..=12.0).contains(&m.hypot(n)), "({m}, {n})");
        }
        let heights = Procedural::Waves {
            size: 128,
            waves: 48,
            cells: 12,
            slope: 0.3,
            seed: 7,
            heights: true,
        };
        let code = heights.coder();
        let mean = (0..128)
            .flat_map(|j| (0..128).map(move |i| (i, j)))
            .map(|(i, j)| f64::from(code(i, j)[0]))
            .sum::<f64>()
            / (128.0 * 128.0);
        assert!((mean - 127.5).abs() < 8.0, "mean code {mean}");
        // Another seed, other waves.
        let other = Procedural::Waves {
            size: 128,
            waves: 48,
            cells: 12,
            slope: 0.3,
            seed: 8,
            heights: false,
        };
        assert_ne!(other.code(3, 5), p.code(3, 5));
    }

    #[test]
    fn bricks_lay_in_running_bond_with_mortar_and_bevels() {
        let b = |heights| Procedural::Bricks {
            width: 64,
            height: 32,
            rows: 4,
            columns: 4,
            mortar: 2.0,
            bevel: 2.0,
            heights,
        };
        let (c, h) = (b(false), b(true));
        // Bricks are 16 x 8 texels. Texel (0, 0) lies in the mortar (d = 0.5 - 1 < 0).
        assert_eq!(c.code(0, 0), [176, 170, 160, 255]);
        assert_eq!(h.code(0, 0)[0], 0);
        // The middle of the first brick: d = 3.5 - 1 = 2.5 > bevel: full height, brick red.
        assert_eq!(h.code(8, 4)[0], 255);
        assert!(c.code(8, 4)[0] > c.code(8, 4)[1]);
        // On the bevel: d = 1.5 - 1 = 0.5 of 2, smoothstep(0.25) = 0.15625.
        assert_eq!(h.code(8, 1)[0], (255.0f64 * 0.15625).round() as u8);
        // Course 1 is shifted by half a brick: its joint is at x = 8, course 0's at x = 0, 16.
        assert_eq!(h.code(8, 12)[0], 0);
        assert_eq!(h.code(16, 12)[0], 255);
        // Tiles: the last column and the first share the shade pattern of one brick across the
        // seam in the shifted course.
        assert_eq!(c.code(63, 12), c.code(0, 12));
    }

    #[test]
    fn noise_tiles_stays_in_range_and_splat_weights_sum_to_one() {
        for kind in [
            NoiseKind::Heights,
            NoiseKind::Splat { layers: 3 },
            NoiseKind::Color {
                rgba: [200, 100, 50, 255],
            },
        ] {
            let p = Procedural::Noise {
                size: 64,
                cells: 4,
                seed: 7,
                kind,
            };
            let t: Vec<[u8; 4]> = (0..64 * 64).map(|k| p.code(k % 64, k / 64)).collect();
            // Opposite edges continue each other: neighbours across the seam differ no more than
            // neighbours inside.
            let step =
                |a: [u8; 4], b: [u8; 4]| (0..3).map(|c| a[c].abs_diff(b[c])).max().unwrap_or(0);
            let inner = (0..64)
                .map(|j| step(t[j * 64 + 31], t[j * 64 + 32]))
                .max()
                .unwrap();
            let seam = (0..64)
                .map(|j| step(t[j * 64 + 63], t[j * 64]))
                .max()
                .unwrap();
            assert!(
                seam <= inner.max(1) * 2,
                "{kind:?}: seam {seam}, inner {inner}"
            );
            match kind {
                NoiseKind::Splat { layers } => {
                    for c in &t {
                        let sum: u32 = c.iter().map(|&x| u32::from(x)).sum();
                        assert!((253..=257).contains(&sum), "{c:?}");
                        assert_eq!(c[3], 0, "only {layers} channels weigh");
                    }
                }
                NoiseKind::Color { rgba } => {
                    assert!(t
                        .iter()
                        .all(|c| c[0] <= rgba[0] && c[0] >= 80 && c[3] == 255));
                }
                NoiseKind::Heights => {
                    let (lo, hi) = t
                        .iter()
                        .fold((255, 0), |(lo, hi), c| (c[0].min(lo), c[0].max(hi)));
                    assert!(hi - lo > 100, "a range of heights: {lo}..{hi}");
                }
            }
        }
    }

    #[test]
    fn grid_uv_solid() {
        let g = Procedural::Grid {
            width: 16,
            height: 16,
            cells: 4,
            line_width: 1.0,
        };
        assert_eq!(g.code(0, 7)[0], 0);
        assert_eq!(g.code(4, 7)[0], 0);
        assert_eq!(g.code(5, 7)[0], 255);
        assert_eq!(g.code(5, 8)[0], 0);
        let uv = Procedural::Uv {
            width: 256,
            height: 128,
        };
        assert_eq!(uv.code(0, 0), [0, 1, 0, 255]);
        assert_eq!(uv.code(255, 127), [255, 254, 0, 255]);
        let s = Procedural::Solid {
            width: 2,
            height: 3,
            rgba: [1, 2, 3, 4],
        };
        assert_eq!(s.code(1, 2), [1, 2, 3, 4]);
    }

    #[test]
    fn generate_applies_colour_space_and_limits() {
        let c = Procedural::Checker {
            width: 8,
            height: 8,
            checks: 2,
        };
        let t = c.generate(ColorSpace::Srgb, &Limits::default()).unwrap();
        assert_eq!(t.texel(0, 0, 0).unwrap(), [0.0, 0.0, 0.0, 1.0]);
        assert_eq!(t.texel(0, 4, 0).unwrap(), [1.0; 4]);
        // Level 3 (1x1) averages half black, half white in linear light.
        assert!((t.texel(3, 0, 0).unwrap()[0] - 0.5).abs() < 0.003);
        let z = Procedural::ZonePlate { size: 64 };
        let ts = z.generate(ColorSpace::Srgb, &Limits::default()).unwrap();
        let tl = z.generate(ColorSpace::Linear, &Limits::default()).unwrap();
        assert_eq!(ts.texel(0, 40, 32).unwrap()[0], srgb_table()[11]);
        assert_eq!(tl.texel(0, 40, 32).unwrap()[0], 11.0 / 255.0);
        let big = Procedural::Checker {
            width: 100_000,
            height: 100_000,
            checks: 8,
        };
        assert!(matches!(
            big.generate(ColorSpace::Srgb, &Limits::default()),
            Err(TextureError::TooLarge { .. })
        ));
    }
}
