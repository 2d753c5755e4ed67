#!/usr/bin/env bash
# Install what `cargo +nightly fuzz` needs: the nightly toolchain (libFuzzer's sanitizer flags are
# nightly-only) and cargo-fuzz from crates.io. Idempotent; run once per machine.
set -euo pipefail
rustup toolchain list | grep -q '^nightly' || rustup toolchain install nightly --profile minimal
command -v cargo-fuzz >/dev/null 2>&1 || cargo install cargo-fuzz --locked
# libFuzzer is C++: cargo-fuzz builds it with the system's C++ compiler.
command -v c++ >/dev/null 2>&1 || { apt-get update && apt-get install -y g++; }
cargo +nightly fuzz --version
