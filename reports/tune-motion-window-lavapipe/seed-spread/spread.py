#!/usr/bin/env python3
"""Each config's JOD in motion over render seeds, and its margin over regular 4 spp's JOD of the
same seed (the margin is what S's strict test compares; the references are the same).

Usage: python3 spread.py SCENE=SEED1.csv,SEED2.csv,... [SCENE=...]
Prints one Markdown table per scene."""
import csv
import statistics
import sys

REGULAR_4 = "bg:1x4"


def jods(path):
    with open(path, newline="") as f:
        return {row["config"]: float(row["jod_motion"]) for row in csv.DictReader(f)}


def table(scene, paths):
    runs = [jods(p) for p in paths]
    configs = [c for c in runs[0] if all(c in r for r in runs)]
    print(f"\n{scene} ({len(runs)} render seeds)\n")
    print("| config | JOD per seed | mean | spread (max − min) | margin over regular 4 spp per seed |")
    print("|---|---|---:|---:|---|")
    for c in configs:
        values = [r[c] for r in runs]
        margins = [r[c] - r[REGULAR_4] for r in runs]
        print(
            f"| `{c}` | {' / '.join(f'{v:.3f}' for v in values)} | "
            f"{statistics.mean(values):.3f} | {max(values) - min(values):.3f} | "
            + ("—" if c == REGULAR_4 else " / ".join(f"{m:+.3f}" for m in margins))
            + " |"
        )


for arg in sys.argv[1:]:
    scene, files = arg.split("=", 1)
    table(scene, files.split(","))
