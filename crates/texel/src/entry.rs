//! The few calls that do a whole job on a [`Scene`]: render it ([`render_scene`], and as the
//! 8-bit image `texel render` writes, [`render_image`]) and make its converging reference
//! ([`reference_scene`], or [`PreparedScene::reference`] on a scene already prepared).

use std::sync::atomic::AtomicBool;

#[cfg(doc)]
use texel_prepare::FramePlan;
use texel_prepare::{
    ColorHandling, Error, FrameOptions, MemoryBudget, PreparedScene, ReferenceRun, SceneOptions,
    TextureStorage,
};
use texel_raster::{ColorTarget, Frame, RasterError, ReferenceEstimate, ReferencePlan, View};
use texel_scene::{Camera, Scene};
use texel_texture::Filter;

use texel_quality as quality;

/// Bytes per pixel a converging reference holds besides its frame: its running statistics,
/// masks and results.
pub(crate) const REFERENCE_BYTES_PER_PIXEL: u64 = 192;

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
    /// Worker threads; `None`: all cores.
    pub threads: Option<usize>,
    /// How 8-bit textures are kept: as stored, or decoded to float (the same image; faster mip
    /// and anisotropic filtering, four times the texture memory; a texture whose float copy does
    /// not fit `max_memory` stays stored).
    pub texture_storage: TextureStorage,
}

/// `scene` prepared as a command prepares it: at `size` (or its own), with `color` handling,
/// 8-bit textures kept as `texture_storage` says, non-finite and out-of-range texels refused,
/// every other option at its default.
fn prepare(
    scene: &Scene,
    size: Option<(u32, u32)>,
    color: ColorHandling,
    texture_storage: TextureStorage,
    budget: &mut MemoryBudget,
) -> Result<PreparedScene, Error> {
    let options = SceneOptions {
        size,
        color,
        replace_non_finite: false,
        texture_storage,
        ..SceneOptions::default()
    };
    PreparedScene::new(scene.clone(), &options, budget)
}

/// The files a scene reads, found by loading and preparing it as rendering does (so by the code
/// that reads them): the scene file, its meshes (OBJ, glTF and the glTF's buffers and images),
/// textures and environment maps, each once, in the order they are first opened. `arg` is a path
/// or `builtin:NAME` (which reads no file); `max_memory` bounds the preparation as
/// [`RenderOptions::max_memory`] does. What a job needs beside it on another machine.
///
/// # Errors
/// As [`render_scene`] before its first pixel: the scene cannot be loaded, a texture cannot be
/// decoded, the budget is exceeded.
pub fn scene_inputs(arg: &str, max_memory: Option<u64>) -> Result<Vec<std::path::PathBuf>, Error> {
    let (prepared, files) = texel_io::record_opened(|| -> Result<(), Error> {
        let scene = Scene::load(arg)?;
        let mut budget = MemoryBudget::limit_or_default(max_memory);
        prepare(
            &scene,
            None,
            ColorHandling::default(),
            TextureStorage::Stored,
            &mut budget,
        )?;
        Ok(())
    });
    prepared.map(|()| files)
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
/// summed-area table) and draw every mesh ([`FramePlan::render`]). The frame's colour target is
/// the 8-bit one the colour handling encodes to ([`PreparedScene::settings`]); a debug view's,
/// whose values are meant for display, is sRGB whatever the colour handling
/// ([`FrameOptions::apply`]). [`render_image`] gives the image.
///
/// # Errors
/// [`Error::OverBudget`], [`Error::Scene`] (textures that cannot be loaded), [`Error::Texture`],
/// [`Error::Raster`] (an invalid size).
pub fn render_scene(scene: &Scene, options: &RenderOptions) -> Result<Frame, Error> {
    Ok(render_encoded(scene, options)?.0)
}

/// [`render_scene`]'s frame and the encoding of its 8-bit image.
fn render_encoded(
    scene: &Scene,
    options: &RenderOptions,
) -> Result<(Frame, quality::Encoding), Error> {
    let mut budget = MemoryBudget::limit_or_default(options.max_memory);
    let prepared = prepare(
        scene,
        options.size,
        options.color,
        options.texture_storage,
        &mut budget,
    )?;
    let frame = FrameOptions {
        view: options.view,
        threads: options.threads,
        ..FrameOptions::default()
    };
    prepared.plan(options.filter, &mut budget)?.render(&frame)
}

/// [`render_scene`]'s frame as the 8-bit RGBA image `texel render -o FILE.png` writes: encoded
/// as the colour handling says, a debug view in sRGB.
///
/// # Errors
/// As [`render_scene`].
pub fn render_image(scene: &Scene, options: &RenderOptions) -> Result<quality::Image8, Error> {
    let (frame, encoding) = render_encoded(scene, options)?;
    Ok(frame_image(&frame, encoding)?)
}

/// How [`reference_scene`] makes a reference.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ReferenceOptions {
    /// Samples, tolerance and seed; its display encoding follows `color`.
    pub plan: ReferencePlan,
    /// Output size `(width, height)`, overriding the scene's.
    pub size: Option<(u32, u32)>,
    /// Colour handling of textures and output.
    pub color: ColorHandling,
    /// Worker threads; `None`: all cores.
    pub threads: Option<usize>,
    /// Only these pixels ([`ReferenceRun::scissor`]).
    pub scissor: Option<[u32; 4]>,
    /// Most bytes the reference may hold at once; `None`: the process's default.
    pub max_memory: Option<u64>,
}

