#!/bin/bash
# bench --gpu with device time from passes recorded back to back (GpuDraws::pass_times).
set -u
cd "$(dirname "$0")"
export LD_LIBRARY_PATH=$PWD XDG_RUNTIME_DIR=/tmp
ICD=$PWD/nvidia_egl_icd.json
export VK_DRIVER_FILES=$ICD VK_ICD_FILENAMES=$ICD TEXEL_ADAPTER=NVIDIA
nvidia-smi --query-gpu=clocks.sm,clocks.mem,pstate --format=csv -lms 250 > $OUT/passes-clocks.csv &
F=nearest,bilinear,mip-nearest,trilinear,aniso2,aniso4,aniso8,aniso16,bicubic,ewa,hw-trilinear,hw-aniso16
for r in 1 2; do
  for S in 1280x720:30 3840x2160:12; do
    echo "== $S round $r"
    timeout 100 ./texel bench ground.toml --gpu --color raw --size ${S%:*} --frames ${S#*:} \
      --filters $F --json > $OUT/passes-${S%:*}-$r.json; echo "rc=$?"
    sed -n '/device_ms/,$p' $OUT/passes-${S%:*}-$r.json | tr -d '\n '; echo
  done
done
kill %1
sort $OUT/passes-clocks.csv | uniq -c | sort -rn | head -5
