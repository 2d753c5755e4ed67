//! texel-texture: texture images, address modes, mip pyramids and every classic texture filter,
//! behind a WebGPU-style sampler.
//!
//! Conventions (fixed by docs/guide/conventions.md): `uv` is normalised, `xy = (u * W, v * H)` is
//! continuous texel space with texel `(i, j)` covering `[i, i+1) x [j, j+1)`, row 0 is the top of the
//! image file. Colours returned by samplers are linear RGBA `f32`.
//!
//! ```
//! use texel_texture::{AddressMode, ColorSpace, FilterMode, Footprint, Limits, MipmapFilterMode,
//!                     Sampler, SamplerDescriptor, Texture};
//!
//! // A 2x2 linear texture: black, white / white, black.
//! let b = [0, 0, 0, 255];
//! let w = [255, 255, 255, 255];
//! let tex = Texture::from_rgba8(2, 2, vec![b, w, w, b], ColorSpace::Linear, &Limits::default())?;
//! let sampler = Sampler::new(SamplerDescriptor {
//!     mag_filter: FilterMode::Linear,
//!     min_filter: FilterMode::Linear,
//!     mipmap_filter: MipmapFilterMode::Linear,
//!     ..SamplerDescriptor::default().with_address_mode(AddressMode::Repeat)
//! })?;
//! // At the texture's centre, bilinear blends all four texels equally.
//! let c = sampler.sample(&tex, &Footprint::point(0.5, 0.5));
//! assert!((c[0] - 0.5).abs() < 1e-6);
//! // A footprint covering the whole texture per pixel reads the 1x1 level: the mean, 0.5,
//! // stored as the 8-bit code 128 like every level of an 8-bit texture.
//! let (c, reads) = sampler.sample_counted(&tex, &Footprint::isotropic(0.3, 0.7, 1.0));
//! assert_eq!(c[0], 128.0 / 255.0);
//! assert_eq!(reads, 4); // bilinear in the 1x1 level (lod clamps to the last level)
//! # Ok::<(), texel_texture::TextureError>(())
//! ```

pub mod base;
pub mod engine;
pub mod kernel;
pub mod mapping;
pub mod storage;
pub mod technique;

pub use base::address::{Address, AddressMode, BorderColor};
pub use base::descriptor::SamplerDescriptor;
pub use base::error::TextureError;
pub use base::filter::{Cubic, FilterMode, MipmapFilterMode, EWA_DEFAULT_ANISOTROPY};
pub use base::footprint::{Axes, Footprint};
pub use base::footprint_batch::{FootprintBatch, FootprintLanes};
pub use base::named::Filter;
pub use engine::sampler::Sampler;
pub use engine::span::{BoundSampler, SpanKind, Wants};
pub use storage::lanes::Lanes;
pub use storage::tables::{Ripmap, SummedAreaTable};
pub use storage::texture::{
    replace_non_finite, ColorSpace, Format, LevelInfo, LevelTexels, Limits, LoadOptions, Loaded,
    Texture, MAX_TEXEL, NON_FINITE_CLAMP,
};
pub use technique::lab::{Convention, Rules};
