#!/usr/bin/env bash
# Frames per second of `texel view` per mode, in an X server (Xvfb) on this machine: prints the
# Markdown table of docs/guide/viewer.md. Each mode runs FRAMES frames at SIZE on THREADS threads
# without the HUD; "render ms" is the median time the render thread took per frame, "fps" the
# frames shown per second of wall time (rendering, encoding for display and presenting through X).
#
# Usage: scripts/view_fps.sh [EXE] (default target/release/texel; FRAMES=60 SIZE=1280x720 THREADS=2
# STORAGE=float, the viewer's default, or STORAGE=stored for --texture-storage stored)
set -euo pipefail
exe=${1:-target/release/texel}
frames=${FRAMES:-60}
size=${SIZE:-1280x720}
threads=${THREADS:-2}
storage=${STORAGE:-float}
command -v xvfb-run >/dev/null || { echo "needs xvfb-run (apt-get install xvfb)" >&2; exit 1; }
echo "| key | mode | render ms (median) | fps |"
echo "|---|---|--:|--:|"
for key in 1 2 3 4 5 6 7 8 9 e b m t 0; do
  line=$(env -u WAYLAND_DISPLAY xvfb-run -a -s "-screen 0 1920x1080x24" \
    "$exe" view builtin:ground --size "$size" --threads "$threads" --texture-storage "$storage" --keys "$key" \
    --frames "$frames" --no-hud 2>&1 | grep '^texel view:')
  case $key in
    1) mode=nearest ;; 2) mode=bilinear ;; 3) mode=mip-nearest ;; 4) mode=trilinear ;;
    5) mode=aniso2 ;; 6) mode=aniso4 ;; 7) mode=aniso8 ;; 8) mode=aniso16 ;;
    9) mode=ewa ;; e) mode=ewa-probes ;; b) mode=bicubic ;; m) mode=ripmap ;; t) mode=sat ;; 0) mode="reference (4 samples/px a frame)" ;;
  esac
  ms=$(sed -E 's/.*median ([0-9.]+) ms.*/\1/' <<<"$line")
  fps=$(sed -E 's/.*render, ([0-9.]+) frames per second.*/\1/' <<<"$line")
  echo "| $key | $mode | $ms | $fps |"
done
