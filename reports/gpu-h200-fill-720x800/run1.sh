#!/bin/bash
# Device run 5 (issue 39): lanes that fill the GPU. Same bits; every tune candidate with the
# old rule (--trace-threads 0) and the new default, interleaved per scene; the full report.
set -u -o pipefail
t0=$(date +%s)
log() { echo "[$(( $(date +%s) - t0 )) s] $*"; }
[ -n "${LOCAL:-}" ] || { for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig; }
nv=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
if [ -f $nv ]; then export VK_DRIVER_FILES=$nv; fi
nvidia-smi -L > $OUT/machine.txt 2>&1
B=dist/fovea-gpu
log "same image with the lanes filled as without"
for t in 0 100000000; do
  timeout 60 $B/fovea render --scene cornell --width 720 --height 800 --foveation thesis --spp 4 --trace-threads $t --out /tmp/fill-$t.exr 2>&1 | grep -E "GPU|error"
done
cmp /tmp/fill-0.exr /tmp/fill-100000000.exr && echo "filled lanes: same bytes"
log "tune candidates, old rule then new, one scene at a time"
while IFS=$'\t' read -r scene args; do
  name=$(basename "$scene" .glb)
  for t in 0 default; do
    extra=""; [ $t = 0 ] && extra="--trace-threads 0"
    timeout ${CAND_S:-150} $B/fovea gpu-report /tmp/candidates-$t/$name --quick --size ${CSIZE:-720x800} --history --scenes "$scene" $extra $args 2>&1 | tail -1
    rm -rf /tmp/candidates-$t/$name/session-*
  done
  tar -czf $OUT/candidates.tar.gz -C /tmp candidates-0 candidates-default
  log "$name done"
done < reports/gpu-h200-candidates-720x800/configs/args.tsv
[ -n "${NOFULL:-}" ] && exit 0
log "full report"
timeout ${FULL_S:-90} $B/fovea gpu-report /tmp/full --size ${SIZE:-1440x1600} 2>&1 | tail -1
rm -rf /tmp/full/session-*
tar -czf $OUT/full.tar.gz -C /tmp full
log done
