#!/bin/bash
# Device run (issue 39): the XR-4's wide full-resolution foveae in stereo, now that each eye has
# its own texel view; regular 4 spp and 30:1x4 bg:2x2 beside them as the old report's anchors.
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
for c in 20:1x4_bg:1x1_occ56_blend1=c001 30:1x4_bg:1x1_occ56_blend1=c006 \
  30:1x8_bg:1x1d3m4_occ56_blend1=c008 30:1x4_bg:2x2_occ56_blend1=c007 bg:1x4=c018; do
  args+=(--config ${c%=*}=$C/${c#*=}.toml)
done
one() {  # display scene seconds
  local out=/tmp/panels/panel-$1/$2 size=()
  [ -n "${SIZE:-}" ] && size=(--size $SIZE)
  timeout $3 $B/fovea gpu-report $out --quick --history --display $1 "${size[@]}" --scenes $2 "${args[@]}" 2>&1 | tail -3
  rm -rf $out/session-*
  tar -czf $OUT/panels.tar.gz -C /tmp/panels .
  log "$1 $2 done"
}
one varjo-xr-4 cornell ${S1:-170}
one varjo-xr-4 bunny-high ${S2:-130}
log done
