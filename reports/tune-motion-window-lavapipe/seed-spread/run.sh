#!/usr/bin/env bash
# Judges the motion objective's deciding configs again with other render seeds (the
# reference, cached, stays the same): how far a config's JOD moves with its noise alone.
# Usage: bash run.sh FOVEA OUT_DIR SEED...   (from the repository root; about 8 min per scene
# and seed on the 2-core VM with the references cached in /tmp/tune-refs-window)
set -euo pipefail
fovea=$1 out=$2
shift 2
inc=reports/tune-motion-window-lavapipe/include
common=(--objective motion --reference-spp 128 --space small --budget-of-regular 2
  --reference-cache /tmp/tune-refs-window --display vive-pro-eye --window 632x474 --frames 1)
mkdir -p "$out"
for seed in "$@"; do
  "$fovea" tune --scene assets/gltf/textured-room.glb "${common[@]}" --render-seed "$seed" \
    --candidates 6 --include $inc/r4.toml,$inc/r1d3m4.toml \
    --out "$out/textured-room-seed$seed.toml"
  "$fovea" tune --scene bunny-high "${common[@]}" --render-seed "$seed" \
    --candidates 8 --include $inc/r4.toml,$inc/f20x4-bg2x2.toml,$inc/f30x4-bg2x2.toml,$inc/r1d3m4.toml \
    --out "$out/bunny-high-seed$seed.toml"
  "$fovea" tune --scene cornell "${common[@]}" --render-seed "$seed" \
    --candidates 7 --include $inc/r4.toml,$inc/r1d3m4.toml,$inc/f30x8-bg1d3m4.toml \
    --out "$out/cornell-seed$seed.toml"
done
