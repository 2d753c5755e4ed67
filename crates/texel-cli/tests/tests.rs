//! The `texel` binary's integration tests, one test binary (as ripgrep's `tests/tests.rs`):
//! [`util`] holds the shared helpers, each other module one area.

mod cli;
mod hostile;
mod util;
