#!/usr/bin/env bash
# Do two texel binaries render the same images, byte for byte? For refactors that must not change
# a pixel. Usage: scripts/same_images.sh OLD_TEXEL NEW_TEXEL [OUT_DIR]
# Renders every filter on every built-in scene and scenes/ground.toml at 320x180, the
# 16-spp reference and five debug views at 160x90, the lit built-ins and raw colour (134 images),
# and compares the PNG files.
# A binary of an older commit: git worktree add /tmp/base REV && cargo build --release
#   --manifest-path /tmp/base/Cargo.toml --target-dir /tmp/base-target -p texel-cli
set -euo pipefail
old=$1 new=$2 out=${3:-$(mktemp -d)}
cd "$(dirname "$0")/.."
mkdir -p "$out/old" "$out/new"
scenes=(builtin:ground builtin:ground-rotated builtin:zoneplate builtin:cube builtin:sphere builtin:triangle)
scenes+=(scenes/ground.toml)
n=0 differ=0
check() { # name, then the arguments after the scene
  local name=$1; shift
  "$old" "$@" -o "$out/old/$name.png" 2>/dev/null
  "$new" "$@" -o "$out/new/$name.png" 2>/dev/null
  n=$((n + 1))
  if ! cmp -s "$out/old/$name.png" "$out/new/$name.png"; then
    differ=$((differ + 1)); echo "differs: $name"
  fi
}
# A binary whose reference refines adaptively takes --max-spp; both binaries must take it (or
# neither) for their references to be comparable.
fixed_spp=""
if "$old" reference --help | grep -q -- --max-spp && "$new" reference --help | grep -q -- --max-spp; then
  fixed_spp="--max-spp 16"
fi
for s in "${scenes[@]}"; do
  tag=$(echo "$s" | tr '/:.' '___')
  for f in nearest bilinear bicubic mip-nearest trilinear aniso2 aniso4 aniso8 aniso16 ewa ripmap sat; do
    check "$tag-$f" render "$s" --size 320x180 --filter "$f"
  done
  check "$tag-reference" reference "$s" --size 160x90 --spp 16 $fixed_spp
  for v in uv mip lod aniso fetches; do
    check "$tag-$v" render "$s" --size 160x90 --view "$v"
  done
done
# Lit materials (normal, roughness and height maps, layers) and raw colour output.
for s in builtin:glossy builtin:bricks builtin:terrain; do
  tag=$(echo "$s" | tr '/:.' '___')
  for f in trilinear aniso16; do
    check "$tag-$f" render "$s" --size 320x180 --filter "$f"
  done
done
for f in nearest trilinear; do
  check "ground-raw-$f" render builtin:ground --size 320x180 --filter "$f" --color raw
done
echo "$n images compared, $differ differ (images in $out)"
[ "$differ" -eq 0 ]
