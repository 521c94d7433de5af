#!/bin/bash
# Device run (issue 39): no extra ray with history on (surface and, while denoising, albedo from
# the points' samples) against cf7773b's centre ray: both bundles, one after the other per scene, the Vive Pro Eye's
# panel, history on.
set -u -o pipefail
t0=$(date +%s)
log() { echo "[$(( $(date +%s) - t0 )) s] $*"; }
[ -n "${LOCAL:-}" ] || { for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig; }
nv=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
if [ -f $nv ]; then export VK_DRIVER_FILES=$nv; fi
nvidia-smi -L > $OUT/machine.txt 2>&1
C=.devrun/win/cornell
args=()
for c in bg:1x1=c015 bg:1x2=c017 bg:1x4=c018 bg:1x1d3m4_occ56=c016 20:1x4_bg:2x2_occ56_blend1=c002 \
  30:1x4_bg:2x2_occ56_blend1=c007 20:1x4_bg:2x2d3m4_occ56_blend1=c003; do
  args+=(--config ${c%=*}=$C/${c#*=}.toml)
done
one() {  # bundle-suffix scene seconds name
  local out=/tmp/surf/$4 size=()
  [ -n "${SIZE:-}" ] && size=(--size $SIZE)
  timeout $3 dist/fovea-gpu$1/fovea gpu-report $out --quick --history --display vive-pro-eye "${size[@]}" --scenes $2 "${args[@]}" 2>&1 | tail -1
  rm -rf $out/session-*
  tar -czf $OUT/surf.tar.gz -C /tmp/surf .
  log "$4 done"
}
for s in cornell bunny-high assets/gltf/textured-room.glb; do
  n=$(basename $s .glb)
  one "" $s ${S:-70} $n-old
  one "-new" $s ${S:-70} $n-new
done
log done
