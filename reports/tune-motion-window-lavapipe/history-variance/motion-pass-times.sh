#!/usr/bin/env bash
# The temporal pass's time in motion before and after it shares the neighbourhood clamp's
# reads with the denoiser's noise estimate: 720x800, Vive Pro Eye field, bg:1x1d3m4, a camera
# turning 0.5 deg yaw and 0.2 deg pitch a frame for 12 frames; the medians of frames 2-11, the
# two binaries taking turns, three rounds. Also checks the frames are the same bit for bit.
# Usage: bash motion-pass-times.sh BEFORE AFTER   (fovea binaries; from the repository root)
set -euo pipefail
before=$1 after=$2 work=$(mktemp -d)
{
  echo "frame,dx,dy,dz,yaw_deg,pitch_deg,roll_deg"
  for k in $(seq 0 11); do awk -v k="$k" 'BEGIN { printf "%d,0,0,0,%.1f,%.1f,0\n", k, 0.5 * k, 0.2 * k }'; done
} > "$work/turn.csv"
echo "scene,binary,round,frame_ms,temporal_ms"
for scene in cornell bunny-high; do
  for round in 1 2 3; do
    for name in before after; do
      bin=${!name}
      "$bin" render --scene $scene --width 720 --height 800 --fov vive-pro-eye \
        --foveation reports/tune-motion-window-lavapipe/include/r1d3m4.toml \
        --camera-path "$work/turn.csv" --out "$work/$name" --pass-times > "$work/log" 2>&1
      python3 - "$work/log" "$scene,$name,$round" <<'P'
import re, statistics, sys
text = open(sys.argv[1]).read()
frames = [float(ms) for k, ms in re.findall(r"^frame (\d+): ([\d.]+) ms GPU", text, re.M) if int(k) >= 2]
temporal = [float(ms) for ms in re.findall(r"gpu pass temporal: ([\d.]+) ms", text)][2:]
print(f"{sys.argv[2]},{statistics.median(frames):.1f},{statistics.median(temporal):.1f}")
P
    done
    for f in "$work"/before/*.png; do cmp -s "$f" "$work/after/$(basename "$f")" || echo "# $scene: $(basename "$f") differs"; done
  done
done
rm -rf "$work"
