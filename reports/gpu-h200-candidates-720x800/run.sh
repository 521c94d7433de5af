#!/bin/bash
# Device run 4 (issue 39): every tune candidate's GPU time at 720x800 with history; the full
# report of this commit.
set -u -o pipefail
t0=$(date +%s)
log() { echo "[$(( $(date +%s) - t0 )) s] $*"; }
[ -n "${LOCAL:-}" ] || { for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig; }
nv=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
if [ -f $nv ]; then export VK_DRIVER_FILES=$nv; fi
nvidia-smi -L > $OUT/machine.txt 2>&1
B=dist/fovea-gpu
log "tune candidates, one scene at a time"
while IFS=$'\t' read -r scene args; do
  name=$(basename "$scene" .glb)
  timeout ${CAND_S:-150} $B/fovea gpu-report /tmp/candidates/$name --quick --size ${CSIZE:-720x800} --history --scenes "$scene" $args 2>&1 | tail -2
  rm -rf /tmp/candidates/$name/session-*
  tar -czf $OUT/candidates.tar.gz -C /tmp candidates
  log "$name done"
done < reports/gpu-h200-candidates-720x800/configs/args.tsv
[ -n "${NOFULL:-}" ] && exit 0
log "full report"
timeout ${FULL_S:-90} $B/fovea gpu-report /tmp/full --size ${SIZE:-1440x1600} 2>&1 | tail -1
rm -rf /tmp/full/session-*
tar -czf $OUT/full.tar.gz -C /tmp full
log done
