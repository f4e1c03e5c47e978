#!/usr/bin/env python3
"""Per-step wall time of `clod simulate` / `clod mujoco` runs: median and p99 of summary.json's
step_seconds (microseconds) and contacts per step (contacts.csv rows / steps), one line per DIR.

usage: step_times.py DIR [DIR ...]   (for clod mujoco pass OUT/mujoco and OUT/clod)
"""
import csv
import json
import statistics
import sys

for d in sys.argv[1:]:
    summary = json.load(open(d + "/summary.json"))
    steps = sorted(1e6 * s for s in summary["step_seconds"])
    rows = sum(1 for _ in csv.DictReader(open(d + "/contacts.csv")))
    print(f"{d}: {len(steps)} steps, {statistics.median(steps):.0f} us median, "
          f"{steps[int(0.99 * (len(steps) - 1))]:.0f} us p99, {rows / len(steps):.2f} contacts per step")
