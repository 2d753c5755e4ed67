//! texel-io: the file input every texel crate reads through. A path must name a regular file (a
//! FIFO, device or directory is refused before it is opened), no file is read past the caller's
//! byte bound, a JPEG that ends before its image data does is refused, and a third-party decoder
//! that panics becomes an error ([`guarded`]). The lowest crate of the workspace: it depends on
//! no other texel crate.

pub mod input;

pub use input::{check_jpeg_complete, guarded, in_guarded_decode, open_regular, read_regular};
