//! Texel storage and its reads, from the bottom up: the formats and the storage layout
//! ([`mod@format`]), the eight-lane quad kernel (`lanes`), the decoders that turn stored codes into
//! linear values one level at a time (`fetch`), the mip chain's construction ([`pyramid`]), the
//! prefiltered tables' storage (`tables`), the [`texture::Texture`] that owns them, and the whole
//! pyramid as the filters see it (`view`). Imports only the ground floor ([`crate::base`]).

pub(crate) mod fetch;
pub mod format;
pub(crate) mod lanes;
pub mod pyramid;
pub mod tables;
pub mod texture;
pub(crate) mod view;
