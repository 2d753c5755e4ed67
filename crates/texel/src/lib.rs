//! texel: texture mapping and texture filtering on the CPU, measured.
//!
//! This crate is the front door to the texel libraries: it re-exports them
//! ([`texture`]: textures, mip pyramids and every filter behind a [`Sampler`]; [`raster`]: the
//! clipped, perspective-correct rasterizer and the supersampled reference; [`scene`]: scene files,
//! OBJ and glTF meshes, built-in scenes; [`quality`]: PSNR, SSIM and reports) and owns the step
//! between a [`Scene`] and draw calls ([`PreparedScene`]), so that a program renders a scene the
//! way the `texel` command does:
//!
//! ```
//! use texel::{render_scene, Filter, RenderOptions, Scene};
//!
//! let scene = Scene::load("builtin:ground")?;
//! let options = RenderOptions {
//!     filter: Some(Filter::Aniso16),
//!     size: Some((64, 36)),
//!     ..RenderOptions::default()
//! };
//! let frame = render_scene(&scene, &options)?;
//! assert_eq!((frame.width, frame.height), (64, 36));
//! // The ground covers the lower part of the frame; the sky is the background.
//! assert!(frame.covered(63 * 36 - 1) && !frame.covered(0));
//! # Ok::<(), texel::Error>(())
//! ```
//!
//! For more control (several filters on one loaded scene, debug views, threads, timing), use
//! [`PreparedScene`] with [`raster::render`] as `examples/render_scene.rs` does.

pub mod ao;
pub mod bake;
pub mod bvh;
mod error;
mod filter;
pub mod memory;
mod prepare;
pub mod tessellate;

pub use texel_quality as quality;
pub use texel_raster as raster;
pub use texel_scene as scene;
pub use texel_texture as texture;

pub use error::Error;
pub use filter::Filter;
pub use memory::MemoryBudget;
pub use prepare::{ColorHandling, PreparedScene, SceneOptions};
pub use texel_raster::{render, ColorTarget, DrawCall, Frame, RenderSettings, View};
pub use texel_scene::{Scene, SceneLimits};
pub use texel_texture::{Sampler, SamplerDescriptor, Texture};

/// How [`render_scene`] renders.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RenderOptions {
    /// The filter of every mesh; `None`: a glTF mesh's own sampler filters, else trilinear.
    pub filter: Option<Filter>,
    /// Output size `(width, height)`, overriding the scene's.
    pub size: Option<(u32, u32)>,
    /// Colour handling of textures and output.
    pub color: ColorHandling,
    /// What each pixel shows (the textured colour, or a debug view).
    pub view: View,
    /// Most bytes the render may hold at once (meshes, textures, frame); `None`: the process's
    /// default ([`MemoryBudget::process_default`]).
    pub max_memory: Option<u64>,
}

/// A frame's colour as an 8-bit image in `encoding`: an 8-bit frame of that encoding as stored,
/// anything else through [`Frame::to_8bit`] (a float frame is quantised exactly as an 8-bit
/// target of the same draws would store it).
///
/// # Errors
/// [`quality::QualityError`] for a frame of no pixels or sides beyond [`quality::MAX_SIDE`].
pub fn frame_image(
    frame: &Frame,
    encoding: quality::Encoding,
) -> Result<quality::Image8, quality::QualityError> {
    let target = match encoding {
        quality::Encoding::Srgb => ColorTarget::Srgb8,
        quality::Encoding::Linear => ColorTarget::Unorm8,
    };
    quality::Image8::from_rgba_bytes(frame.width, frame.height, &frame.to_8bit(target))
}

/// Render `scene` as the options say: load its textures, build the samplers (and any ripmap or
/// summed-area table) and draw every mesh, on all cores. The frame's colour target is the 8-bit
/// one the colour handling encodes to ([`PreparedScene::settings`]); [`frame_image`] gives it as
/// an [`quality::Image8`] to write a PNG.
///
/// # Errors
/// [`Error::OverBudget`], [`Error::Scene`] (textures that cannot be loaded), [`Error::Texture`],
/// [`Error::Raster`] (an invalid size).
pub fn render_scene(scene: &Scene, options: &RenderOptions) -> Result<Frame, Error> {
    let mut budget = match options.max_memory {
        Some(b) => MemoryBudget::new(b, format!("the memory limit of {}", memory::mib(b))),
        None => MemoryBudget::process_default(),
    };
    let prepared = PreparedScene::new(
        scene.clone(),
        &SceneOptions {
            size: options.size,
            color: options.color,
            replace_non_finite: false,
            ..SceneOptions::default()
        },
        &mut budget,
    )?;
    let samplers = match options.filter {
        Some(f) => prepared.samplers(f)?,
        None => prepared.default_samplers()?,
    };
    prepared.build_structures_within(&samplers, &mut budget)?;
    let mut settings = prepared.settings_for(&samplers, &prepared.scene.camera);
    settings.view = options.view;
    Ok(render(&settings, &prepared.draws(&samplers))?)
}
