#!/usr/bin/env bash
# Run one cargo-fuzz target: scripts/fuzz.sh TARGET [RUNS] [extra libFuzzer flags...]
# Targets: scene_toml obj gltf image_decode sampler raster (see fuzz/README.md). RUNS defaults to
# 10 000 000 executions. The working corpus grows in fuzz/corpus/TARGET (not committed); the
# committed seeds in fuzz/seeds/TARGET are read only. Debug assertions are on (-a), so integer
# overflow panics count as crashes. Needs scripts/install-fuzz.sh once.
set -euo pipefail
cd "$(dirname "$0")/../fuzz"
target=$1
runs=${2:-10000000}
shift $(( $# >= 2 ? 2 : 1 ))
mkdir -p "corpus/$target"
RAYON_NUM_THREADS=1 exec cargo +nightly fuzz run -a "$target" "corpus/$target" "seeds/$target" -- \
  -runs="$runs" -max_len=4096 -timeout=10 -rss_limit_mb=2048 -print_final_stats=1 "$@"
