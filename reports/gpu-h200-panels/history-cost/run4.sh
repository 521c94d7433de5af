#!/bin/bash
# Device run (issue 39): what the history costs per config on the GPU (its extra centre ray per
# lattice point in the trace, and the temporal pass): the same configs with and without
# --history, the Vive Pro Eye's panel, the textured room and cornell.
set -u -o pipefail
t0=$(date +%s)
log() { echo "[$(( $(date +%s) - t0 )) s] $*"; }
[ -n "${LOCAL:-}" ] || { for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig; }
nv=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
if [ -f $nv ]; then export VK_DRIVER_FILES=$nv; fi
nvidia-smi -L > $OUT/machine.txt 2>&1
B=dist/fovea-gpu
C=.devrun/win/cornell
args=()
for c in bg:1x1=c015 bg:1x2=c017 bg:1x4=c018 20:1x4_bg:2x2_occ56_blend1=c002 30:1x4_bg:2x2_occ56_blend1=c007; do
  args+=(--config ${c%=*}=$C/${c#*=}.toml)
done
one() {  # scene seconds history(on|off) name
  local out=/tmp/hist/$4-$3 size=() h=()
  [ -n "${SIZE:-}" ] && size=(--size $SIZE)
  [ $3 = on ] && h=(--history)
  timeout $2 $B/fovea gpu-report $out --quick "${h[@]}" --display vive-pro-eye "${size[@]}" --scenes $1 "${args[@]}" 2>&1 | tail -2
  rm -rf $out/session-*
  tar -czf $OUT/hist.tar.gz -C /tmp/hist .
  log "$1 history $3 done"
}
one cornell ${S1:-60} off cornell
one cornell ${S1:-60} on cornell
one assets/gltf/textured-room.glb ${S2:-110} off textured-room
one assets/gltf/textured-room.glb ${S2:-110} on textured-room
log done
