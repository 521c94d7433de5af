#!/usr/bin/env bash
# Regular 4 spp, regular 1 spp denoised (`bg:1x1d3m4`) and 4-spp foveae of 30, 20 and 10 deg
# inside it, with the small space's regular and foveated configs, judged in motion on the
# three scenes at once (two cores: about 20 min with the references cached in
# /tmp/tune-refs-window; rendering them first took about 40 min more): the step-within-object
# run with the two smaller foveae added.
# Usage: bash run.sh FOVEA OUT_DIR TAG   (from the repository root); writes
# OUT_DIR/<scene>-TAG.toml and its -candidates.csv, -front.*, -tune.json and .log
set -euo pipefail
inc=reports/tune-motion-window-lavapipe/include
MORE_CONFIGS=",$inc/f20x4-bg1d3m4.toml,$inc/f10x4-bg1d3m4.toml" CANDIDATES=9 \
  exec bash reports/tune-motion-window-lavapipe/step-within-object/run.sh "$@"
