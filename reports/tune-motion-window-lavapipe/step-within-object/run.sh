#!/usr/bin/env bash
# Regular 4 spp, regular 1 spp denoised (`bg:1x1d3m4`) and a 4-spp fovea of 30 deg inside it,
# with the small space's regular and foveated configs, judged in motion on the three scenes at
# once (two cores: about 35 min with the references cached in /tmp/tune-refs-window).
# Usage: bash run.sh FOVEA OUT_DIR TAG   (from the repository root); writes
# OUT_DIR/<scene>-TAG.toml and its -candidates.csv, -front.*, -tune.json and .log
# MORE_CONFIGS (comma-separated TOMLs, each with a leading comma) adds configs to the three,
# CANDIDATES their count with the small space's four (default 7: none added).
set -euo pipefail
fovea=$1 out=$2 tag=$3
inc=reports/tune-motion-window-lavapipe/include
more=${MORE_CONFIGS:-}
candidates=${CANDIDATES:-7}
mkdir -p "$out"
for scene in cornell bunny-high assets/gltf/textured-room.glb; do
  name=$(basename "$scene" .glb)
  "$fovea" tune --scene "$scene" --objective motion --reference-spp 128 --space small \
    --budget-of-regular 2 --reference-cache /tmp/tune-refs-window --display vive-pro-eye \
    --window 632x474 --frames 1 --candidates "$candidates" \
    --include "$inc/r4.toml,$inc/r1d3m4.toml,$inc/f30x4-bg1d3m4.toml$more" \
    --out "$out/$name-$tag.toml" > "$out/$name-$tag.log" 2>&1 &
done
wait
