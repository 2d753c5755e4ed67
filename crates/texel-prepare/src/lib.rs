//! texel-prepare: the step between a [`texel_scene::Scene`] and draw calls. [`PreparedScene`]
//! loads a scene's textures within a [`MemoryBudget`], derives what its materials read (moment
//! maps for specular antialiasing, baked layers, tessellated displacement, a baked ambient
//! occlusion map) and hands out one [`FramePlan`] per filter: the samplers with their structures
//! built, the settings and the draw calls that the CPU rasterizer, the reference and the GPU path
//! take. [`PreparedScene::reference`] runs the converging reference on it.
//!
//! The `texel` crate re-exports all of this; depend on `texel` unless you want this step alone.

pub mod ao;
pub mod bake;
pub mod bvh;
mod error;
pub mod memory;
mod plan;
mod prepare;
mod reference;
pub mod tessellate;

pub use error::Error;
pub use memory::MemoryBudget;
pub use plan::{FrameOptions, FramePlan};
pub use prepare::{ColorHandling, PreparedScene, SceneOptions, TextureStorage};
pub use reference::ReferenceRun;

use texel_texture::Filter;
