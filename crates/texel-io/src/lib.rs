//! texel-io: the file input and output every texel crate goes through.
//!
//! - Input ([`input`]): a path must name a regular file (a FIFO, device or directory is refused
//!   before it is opened), no file is read past the caller's byte bound, a JPEG that ends before
//!   its image data does is refused, and a third-party decoder that panics becomes an error
//!   ([`guarded`]).
//! - Output ([`output`]): readers see the old output or the whole new one, never a torn one, and
//!   nothing but a regular file (or a new path) is replaced ([`write_atomic`], [`publish_dir`]).
//!
//! The lowest crate of the workspace: it depends on no other texel crate.

pub mod input;
pub mod output;

pub use input::{check_jpeg_complete, guarded, in_guarded_decode, open_regular, read_regular};
pub use output::{publish_dir, remove_pending_and_exit, write_atomic, OutputError, OUTPUT_MARKER};
