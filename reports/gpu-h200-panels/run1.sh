#!/bin/bash
# Device run 7 (issue 39): the window tunes' cornell configs over each display's whole panel
# (XR-4 3840x3744, Vive Pro Eye 1440x1600), history on; then bunny-high's times of the same.
set -u -o pipefail
t0=$(date +%s)
log() { echo "[$(( $(date +%s) - t0 )) s] $*"; }
[ -n "${LOCAL:-}" ] || { for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig; }
nv=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
if [ -f $nv ]; then export VK_DRIVER_FILES=$nv; fi
nvidia-smi -L > $OUT/machine.txt 2>&1
B=dist/fovea-gpu
args=$(cut -f2 .devrun/win.args | head -1)
one() {  # display scene seconds [size]
  local out=/tmp/panels/panel-$1/$2 size=()
  [ -n "${4:-}" ] && size=(--size $4)
  timeout $3 $B/fovea gpu-report $out --quick --history --display $1 "${size[@]}" --scenes $2 $args 2>&1 | tail -2
  rm -rf $out/session-*
  tar -czf $OUT/panels.tar.gz -C /tmp/panels .
  log "$1 $2 done"
}
one varjo-xr-4 cornell ${S1:-150} ${SIZE_XR4:-}
one vive-pro-eye cornell ${S2:-80} ${SIZE_VIVE:-}
one varjo-xr-4 bunny-high ${S3:-120} ${SIZE_XR4:-}
one vive-pro-eye bunny-high ${S4:-60} ${SIZE_VIVE:-}
log done
