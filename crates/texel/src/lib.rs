//! texel: texture mapping and texture filtering on the CPU, measured.
//!
//! This crate is the front door to the texel libraries: it re-exports them
//! ([`texture`]: textures, mip pyramids and every filter behind a [`Sampler`]; [`raster`]: the
//! clipped, perspective-correct rasterizer and the supersampled reference; [`scene`]: scene files,
//! OBJ and glTF meshes, built-in scenes; [`quality`]: PSNR, SSIM and reports; [`prepare`]: the
//! step between a [`Scene`] and draw calls, [`PreparedScene`]) and adds the few calls that do a
//! whole job, so that a program renders a scene the way the `texel` command does:
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

pub mod compare;
mod entry;
pub mod timing;

pub use texel_io as io;
pub use texel_lab as lab;
pub use texel_quality as quality;
pub use texel_raster as raster;
pub use texel_scene as scene;
pub use texel_texture as texture;

pub use entry::{
    encoding, frame_image, reference_prepared, reference_scene, render_image, render_scene,
    scene_inputs, show_view, ReferenceOptions, RenderOptions, REFERENCE_BYTES_PER_PIXEL,
};
pub use texel_prepare as prepare;
pub use texel_prepare::{ao, bake, bvh, memory, tessellate};
pub use texel_prepare::{
    ColorHandling, Error, FramePlan, MemoryBudget, PreparedScene, ReferenceRun, SceneOptions,
    TextureStorage,
};
pub use texel_raster::{render, ColorTarget, DrawCall, Frame, RenderSettings, View};
pub use texel_scene::{Scene, SceneLimits};
pub use texel_texture::{Filter, Sampler, SamplerDescriptor, Texture};
