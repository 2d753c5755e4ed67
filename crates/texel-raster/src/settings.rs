//! How a frame is rendered: size, background, derivative and interpolation modes, debug view, light,
//! threads.

use texel_texture::base::color::{rgba_to_srgb8, rgba_to_unorm8, srgb_table, unorm8_table};

use crate::environment::Environment;
use crate::error::RasterError;
use crate::material::{Light, MAX_LIGHTS};

/// The largest frame side in pixels (keeps fixed-point edge functions far from `i64` overflow,
/// see [`crate::setup`]).
pub const MAX_DIMENSION: u32 = 16384;

/// The largest frame in pixels (`2^26`, about 67 M: the frame's buffers then take about 2 GiB).
pub const MAX_PIXELS: u64 = 1 << 26;

/// How the screen-space derivatives of `uv` handed to the sampler are computed.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum Derivatives {
    /// Exact derivatives of the perspective-correct `uv` at the pixel centre, from the plane
    /// equations: with `q = u/w` and `r = 1/w`, `du/dx = (q_x r - q r_x) / r^2` (conventions.md).
    #[default]
    #[cfg_attr(
        feature = "clap",
        value(help = "Exact derivatives from the triangle's plane equations")
    )]
    Analytic,
    /// GPU-style differences over aligned 2x2 quads ("fine" derivatives, D3D `ddx_fine`): for a pixel
    /// in quad row `y`, `du/dx = u(right, y) - u(left, y)`; for quad column `x`,
    /// `du/dy = u(x, bottom) - u(x, top)`. Pixels of the quad outside the triangle (helper pixels)
    /// are evaluated from the same plane equations.
    #[cfg_attr(
        feature = "clap",
        value(help = "Differences within 2x2 pixel quads, as GPUs compute them")
    )]
    Quad,
}

/// How attributes are interpolated across a triangle.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum Perspective {
    /// Perspective-correct: `a/w` and `1/w` are linear in screen space, `a = (a/w) / (1/w)`.
    #[default]
    #[cfg_attr(
        feature = "clap",
        value(help = "Perspective-correct (interpolate a/w and 1/w)")
    )]
    Correct,
    /// Affine (screen-space linear) interpolation of the attributes of each clipped triangle: the
    /// "incorrect" image of the lectures (textures swim and bend). Depth stays correct.
    #[cfg_attr(
        feature = "clap",
        value(help = "Affine in screen space (the lectures' incorrect image)")
    )]
    Affine,
}

/// What each pixel shows.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum View {
    /// Texture colour times vertex colour, optionally lit (the normal image).
    #[default]
    #[cfg_attr(feature = "clap", value(help = "The textured image"))]
    Color,
    /// `fract(u)` in red, `fract(v)` in green (as displayed: 8-bit red = `fract(u) * 255`).
    #[cfg_attr(feature = "clap", value(help = "fract(u) in red, fract(v) in green"))]
    Uv,
    /// The integer mip level the nearest-level rule reads (`ceil(lod + 1/2) - 1`), one colour per
    /// level from [`crate::views::MIP_PALETTE`].
    #[cfg_attr(
        feature = "clap",
        value(help = "Integer mip level, one colour per level")
    )]
    Mip,
    /// The continuous lod: the palette of [`View::Mip`] interpolated between integer levels.
    #[cfg_attr(feature = "clap", value(help = "Continuous level of detail"))]
    Lod,
    /// The footprint's anisotropy `|Pmax| / |Pmin|` on a colour ramp, 1 to 16 on a log2 scale.
    #[cfg_attr(feature = "clap", value(help = "Footprint anisotropy ratio"))]
    Aniso,
    /// Texels the filter read for the pixel, as a heat map (log2 scale, see [`crate::views`]).
    /// Turns on texel counting.
    #[cfg_attr(feature = "clap", value(help = "Texels read per pixel (heat map)"))]
    Fetches,
    /// The perspective-correct barycentric weights of the original (unclipped) triangle as RGB.
    #[cfg_attr(feature = "clap", value(help = "Barycentric weights as RGB"))]
    Barycentric,
}

