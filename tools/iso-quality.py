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
"""
import csv
import math
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
    judged = [r for r in rows if r[jod_column] not in ("", "NaN", "nan")]
    regular = [r for r in judged if r["config"].startswith("bg:1x") and r["config"][5:].isdigit()]
    regular.sort(key=lambda r: int(r["config"][5:]))
    # ms per unit of pace: the budget config's (pace 1) median, from any row's ms / pace.
    ms = float(regular[-1]["gpu_ms"]) / float(regular[-1]["pace_ratio"])
    counts = ["paths_per_pixel"]
    if all(r.get("rays_per_pixel", "") not in ("", "NaN", "nan") for r in judged):
        counts.append("rays_per_pixel")
    names = {"paths_per_pixel": "paths", "rays_per_pixel": "rays"}
    print(f"\n{path} ({jod_column})")
    print("| target | regular ms | cheapest config | its JOD | its ms | S (GPU ms) | "
          + " | ".join(f"S ({names[c]})" for c in counts) + " |")
    print("|---|---:|---|---:|---:|---:|" + "---:|" * len(counts))
    for target_row in regular:
        target = float(target_row[jod_column])
        reach = [r for r in judged if float(r[jod_column]) >= target - 1e-9]
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


def main():
    if len(sys.argv) < 2:
        sys.exit("usage: tools/iso-quality.py FILE-candidates.csv...")
    for path in sys.argv[1:]:
        for column in ("jod", "jod_forward"):
            report(path, column)


if __name__ == "__main__":
    main()
