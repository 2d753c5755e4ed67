//! Texel storage and its reads: the texture and its mip pyramid, the decoders that turn stored
//! codes into linear values ([`fetch`]) and the eight-lane quad kernel they may use ([`lanes`]).
//! Imports only the ground floor ([`crate::base`]).

pub(crate) mod fetch;
pub(crate) mod lanes;
pub mod pyramid;
pub mod texture;
