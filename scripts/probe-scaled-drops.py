#!/usr/bin/env python3
"""Shared meshes dropped onto a box at a given size, through `clod simulate`: the deepest sink
below the box's top at any frame, in % of the mesh's diagonal (issue 17 allows 1 %), and the
speed at the end (docs/dynamics.md, "Known limits": millimetre meshes).

usage: scripts/probe-scaled-drops.py MESHES SIZES MODELS BUDGETS OUTDIR
  MESHES: comma list of shared mesh names (bunny-1500,spot,fandisk); SIZES: diagonals in metres;
  MODELS: cfm,exact,contact-tree,...; BUDGETS: tests per frame (0 = unlimited), or microseconds
  per frame with a `us` suffix (200us).
  environment: RATES (60), J parallel runs (2), CLOD (build/bin/clod),
  CLOD_MESH_DIR (../shared/data/meshes).
Each mesh is centred over a 4 x 4 x 0.5 diagonal box, turned 45 deg about x, its lowest point
0.3 diagonals above the box, density 1,000, and runs 4 sqrt(max(size, 1)) simulated seconds
(Froude similarity: time scales with sqrt(size)). Prints one line per run, FAIL where it sank
more than 1 % or still moves faster than 1 % of its diagonal per second at the end.
"""
import concurrent.futures as cf, csv, json, math, os, subprocess, sys

from clod_rotation import rotate

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
CLOD = os.environ.get('CLOD', os.path.join(ROOT, 'build', 'bin', 'clod'))
MESHES = os.environ.get('CLOD_MESH_DIR', os.path.join(ROOT, '..', 'shared', 'data', 'meshes'))
TURN = [math.cos(math.pi / 8), math.sin(math.pi / 8), 0.0, 0.0]  # 45 deg about x


def vertices(mesh):
    return [[float(x) for x in line.split()[1:4]] for line in open(os.path.join(MESHES, mesh + '.obj'))
            if line.startswith('v ')]


def run(job):
    mesh, size, model, budget, rate, out = job
    raw = vertices(mesh)
    lo = [min(v[i] for v in raw) for i in range(3)]
    hi = [max(v[i] for v in raw) for i in range(3)]
    scale = size / math.dist(lo, hi)
    local = [[c * scale for c in v] for v in raw]
    turned = [rotate(TURN, v) for v in local]
    centre = [(min(v[i] for v in turned) + max(v[i] for v in turned)) / 2 for i in range(2)]
    lowest = min(v[2] for v in turned)
    timed = budget.endswith('us')
    scene = {"dt": 1.0 / rate, "duration": 4.0 * math.sqrt(max(size, 1.0)), "contact_model": model,
             "budget_us" if timed else "budget": float(budget[:-2]) if timed else int(budget),
             "bodies": [{"name": "ground", "box": [2 * size, 2 * size, 0.25 * size], "position": [0, 0, -0.25 * size],
                         "static": True, "friction": 0.6},
                        {"name": "mesh", "mesh": os.path.join(MESHES, mesh + '.obj'), "scale": scale,
                         "position": [-centre[0], -centre[1], 0.3 * size - lowest], "orientation": TURN,
                         "friction": 0.6, "density": 1000}]}
    os.makedirs(out, exist_ok=True)
    with open(os.path.join(out, 'scene.json'), 'w') as f:
        json.dump(scene, f)
    r = subprocess.run([CLOD, 'simulate', os.path.join(out, 'scene.json'), '-o', os.path.join(out, 'out')],
                       capture_output=True, text=True)
    if r.returncode:
        return job, None, None, r.stderr.strip()[-300:]
    sink, last = 0.0, None
    for row in csv.DictReader(open(os.path.join(out, 'out', 'trajectory.csv'))):
        if row['body'] != 'mesh':
            continue
        q = [float(row[k]) for k in ('qw', 'qx', 'qy', 'qz')]
        z = min(rotate(q, v)[2] for v in local) + float(row['pz'])
        sink = max(sink, -z / size)
        last = row
    speed = math.sqrt(sum(float(last[k]) ** 2 for k in ('vx', 'vy', 'vz'))) / size
    return job, sink, speed, None


def main():
    if len(sys.argv) != 6:
        sys.exit(__doc__)
    meshes, sizes, models, budgets, outdir = sys.argv[1:]
    rates = [float(r) for r in os.environ.get('RATES', '60').split(',')]
    jobs = [(m, float(s), model, b, rate, os.path.join(outdir, f'{m}_{s}_{model}_{b}_{rate:g}'))
            for m in meshes.split(',') for s in sizes.split(',') for model in models.split(',')
            for b in budgets.split(',') for rate in rates]
    failed = 0
    with cf.ThreadPoolExecutor(int(os.environ.get('J', '2'))) as pool:
        for (mesh, size, model, budget, rate, _), sink, speed, error in pool.map(run, jobs):
            what = f'{mesh} {size:g} m {model} budget {budget} {rate:g} Hz'
            if error:
                failed += 1
                print(f'FAIL {what}: {error}', flush=True)
                continue
            bad = sink > 0.01 or speed > 0.01
            failed += bad
            print(f'{"FAIL" if bad else "ok  "} {what}: sink {100 * sink:.3f} %, end speed {speed:.4f} diagonals/s',
                  flush=True)
    print(f'{failed} of {len(jobs)} runs failing')


if __name__ == '__main__':
    main()
