#!/usr/bin/env bash
# Regular 4 spp, regular 1 spp denoised (`bg:1x1d3m4`) and 4-spp foveae of 30, 20 and 10 deg
# inside it, with the small space's regular and foveated configs, judged in motion on the
# three scenes at once (two cores: about 20 min with the references cached in
# /tmp/tune-refs-window; rendering them first took about 40 min more).
# Usage: bash run.sh FOVEA OUT_DIR TAG   (from the repository root); writes
# OUT_DIR/<scene>-TAG.toml and its -candidates.csv, -front.*, -tune.json and .log
set -euo pipefail
fovea=$1 out=$2 tag=$3
inc=reports/tune-motion-window-lavapipe/include
mkdir -p "$out"
for scene in cornell bunny-high assets/gltf/textured-room.glb; do
  name=$(basename "$scene" .glb)
  "$fovea" tune --scene "$scene" --objective motion --reference-spp 128 --space small \
    --budget-of-regular 2 --reference-cache /tmp/tune-refs-window --display vive-pro-eye \
    --window 632x474 --frames 1 --candidates 9 \
    --include "$inc/r4.toml,$inc/r1d3m4.toml,$inc/f30x4-bg1d3m4.toml,$inc/f20x4-bg1d3m4.toml,$inc/f10x4-bg1d3m4.toml" \
    --out "$out/$name-$tag.toml" > "$out/$name-$tag.log" 2>&1 &
done
wait
