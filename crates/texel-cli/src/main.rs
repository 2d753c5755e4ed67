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
mod cmd_lab;
mod cmd_mips;
mod cmd_reference;
mod cmd_render;
mod cmd_warp;
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
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => return clap_exit(&e),
    };
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
        texel_io::stderr_line(format_args!("texel: warning: cannot handle interrupts ({e}); an interrupted run may leave hidden .texel-*.tmp files"));
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
        Command::Lab(args) => cmd_lab::run(&args, &mut input),
        Command::LabDevice { dir } => cmd_lab::device(&dir),
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
            // One line whatever the paths and names in it hold.
            texel_io::stderr_line(format_args!(
                "texel: error: {}",
                texel_io::chain_line(err.as_ref())
            ));
            if err.downcast_ref::<interrupt::Interrupted>().is_some() {
                return ExitCode::from(interrupt::INTERRUPTED as u8);
            }
            ExitCode::FAILURE
        }
    }
}

/// Print clap's message (help, version or a usage error) and return the status it asks for. Help
/// or a version that cannot be written to standard output is an error. A usage error shows the
/// arguments it quotes that hold control or bidirectional characters escaped (and then without
/// colour), so that they can neither drive the terminal nor fake a line.
fn clap_exit(e: &clap::Error) -> ExitCode {
    let hostile: Vec<String> = std::env::args_os()
        .skip(1)
        .map(|a| a.to_string_lossy().into_owned())
        .filter(|a| a.chars().any(texel_io::term::needs_escape))
        .collect();
    if !e.use_stderr() {
        if let Err(err) = e.print() {
            if err.kind() != std::io::ErrorKind::BrokenPipe {
                texel_io::stderr_line(format_args!(
                    "texel: error: cannot write to standard output: {err}"
                ));
                return ExitCode::FAILURE;
            }
        }
    } else if hostile.is_empty() {
        let _ = e.print();
    } else {
        // The message with clap's styles, where the arguments appear as given.
        let mut text = e.render().ansi().to_string();
        for a in &hostile {
            // The whole argument, and the value after its `=` that clap may quote alone.
            for part in std::iter::once(a.as_str()).chain(a.split_once('=').map(|(_, v)| v)) {
                text = text.replace(part, &texel_io::escape(part));
            }
        }
        // Without the styles (plain text, as clap prints when colour is off).
        let plain = clap::builder::StyledStr::from(text).to_string();
        texel_io::stderr_text(&plain);
    }
    ExitCode::from(u8::try_from(e.exit_code()).unwrap_or(2))
}
