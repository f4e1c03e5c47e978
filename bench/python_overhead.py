#!/usr/bin/env python3
"""Overhead of the Python bindings: batched closest points and queries from Python against the
same work in C++ (bench/python_overhead.cpp), measured in one run on the same inputs.

    cmake --build build --target clod_python clod_python_overhead
    PYTHONPATH=build/python /usr/bin/python3 bench/python_overhead.py --build build

Work: bunny-1500 (shared meshes), 10^5 query points uniform in its bounding box grown by 10 %
(mesh.closest vs a TBB loop of MeshDistance::signedQuery) and 10^4 poses of a second bunny
(uniform random rotations, centres 0.3-0.9 diagonals apart: mostly overlapping) queried with the
cfm model at 256 tests (clod.query_batch vs a TBB loop of queryContacts with one QueryScratch per
thread). The two sides alternate, round after round (the C++ program is started once per round and
warms up first), so load from other processes hits both alike; the table gives the medians over all
repetitions. The Python time includes argument checking, pose parsing and packing the results into
NumPy arrays.
"""

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np

import clod


def median_seconds(function, reps):
    function()  # warm-up
    times = []
    for _ in range(reps):
        start = time.perf_counter()
        function()
        times.append(time.perf_counter() - start)
    return statistics.median(times), times


def random_poses(count, diagonal, rng):
    q = rng.normal(size=(count, 4))
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    direction = rng.normal(size=(count, 3))
    direction /= np.linalg.norm(direction, axis=1, keepdims=True)
    distance = rng.uniform(0.3, 0.9, size=(count, 1)) * diagonal
    return np.hstack([direction * distance, q])


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    parser.add_argument("--build", default=os.path.join(root, "build"), help="CMake build folder with clod_python_overhead")
    parser.add_argument("--mesh", default=os.path.join(root, "..", "shared", "data", "meshes", "bunny-1500.obj"))
    parser.add_argument("--points", type=int, default=100_000)
    parser.add_argument("--poses", type=int, default=10_000)
    parser.add_argument("--model", default="cfm")
    parser.add_argument("--budget", type=int, default=256)
    parser.add_argument("--rounds", type=int, default=5, help="C++ / Python alternations")
    parser.add_argument("--reps", type=int, default=3, help="repetitions per side and round")
    args = parser.parse_args()

    rng = np.random.default_rng(2024)
    mesh = clod.Mesh.load(args.mesh)
    baked = clod.bake(mesh, sphere_tree="octree", contact_tree=False, measure_fit=False)
    lo, hi = mesh.bounds
    points = rng.uniform(lo - 0.1 * (hi - lo), hi + 0.1 * (hi - lo), size=(args.points, 3))
    poses = random_poses(args.poses, mesh.diagonal, rng)
    identity = np.array([0, 0, 0, 1, 0, 0, 0], dtype=np.float64)

    cpp_closest_all, cpp_query_all, py_closest_all, py_query_all, py_query_own = [], [], [], [], []
    with tempfile.TemporaryDirectory() as tmp:
        bake_path = os.path.join(tmp, "mesh.clod")
        baked.save(bake_path)
        points.astype("<f8").tofile(os.path.join(tmp, "points.f64"))
        poses.astype("<f8").tofile(os.path.join(tmp, "poses.f64"))
        loaded = clod.Bake.load(bake_path)  # the very file the C++ side reads
        mesh_b = loaded.mesh
        program = os.path.join(args.build, "bin", "clod_python_overhead")
        for _ in range(args.rounds):
            out = subprocess.run([program, bake_path, os.path.join(tmp, "points.f64"), os.path.join(tmp, "poses.f64"),
                                  args.model, str(args.budget), str(args.reps)], capture_output=True, text=True, check=True)
            cpp = json.loads(out.stdout)
            cpp_closest_all += cpp["closest_seconds"]
            cpp_query_all += cpp["query_seconds"]
            py_closest_all += median_seconds(lambda: mesh_b.closest(points), args.reps)[1]
            for _ in range(args.reps):
                start = time.perf_counter()
                batch = clod.query_batch(loaded, identity, loaded, poses, model=args.model, budget=args.budget)
                py_query_all.append(time.perf_counter() - start)
                # The bindings' own share: the call minus its parallel queries (pose parsing, packing).
                py_query_own.append(py_query_all[-1] - batch.wall_seconds)

    batch = clod.query_batch(loaded, identity, loaded, poses, model=args.model, budget=args.budget)
    assert len(batch.pos) == cpp["contacts"], (len(batch.pos), cpp["contacts"])  # the same work on both sides
    loop_count = min(args.poses, 2000)
    start = time.perf_counter()
    for i in range(loop_count):
        clod.query(loaded, identity, loaded, poses[i], model=args.model, budget=args.budget)
    loop_per_query = (time.perf_counter() - start) / loop_count

    cpp_closest, cpp_query = statistics.median(cpp_closest_all), statistics.median(cpp_query_all)
    py_closest, py_query = statistics.median(py_closest_all), statistics.median(py_query_all)
    print(f"# {os.cpu_count()} CPUs, {args.rounds} rounds x {args.reps} repetitions per side (medians), mesh {os.path.basename(args.mesh)} "
          f"({mesh.triangle_count} triangles), model {args.model}, budget {args.budget}")
    print("| work | C++ (s) | Python (s) | Python / C++ |")
    print("|---|---|---|---|")
    print(f"| closest points, {args.points} points | {cpp_closest:.4f} | {py_closest:.4f} | {py_closest / cpp_closest:.3f} |")
    print(f"| query_batch, {args.poses} poses ({cpp['contacts']} contacts) | {cpp_query:.4f} | {py_query:.4f} | "
          f"{py_query / cpp_query:.3f} |")
    print(f"\nquery_batch: the bindings' own time (pose parsing, packing the arrays) is "
          f"{statistics.median(py_query_own) * 1e3:.2f} ms of the call ({statistics.median(py_query_own) / py_query:.1%})")
    print(f"one clod.query call at a time (a Python loop, {loop_count} calls, one thread): "
          f"{loop_per_query * 1e6:.1f} us per query")
    return 0


if __name__ == "__main__":
    sys.exit(main())
