#!/usr/bin/env python3
"""How far a drop's landing moves when the mesh starts a hair higher or lower.

usage: scripts/drop-sensitivity.py DROP RATE MODEL BUDGET [OUTDIR]
  DROP: bunny, spot or fandisk (scenes/drop_DROP.json, issue 17's drop scenes at their defaults)
  RATE: frames per second; MODEL: cfm, exact, contact-tree, ...; BUDGET: tests per frame (0 =
  unlimited). Environment: CLOD (build/bin/clod).
Runs `clod simulate` from the scene's height and from 1 and 10 um higher and lower, and prints
how far the mesh's vertex centroid ends from where the unperturbed run ends it (mm). A budget
step whose outcome differs by less than this is a different landing, not a worse contact answer
(docs/benchmarks/degradation.md, REPRODUCING.md "degradation").
"""
import csv, json, math, os, subprocess, sys, tempfile

from clod_rotation import rotate

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
CLOD = os.environ.get('CLOD', os.path.join(ROOT, 'build', 'bin', 'clod'))
OFFSETS = [0.0, 1e-6, -1e-6, 1e-5, -1e-5]


def final_centroid(scene, mesh_body, centroid, workdir, offset):
    scene = json.loads(json.dumps(scene))
    scene['bodies'][mesh_body]['position'][2] += offset
    path = os.path.join(workdir, f'scene{offset:+g}.json')
    with open(path, 'w') as f:
        json.dump(scene, f)
    out = os.path.join(workdir, f'out{offset:+g}')
    subprocess.run([CLOD, 'simulate', path, '-o', out], check=True, capture_output=True)
    name = scene['bodies'][mesh_body]['name']
    last = None
    with open(os.path.join(out, 'trajectory.csv')) as f:
        for row in csv.DictReader(f):
            if row['body'] == name:
                last = row
    q = [float(last[k]) for k in ('qw', 'qx', 'qy', 'qz')]
    p = [float(last[k]) for k in ('px', 'py', 'pz')]
    c = rotate(q, centroid)
    return [c[i] + p[i] for i in range(3)]


def main():
    if len(sys.argv) not in (5, 6):
        sys.exit(__doc__)
    drop, rate, model, budget = sys.argv[1], float(sys.argv[2]), sys.argv[3], int(sys.argv[4])
    scene_path = os.path.join(ROOT, 'scenes', f'drop_{drop}.json')
    with open(scene_path) as f:
        scene = json.load(f)
    scene.update({'dt': 1.0 / rate, 'contact_model': model, 'budget': budget})
    mesh_body = next(i for i, b in enumerate(scene['bodies']) if 'mesh' in b)
    body = scene['bodies'][mesh_body]
    body['mesh'] = os.path.normpath(os.path.join(os.path.dirname(scene_path), body['mesh']))
    with open(body['mesh']) as f:
        vertices = [[float(x) * body['scale'] for x in line.split()[1:4]] for line in f if line.startswith('v ')]
    centroid = [sum(v[i] for v in vertices) / len(vertices) for i in range(3)]
    workdir = sys.argv[5] if len(sys.argv) == 6 else tempfile.mkdtemp(prefix='clod-drop-sensitivity-')
    os.makedirs(workdir, exist_ok=True)
    ends = [final_centroid(scene, mesh_body, centroid, workdir, o) for o in OFFSETS]
    print(f'drop_{drop} {model} budget {budget} at {rate:g} Hz: landing moved by (mm)')
    for o, e in zip(OFFSETS[1:], ends[1:]):
        print(f'  {o * 1e6:+5.0f} um: {math.dist(e, ends[0]) * 1e3:.2f}')
    print(f'  largest: {max(math.dist(e, ends[0]) for e in ends[1:]) * 1e3:.2f}')


if __name__ == '__main__':
    main()
