//! texel-raster: a clipped, watertight, perspective-correct textured-triangle rasterizer on all
//! cores, with debug views and the supersampled reference renderer every filter is judged against.
//!
//! Pipeline (docs/guide/conventions.md): world-space [`Vertex`]es are transformed by
//! a [`DrawCall`]'s `clip_from_world` ([`camera`]), clipped in homogeneous space against the near and
//! far planes and a guard band ([`clip`]), set up once per triangle with fixed-point edge functions,
//! the top-left fill rule and homogeneous plane equations ([`setup`]), binned to 64x64 tiles and
//! rasterised in parallel ([`tile`]); every covered pixel gets perspective-correct barycentrics and
//! `uv` derivatives ([`interp`]) that become the sampler's footprint, and is shaded (`shade.rs`) or
//! shown through a debug view ([`views`]). [`reference::render_reference`] supersamples the same
//! geometry.
//!
//! ```
//! use glam::{Mat4, Vec2, Vec3};
//! use texel_raster::{render, DrawCall, RenderSettings, Vertex};
//! use texel_texture::{Format, Limits, Sampler, SamplerDescriptor, Texture};
//!
//! // A white 1x1 texture on a triangle given directly in NDC (clip_from_world = identity, w = 1).
//! let tex = Texture::from_fn(1, 1, Format::Rgba8Unorm, &Limits::default(), |_, _| [1.0; 4])?;
//! let sampler = Sampler::new(SamplerDescriptor::default())?;
//! let vertices = [
//!     Vertex::new(Vec3::new(-1.0, -1.0, 0.0), Vec2::new(0.0, 1.0)),
//!     Vertex::new(Vec3::new(1.0, -1.0, 0.0), Vec2::new(1.0, 1.0)),
//!     Vertex::new(Vec3::new(-1.0, 1.0, 0.0), Vec2::new(0.0, 0.0)),
//! ];
//! let draw = DrawCall {
//!     vertices: &vertices,
//!     triangles: &[[0, 1, 2]],
//!     texture: &tex,
//!     sampler: &sampler,
//!     clip_from_world: Mat4::IDENTITY,
//!     material: None,
//!     uv_mapping: None,
//! };
//! let frame = render(&RenderSettings::new(8, 8), &[draw])?;
//! // The lower-left half is white. The 8 diagonal pixel centres lie exactly on the hypotenuse, a
//! // right edge under the top-left rule, so they belong to the (absent) upper-right neighbour.
//! assert_eq!(frame.color[frame.index(0, 7)], [1.0; 4]);
//! assert_eq!(frame.color[frame.index(7, 0)], [0.0, 0.0, 0.0, 1.0]);
//! assert_eq!(frame.covered_pixels(), 28);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

pub mod adaptive;
pub mod camera;
pub mod clip;
mod draw;
mod error;
pub mod exact;
mod frame;
pub mod interp;
mod point;
pub mod reference;
mod relief;
mod settings;
pub mod setup;
mod shade;
mod stream;
pub mod tile;
pub mod views;
pub mod warp;

pub use adaptive::{
    render_reference_adaptive, ProgressiveReference, ReferenceEstimate, ReferencePlan,
    ReferenceStatus,
};
pub use draw::{DrawCall, UvEvaluation, UvMapping, Vertex};
pub use error::RasterError;
pub use exact::{render_exact, ExactImage};
pub use frame::Frame;
pub use reference::{render_reference, render_reference_strata};
pub use settings::{
    ColorTarget, Derivatives, Perspective, Precision, RenderSettings, View, MAX_DIMENSION,
    MAX_PIXELS,
};
pub use stream::{last_level_cache_bytes, set_streaming, streaming, Streaming};
pub use texel_shade::{environment, inputs, layers, material};
pub use texel_shade::{
    ChannelInput, Displacement, Environment, EnvironmentMaps, Layer, LayerBlend, Layers, Light,
    Material, SpecularAa, TextureInput, MAX_LIGHTS,
};
pub use texel_texture::engine::dispatch::{level as simd_level, limit_level, SimdLevel};

