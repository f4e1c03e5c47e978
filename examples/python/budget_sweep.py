#!/usr/bin/env python3
"""A budgeted query sweep: how contacts between two overlapping meshes improve with the budget.

    PYTHONPATH=build/python /usr/bin/python3 examples/python/budget_sweep.py [MESH] [-o sweep.png]

Bakes the mesh once, places a turned copy so that it penetrates the first by 1 % of the diagonal
(found by bisection on the exact model), and queries the pair with every
model at budgets of 1 .. 4096 sphere/triangle tests and unlimited. For each answer it prints the
tests used, the level reached, the contacts and the angle between the deepest contact's normal and
the exact model's at an unlimited budget (the reference). With -o, plots angle and depth vs budget.
"""

import argparse
import os

import numpy as np

import clod

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("mesh", nargs="?", default=os.path.join(ROOT, "..", "shared", "data", "meshes", "bunny-1500.obj"))
    parser.add_argument("-o", "--output", help="plot file (PNG)")
    parser.add_argument("--quick", action="store_true", help="a small bake (tests)")
    args = parser.parse_args()

    mesh = clod.Mesh.load(args.mesh)
    options = dict(sphere_tree="octree", levels=3, sdf_depth=6) if args.quick else dict(sphere_tree="octree")
    baked = clod.bake(mesh, **options)
    identity = [0, 0, 0, 1, 0, 0, 0]
    # B: the same mesh turned 30 degrees about z, moved along x until it just touches A (bisection
    # on the exact model at an unlimited budget), then 1 % of the diagonal back into A.
    half = np.radians(30) / 2
    rotation = [np.cos(half), 0, 0, np.sin(half)]
    apart, touching = 2.0 * mesh.diagonal, 0.0
    for _ in range(16 if args.quick else 40):
        middle = 0.5 * (apart + touching)
        if clod.query(baked, identity, baked, [middle, 0, 0, *rotation], model="exact").colliding:
            touching = middle
        else:
            apart = middle
    pose_b = [touching - 0.01 * mesh.diagonal, 0, 0, *rotation]

    reference = clod.query(baked, identity, baked, pose_b, model="exact")
    n_ref = reference.normal[0]
    budgets = [1, 16, 256, None] if args.quick else [1, 4, 16, 64, 256, 1024, 4096, None]
    models = ("dos", "cfm", "exact") if args.quick else ("dos", "average", "cfm", "contact-tree", "exact")
    rows = []
    print(f"{'model':>12} {'budget':>8} {'tests':>7} {'level':>5} {'contacts':>8} {'depth':>9} {'angle':>7}")
    for model in models:
        for budget in budgets:
            r = clod.query(baked, identity, baked, pose_b, model=model, budget=budget, max_contacts=8)
            angle = np.degrees(np.arccos(np.clip(r.normal[0] @ n_ref, -1, 1))) if len(r) else np.nan
            depth = r.penetration_depth[0] if len(r) else np.nan
            rows.append((model, budget or 0, r.budget_used, angle, depth))
            print(f"{model:>12} {budget or 'inf':>8} {r.budget_used:>7} {r.max_level:>5} {len(r):>8} {depth:>9.4f} {angle:>6.1f}°")
    if args.output:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, axes = plt.subplots(1, 2, figsize=(11, 4))
        for model in models:
            mine = [row for row in rows if row[0] == model]
            used = [max(row[2], 1) for row in mine]
            axes[0].plot(used, [row[3] for row in mine], "o-", label=model)
            axes[1].plot(used, [row[4] for row in mine], "o-", label=model)
        for ax, label in zip(axes, ("normal error vs exact (degrees)", "deepest contact depth")):
            ax.set_xscale("log")
            ax.set_xlabel("tests used")
            ax.set_ylabel(label)
            ax.grid(True, alpha=0.3)
        axes[0].legend()
        fig.savefig(args.output, dpi=120, bbox_inches="tight")
        print(f"wrote {args.output}")


if __name__ == "__main__":
    main()