/// The converging reference of `scene` as `texel reference` makes it: the scene prepared as the
/// options say, 192 bytes a pixel charged for the statistics, then
/// [`PreparedScene::reference`] from the scene's camera. `stop`, once set, ends it after the
/// current pass (the estimate says it was interrupted).
///
/// # Errors
/// As [`render_scene`] and [`PreparedScene::reference`].
pub fn reference_scene(
    scene: &Scene,
    options: &ReferenceOptions,
    stop: Option<&AtomicBool>,
) -> Result<ReferenceEstimate, Error> {
    let mut budget = MemoryBudget::limit_or_default(options.max_memory);
    let prepared = prepare(
        scene,
        options.size,
        options.color,
        TextureStorage::Stored,
        &mut budget,
    )?;
    let plan = ReferencePlan {
        srgb_display: options.color == ColorHandling::Srgb,
        ..options.plan
    };
    let run = ReferenceRun {
        plan,
        threads: options.threads,
        scissor: options.scissor,
        progress: None,
        stop,
    };
    reference_prepared(&prepared, &prepared.scene.camera, &run, &mut budget)
}

/// The converging reference of a prepared scene seen by `camera`, as `texel reference` and
/// [`reference_scene`] make it: 192 bytes a pixel charged to `budget` for its
/// statistics (and kept: the estimate holds them), then [`PreparedScene::reference`]. A stop before the first pass is
/// [`Error::Cancelled`]; one after it returns the estimate so far, marked interrupted.
///
/// # Errors
/// [`Error::OverBudget`], [`Error::Cancelled`] and [`PreparedScene::reference`]'s.
pub fn reference_prepared(
    prepared: &PreparedScene,
    camera: &Camera,
    run: &ReferenceRun,
    budget: &mut MemoryBudget,
) -> Result<ReferenceEstimate, Error> {
    let bytes = u64::from(prepared.width) * u64::from(prepared.height) * REFERENCE_BYTES_PER_PIXEL;
    budget.take("the reference's per-pixel statistics", bytes)?;
    prepared.reference(camera, run).map_err(cancelled)
}

/// A reference stopped before its first pass ([`RasterError::Interrupted`]) as
/// [`Error::Cancelled`]; any other error as it is.
pub(crate) fn cancelled(e: Error) -> Error {
    match e {
        Error::Raster(RasterError::Interrupted) => Error::Cancelled,
        e => e,
    }
}