/// Render `draws` (in order; equal depths keep the earlier fragment) into a new [`Frame`].
///
/// Tiles are rendered in parallel on rayon's global pool, or on a local pool of
/// `settings.threads` threads; the result is bit for bit the same for every thread count.
/// Degenerate, non-finite, back-facing (when culling) and invisible triangles are skipped.
///
/// # Errors
/// Invalid settings ([`RenderSettings::validate`]), [`RasterError::IndexOutOfRange`],
/// [`RasterError::ThreadPool`].
pub fn render(settings: &RenderSettings, draws: &[DrawCall]) -> Result<Frame, RasterError> {
    settings.validate()?;
    setup::validate_draws(draws)?;
    with_threads(settings.threads, || {
        let mut frame = Frame::new(settings);
        tile::draw_frame(settings, draws, &mut frame)?;
        Ok(frame)
    })
}

/// [`render`] into an existing frame, reusing its buffers: the frame is cleared
/// ([`Frame::reset`]) and drawn. The result is bit for bit what [`render`] returns. For repeated
/// renders of one size this saves the allocation (and page faults) of a new frame.
///
/// # Errors
/// As [`render`]; on error the frame is left unchanged.
pub fn render_into(
    settings: &RenderSettings,
    draws: &[DrawCall],
    frame: &mut Frame,
) -> Result<(), RasterError> {
    settings.validate()?;
    setup::validate_draws(draws)?;
    with_threads(settings.threads, || {
        frame.reset(settings);
        tile::draw_frame(settings, draws, frame)
    })
}

/// Draw on top of `frame` without clearing it, as a GPU draw call into a bound render target:
/// fragments are depth-tested against the frame's depth and overwrite its colour. Use
/// [`Frame::reset`] (the clear) first for a fresh image; `reset` then `draw_into` equals
/// [`render_into`] bit for bit. This is what `texel bench` times, as the llvmpipe comparison
/// script times the draw after an untimed clear. A frame that still holds its clear
/// ([`Frame::holds_clear`]) may be drawn from the clear rather than from its buffers, as a GPU
/// draws into a fast-cleared target: pixels written by hand after [`Frame::reset`] need
/// [`Frame::forget_clear`] first.
///
/// # Errors
/// As [`render`], and [`RasterError::FrameMismatch`] when the frame was not reset for these
/// settings (size or side channels differ, see [`Frame::matches`]). On error nothing is drawn.
pub fn draw_into(
    settings: &RenderSettings,
    draws: &[DrawCall],
    frame: &mut Frame,
) -> Result<(), RasterError> {
    settings.validate()?;
    setup::validate_draws(draws)?;
    if !frame.matches(settings) {
        return Err(RasterError::FrameMismatch {
            frame: [frame.width, frame.height],
            settings: [settings.width, settings.height],
        });
    }
    with_threads(settings.threads, || {
        tile::draw_frame(settings, draws, frame)
    })
}

/// Run `f` on rayon's global pool (`None`: all cores) or on a local pool of `n` threads: how
/// every texel job (a frame, a reference, a bench, a bake) honours a thread count.
///
/// # Errors
/// [`RasterError::InvalidThreadCount`] for 0, [`RasterError::ThreadPool`] when the pool cannot
/// start.
pub fn on_threads<T: Send>(
    threads: Option<usize>,
    f: impl FnOnce() -> T + Send,
) -> Result<T, RasterError> {
    match threads {
        None => Ok(f()),
        Some(0) => Err(RasterError::InvalidThreadCount(0)),
        Some(n) => Ok(rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .map_err(|e| RasterError::ThreadPool {
                threads: n,
                message: e.to_string(),
            })?
            .install(f)),
    }
}

/// [`on_threads`] for work that can fail.
pub(crate) fn with_threads<T: Send>(
    threads: Option<usize>,
    f: impl FnOnce() -> Result<T, RasterError> + Send,
) -> Result<T, RasterError> {
    on_threads(threads, f)?
}
