#!/bin/bash
# Device run 6 (issue 39): the fill threshold: every tune candidate with --trace-threads 0,
# 2^18 and 2^20, interleaved per scene.
set -u -o pipefail
t0=$(date +%s)
log() { echo "[$(( $(date +%s) - t0 )) s] $*"; }
[ -n "${LOCAL:-}" ] || { for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig; }
nv=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
if [ -f $nv ]; then export VK_DRIVER_FILES=$nv; fi
nvidia-smi -L > $OUT/machine.txt 2>&1
B=dist/fovea-gpu
while IFS=$'\t' read -r scene args; do
  name=$(basename "$scene" .glb)
  for t in 0 262144 1048576; do
    timeout ${CAND_S:-100} $B/fovea gpu-report /tmp/threads-$t/$name --quick --size 720x800 --history --scenes "$scene" --trace-threads $t $args 2>&1 | tail -1
    rm -rf /tmp/threads-$t/$name/session-*
  done
  tar -czf $OUT/threads.tar.gz -C /tmp threads-0 threads-262144 threads-1048576
  log "$name done"
done < reports/gpu-h200-candidates-720x800/configs/args.tsv
log done
