//! The ground floor: the vocabulary every other floor speaks. Numbers (staged floors and
//! roundings, a small deterministic generator), address modes, colour encodings, footprints and
//! their batches, the sampler's descriptor, the filters by name and the crate's errors. Nothing here imports from a
//! floor above.

pub mod address;
pub mod color;
pub mod descriptor;
pub(crate) mod error;
pub mod filter;
pub mod floor;
pub mod footprint;
pub(crate) mod footprint_batch;
pub mod lerp;
pub mod named;
pub mod rng;
