#!/usr/bin/env bash
# Does `--texture-storage float` (8-bit textures decoded once to f32) render the same bytes as the
# stored textures? Renders every built-in scene with ten filters (nearest to EWA, ripmap and
# summed-area table), in sRGB and raw colour, at 200x120, both ways (280 pairs), and compares the
# PNG files. Usage: scripts/same_images_storage.sh [TEXEL] (default target/release/texel)
set -euo pipefail
exe=${1:-target/release/texel}
cd "$(dirname "$0")/.."
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
n=0 differ=0
for s in ground ground-rotated zoneplate cube sphere globe globe-equirect triangle glossy bricks \
  terrain knot mirror-spheres mirror-plane; do
  for f in nearest bilinear bicubic mip-nearest trilinear aniso2 aniso16 ewa ripmap sat; do
    for c in srgb raw; do
      args=(render "builtin:$s" --filter "$f" --color "$c" --size 200x120)
      "$exe" "${args[@]}" --texture-storage stored -o "$out/a.png" 2>/dev/null
      "$exe" "${args[@]}" --texture-storage float -o "$out/b.png" 2>/dev/null
      n=$((n + 1))
      cmp -s "$out/a.png" "$out/b.png" || { differ=$((differ + 1)); echo "differs: $s $f $c"; }
    done
  done
done
echo "$n pairs compared, $differ differ"
[ "$differ" -eq 0 ]
