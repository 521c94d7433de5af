#!/usr/bin/env python3
"""Iso-quality speed-ups from `fovea tune` runs.

For each FILE-candidates.csv given: regular rendering's curve (the unfiltered `bg:1xN`
baselines: JOD against cost, linear in log cost between measured points) and, at each
target JOD (those of regular 1, 2 and 4 spp), the cheapest config that reaches it.
S = the cost regular rendering needs for that JOD / the cheapest config's cost. Cost is GPU
time as `pace_ratio` (each config's time over the budget's regular frame timed interleaved
with it: robust to the machine's speed drifting during the run; shown in ms as that ratio
times the budget config's own median) and, beside it, camera paths per pixel and, in runs
that counted them, all rays per pixel (what a GPU, whose per-pixel passes cost little, pays
most closely; the same on any machine). JOD is the run's objective (`jod`: in motion with `--objective motion`) and, as
the worst case, the first frame after the eye lands looking ahead (`jod_forward`).

    python3 tools/iso-quality.py reports/tune-motion-filter-lavapipe-720x800/*-candidates.csv

Tune times its candidates on the machine it runs on (lavapipe here). To know S in a GPU's time,
time the same configs there: `--write-configs DIR` writes each scene's distinct configs as
foveation files and prints, per scene, the `--config NAME=FILE` arguments of `fovea
gpu-report` (NAME: the config's short form, `_` for spaces); `--gpu-frames FRAMES.csv[,…]` then
reads those reports' one-eye medians as the cost and pools each scene's runs (one GPU run's
times compare across them; lavapipe runs' paces do not). Both leave out the runs whose regular
4 spp JOD differs from that of most runs of the scene (an older renderer's images).

    python3 tools/iso-quality.py --write-configs /tmp/configs reports/tune-motion-*-720x800/*-candidates.csv
    fovea gpu-report OUT --quick --size 720x800 --history --scenes SCENE --config …   # on the GPU
    python3 tools/iso-quality.py --gpu-frames OUT/frames.csv reports/tune-motion-*-720x800/*-candidates.csv
"""
import csv
import json
import math
import os
import sys


def regular_cost(curve, jod):
    """Cost regular rendering needs for `jod` (interpolated in log cost), None past its end."""
    curve = sorted(curve)
    for (c0, j0), (c1, j1) in zip(curve, curve[1:]):
        if j0 <= jod <= j1 and j1 > j0:
            t = (jod - j0) / (j1 - j0)
            return math.exp(math.log(c0) + t * (math.log(c1) - math.log(c0)))
    if curve and jod <= curve[0][1]:
        return curve[0][0]
    return None


def report(path, jod_column):
    rows = list(csv.DictReader(open(path)))
    judged_rows = [r for r in rows if judged(r, jod_column)]
    regular = regular_rows(judged_rows)
    # ms per unit of pace: the budget config's (pace 1) median, from any row's ms / pace.
    ms = float(regular[-1]["gpu_ms"]) / float(regular[-1]["pace_ratio"])
    counts = ["paths_per_pixel"]
    if all("rays_per_pixel" in r and judged(r, "rays_per_pixel") for r in judged_rows):
        counts.append("rays_per_pixel")
    names = {"paths_per_pixel": "paths", "rays_per_pixel": "rays"}
    print(f"\n{path} ({jod_column})")
    print("| target | regular ms | cheapest config | its JOD | its ms | S (GPU ms) | "
          + " | ".join(f"S ({names[c]})" for c in counts) + " |")
    print("|---|---:|---|---:|---:|---:|" + "---:|" * len(counts))
    for target_row in regular:
        target = float(target_row[jod_column])
        reach = [r for r in judged_rows if float(r[jod_column]) >= target - 1e-9]
        by_ms = min(reach, key=lambda r: float(r["pace_ratio"]))
        curve_ms = [(float(r["pace_ratio"]), float(r[jod_column])) for r in regular]
        need_ms = regular_cost(curve_ms, target)
        s_ms = need_ms / float(by_ms["pace_ratio"])
        by_count = []
        for c in counts:
            cheapest = min(reach, key=lambda r: float(r[c]))
            need = regular_cost([(float(r[c]), float(r[jod_column])) for r in regular], target)
            by_count.append(f"{need / float(cheapest[c]):.2f} (`{cheapest['config']}`)")
        print(
            f"| regular {target_row['config'][5:]} spp: {target:.3f} | {need_ms * ms:.1f} | "
            f"`{by_ms['config']}` | {float(by_ms[jod_column]):.3f} | "
            f"{float(by_ms['pace_ratio']) * ms:.1f} | "
            f"{s_ms:.2f} | " + " | ".join(by_count) + " |"
        )


def regular_rows(rows):
    """The unfiltered regular baselines (`bg:1xN`), by spp."""
    regular = [r for r in rows if r["config"].startswith("bg:1x") and r["config"][5:].isdigit()]
    return sorted(regular, key=lambda r: int(r["config"][5:]))


