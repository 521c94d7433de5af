#!/usr/bin/env bash
# A 4-spp fovea (20 or 30 deg) inside the room's winner, a denoised 1-spp periphery, judged
# in motion on the three scenes beside regular 4 spp.
# Usage: bash run.sh FOVEA OUT_DIR   (from the repository root; about 8 min per scene on the
# 2-core VM with the references cached in /tmp/tune-refs-window)
set -euo pipefail
fovea=$1 out=$2
inc=reports/tune-motion-window-lavapipe/include
mkdir -p "$out"
for scene in assets/gltf/textured-room.glb bunny-high cornell; do
  name=$(basename "$scene" .glb)
  "$fovea" tune --scene "$scene" --objective motion --reference-spp 128 --space small \
    --budget-of-regular 2 --reference-cache /tmp/tune-refs-window --display vive-pro-eye \
    --window 632x474 --frames 1 --candidates 7 \
    --include $inc/r4.toml,$inc/f20x4-bg1d3m4.toml,$inc/f30x4-bg1d3m4.toml \
    --out "$out/$name-fovea-denoised-periphery.toml"
done
