#!/usr/bin/env python3
"""Re-run the failing runs of a probe-random-scenes.py log with another build, from the scene
files the probe kept in its output folder, and judge them by the same criteria.

usage: scripts/probe-rerun-failures.py LOG OUTDIR [KIND]
  LOG: the probe's printed output (its FAIL lines); OUTDIR: the probe's output folder; KIND: only
  runs of scenes of that kind (a prefix of the scene id: tumble, spin, ...).
  environment: CLOD (build/bin/clod), and SCALE as the probe had it (the judge's thresholds are
  stored with each scene already scaled).
Prints one line per run: `ok`, or the criteria it still breaks.
"""
import json, os, re, subprocess, sys, tempfile
import importlib.util

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
spec = importlib.util.spec_from_file_location('probe', os.path.join(HERE, 'probe-random-scenes.py'))
probe = importlib.util.module_from_spec(spec)
spec.loader.exec_module(probe)


def box_corners(scene):
    """A box scene's judged vertices: the dynamic box's corners (the probe keeps no vertices)."""
    box = [b for b in scene['bodies'] if not b.get('static')][0]
    h = box.get('box') or box.get('_box')
    if h is None: return None
    return [[sx * h[0], sy * h[1], sz * h[2]] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)]


def main():
    if len(sys.argv) not in (3, 4): sys.exit(__doc__)
    log, outdir = sys.argv[1], sys.argv[2]
    only = sys.argv[3] if len(sys.argv) == 4 else ''
    for line in open(log):
        m = re.match(r'FAIL (\S+) (\S+) b=(\d+) us=([\d.]+) ([\d.]+)Hz', line)
        if not m or not m.group(1).startswith(only): continue
        sid, model, budget, us, hz = m.groups()
        run = os.path.join(outdir, f"{sid}_{model}_{budget}_{us if us == '0' else float(us)}_{float(hz)}")
        meta = json.load(open(os.path.join(outdir, sid + '.json')))
        scene, info = meta['scene'], meta['info']
        if info['kind'] == 'drop' and 'verts' not in info:
            info['verts'] = box_corners(scene)
            if info['verts'] is None:
                print('SKIP', sid, model, '(a mesh drop: its vertices are not kept)')
                continue
        with tempfile.TemporaryDirectory() as out:
            r = subprocess.run([probe.CLOD, 'simulate', os.path.join(run, 'scene.json'), '-o', out], capture_output=True, text=True)
            if r.returncode:
                print('EXIT', sid, model, f'b={budget} us={us} {hz}Hz', r.stderr.strip()[-200:])
                continue
            ran = json.load(open(os.path.join(run, 'scene.json')))
            fails, _ = probe.judge(os.path.join(out, 'trajectory.csv'), info, 1.0 / float(hz), dict(ran, bodies=scene['bodies']))
        print('NOW', sid, model, f'b={budget} us={us} {hz}Hz', '; '.join(fails) if fails else 'ok')


if __name__ == '__main__':
    main()