impl View {
    /// Every view, in the order help lists them and the viewer's V key cycles through them.
    pub const ALL: [View; 7] = [
        View::Color,
        View::Uv,
        View::Mip,
        View::Lod,
        View::Aniso,
        View::Fetches,
        View::Barycentric,
    ];

    /// The name the command line (`--view`), the viewer and Python use.
    pub fn name(self) -> &'static str {
        match self {
            View::Color => "color",
            View::Uv => "uv",
            View::Mip => "mip",
            View::Lod => "lod",
            View::Aniso => "aniso",
            View::Fetches => "fetches",
            View::Barycentric => "barycentric",
        }
    }
}

impl std::fmt::Display for View {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for View {
    type Err = String;

    /// A view's name, case ignored.
    fn from_str(s: &str) -> Result<Self, String> {
        Self::ALL
            .into_iter()
            .find(|v| v.name().eq_ignore_ascii_case(s.trim()))
            .ok_or_else(|| {
                let names: Vec<&str> = Self::ALL.iter().map(|v| v.name()).collect();
                format!("unknown view {s:?}: valid views are {}", names.join(", "))
            })
    }
}

/// How the colour view filters textures stored as 8-bit unorm (`Rgba8Unorm`) with the core
/// filters (nearest or bilinear within a level, any mipmap filter).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum Precision {
    /// `f32` throughout: texels decoded to floats, exact weights, one encode at the end.
    #[default]
    #[cfg_attr(feature = "clap", value(help = "f32 throughout"))]
    Exact,
    /// As GPUs filter unorm8 texels: 8-bit sub-texel and mip weights and a rounding to 8 bits
    /// per blend ([`texel_texture::kernel::fixed8`]; the CLI's `--precision gpu`). Other textures, other
    /// filters and the reference keep [`Precision::Exact`].
    #[cfg_attr(
        feature = "clap",
        value(help = "8-bit weights and 8-bit results per blend, as GPUs filter unorm8 textures")
    )]
    Gpu,
}

impl Precision {
    /// The name the command line and reports use: `exact` or `gpu`.
    pub fn name(self) -> &'static str {
        match self {
            Precision::Exact => "exact",
            Precision::Gpu => "gpu",
        }
    }
}

/// The colour render target's format: what [`crate::Frame`] stores per pixel, as a GPU's colour
/// attachment format. Fragments are encoded as they are written, so an 8-bit target's bytes are
/// exactly what [`crate::Frame::to_srgb8`] or [`crate::Frame::to_raw8`] make of a
/// [`ColorTarget::Float`] frame of the same draws (the same `f32` colour goes through the same
/// encoder).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum ColorTarget {
    /// Linear RGBA `f32` in [`crate::Frame::color`] (16 bytes a pixel): exact, unclamped; for
    /// EXR output, accumulation and the reference.
    #[default]
    Float,
    /// RGBA8 in [`crate::Frame::color8`] (4 bytes a pixel), RGB through the sRGB OETF (IEC
    /// 61966-2-1) and alpha linear, as Vulkan's `R8G8B8A8_SRGB`: values clamp to `[0, 1]`, NaN
    /// encodes as 0.
    Srgb8,
    /// RGBA8 in [`crate::Frame::color8`], every channel `round(255 * clamp(c, 0, 1))` with no
    /// transfer function, as Vulkan's `R8G8B8A8_UNORM` (the CLI's `--color raw`).
    Unorm8,
}

impl ColorTarget {
    /// Whether the target stores 8-bit colour ([`crate::Frame::color8`]).
    pub fn is_8bit(self) -> bool {
        self != ColorTarget::Float
    }

