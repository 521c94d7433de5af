#!/usr/bin/env python3
"""Mitsuba 3 reference timing: Cornell box, 512x512, `path` integrator, CPU (llvm_ad_rgb).

A peer tool for measuring fovea's trace throughput against (README, "Measured"), never a
dependency of fovea: run it in its own venv, on the same machine and in the same session as
`fovea render --bench --width 512 --height 512 --spp 16 --max-bounces 8`.

Depth mapping (fovea `--max-bounces B`  ->  Mitsuba `max_depth = B + 1`; default B=8 -> 9):
  Mitsuba's `path` integrator documents max_depth as "the longest path depth in
  the generated output image (where -1 corresponds to infinity). A value of 1
  will only render directly visible light sources. 2 will lead to single-bounce
  (direct-only) illumination, and so on."  So max_depth counts path segments,
  including the camera -> first-hit segment: max_depth=D collects emission at
  vertices 0..D-1 (vertex 0 = camera ray's hit). In the source, depth starts at 1
  after the camera hit and each loop iteration (run while depth < max_depth)
  adds emission (NEE + BSDF hit) from one more vertex.
  fovea --max-bounces 8 gathers emission at vertices 0..8 = 9 segments -> max_depth=9.
  Note: Mitsuba's `path` also applies Russian roulette after rr_depth (default 5).

Install: python3 -m venv /tmp/mitsuba-venv && /tmp/mitsuba-venv/bin/pip install "mitsuba==3.9.0" "drjit==1.4.0"
         then /tmp/mitsuba-venv/bin/python tools/mitsuba-cornell.py. drjit 1.5.0 (mitsuba 3.9.1) emits
llvm.minimum, which the system libLLVM-15 cannot compile on x86 ("LLVM ERROR: Cannot select ... fminimum").

Usage: python mitsuba-cornell.py [--max-depth 9] [--spp 16] [--frames 3] [--out img.exr]
"""
import argparse, statistics, time

import drjit as dr
import mitsuba as mi

ap = argparse.ArgumentParser()
ap.add_argument('--max-depth', type=int, default=9, help='Mitsuba max_depth (= fovea max-bounces + 1)')
ap.add_argument('--spp', type=int, default=16, help='samples per pixel')
ap.add_argument('--frames', type=int, default=3, help='timed frames after the warm-up')
ap.add_argument('--out', help='optional: write the last frame here (e.g. .exr)')
args = ap.parse_args()

mi.set_variant('llvm_ad_rgb')
W = H = 512

scene_dict = mi.cornell_box()
scene_dict['sensor']['film']['width'] = W
scene_dict['sensor']['film']['height'] = H
scene_dict['sensor']['sampler']['sample_count'] = args.spp
scene_dict['integrator'] = {'type': 'path', 'max_depth': args.max_depth}
scene = mi.load_dict(scene_dict)

def render(seed):
    t0 = time.perf_counter()
    img = mi.render(scene, spp=args.spp, seed=seed)
    dr.eval(img)
    dr.sync_thread()          # wait until the kernel has really finished
    return img, time.perf_counter() - t0

print(f'mitsuba {mi.__version__}, drjit {dr.__version__}, variant {mi.variant()}, '
      f'drjit threads {dr.thread_count() if hasattr(dr, "thread_count") else "n/a"}')
print(f'{W}x{H}, spp={args.spp}, max_depth={args.max_depth}, frames={args.frames}')

_, t = render(seed=10_000)    # warm-up: JIT compile (seed differs from timed ones)
print(f'warm-up (incl. JIT compile): {t:.3f} s')

times = []
for i in range(args.frames):
    img, t = render(seed=i)
    times.append(t)
    print(f'frame {i}: {t:.3f} s  {W * H * args.spp / t / 1e6:.3f} Msamples/s')

med = statistics.median(times)
print(f'median: {med:.3f} s  {W * H * args.spp / med / 1e6:.3f} Msamples/s')

if args.out:
    mi.util.write_bitmap(args.out, img)
    print(f'wrote {args.out}')
