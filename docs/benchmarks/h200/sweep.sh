#!/bin/bash
# Device time of a frame by size: where does the 4K frame's cost step up?
set -u
cd "$(dirname "$0")"
export LD_LIBRARY_PATH=$PWD XDG_RUNTIME_DIR=/tmp
ICD=$PWD/nvidia_egl_icd.json
export VK_DRIVER_FILES=$ICD VK_ICD_FILENAMES=$ICD TEXEL_ADAPTER=NVIDIA
nvidia-smi --query-gpu=clocks.sm,clocks.mem,pstate --format=csv -lms 500 > $OUT/clocks.csv &
for S in 640x360 1280x720 1920x1080 2560x1440 3200x1800 3840x2160; do
  echo "== $S"
  timeout 60 ./texel bench ground.toml --gpu --color raw --frames 8 --warmup 1 --size $S \
    --filters nearest,trilinear,aniso16,hw-trilinear,hw-aniso16 | tail -5
done
kill %1
sort $OUT/clocks.csv | uniq -c | sort -rn | head
