#!/usr/bin/env python3
"""Times foveation configs as `fovea tune` times them: one eye at the headset's field of view,
gaze forward, the temporal history on, the camera still (or, with `--turn-deg`, turning that
many degrees a frame, so that the temporal pass reprojects as it does in motion); the median
GPU time of a sequence's frames after the first two (which fill the history). Each config
runs under every binary given, one after the other, so that the binaries' times of a config
are taken side by side: on a machine whose speed drifts, compare them as ratios within one
run.

  python3 tools/time-configs.py --bin before=/tmp/fovea-old --bin after=target/release/fovea \\
      --scene cornell --scene assets/gltf/textured-room.glb \\
      --config reg4=r4.toml --config d3m4=r1d3m4.toml --out times.csv

Writes one CSV row per scene, config and binary (rewritten after every row, so an interrupted
run keeps what it measured): the median frame time and, where the binary prints them
(`fovea render --pass-times`), the medians of the trace, temporal and denoise passes."""

import argparse
import csv
import os
import re
import statistics
import subprocess
import sys
import tempfile

FRAME = re.compile(r"^frame (\d+): ([\d.]+) ms GPU", re.M)
PASS = re.compile(r"^  gpu pass (.+?): ([\d.]+) ms$")
SKIPPED = 2  # frames that fill the history before the timed ones


def named(text):
    name, sep, value = text.partition("=")
    if not sep or not name or not value:
        raise argparse.ArgumentTypeError(f"'{text}': give NAME=PATH")
    return name, value


def camera_path(frames, turn_deg, folder):
    """The camera's path: still, or yawing `turn_deg` degrees a frame."""
    path = os.path.join(folder, "path.csv")
    with open(path, "w") as f:
        f.write("frame,dx,dy,dz,yaw_deg,pitch_deg,roll_deg\n")
        for k in range(frames):
            f.write(f"{k},0,0,0,{turn_deg * k:g},0,0\n")
    return path


def passes_of(stdout):
    """Per pass, its summed milliseconds in each timed frame (a pass runs once per eye)."""
    per_pass, frame = {}, -1
    for line in stdout.splitlines():
        m = FRAME.match(line)
        if m:
            frame = int(m.group(1))
            continue
        m = PASS.match(line)
        if m and frame >= SKIPPED:
            frames = per_pass.setdefault(m.group(1), {})
            frames[frame] = frames.get(frame, 0.0) + float(m.group(2))
    return {name: statistics.median(v.values()) for name, v in per_pass.items()}


def time_one(binary, scene, config, args, path, folder):
    command = [
        binary, "render", "--scene", scene, "--width", str(args.width), "--height",
        str(args.height), "--fov", args.fov, "--foveation", config, "--camera-path", path,
        "--out", os.path.join(folder, "frames"),
    ]
    if args.pass_times:
        command.append("--pass-times")
    run = subprocess.run(command, capture_output=True, text=True)
    times = [float(ms) for k, ms in FRAME.findall(run.stdout) if int(k) >= SKIPPED]
    if run.returncode != 0 or not times:
        sys.exit(f"time-configs: {' '.join(command)} failed:\n{run.stderr[-2000:]}")
    return statistics.median(times), len(times), passes_of(run.stdout)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--bin", type=named, action="append", required=True,
                        help="NAME=PATH of a fovea binary (repeat to compare)")
    parser.add_argument("--scene", action="append", required=True,
                        help="a built-in scene or a .gltf/.glb file (repeat)")
    parser.add_argument("--config", type=named, action="append", required=True,
                        help="NAME=FILE of a foveation TOML (repeat)")
    parser.add_argument("--frames", type=int, default=18,
                        help=f"frames per sequence, the first {SKIPPED} untimed (default 18)")
    parser.add_argument("--width", type=int, default=720)
    parser.add_argument("--height", type=int, default=800)
    parser.add_argument("--fov", default="vive-pro-eye")
    parser.add_argument("--turn-deg", type=float, default=0.0,
                        help="yaw the camera this many degrees a frame (default 0: still)")
    parser.add_argument("--no-pass-times", dest="pass_times", action="store_false",
                        help="for binaries without `fovea render --pass-times`")
    parser.add_argument("--out", required=True, help="the CSV to write")
    args = parser.parse_args()
    if args.frames <= SKIPPED:
        sys.exit(f"time-configs: --frames must be more than {SKIPPED}")
    fields = ["scene", "config", "binary", "frames", "gpu_ms", "trace_ms", "temporal_ms",
              "denoise_ms"]
    rows = []
    with tempfile.TemporaryDirectory() as folder:
        path = camera_path(args.frames, args.turn_deg, folder)
        for scene in args.scene:
            for config_name, config in args.config:
                for bin_name, binary in args.bin:
                    ms, frames, passes = time_one(binary, scene, config, args, path, folder)
                    row = {"scene": os.path.basename(scene), "config": config_name,
                           "binary": bin_name, "frames": frames, "gpu_ms": f"{ms:.2f}"}
                    for name in ["trace", "temporal", "denoise"]:
                        row[f"{name}_ms"] = f"{passes[name]:.2f}" if name in passes else ""
                    rows.append(row)
                    print(",".join(str(row[f]) for f in fields), flush=True)
                    with open(args.out, "w", newline="") as f:
                        writer = csv.DictWriter(f, fieldnames=fields)
                        writer.writeheader()
                        writer.writerows(rows)


if __name__ == "__main__":
    main()
