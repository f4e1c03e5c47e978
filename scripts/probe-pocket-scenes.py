#!/usr/bin/env python3
"""Bodies in the pockets of closed non-convex static bodies, run through `clod simulate` with every
surface model and judged against where they must rest (docs/narrow-phase.md, "Closed non-convex
bodies"; docs/benchmarks/degradation.md, "Pockets").

usage: scripts/probe-pocket-scenes.py OUTDIR
  Writes two static meshes into OUTDIR: an L (a 4 x 4 x 0.5 m floor, top at z = 0, and a 1 m
  thick, 2 m high wall whose inner face is at x = 1) and a bin (2 x 2 x 1 m, walls and floor
  0.1 m thick, inner floor at z = 0.1). Scenes: a 0.5 m box resting on the L's floor in the open
  and in the corner (flush with the wall); a 0.4 m box, a 0.2 m ball and spot dropped into the bin.
  environment: MODELS (cfm,contact-tree,exact), BUDGETS tests per frame (16,64,256,0), RATE (60),
  CLOD (build/bin/clod), CLOD_MESH_DIR (../shared/data/meshes), J parallel runs (2).
Prints per run the body's final height against its resting height, its lowest height (through
the floor: metres below) and final speed; FAIL where it ends more than 1 cm off its rest height
or moving faster than 1 cm/s.
"""
import concurrent.futures as cf, csv, json, math, os, subprocess, sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
CLOD = os.environ.get('CLOD', os.path.join(ROOT, 'build', 'bin', 'clod'))
MESHES = os.path.abspath(os.environ.get('CLOD_MESH_DIR', os.path.join(ROOT, '..', 'shared', 'data', 'meshes')))

def write_obj(path, V, F):
    with open(path, 'w') as f:
        f.write(''.join('v %g %g %g\n' % v for v in V) + ''.join('f %d %d %d\n' % (a + 1, b + 1, c + 1) for a, b, c in F))

def l_mesh(path):
    prof = [(-2, -0.5), (2, -0.5), (2, 2), (1, 2), (1, 0), (-2, 0)]  # (x, z), counter-clockwise seen from -y
    V = [(x, y, z) for y in (-2, 2) for (x, z) in prof]
    F = []
    for a, b, c in [(0, 1, 4), (0, 4, 5), (1, 2, 3), (1, 3, 4)]:
        F += [(a, b, c), (c + 6, b + 6, a + 6)]
    for i in range(6):
        j = (i + 1) % 6
        F += [(i, i + 6, j + 6), (i, j + 6, j)]
    write_obj(path, V, F)

def bin_mesh(path):
    o, i, H, T = 1.0, 0.9, 1.0, 0.1
    V = [(-o, -o, 0), (o, -o, 0), (o, o, 0), (-o, o, 0), (-o, -o, H), (o, -o, H), (o, o, H), (-o, o, H),
         (-i, -i, H), (i, -i, H), (i, i, H), (-i, i, H), (-i, -i, T), (i, -i, T), (i, i, T), (-i, i, T)]
    F = []
    quad = lambda a, b, c, d: F.extend([(a, b, c), (a, c, d)])
    quad(0, 3, 2, 1)  # outer bottom
    for k in range(4):
        a, b = k, (k + 1) % 4
        quad(a, b, 4 + b, 4 + a)           # outer sides
        quad(4 + a, 4 + b, 8 + b, 8 + a)   # rim
        quad(8 + a, 8 + b, 12 + b, 12 + a)  # inner sides
    quad(12, 13, 14, 15)  # inner floor
    write_obj(path, V, F)

def unit(q):
    n = math.sqrt(sum(x * x for x in q)); return [x / n for x in q]

# name: (static mesh, body, resting height of its frame origin or None (judged by speed only))
SCENES = {
    'l-open': ('L', {"box": [0.25, 0.25, 0.25], "position": [-1.0, 0.3, 0.25]}, 0.25),
    'l-corner': ('L', {"box": [0.25, 0.25, 0.25], "position": [0.75, 0.3, 0.25]}, 0.25),
    'bin-box': ('bin', {"box": [0.2, 0.2, 0.2], "position": [0.1, -0.05, 0.6], "orientation": unit([0.96, 0.1, 0.2, 0.1])}, 0.3),
    'bin-ball': ('bin', {"sphere": 0.2, "position": [0.1, 0.0, 0.6]}, 0.3),
    'bin-spot': ('bin', {"mesh": os.path.join(MESHES, 'spot.obj'), "scale": 0.5, "position": [0.0, 0.0, 0.7],
                         "orientation": unit([0.7071, 0.7071, 0, 0])}, None),
}

def run(args):
    out, name, model, budget, rate = args
    static, body, rest = SCENES[name]
    b = dict(body, name='obj', friction=0.6)
    sc = {"gravity": [0, 0, -9.81], "dt": 1.0 / rate, "duration": 3.0, "contact_model": model, "budget": budget,
          "bodies": [{"name": "ground", "mesh": os.path.join(out, static + '.obj'), "position": [0, 0, 0], "static": True,
                      "friction": 0.6}, b]}
    d = os.path.join(out, f"{name}_{model}_{budget}_{int(rate)}"); os.makedirs(d, exist_ok=True)
    json.dump(sc, open(os.path.join(d, 'scene.json'), 'w'))
    r = subprocess.run(['nice', CLOD, 'simulate', os.path.join(d, 'scene.json'), '-o', os.path.join(d, 'out')],
                       capture_output=True, text=True, timeout=900)
    if r.returncode: return args, 'FAIL exit %d: %s' % (r.returncode, r.stderr.strip()[-200:])
    rows = [x for x in csv.DictReader(open(os.path.join(d, 'out', 'trajectory.csv'))) if x['body'] == 'obj']
    z = [float(x['pz']) for x in rows]
    v = math.sqrt(sum(float(rows[-1][k]) ** 2 for k in ('vx', 'vy', 'vz')))
    bad = v > 0.01 or (rest is not None and abs(z[-1] - rest) > 0.01)
    return args, '%sfinal z %.3f (rest %s) lowest %.3f speed %.3f m/s' % (
        'FAIL ' if bad else '', z[-1], '%.3f' % rest if rest is not None else '-', min(z), v)

if __name__ == '__main__':
    out = os.path.abspath(sys.argv[1]); os.makedirs(out, exist_ok=True)
    l_mesh(os.path.join(out, 'L.obj')); bin_mesh(os.path.join(out, 'bin.obj'))
    models = os.environ.get('MODELS', 'cfm,contact-tree,exact').split(',')
    budgets = [int(x) for x in os.environ.get('BUDGETS', '16,64,256,0').split(',')]
    rate = float(os.environ.get('RATE', '60'))
    jobs = [(out, n, m, b, rate) for n in SCENES for m in models for b in budgets]
    fails = 0
    with cf.ThreadPoolExecutor(int(os.environ.get('J', '2'))) as ex:
        for (o, n, m, b, r), res in ex.map(run, jobs):
            fails += res.startswith('FAIL')
            print(f"{n:9s} {m:13s} {b:5d} tests {r:.0f} Hz  {res}", flush=True)
    print(f"runs {len(jobs)} failing {fails}")
