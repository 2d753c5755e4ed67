//! `texel`: render textured scenes with every classic texture filter, measure each against a
//! supersampled reference, warp images without aliasing and look at mip pyramids.
//!
//! The binary is thin (as ripgrep's `crates/core/main.rs`): argument parsing with clap derive, one
//! function per command, anyhow with context at the top. The work lives in the texel libraries.

mod budget;
mod cli;
mod cmd_bake_ao;
mod cmd_bench;
mod cmd_compare;
mod cmd_demo;
mod cmd_mips;
mod cmd_reference;
mod cmd_render;
mod cmd_warp;
mod controls;
mod filters;
mod input;
mod interrupt;
mod output;
mod progress;
mod threads;
mod view;

use std::process::ExitCode;

use clap::Parser;

use cli::{Cli, Command};

fn main() -> ExitCode {
    let cli = Cli::parse();
    // A decoder panic that texel_io::guarded turns into an error is not reported as a
    // panic; every other panic is.
    let default_hook = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        if !texel_io::in_guarded_decode() {
            default_hook(info);
        }
    }));
    // An interrupted run deletes its unpublished temporary files and staging directories.
    if let Err(e) = ctrlc::set_handler(interrupt::on_signal) {
        eprintln!("texel: warning: cannot handle interrupts ({e}); an interrupted run may leave hidden .texel-*.tmp files");
    }
    let mut input = input::Input {
        budget: budget::budget(cli.max_memory),
        sanitize: cli.sanitize,
    };
    let result = match cli.command {
        Command::Render(args) => cmd_render::run(&args, &mut input),
        Command::Reference(args) => cmd_reference::run(&args, &mut input),
        Command::Bench(args) => cmd_bench::run(&args, &mut input),
        Command::Compare(args) => cmd_compare::run(&args, &mut input),
        Command::Demo(args) => cmd_demo::run(&args, &mut input),
        Command::Warp(args) => cmd_warp::run(&args, &mut input),
        Command::Mips(args) => cmd_mips::run(&args, &mut input),
        Command::BakeAo(args) => cmd_bake_ao::run(&args, &mut input),
        Command::View(args) => view::run(&args, input),
        Command::GpuInfo => cmd_render::gpu_info(),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(err) => {
            // A closed pipe (`texel bench --json | head`) is not an error.
            if err.chain().any(|c| {
                c.downcast_ref::<std::io::Error>()
                    .is_some_and(|e| e.kind() == std::io::ErrorKind::BrokenPipe)
            }) {
                return ExitCode::SUCCESS;
            }
            eprintln!("texel: error: {}", chain_line(&err));
            if err.downcast_ref::<interrupt::Interrupted>().is_some() {
                return ExitCode::from(interrupt::INTERRUPTED as u8);
            }
            ExitCode::FAILURE
        }
    }
}

/// The error and its causes on one line: `outer: cause: root cause`.
fn chain_line(err: &anyhow::Error) -> String {
    let mut parts: Vec<String> = Vec::new();
    for cause in err.chain() {
        let s = cause.to_string();
        if !parts.last().is_some_and(|p| p.contains(&s)) {
            parts.push(s);
        }
    }
    parts.join(": ")
}
