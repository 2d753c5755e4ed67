//! texel-shade: what lit scenes are made of, below the rasterizer that shades with it.
//!
//! - [`material`]: the material model (Lambert diffuse plus a GGX specular lobe), lights, and
//!   specular antialiasing of what normal and height maps put under a pixel (Toksvig, LEAN with
//!   a convolved lobe, projected roughness), with the moment maps they read;
//! - [`layers`]: layered materials, each layer's maps filtered through the pixel's footprint and
//!   blended by a mask;
//! - [`environment`]: environment maps (equirectangular, cube, octahedral), prefiltered for the
//!   split-sum specular and for irradiance;
//! - [`inputs`]: a texture read through a sampler, the way every map is read.
//!
//! texel-raster's fragment shading (`shade.rs`, `relief.rs`) combines these per pixel; every
//! texture read goes through a texel-texture [`texel_texture::Sampler`] and its footprint.

pub mod environment;
mod error;
pub mod inputs;
pub mod layers;
pub mod material;

pub use environment::{Environment, EnvironmentMaps};
pub use error::ShadeError;
pub use layers::{Layer, LayerBlend, Layers};
pub use material::{
    ChannelInput, Displacement, Light, Material, SpecularAa, TextureInput, MAX_LIGHTS,
};
