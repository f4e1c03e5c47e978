#!/usr/bin/env python3
"""Exact closest points on a mesh: a signed-distance slice and closest-point segments, plotted.

    PYTHONPATH=build/python /usr/bin/python3 examples/python/closest_points.py [MESH] -o closest.png

Samples a grid on the plane through the mesh's centre (normal z), asks clod for the closest point,
feature, normal and signed distance of every grid point in one call (parallel, GIL released), and
draws the signed distance as a colour map with its zero contour (the mesh's cross-section) and, for
a few points, the segment to their closest point.
"""

import argparse
import os
import time

import matplotlib

matplotlib.use("Agg")  # files only, no display needed
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import clod  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("mesh", nargs="?", default=os.path.join(ROOT, "..", "shared", "data", "meshes", "bunny-1500.obj"))
    parser.add_argument("-o", "--output", default="closest.png")
    parser.add_argument("--resolution", type=int, default=400, help="grid points per side")
    parser.add_argument("--quick", action="store_true", help="a coarse grid (tests)")
    args = parser.parse_args()
    n = 60 if args.quick else args.resolution

    mesh = clod.Mesh.load(args.mesh)
    lo, hi = mesh.bounds
    margin = 0.15 * (hi - lo)
    xs = np.linspace(lo[0] - margin[0], hi[0] + margin[0], n)
    ys = np.linspace(lo[1] - margin[1], hi[1] + margin[1], n)
    gx, gy = np.meshgrid(xs, ys)
    z = 0.5 * (lo[2] + hi[2])
    points = np.column_stack([gx.ravel(), gy.ravel(), np.full(gx.size, z)])

    start = time.perf_counter()
    result = mesh.closest(points)
    seconds = time.perf_counter() - start
    kinds = np.bincount(result.feature_type, minlength=3)
    print(f"{len(points)} points in {seconds * 1e3:.1f} ms ({result.sign_method} signs); closest features: "
          f"{kinds[clod.FEATURE_VERTEX]} vertices, {kinds[clod.FEATURE_EDGE]} edges, {kinds[clod.FEATURE_FACE]} faces")

    sd = result.signed_distance.reshape(gx.shape)
    limit = np.abs(sd).max()
    fig, ax = plt.subplots(figsize=(7, 6))
    image = ax.pcolormesh(gx, gy, sd, cmap="RdBu", vmin=-limit, vmax=limit, shading="auto")
    ax.contour(gx, gy, sd, levels=[0.0], colors="k", linewidths=1.5)
    fig.colorbar(image, ax=ax, label="signed distance (negative inside)")
    rng = np.random.default_rng(0)
    for i in rng.choice(len(points), size=25, replace=False):
        p, q = points[i], result.point[i]
        ax.plot([p[0], q[0]], [p[1], q[1]], color="orange", linewidth=1)
        ax.plot(p[0], p[1], "o", color="orange", markersize=3)
    ax.set_aspect("equal")
    ax.set_title(f"{os.path.basename(args.mesh)}, slice z = {z:.3g}\norange: segments to the closest points")
    fig.savefig(args.output, dpi=120, bbox_inches="tight")
    print(f"wrote {args.output}")


if __name__ == "__main__":
    main()
