#!/usr/bin/env bash
# Makes the venv with FovVideoVDP (pyfvvdp, from the Python package index) that `fovea bench`
# and `fovea tune` call for JOD scores: .venv-fvvdp/ at the repository root (idempotent).
# FovVideoVDP is a peer tool, like Mitsuba: the renderer itself never needs it.
#
# torch comes from the package index as well; its Linux wheels bring the CUDA runtime
# packages (about 5 GB installed), which the metric does not use here: it runs on the CPU.
set -euo pipefail
cd "$(dirname "$0")/.."
VENV=.venv-fvvdp
PYFVVDP=pyfvvdp==1.2.2

SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
if ! python3 -c 'import ensurepip, venv' 2>/dev/null; then
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -q python3-venv
fi
if [ -x "$VENV/bin/python" ] && "$VENV/bin/python" -c 'import pyfvvdp, torch' 2>/dev/null; then
  echo "setup-fvvdp: $VENV already has pyfvvdp"
  exit 0
fi
python3 -m venv "$VENV"
# No download cache: the wheels (~3 GB) would stay in ~/.cache beside their installed copy.
"$VENV/bin/pip" install -q --no-cache-dir "$PYFVVDP"
# The check fovea makes before it trusts the venv: the metric loads and scores an image.
"$VENV/bin/python" - <<'PY'
import numpy as np, torch, pyfvvdp
m = pyfvvdp.fvvdp(display_name="htc_vive_pro", foveated=True, quiet=True)
img = torch.tensor(np.full((32, 32, 3), 0.5, dtype=np.float32))
q, _ = m.predict(img, img, dim_order="HWC")
assert abs(float(q) - 10.0) < 1e-3, q
print(f"setup-fvvdp: pyfvvdp ready (torch {torch.__version__})")
PY
