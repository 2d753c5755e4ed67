//! texel-io: the file input and output every texel crate goes through.
//!
//! - Input ([`input`]): a path must name a regular file (a FIFO, device or directory is refused
//!   before it is opened), no file is read past the caller's byte bound, a JPEG that ends before
//!   its image data does is refused, and a third-party decoder that panics becomes an error
//!   ([`guarded`]).
//! - Output ([`output`]): readers see the old output or the whole new one, never a torn one, and
//!   nothing but a regular file (or a new path) is replaced ([`write_atomic`], [`publish_dir`]).
//! - Terminal ([`term`]): messages show control and bidirectional characters as escapes
//!   ([`escape`]), and writes to standard output and error never panic ([`stderr_line`]).
//!
//! The lowest crate of the workspace: it depends on no other texel crate.

pub mod input;
pub mod output;
pub mod term;

pub use input::{
    check_jpeg_complete, files_opened, guarded, in_guarded_decode, open_regular, read_regular,
    record_opened,
};
pub use output::{
    check_output, publish_dir, remove_pending_and_exit, same_output, write_atomic, OutputError,
    OUTPUT_MARKER,
};
pub use term::{chain_line, escape, stderr_line, stderr_text, stdout_line, stdout_text};