def scene_of(row):
    """The run's one scene, as gpu-report's --scenes takes it (a built-in name or a path)."""
    scenes = list(json.loads(row["scenes_json"]))
    if len(scenes) != 1:
        sys.exit(f"iso-quality: a run of {len(scenes)} scenes; give one-scene runs")
    return scenes[0]


def judged(row, column="jod"):
    return row[column] not in ("", "NaN", "nan")


def pooled_runs(paths):
    """Each scene's judged rows of all runs, one per config, leaving out the runs of an older
    renderer (a regular 4 spp JOD other than most runs')."""
    runs = []
    for path in paths:
        rows = list(csv.DictReader(open(path)))
        if rows:
            reg4 = [r["jod"] for r in rows if r["config"] == "bg:1x4"]
            runs.append((path, scene_of(rows[0]), reg4[0] if reg4 else None, rows))
    votes = {}
    for _, scene, reg4, _ in runs:
        if reg4 is not None:
            votes.setdefault(scene, []).append(reg4)
    usual = {scene: max(set(v), key=v.count) for scene, v in votes.items()}
    pools = {}
    for path, scene, reg4, rows in runs:
        if reg4 is not None and reg4 != usual[scene]:
            print(f"# left out {path}: regular 4 spp JOD {reg4}, not {usual[scene]}",
                  file=sys.stderr)
            continue
        for r in rows:
            if judged(r):
                pools.setdefault(scene, {}).setdefault(r["config"], r)
    return pools


def gpu_name(config):
    return config.replace(" ", "_")


def toml_of(config):
    """The foveation file's text (assets/foveation/ shows the layout)."""
    lines = [f"blend_deg = {float(config['blend_deg'])}"]
    if config.get("occlusion_deg") is not None:
        lines.append(f"occlusion_deg = {float(config['occlusion_deg'])}")
    for layer in config["layers"]:
        lines += ["", "[[layer]]"]
        lines += [f"{key} = {json.dumps(value)}" for key, value in layer.items()]
    return "\n".join(lines) + "\n"


def write_configs(out, paths):
    for scene, pool in pooled_runs(paths).items():
        folder = os.path.join(out, os.path.splitext(os.path.basename(scene))[0])
        os.makedirs(folder, exist_ok=True)
        args = []
        for i, (name, row) in enumerate(sorted(pool.items())):
            path = os.path.join(folder, f"c{i:03}.toml")
            with open(path, "w") as f:
                f.write(f"# {name}\n" + toml_of(json.loads(row["config_json"])))
            args.append(f"--config {gpu_name(name)}={path}")
        print(f"{scene}\t{' '.join(args)}")


def gpu_report(frames_paths, paths):
    """S with each config's one-eye GPU median from gpu-reports' frames.csv (comma-separated
    paths; a config in several, at its fastest) as its cost."""
    ms = {}
    for frames_path in frames_paths.split(","):
        for f in csv.DictReader(open(frames_path)):
            if f["eyes"] == "1":
                key = (f["scene"], f["mode"])
                ms[key] = min(ms.get(key, math.inf), float(f["median_ms"]))
    for scene, pool in pooled_runs(paths).items():
        rows = [r for r in pool.values() if (scene, gpu_name(r["config"])) in ms]
        missing = len(pool) - len(rows)
        for r in rows:
            r["gpu_ms"] = ms[(scene, gpu_name(r["config"]))]
        regular = regular_rows(rows)
        if not regular:
            print(f"\n{scene}: no regular config timed in {frames_paths}")
            continue
        for column in ("jod", "jod_forward"):
            print(f"\n{scene} ({column}; {len(rows)} configs timed, {missing} not)")
            print("| target | regular ms | cheapest config | its JOD | its ms | S (GPU ms) |")
            print("|---|---:|---|---:|---:|---:|")
            curve = [(r["gpu_ms"], float(r[column])) for r in regular]
            for target_row in regular:
                target = float(target_row[column])
                reach = [r for r in rows if float(r[column]) >= target - 1e-9]
                best = min(reach, key=lambda r: r["gpu_ms"])
                need = regular_cost(curve, target)
                print(f"| regular {target_row['config'][5:]} spp: {target:.3f} | {need:.3f} | "
                      f"`{best['config']}` | {float(best[column]):.3f} | {best['gpu_ms']:.3f} | "
                      f"{need / best['gpu_ms']:.2f} |")


def main():
    args = sys.argv[1:]
    if len(args) >= 3 and args[0] == "--write-configs":
        return write_configs(args[1], args[2:])
    if len(args) >= 3 and args[0] == "--gpu-frames":
        return gpu_report(args[1], args[2:])
    if not args or args[0].startswith("--"):
        sys.exit("usage: tools/iso-quality.py [--write-configs DIR | --gpu-frames FRAMES.csv[,FRAMES.csv...]] "
                 "FILE-candidates.csv...")
    for path in args:
        for column in ("jod", "jod_forward"):
            report(path, column)


if __name__ == "__main__":
    main()
