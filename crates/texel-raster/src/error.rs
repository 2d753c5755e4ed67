//! The one error type of texel-raster.

use thiserror::Error;

/// Everything that can go wrong when rendering.
///
/// Only bad input is an error: degenerate, non-finite or invisible triangles are not errors, they are
/// skipped (as a GPU skips them).
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum RasterError {
    /// Width or height is zero, or a side exceeds [`crate::MAX_DIMENSION`].
    #[error("frame size {width}x{height} is invalid: each side must be in 1..={max}")]
    InvalidSize {
        /// Requested width in pixels.
        width: u32,
        /// Requested height in pixels.
        height: u32,
        /// The largest side allowed, in pixels.
        max: u32,
    },
    /// The frame has more pixels than [`crate::MAX_PIXELS`] (its buffers would not fit in memory).
    #[error("frame size {width}x{height} has {pixels} pixels, over the limit of {max}")]
    TooManyPixels {
        /// Requested width in pixels.
        width: u32,
        /// Requested height in pixels.
        height: u32,
        /// `width * height`.
        pixels: u64,
        /// The limit in pixels.
        max: u64,
    },
    /// A triangle refers to a vertex that does not exist.
    #[error("draw {draw}, triangle {triangle}: vertex index {index} out of range (the draw has {vertex_count} vertices)")]
    IndexOutOfRange {
        /// Index of the draw call in the slice passed to `render`.
        draw: usize,
        /// Index of the triangle within the draw.
        triangle: usize,
        /// The offending vertex index.
        index: u32,
        /// Number of vertices in the draw.
        vertex_count: usize,
    },
    /// [`crate::draw_into`] was given a frame not reset for its settings (size or side channels).
    #[error("frame is {}x{} or lacks side channels; the settings want {}x{}: reset the frame first", frame[0], frame[1], settings[0], settings[1])]
    FrameMismatch {
        /// The frame's width and height.
        frame: [u32; 2],
        /// The settings' width and height.
        settings: [u32; 2],
    },
    /// `threads` is `Some(0)`.
    #[error("thread count must be at least 1, got {0}")]
    InvalidThreadCount(usize),
    /// The local rayon thread pool could not be built.
    #[error("could not build a pool of {threads} threads: {message}")]
    ThreadPool {
        /// Requested threads.
        threads: usize,
        /// rayon's message.
        message: String,
    },
    /// The background colour has a NaN or infinite channel.
    #[error("background colour {0:?} is not finite")]
    NonFiniteBackground([f32; 4]),
    /// The scissor rectangle is reversed or reaches outside the frame.
    #[error("scissor rectangle {scissor:?} ([x0, y0, x1, y1]) does not lie in the {width}x{height} frame")]
    InvalidScissor {
        /// The rectangle `[x0, y0, x1, y1]`.
        scissor: [u32; 4],
        /// Frame width in pixels.
        width: u32,
        /// Frame height in pixels.
        height: u32,
    },
    /// A light has a non-finite number.
    #[error("light is not finite: {0}")]
    NonFiniteLight(String),
    /// A draw's material has a factor out of range or not finite.
    #[error("draw {draw}: material factors out of range (roughness and metallic in [0, 1], finite colour and normal scale, channels 0-3)")]
    InvalidMaterial {
        /// Index of the draw call.
        draw: usize,
    },
    /// The reference renderer's samples per pixel side is outside `1..=MAX_SPP_SIDE`.
    #[error("reference samples per pixel side {spp_side} is invalid: it must be in 1..={max}")]
    InvalidSamplesPerPixel {
        /// Requested samples per side (the pixel gets `spp_side^2` samples).
        spp_side: u32,
        /// The largest allowed.
        max: u32,
    },
    /// A converging reference's plan is outside its ranges.
    #[error(
        "reference plan is invalid: min_spp {min_spp} must be in 1..={min_max}, max_spp {max_spp} in min_spp..={max_max}, tolerance {tolerance} finite and not negative",
    )]
    InvalidReferencePlan {
        /// The minimum samples per pixel asked for.
        min_spp: u32,
        /// The largest minimum allowed (`MAX_SPP_SIDE^2`).
        min_max: u32,
        /// The maximum samples per pixel asked for.
        max_spp: u32,
        /// The largest maximum allowed (`MAX_ADAPTIVE_SPP`).
        max_max: u32,
        /// The tolerance asked for.
        tolerance: f64,
    },
    /// A reference plan's maximum samples per pixel below its minimum.
    #[error("max_spp {max_spp} is below spp {min_spp}: the maximum must be at least the minimum")]
    MaxSppBelowMin {
        /// The minimum samples per pixel asked for.
        min_spp: u32,
        /// The maximum asked for.
        max_spp: u32,
    },
    /// A reference plan's tolerance, in 8-bit steps, negative or not finite.
    #[error("tolerance must be a finite number of 8-bit steps, 0 or more; got {0}")]
    InvalidTolerance(f64),
    /// The work was stopped before it had a result.
    #[error("interrupted before the first pass of the reference completed")]
    Interrupted,
    /// Building the shading inputs (an environment map's faces that do not fit its mapping).
    #[error(transparent)]
    Shade(#[from] texel_shade::ShadeError),
    /// A texture could not be created (the reference renderer builds its own sampler).
    #[error(transparent)]
    Texture(#[from] texel_texture::TextureError),
}
