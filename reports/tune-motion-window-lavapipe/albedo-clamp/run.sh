#!/usr/bin/env bash
# Regular 1 spp denoised (`bg:1x1d3m4`) and a 4-spp fovea of 30 deg inside it, judged in
# motion on the three scenes beside regular 4 spp, with the clamp that spares a denoising
# layer's illumination within a surface (glsl/temporal.comp). With a third argument `f20`:
# the 20-deg fovea inside it instead (the `*-f20-albedo-clamp-*` files).
# Usage: bash run.sh FOVEA OUT_DIR [f20]   (from the repository root; 6-25 min per scene on
# the 2-core VM with the references cached in /tmp/tune-refs-window)
set -euo pipefail
fovea=$1 out=$2 which=${3:-}
inc=reports/tune-motion-window-lavapipe/include
mkdir -p "$out"
for scene in cornell bunny-high assets/gltf/textured-room.glb; do
  name=$(basename "$scene" .glb)
  if [ "$which" = f20 ]; then
    configs=(--candidates 6 --include "$inc/r4.toml,$inc/f20x4-bg1d3m4.toml")
    file="$out/$name-f20-albedo-clamp.toml"
  else
    configs=(--candidates 7 --include "$inc/r4.toml,$inc/r1d3m4.toml,$inc/f30x4-bg1d3m4.toml")
    file="$out/$name-albedo-clamp.toml"
  fi
  "$fovea" tune --scene "$scene" --objective motion --reference-spp 128 --space small \
    --budget-of-regular 2 --reference-cache /tmp/tune-refs-window --display vive-pro-eye \
    --window 632x474 --frames 1 "${configs[@]}" --out "$file"
done
