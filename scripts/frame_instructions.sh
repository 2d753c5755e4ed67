#!/usr/bin/env bash
# Instructions a texel frame retires, counted by cachegrind: deterministic where wall-clock frames
# are not (on a shared VM the same frame can move by 1.5x between rounds; docs/decisions.md). Counts
# instructions, not cycles: a change that retires fewer may still not be faster.
# Usage: scripts/frame_instructions.sh TEXEL_BINARY [FILTERS] [SCENE] [THREADS] [BENCH OPTIONS...]
#   e.g. scripts/frame_instructions.sh target/release/texel nearest,bilinear
#        COLOR=srgb scripts/frame_instructions.sh target/release/texel trilinear,aniso16 \
#          scenes/ground.toml 1 --texture-storage float
# COLOR (default raw) is the bench's --color; BENCH OPTIONS are passed to `texel bench` as they are.
# Needs valgrind (apt-get install valgrind). Per filter: instructions of a bench run of 13 frames
# minus those of a run of 3, over 10 (the difference removes start-up, texture and pyramid
# preparation). `--warmup 0`: the bench's warm-up lasts at least 0.2 s, so under valgrind the
# number of warm-up frames depended on timing and a fast filter's figure moved by a tenth of a
# frame (nearest 24.85 and 27.59 million for two builds of the same code). One thread by
# default: with more, the count includes the threads' waiting and hand-over, which depend on
# timing (the one-thread count was checked to repeat within 0.03 %; more threads were not).
set -euo pipefail
bin=$1 filters=${2:-nearest,bilinear,mip-nearest,trilinear} scene=${3:-scenes/ground.toml}
threads=${4:-1} color=${COLOR:-raw}
extra=("${@:5}")
command -v valgrind >/dev/null || { echo "valgrind is not installed (apt-get install valgrind)" >&2; exit 1; }
refs() { # frames, filter -> instructions of the whole run
  valgrind --tool=cachegrind --cache-sim=no --cachegrind-out-file=/dev/null \
    "$bin" bench "$scene" --color "$color" --frames "$1" --warmup 0 --threads "$threads" \
    --size 1280x720 --filters "$2" "${extra[@]}" 2>&1 >/dev/null | sed -n 's/.*I *refs: *//p' | tr -d ,
}
echo "| filter | instructions a frame (millions) |"
echo "|---|--:|"
for f in ${filters//,/ }; do
  short=$(refs 3 "$f") long=$(refs 13 "$f")
  [ -n "$short" ] && [ -n "$long" ] || { echo "cachegrind gave no count for $f" >&2; exit 1; }
  awk -v a="$short" -v b="$long" -v f="$f" 'BEGIN { printf "| %s | %.2f |\n", f, (b - a) / 10 / 1e6 }'
done