    /// Whether this target stores colour exactly as an 8-bit texture of `format` stores its
    /// texels (`Srgb8` for `Rgba8Srgb`, `Unorm8` for `Rgba8Unorm`), so that a texel written
    /// unchanged may be copied byte for byte: [`ColorTarget::encode`] inverts that format's
    /// decoding for every code.
    pub fn stores_like(self, format: texel_texture::Format) -> bool {
        use texel_texture::Format;
        matches!(
            (self, format),
            (ColorTarget::Srgb8, Format::Rgba8Srgb) | (ColorTarget::Unorm8, Format::Rgba8Unorm)
        )
    }

    /// One linear RGBA colour as this 8-bit target stores it ([`rgba_to_srgb8`] or
    /// [`rgba_to_unorm8`]); [`ColorTarget::Float`] encodes as [`ColorTarget::Srgb8`] (the display
    /// encoding).
    #[inline(always)]
    pub fn encode(self, c: [f32; 4]) -> [u8; 4] {
        match self {
            ColorTarget::Unorm8 => rgba_to_unorm8(c),
            _ => rgba_to_srgb8(c),
        }
    }

    /// The linear colour an 8-bit value of this target stands for (`Srgb8`: the sRGB EOTF on RGB;
    /// `Unorm8` and `Float`: `b / 255`). `encode(decode(b)) == b` for every byte.
    pub fn decode(self, b: [u8; 4]) -> [f32; 4] {
        let (srgb, unorm) = (srgb_table(), unorm8_table());
        match self {
            ColorTarget::Srgb8 => [
                srgb[b[0] as usize],
                srgb[b[1] as usize],
                srgb[b[2] as usize],
                unorm[b[3] as usize],
            ],
            _ => b.map(|x| unorm[x as usize]),
        }
    }
}

/// Everything that configures one frame.
#[derive(Clone, Copy, Debug)]
pub struct RenderSettings<'a> {
    /// Frame width in pixels, `1..=MAX_DIMENSION`.
    pub width: u32,
    /// Frame height in pixels, `1..=MAX_DIMENSION`.
    pub height: u32,
    /// Linear RGBA colour of pixels no triangle covers.
    pub background: [f32; 4],
    /// How `uv` derivatives are computed (ignored by the reference renderer, which samples level 0).
    pub derivatives: Derivatives,
    /// Perspective-correct or affine interpolation (the reference renderer is always correct).
    pub perspective: Perspective,
    /// What each pixel shows (the reference renderer always shades [`View::Color`]).
    pub view: View,
    /// Skip triangles that are clockwise in NDC (back faces, OpenGL's default front face is CCW).
    pub cull_backfaces: bool,
    /// Up to [`MAX_LIGHTS`] lights (`None` slots are skipped). With none the frame is unlit
    /// (texture times vertex colour); with any, every colour pixel is shaded by
    /// [`crate::material`]'s model with its draw's material.
    pub lights: [Option<Light>; MAX_LIGHTS],
    /// Worker threads: `None` uses rayon's global pool, `Some(n)` a local pool of `n >= 1` threads.
    /// The image is identical for every thread count.
    pub threads: Option<usize>,
    /// Count the texels each pixel's filter reads into [`crate::Frame::texels_read`] (slower: uses
    /// `Sampler::sample_counted`). Always on for [`View::Fetches`].
    pub count_texels: bool,
    /// Record each pixel's footprint (uv and derivatives) in [`crate::Frame::footprints`].
    pub capture_footprints: bool,
    /// Draw only the pixels `x0 <= i < x1, y0 <= j < y1` of `[x0, y0, x1, y1]`, as Vulkan's
    /// scissor rectangle: pixels outside are left as they are (background after a clear). Inside,
    /// every pixel is bit for bit what the whole frame gives it, derivatives included (quad
    /// derivatives evaluate helper pixels from the plane equations, so a quad cut by the scissor
    /// keeps its differences). `None` draws the whole frame; the rectangle must lie in the frame
    /// and may be empty.
    pub scissor: Option<[u32; 4]>,
    /// The colour target's format ([`ColorTarget::Float`] by default; the `texel` CLI renders
    /// into the 8-bit target its output encodes to). The reference renderer always renders into
    /// a float target.
    pub target: ColorTarget,
    /// The filtering arithmetic for unorm8 textures ([`Precision::Exact`] by default).
    pub precision: Precision,
    /// The environment map ([`crate::environment`]): light from every direction for lit
    /// frames (it makes a frame lit on its own), reflected by materials, and the background
    /// where [`Environment::background`] says so. `None` by default.
    pub environment: Option<Environment<'a>>,
}

