#!/bin/bash
# texel's GPU path on an NVIDIA machine (docs/guide/gpu.md): adapter, bench --gpu at 720p
# and 4K (two rounds), the CPU path on the host, compare --gpu against a 1024-sample reference.
set -u
cd "$(dirname "$0")"
export LD_LIBRARY_PATH=$PWD XDG_RUNTIME_DIR=/tmp
nvidia-smi --query-gpu=name,driver_version,memory.total,clocks.max.sm --format=csv
lscpu | grep -E 'Model name|^CPU\(s\)|L3'
try() { VK_DRIVER_FILES=$1 VK_ICD_FILENAMES=$1 ./texel gpu-info 2>&1 | grep -i nvidia; }
ICD=$PWD/nvidia_egl_icd.json
if ! try "$ICD"; then
  echo "EGL manifest found no NVIDIA adapter; trying the driver's own"
  ICD=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
  export __EGL_VENDOR_LIBRARY_FILENAMES=/usr/local/nvidia/share/glvnd/egl_vendor.d/10_nvidia.json
  try "$ICD" || { echo "no NVIDIA adapter"; ./texel gpu-info; exit 1; }
fi
export VK_DRIVER_FILES=$ICD VK_ICD_FILENAMES=$ICD TEXEL_ADAPTER=NVIDIA
F=nearest,bilinear,mip-nearest,trilinear,aniso2,aniso4,aniso8,aniso16,bicubic,ewa,hw-trilinear,hw-aniso16
for S in 1280x720 3840x2160; do
  for r in 1 2; do
    echo "== bench --gpu $S round $r"
    timeout 150 ./texel bench ground.toml --gpu --color raw --frames 30 --size $S --filters $F --json \
      > $OUT/bench-$S-$r.json; echo "rc=$?"
    grep -v '^ "\(cpu\|simd\|target\|precision\|streaming\|streamed\|threads\)"' $OUT/bench-$S-$r.json
  done
done
echo "== CPU path on the host, 720p, all threads"
timeout 90 ./texel bench ground.toml --color raw --frames 20 \
  --filters nearest,bilinear,mip-nearest,trilinear,aniso16,ewa; echo "rc=$?"
for S in 1280x720 3840x2160; do
  echo "== compare --gpu $S"
  timeout 240 ./texel compare ground.toml --size $S --filters trilinear,aniso16,ewa --spp 1024 \
    --gpu --out /tmp/cmp-$S > $OUT/compare-$S.md; echo "rc=$?"
  cat $OUT/compare-$S.md
done
