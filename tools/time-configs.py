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

Writes one CSV row per round, scene, config and binary (rewritten after every row, so an
interrupted run keeps what it measured): the median frame time and, where the binary prints
them (`fovea render --pass-times`), the medians of the trace, temporal and denoise passes.

With `--rounds N` the whole set runs N times, every other round in the reverse order of
configs, and with `--baseline NAME` each row also gives its frame and trace time over that
config's in the same round (scene and binary): ratios taken minutes apart, not across a run
in which the machine's speed drifted. The end prints each config's median and range of those
ratios over the rounds."""

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
    parser.add_argument("--rounds", type=int, default=1,
                        help="run the whole set this many times, alternating the order")
    parser.add_argument("--baseline", help="NAME of a --config to give every row's ratio to")
    parser.add_argument("--out", required=True, help="the CSV to write")
    args = parser.parse_args()
    if args.frames <= SKIPPED:
        sys.exit(f"time-configs: --frames must be more than {SKIPPED}")
    if args.rounds < 1:
        sys.exit("time-configs: --rounds must be at least 1")
    if args.baseline and args.baseline not in [name for name, _ in args.config]:
        sys.exit(f"time-configs: --baseline {args.baseline} is none of the --config names")
    fields = ["round", "scene", "config", "binary", "frames", "gpu_ms", "trace_ms",
              "temporal_ms", "denoise_ms", "gpu_of_baseline", "trace_of_baseline"]
    rows = []
    with tempfile.TemporaryDirectory() as folder:
        path = camera_path(args.frames, args.turn_deg, folder)
        for round_ in range(1, args.rounds + 1):
            configs = args.config if round_ % 2 == 1 else args.config[::-1]
            for scene in args.scene:
                for config_name, config in configs:
                    for bin_name, binary in args.bin:
                        ms, frames, passes = time_one(binary, scene, config, args, path, folder)
                        row = {"round": round_, "scene": os.path.basename(scene),
                               "config": config_name, "binary": bin_name, "frames": frames,
                               "gpu_ms": f"{ms:.2f}"}
                        for name in ["trace", "temporal", "denoise"]:
                            row[f"{name}_ms"] = f"{passes[name]:.2f}" if name in passes else ""
                        rows.append(row)
                        add_ratios(rows, args.baseline)
                        print(",".join(str(row.get(f, "")) for f in fields), flush=True)
                        with open(args.out, "w", newline="") as f:
                            writer = csv.DictWriter(f, fieldnames=fields)
                            writer.writeheader()
                            writer.writerows(rows)
    if args.baseline:
        summarise(rows)


def add_ratios(rows, baseline):
    """Each row's frame and trace time over the baseline config's of its round, scene and
    binary, once both are measured (the baseline may come before or after it)."""
    if not baseline:
        return
    for row in rows:
        base = next((b for b in rows if b["config"] == baseline and b["round"] == row["round"]
                     and b["scene"] == row["scene"] and b["binary"] == row["binary"]), None)
        if base is None:
            continue
        row["gpu_of_baseline"] = f"{float(row['gpu_ms']) / float(base['gpu_ms']):.3f}"
        if row["trace_ms"] and base["trace_ms"]:
            row["trace_of_baseline"] = f"{float(row['trace_ms']) / float(base['trace_ms']):.3f}"


def summarise(rows):
    """Per scene, config and binary: the median and range of its ratios over the rounds."""
    groups = {}
    for row in rows:
        if row.get("gpu_of_baseline"):
            groups.setdefault((row["scene"], row["config"], row["binary"]), []).append(row)
    for (scene, config, binary), group in groups.items():
        text = f"{scene} {config} {binary}:"
        for field, what in [("gpu_of_baseline", "frame"), ("trace_of_baseline", "trace")]:
            values = [float(r[field]) for r in group if r.get(field)]
            if values:
                text += (f" {what} {statistics.median(values):.3f}"
                         f" ({min(values):.3f}-{max(values):.3f})")
        print(f"{text} of the baseline over {len(group)} rounds")


if __name__ == "__main__":
    main()