impl RenderSettings<'_> {
    /// Defaults for a `width x height` frame: opaque black background, analytic derivatives,
    /// perspective-correct colour view, no culling, no lights, rayon's global pool, no counting,
    /// a float colour target.
    pub fn new(width: u32, height: u32) -> Self {
        RenderSettings {
            width,
            height,
            background: [0.0, 0.0, 0.0, 1.0],
            derivatives: Derivatives::Analytic,
            perspective: Perspective::Correct,
            view: View::Color,
            cull_backfaces: false,
            lights: [None; MAX_LIGHTS],
            threads: None,
            count_texels: false,
            capture_footprints: false,
            scissor: None,
            target: ColorTarget::Float,
            precision: Precision::Exact,
            environment: None,
        }
    }

    /// The scissor rectangle `[x0, y0, x1, y1]` (the whole frame when there is none).
    pub fn scissor_rect(&self) -> [u32; 4] {
        self.scissor.unwrap_or([0, 0, self.width, self.height])
    }

    /// Whether any light or an environment is set (the frame is shaded).
    pub fn is_lit(&self) -> bool {
        self.lights.iter().any(Option::is_some) || self.environment.is_some()
    }

    /// The lights that are set.
    pub fn active_lights(&self) -> impl Iterator<Item = &Light> {
        self.lights.iter().flatten()
    }

    /// Whether texels are counted (`count_texels` or the fetches view).
    pub fn counts_texels(&self) -> bool {
        self.count_texels || self.view == View::Fetches
    }

    /// Check the settings.
    ///
    /// # Errors
    /// [`RasterError::InvalidSize`], [`RasterError::TooManyPixels`],
    /// [`RasterError::InvalidThreadCount`], [`RasterError::NonFiniteBackground`],
    /// [`RasterError::NonFiniteLight`], [`RasterError::InvalidScissor`].
    pub fn validate(&self) -> Result<(), RasterError> {
        let (width, height) = (self.width, self.height);
        if width == 0 || height == 0 || width > MAX_DIMENSION || height > MAX_DIMENSION {
            return Err(RasterError::InvalidSize {
                width,
                height,
                max: MAX_DIMENSION,
            });
        }
        let pixels = u64::from(width) * u64::from(height);
        if pixels > MAX_PIXELS {
            return Err(RasterError::TooManyPixels {
                width,
                height,
                pixels,
                max: MAX_PIXELS,
            });
        }
        if self.threads == Some(0) {
            return Err(RasterError::InvalidThreadCount(0));
        }
        if !self.background.iter().all(|c| c.is_finite()) {
            return Err(RasterError::NonFiniteBackground(self.background));
        }
        if let Some(r @ [x0, y0, x1, y1]) = self.scissor {
            if x0 > x1 || y0 > y1 || x1 > width || y1 > height {
                return Err(RasterError::InvalidScissor {
                    scissor: r,
                    width,
                    height,
                });
            }
        }
        if let Some(l) = self.active_lights().find(|l| !l.is_finite()) {
            return Err(RasterError::NonFiniteLight(format!("{l:?}")));
        }
        if let Some(e) = self.environment.filter(|e| !e.is_valid()) {
            return Err(RasterError::NonFiniteLight(format!(
                "environment intensity {:?}",
                e.intensity
            )));
        }
        Ok(())
    }
}

impl Default for RenderSettings<'_> {
    /// [`RenderSettings::new`] at 1280 x 720.
    fn default() -> Self {
        RenderSettings::new(1280, 720)
    }
}
