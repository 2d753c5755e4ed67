//! The `texel` binary's integration tests, one test binary (as ripgrep's `tests/tests.rs`):
//! [`util`] holds the shared helpers and fixtures, each other module one command or concern.

mod bake_ao;
mod budget_messages;
mod compare;
mod demo_bench;
mod docs_commands;
mod errors;
mod gpu;
mod help;
mod hostile;
mod lab;
mod meshes;
mod mips;
mod nothing_lost;
mod outputs;
mod published;
mod python;
mod reference;
mod render;
mod shading;
mod terminal;
mod util;
mod view;
mod warp;
