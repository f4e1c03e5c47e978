#!/usr/bin/env python3
"""A falling stack, built in code: boxes dropped one above the other onto the ground.

    PYTHONPATH=build/python /usr/bin/python3 examples/python/falling_stack.py [--boxes 5] [-o stack.png]

Bakes a ground slab and a 1 m box once, adds the ground (static) and the boxes (dynamic, each
dropped from a little above the one below, turned a few degrees) to a clod.World with a budget of
tests per step, runs it with the GIL released (World.run returns every step's positions as one
array) and prints where the boxes came to rest: the stack's heights should be 0.5, 1.5, 2.5, ...
With -o, plots the heights over time.
"""

import argparse

import numpy as np

import clod


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--boxes", type=int, default=5)
    parser.add_argument("--seconds", type=float, default=4.0)
    parser.add_argument("--model", default="cfm", choices=clod.contact_models)
    parser.add_argument("--budget", type=int, default=512, help="tests per step (0 = unlimited)")
    parser.add_argument("-o", "--output", help="plot file (PNG)")
    parser.add_argument("--quick", action="store_true", help="3 boxes, 1 s (tests)")
    args = parser.parse_args()
    if args.quick:
        args.boxes, args.seconds = 3, 1.0

    small = dict(sphere_tree="octree", levels=3, sdf_depth=6, measure_fit=False)
    ground = clod.bake(clod.Mesh.box([3.0, 3.0, 0.25]), **small)
    box = clod.bake(clod.Mesh.box([0.5, 0.5, 0.5]), **small)
    world = clod.World(model=args.model, budget=args.budget, min_substeps=8, dt=1 / 60)
    world.add_body(ground, type="static", position=[0, 0, -0.25], friction=0.6, name="ground")
    for k in range(args.boxes):
        angle = np.radians(5.0 * k)
        world.add_body(box, position=[0, 0, 0.6 + 1.15 * k], orientation=[np.cos(angle / 2), 0, 0, np.sin(angle / 2)],
                       density=500.0, friction=0.6, name=f"box{k}")

    steps = int(round(args.seconds / world.dt))
    run = world.run(steps)
    heights = run["positions"][:, 1:, 2]
    print(f"{args.boxes} boxes, {steps} steps of {world.dt:.4f} s, model {args.model}, budget {args.budget} tests/step: "
          f"at most {run['budget_spent'].max()} spent in a step")
    for k, z in enumerate(world.positions[1:, 2]):
        print(f"  box{k}: rests at z = {z:.4f} m (stacked: {0.5 + k:.1f}), speed {np.linalg.norm(world.velocities[k + 1]):.4f} m/s")
    if args.output:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        t = np.arange(1, steps + 1) * world.dt
        fig, ax = plt.subplots(figsize=(7, 4))
        for k in range(args.boxes):
            ax.plot(t, heights[:, k], label=f"box{k}")
        ax.set_xlabel("time (s)")
        ax.set_ylabel("centre height (m)")
        ax.legend()
        ax.grid(True, alpha=0.3)
        fig.savefig(args.output, dpi=120, bbox_inches="tight")
        print(f"wrote {args.output}")


if __name__ == "__main__":
    main()
