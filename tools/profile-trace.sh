#!/usr/bin/env bash
# Profiles the trace pass on every built-in scene (issue 17's reference settings: 512x512,
# 16 spp, depth 8, pt, regular frames) and writes one CSV row per scene:
#
#   scene, GPU ms, Msamples/s and Mrays/s from `fovea render --bench` (medians of
#   --bench-frames frames after a warm-up frame: lavapipe compiles a pipeline's code on its
#   first dispatch), rays per path, then per ray what the BVH traversal did (TLAS/BLAS nodes
#   intersected, triangle and box/sphere tests, traversal steps at the TLAS/BLAS level) and the
#   SIMD occupancy at each level (busy lanes per subgroup step), from one more frame rendered with
#   --profile-traversal (the same image; counting makes it slower, so it is not timed).
#
# Usage: tools/profile-trace.sh [OUT.csv] [extra fovea render args, e.g. --integrator seed]
# Uses target/release/fovea (build it with `cargo build --release` first). Each scene's row is
# appended as soon as it is measured, so an interrupted run keeps what it measured.
set -euo pipefail

repo=$(cd "$(dirname "$0")/.." && pwd)
out=${1:-profile-trace.csv}
shift || true
fovea="$repo/target/release/fovea"
if [ ! -x "$fovea" ]; then
  echo "no $fovea: run \`cargo build --release\` first" >&2
  exit 1
fi
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

echo "scene,gpu_ms,msamples_per_s,mrays_per_s,rays_per_path,tlas_nodes,blas_nodes,triangles,primitives,tlas_steps,blas_steps,tlas_occupancy,blas_occupancy" > "$out"
# The counters are the software traversal's (ray queries are the driver's, uncounted).
size=(--width 512 --height 512 --spp 16 --max-bounces 8 --traversal software)
# "scene  traversal  gpu ms  Msamples/s  Mrays/s" rows, one per built-in scene.
"$fovea" render --bench "${size[@]}" --bench-frames 3 "$@" | tee "$work/bench.txt"
scenes=$("$fovea" scenes | awk 'NR > 1 { print $1 }')
for scene in $scenes; do
  timing=$(awk -v s="$scene" '$1 == s && NF == 5 { print $3 "," $4 "," $5 }' "$work/bench.txt")
  profiled=$("$fovea" render --scene "$scene" "${size[@]}" "$@" --out "$work/profiled.png" --profile-traversal)
  # "512x512 Pt, software traversal: 123.45 ms GPU, 1.23 Msamples/s, N rays (...)"
  rays=$(grep -E '^[0-9]+x[0-9]+ .* ms GPU' <<< "$profiled" | sed -E 's/.* ([0-9]+) rays .*/\1/')
  rays_per_path=$(awk -v r="$rays" -v p=$((512 * 512 * 16)) 'BEGIN { printf "%.3f", r / p }')
  per_ray=$(grep '^traversal per ray:' <<< "$profiled" | grep -oE '[0-9]+\.[0-9]+' | paste -sd, -)
  occupancy=$(grep '^traversal SIMD occupancy' <<< "$profiled" \
    | sed -E 's/.*TLAS level ([^,]+), BLAS level (.*)$/\1,\2/; s/%//g')
  echo "$scene,$timing,$rays_per_path,$per_ray,$occupancy" | tee -a "$out"
done
echo "wrote $out"
