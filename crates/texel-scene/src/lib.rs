//! texel-scene: what to render — camera, meshes and textures — from TOML scene files, OBJ and glTF
//! meshes, procedural textures and built-in demo scenes. Independent of the rasterizer.
//!
//! - [`Scene::load`] takes `builtin:NAME` ([`builtin_names`]) or a path to a TOML file
//!   (format: [`mod@file`]), and validates it ([`Scene::validate`]).
//! - [`Camera::clip_from_world`] gives the OpenGL-style clip transform.
//! - [`TextureSpec::load`] / [`Scene::load_textures`] build `texel_texture::Texture`s, with an
//!   optional colour-space override (the CLI's `--color raw`); textures that load to the same
//!   texels ([`TextureKey`], [`Scene::texture_groups`]) are loaded once and shared.
//!
//! ```
//! use texel_scene::{Scene, TextureSource, Procedural};
//! use texel_texture::{AddressMode, ColorSpace, Limits};
//!
//! let scene = Scene::load("builtin:ground")?;
//! assert_eq!((scene.output.width, scene.output.height), (1280, 720));
//! assert_eq!(scene.meshes[0].address_mode_u, AddressMode::Repeat);
//! let spec = &scene.textures["checker"];
//! assert_eq!(
//!     spec.source,
//!     TextureSource::Procedural(Procedural::Checker { width: 1024, height: 1024, checks: 8 })
//! );
//! // --color raw: every texture linear.
//! let textures = scene.load_textures(Some(ColorSpace::Linear), &Limits::default())?;
//! assert_eq!(textures["checker"].texel(0, 0, 0), Some([0.0, 0.0, 0.0, 1.0]));
//!
//! // Project the camera's target to the centre of the image.
//! let aspect = scene.output.width as f32 / scene.output.height as f32;
//! let clip = scene.camera.clip_from_world(aspect) * scene.camera.target.extend(1.0);
//! assert!((clip.x / clip.w).abs() < 1e-6 && (clip.y / clip.w).abs() < 1e-6);
//! # Ok::<(), texel_scene::SceneError>(())
//! ```

mod builtin;
mod camera;
mod environment;
mod error;
pub mod file;
mod gltf_import;
mod limits;
mod model;
mod obj;
mod procedural;
mod tangents;
mod texture;
mod validate;
pub use camera::MIN_FOVY_DEG;

pub use builtin::{
    builtin, builtin_names, knot_mesh, shaded_builtin_names, GLOSSY_TOML, GROUND_ROTATION_DEG,
    GROUND_TOML, KNOT_RADIUS, KNOT_SEGMENTS, TRIANGLE_TOML, ZONEPLATE_TOML,
};
pub use camera::Camera;
pub use environment::{
    default_sky_size, max_sky_width, CubeCross, EnvironmentSource, EnvironmentSpec, Sky,
    MAX_SKY_TEXELS, MAX_SKY_WIDTH,
};
pub use error::SceneError;
pub use gltf_import::{import_gltf, load_gltf, load_gltf_slice, load_gltf_with, GltfScene};
pub use limits::SceneLimits;
pub use model::{
    ColorInput, Displacement, EncodedImage, LayerBlendSpec, LayerOrder, LayerSpec, LightSpec,
    MaterialSpec, Mesh, MeshFilters, Output, ScalarInput, Scene, SpecularAaSpec, SphereUv,
    TextureSampler, TextureSource, TextureSpec, MAX_LAYERS, MAX_OUTPUT_SIDE, MAX_SCENE_LIGHTS,
    MAX_SHADING_SAMPLES,
};
pub use obj::{load_obj, load_obj_bytes, load_obj_with};
pub use procedural::{NoiseKind, Procedural, MAX_WAVES, MAX_WAVE_TERMS};
pub use texel_texture::mapping::sphere::Mapping;
pub use texture::{TextureGroup, TextureKey, TextureUse};
