#!/usr/bin/env bash
# The denoiser with the history-aware edge-stop (98739a0) judged in motion on the three scenes
# in the Vive Pro Eye's window: the configs that denoise, beside regular 4 spp.
# Usage: bash run.sh FOVEA OUT_DIR   (from the repository root; about 5-8 min per scene and
# run on the 2-core VM with the references cached in /tmp/tune-refs-window)
set -euo pipefail
fovea=$1 out=$2
inc=reports/tune-motion-window-lavapipe/include
mkdir -p "$out"
tune() {
  "$fovea" tune --scene "$1" --objective motion --reference-spp 128 --space small \
    --budget-of-regular 2 --reference-cache /tmp/tune-refs-window --display vive-pro-eye \
    --window 632x474 --frames 1 --candidates "$2" --include "$3" --out "$4"
}
# The room's winner and the nearest config on every scene, as measured before the change.
for scene in assets/gltf/textured-room.glb bunny-high cornell; do
  name=$(basename "$scene" .glb)
  tune "$scene" 7 $inc/r4.toml,$inc/r1d3m4.toml,$inc/f30x4-bg1d3m4.toml \
    "$out/$name-history-variance.toml"
done
# Stronger denoising: no acuity limit, five iterations, two samples a pixel.
for scene in bunny-high cornell; do
  tune "$scene" 8 $inc/r4.toml,$inc/r1d3.toml,$inc/r1d5.toml,$inc/r2d3.toml \
    "$out/$scene-strong.toml"
done
