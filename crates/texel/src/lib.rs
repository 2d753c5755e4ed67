//! texel: texture mapping and texture filtering on the CPU, measured.
//!
//! This crate is the front door to the texel libraries. Its root holds the types a program
//! starts from ([`Scene`], [`PreparedScene`], [`Filter`], [`SamplerDescriptor`], [`Sampler`],
//! [`Texture`], [`Frame`], [`Report`], [`Error`]) and the calls that do a whole job
//! ([`render_scene`], [`render_image`], [`reference_scene`], [`compare::compare`],
//! [`timing::time_filters`]); its modules name the rest of what those take and return:
//! [`texture`] (textures, mip pyramids, every filter behind a [`Sampler`]), [`raster`] (the
//! clipped, perspective-correct rasterizer and the supersampled reference), [`scene`] (scene
//! files, OBJ and glTF meshes, built-in scenes), [`quality`] (PSNR, SSIM, reports), [`lab`] (a
//! student's GLSL shader run and graded), [`ao`] (baked ambient occlusion) and [`memory`]. The
//! libraries' own crates (`texel-texture`, `texel-raster`, `texel-shade`, ...) hold the rest: the
//! shading inputs of a draw, the lab's per-mode rules, the ripmap and summed-area tables. A
//! program renders a scene the way the `texel` command does:
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
//! [`PreparedScene`] with [`FramePlan::render`] as `examples/render_scene.rs` does, or
//! [`raster::render`] on a plan's settings and draws.

pub mod compare;
mod entry;
pub mod timing;

pub use entry::{
    frame_image, reference_prepared, reference_scene, render_image, render_scene, scene_inputs,
    ReferenceOptions, RenderOptions,
};
pub use texel_prepare::{
    ColorHandling, Error, FrameOptions, FramePlan, MemoryBudget, PreparedScene, ReferenceRun,
    SceneOptions, TextureStorage,
};
pub use texel_quality::Report;
pub use texel_raster::{render, ColorTarget, DrawCall, Frame, RenderSettings, View};
pub use texel_scene::{Scene, SceneLimits};
pub use texel_texture::{Filter, Sampler, SamplerDescriptor, Texture};

/// Textures, their mip pyramids and the sampler that filters them.
pub mod texture {
    pub use texel_texture::base::color::{displayed, linear_to_srgb8, srgb_to_linear};
    pub use texel_texture::{
        Address, AddressMode, Axes, BorderColor, BoundSampler, ColorSpace, Convention, Cubic,
        FilterMode, Footprint, Format, Lanes, LevelInfo, LevelTexels, Limits, LoadOptions, Loaded,
        MipmapFilterMode, Sampler, SamplerDescriptor, SpanKind, Texture, TextureError, Wants,
        MAX_TEXEL, NON_FINITE_CLAMP,
    };
}

/// The rasterizer, its settings and the supersampled reference.
pub mod raster {
    pub use texel_raster::adaptive::{
        display_half_width, DEFAULT_SEED, DEFAULT_TOLERANCE_STEPS, MAX_ADAPTIVE_SPP,
    };
    pub use texel_raster::reference::Progress;
    pub use texel_raster::warp::{warp_perspective, WarpError, MAX_WARP_PIXELS};
    pub use texel_raster::{
        draw_into, limit_level, on_threads, render, render_reference_strata, set_streaming,
        simd_level, ColorTarget, Derivatives, DrawCall, Frame, Perspective, Precision,
        ProgressiveReference, RasterError, ReferenceEstimate, ReferencePlan, ReferenceStatus,
        RenderSettings, SimdLevel, SpecularAa, Streaming, UvEvaluation, View,
    };
    pub use texel_raster::{UvMapping, Vertex};
    pub use texel_shade::ShadeError;
}

/// Scene files, meshes and the built-in scenes.
pub mod scene {
    pub use texel_scene::{
        builtin, builtin_names, knot_mesh, load_gltf_with, load_obj_with, shaded_builtin_names,
        Camera, ColorInput, Displacement, EncodedImage, EnvironmentSource, EnvironmentSpec,
        LayerBlendSpec, LayerOrder, LayerSpec, LightSpec, Mapping, MaterialSpec, Mesh, MeshFilters,
        NoiseKind, Output, Procedural, ScalarInput, Scene, SceneError, SceneLimits, Sky,
        SpecularAaSpec, SphereUv, TextureGroup, TextureKey, TextureSampler, TextureSource,
        TextureSpec, TextureUse, MAX_SHADING_SAMPLES,
    };
}

/// Image quality: PSNR, SSIM, error maps and reports.
pub mod quality {
    pub use texel_quality::html::escape as html_escape;
    pub use texel_quality::ssim::ssim;
    pub use texel_quality::{
        block_psnr, encode_exr_with_text, png_with_text, psnr, psnr_band, viridis,
        write_exr_atomic, Encoding, FilterRow, Image8, Mask, Report, DEFAULT_BLOCK, MAX_SIDE,
        OUTSIDE,
    };
    pub use texel_quality::{Orbit, QualityError, ReferenceSummary, Scores};
}

/// The texture-filtering lab: its scenes, its GLSL shaders and their grading.
pub mod lab {
    pub use texel_lab::gl::GlDraw;
    pub use texel_lab::gl::{GlScene, ShaderDraws};
    pub use texel_lab::scene::device_scene;
    pub use texel_lab::source::{level_size_queries, violations};
    pub use texel_lab::{
        grade, read_shader, run_device, Capture, DeviceRun, Error, Gl, GlError, GradeOptions,
        Images, Job, LabReport, LabScene, LevelRange, ModeResult, Names, PyramidMemory, Questions,
        RubricPart, Verdict, Violation,
    };
}

/// Ambient occlusion baked into a texture.
pub mod ao {
    pub use texel_prepare::ao::{
        bake_ao, protected_levels, AoMap, AoMesh, AoSettings, MAX_AO_RAYS, MAX_AO_SIZE,
    };
}

/// What a prepared scene costs in memory.
pub mod memory {
    pub use texel_prepare::memory::{default_limit, mib, FRAME_BYTES_PER_PIXEL};
}
