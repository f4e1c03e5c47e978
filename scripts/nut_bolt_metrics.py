#!/usr/bin/env python3
"""Measures a nut-on-bolt run (docs/engines.md, "Nut on a bolt") from the files `clod simulate
scenes/nut_bolt.json -o DIR` or `clod mujoco scenes/mujoco/nut_bolt.xml -o DIR` write (for the
latter pass DIR/clod or DIR/mujoco): turns about the bolt's axis, advance per turn after the first
0.1 s (the nut settles onto the load flank first), the nut's height off the thread's helix (the
play is +-87 um), lateral shift and tilt, microseconds per step (median and p99 of the run's
step times) and contacts per step (the one nut-bolt pair).

usage: nut_bolt_metrics.py DIR [--origin-z Z] [--pitch P] [--screw-ratios S]

--screw-ratios S also prints, for the contacts of the last S seconds, the screw ratio
(p x n)_z / n_z of each contact (p its point, n its normal, the bolt's axis being z): on the
flanks of a helix of pitch P it is +-P / 2 pi at every point (0.318 mm for M16 x 2); contacts
whose ratios have both signs can hold the nut's weight without turning it (docs/engines.md,
"Why the nut jams from rest"), and the radial / tangential / axial parts of the normals.

The trajectory holds the pose of what the run calls the nut: its mesh frame (clod simulate) or
its geom, which MuJoCo puts at the mesh's centroid (clod mujoco). Both move rigidly with the
nut, so the nut's own origin -- at (0, 0, Z) at the start, Z = 0.018 in the scenes -- is
followed through the relative rotation.
"""
import argparse
import csv
import json
import math
import statistics


def qmul(a, b):
    w1, x1, y1, z1 = a
    w2, x2, y2, z2 = b
    return (w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2, w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
            w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2, w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2)


def rotate(q, v):
    w, x, y, z = q
    return qmul(qmul(q, (0.0,) + tuple(v)), (w, -x, -y, -z))[1:]


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("dir")
    parser.add_argument("--origin-z", type=float, default=0.018)
    parser.add_argument("--pitch", type=float, default=0.002)
    parser.add_argument("--screw-ratios", type=float, default=0.0)
    args = parser.parse_args()
    rows = [r for r in csv.DictReader(open(args.dir + "/trajectory.csv")) if r["body"] == "nut"]
    key = ("qw", "qx", "qy", "qz")
    q0 = tuple(float(rows[0][k]) for k in key)
    q0inv = (q0[0], -q0[1], -q0[2], -q0[3])
    p0 = [float(rows[0][k]) for k in ("px", "py", "pz")]
    toOrigin = (-p0[0], -p0[1], args.origin_z - p0[2])
    turns, previous = 0.0, None
    samples = []
    for r in rows:
        q = qmul(tuple(float(r[k]) for k in key), q0inv)
        angle = 2 * math.atan2(q[3], q[0])
        if previous is not None:
            d = angle - previous
            turns += (d - 2 * math.pi * round(d / (2 * math.pi))) / (2 * math.pi)
        previous = angle
        o = rotate(q, toOrigin)
        origin = [float(r[k]) + o[i] for i, k in enumerate(("px", "py", "pz"))]
        tilt = 2 * math.degrees(math.asin(min(1.0, math.hypot(q[1], q[2]))))
        samples.append((float(r["time"]), origin, turns, tilt))
    t0 = samples[0][0] + 0.1
    settled = next(s for s in samples if s[0] >= t0)
    end = samples[-1]
    off = [(s[1][2] - args.origin_z) - args.pitch * s[2] for s in samples]
    summary = json.load(open(args.dir + "/summary.json"))
    steps = [1e6 * s for s in summary["step_seconds"]]
    contactSteps = {}
    for r in csv.DictReader(open(args.dir + "/contacts.csv")):
        contactSteps[r["step"]] = contactSteps.get(r["step"], 0) + 1
    perStep = sum(contactSteps.values()) / max(1, len(samples) - 1)
    advance = (end[1][2] - settled[1][2]) / (end[2] - settled[2]) if abs(end[2] - settled[2]) > 1e-3 else float("nan")
    print(f"{args.dir}: {end[0]:.2f} s simulated, {end[2]:+.3f} turns, advance per turn {advance * 1e3:.4f} mm "
          f"({100 * (advance / args.pitch - 1):+.2f} % of the pitch), off the helix [{min(off) * 1e6:.1f}, "
          f"{max(off) * 1e6:.1f}] um, lateral max {max(math.hypot(s[1][0], s[1][1]) for s in samples) * 1e6:.1f} um, "
          f"tilt max {max(s[3] for s in samples):.3f} deg; {statistics.median(steps):.0f} us per step median, "
          f"{sorted(steps)[int(0.99 * (len(steps) - 1))]:.0f} p99; {perStep:.2f} contacts per step")
    if args.screw_ratios > 0:
        dt = samples[1][0] - samples[0][0]
        first = int(round((end[0] - args.screw_ratios) / dt))
        ratios, tangential = [], []
        for r in csv.DictReader(open(args.dir + "/contacts.csv")):
            if int(r["step"]) < first:
                continue
            x, y = float(r["px"]), float(r["py"])
            nx, ny, nz = float(r["nx"]), float(r["ny"]), float(r["nz"])
            if abs(nz) < 1e-9:
                continue
            ratios.append((x * ny - y * nx) / nz)
            radius = math.hypot(x, y)
            tangential.append((-nx * y + ny * x) / radius)
        ratios.sort()
        tangential.sort()
        if ratios:
            print(f"screw ratio (p x n)_z / n_z over {len(ratios)} contacts of the last {args.screw_ratios} s: "
                  f"min {ratios[0] * 1e3:.3f} mm, median {ratios[len(ratios) // 2] * 1e3:.3f} mm, max {ratios[-1] * 1e3:.3f} mm "
                  f"(a flank's: +-{args.pitch / (2 * math.pi) * 1e3:.3f} mm); tangential part of the normals "
                  f"{tangential[0]:.3f} .. {tangential[-1]:.3f}")


if __name__ == "__main__":
    main()
