#!/usr/bin/env python3
"""Randomised variants of issue 17's scene categories, run through `clod simulate` and judged by
the issue's numbers (docs/benchmarks/degradation.md, "Random drops").

usage: scripts/probe-random-scenes.py SEED KINDS OUTDIR
  KINDS: comma-separated of stack, tower, pyramid, slide, slope-rest, slope-slide, drop, mass,
  tumble, spin, roll, pile, overhang
  environment: MODELS (cfm,contact-tree,exact), BUDGETS tests per frame (16,64,256,1024,0),
  BUS microseconds per frame (50,200,1000), RATES (240,60), J parallel runs (2),
  CLOD (build/bin/clod), CLOD_MESH_DIR (../shared/data/meshes), SCALE (1: every length times
  SCALE, velocities and times times sqrt(SCALE), so gravity's outcomes scale with the lengths and
  the judge's thresholds are scaled the same way; issue 21's 1 mm .. 100 m), GROUND (box: a
  static box; quad, grid: its top face as an open mesh of 2 triangles, or of ~0.5 m squares;
  step: the box as a closed non-convex mesh with a wall on its +x end),
  BOXES (box: primitives; obj: each dynamic box a closed 12-triangle OBJ; tessN: its faces cut
  into N x N squares), DROPS (the meshes a drop picks from: bunny-1500,spot,fandisk).
Prints one FAIL line per run that breaks a criterion of issue 17's point 1 (drops: the lowest
vertex more than 1 % of the diagonal below the floor top at any frame, or still moving after
5 s; every scene: a dynamic body's centre inside a static box or under it within its footprint
at any frame, "through"), NONMONO lines where the run's error grew with the budget, the deepest
sink of the drops, and a count. Each run's scene,
trajectory and summary stay in OUTDIR.
"""
import json, math, os, random, subprocess, sys, csv, concurrent.futures as cf

from clod_rotation import rotate as rot

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
CLOD = os.environ.get('CLOD', os.path.join(ROOT, 'build', 'bin', 'clod'))
MESHES = os.environ.get('CLOD_MESH_DIR', os.path.join(ROOT, '..', 'shared', 'data', 'meshes'))
G = 9.81
SCALE = float(os.environ.get('SCALE', '1'))
def qz(deg):
    a = math.radians(deg) / 2; return [math.cos(a), 0, 0, math.sin(a)]
def qy(deg):
    a = math.radians(deg) / 2; return [math.cos(a), 0, math.sin(a), 0]
def qmul(a, b):
    w1,x1,y1,z1=a; w2,x2,y2,z2=b
    return [w1*w2-x1*x2-y1*y2-z1*z2, w1*x2+x1*w2+y1*z2-z1*y2, w1*y2-x1*z2+y1*w2+z1*x2, w1*z2+x1*y2-y1*x2+z1*w2]
def tilt(q0, q):
    # angle between body z axes
    a = rot(q0, [0,0,1]); b = rot(q, [0,0,1])
    d = max(-1,min(1,sum(x*y for x,y in zip(a,b)))); return math.degrees(math.acos(d))
GROUND = os.environ.get('GROUND', 'box')
GROUND_DIR = [None]  # set by main: where GROUND's meshes are written
def ground_mesh(hx, hy, hz):
    """GROUND=quad: the box's top face as one open quad (2 triangles); GROUND=grid: as a grid of
    ~0.5 m squares (open, up to 60 x 60). What a user's floor mesh is."""
    n = 1 if GROUND == 'quad' else max(2, min(60, round(2 * max(hx, hy) / 0.5)))
    path = os.path.join(GROUND_DIR[0], f"ground_{GROUND}_{hx:.6g}_{hy:.6g}_{hz:.6g}.obj")
    if not os.path.exists(path):
        with open(path + '.tmp', 'w') as f:
            for j in range(n + 1):
                for i in range(n + 1):
                    f.write(f"v {-hx + 2 * hx * i / n:.9g} {-hy + 2 * hy * j / n:.9g} {hz:.9g}\n")
            for j in range(n):
                for i in range(n):
                    a = j * (n + 1) + i + 1
                    f.write(f"f {a} {a + 1} {a + n + 2}\nf {a} {a + n + 2} {a + n + 1}\n")
        os.replace(path + '.tmp', path)
    return os.path.abspath(path)
def step_mesh(hx, hy, hz):
    """GROUND=step: the box as a closed non-convex body, a slab with a wall 0.2 x 0.5 standing on
    its +x end (an L's profile extruded along y): what a user's room, shelf or stair mesh is."""
    path = os.path.join(GROUND_DIR[0], f"ground_step_{hx:.6g}_{hy:.6g}_{hz:.6g}.obj")
    if os.path.exists(path): return os.path.abspath(path)
    w = min(0.2, hx)
    prof = [(-hx, -hz), (hx, -hz), (hx, hz), (hx, hz + 0.5), (hx - w, hz + 0.5), (hx - w, hz), (-hx, hz)]
    n = len(prof); V = [(x, y, z) for y in (-hy, hy) for (x, z) in prof]
    F = []
    for i in range(n):  # the extruded sides, outward (the profile runs counter-clockwise in x, z)
        j = (i + 1) % n
        F += [(i, j + n, j), (i, i + n, j + n)]
    for t in [(0, 1, 2), (0, 2, 5), (0, 5, 6), (5, 2, 3), (5, 3, 4)]:  # the caps: floor and wall
        F += [(t[0], t[1], t[2]), (t[0] + n, t[2] + n, t[1] + n)]
    with open(path + '.tmp', 'w') as f:
        for v in V: f.write("v %.9g %.9g %.9g\n" % v)
        for t in F: f.write("f %d %d %d\n" % (t[0] + 1, t[1] + 1, t[2] + 1))
    os.replace(path + '.tmp', path)
    return os.path.abspath(path)
def ground(hx, hy, mu, pos=(0,0,-0.25), q=None, hz=0.25):
    b = {"name":"ground","box":[hx,hy,hz],"position":list(pos),"static":True,"friction":mu}
    if GROUND != 'box':
        # The judge still holds bodies against the box whose top the mesh is ("_box").
        del b["box"]; b["mesh"] = (step_mesh if GROUND == 'step' else ground_mesh)(hx, hy, hz)
        b["_box"] = [hx, hy, hz]; b["scale"] = 1.0
    if q: b["orientation"]=q
    return b
BOXES = os.environ.get('BOXES', 'box')
DROPS = os.environ.get('DROPS', 'bunny-1500,spot,fandisk').split(',')
def box_mesh(h):
    """BOXES=obj: a dynamic box as a closed 12-triangle OBJ; BOXES=tessN (e.g. tess4): each face
    cut into N x N squares, as a modelling tool exports a subdivided cube."""
    n = 1 if BOXES == 'obj' else int(BOXES[4:] or 4)
    path = os.path.join(GROUND_DIR[0], f"box_{BOXES}_{h[0]:.6g}_{h[1]:.6g}_{h[2]:.6g}.obj")
    if os.path.exists(path): return os.path.abspath(path)
    index = {}; V = []; F = []
    def vid(p):
        k = tuple(round(x, 12) for x in p)
        if k not in index: index[k] = len(V) + 1; V.append(p)
        return index[k]
    for axis in range(3):
        for sgn in (-1, 1):
            u, w = (axis + 1) % 3, (axis + 2) % 3
            def at(i, j):
                p = [0.0, 0.0, 0.0]; p[axis] = sgn * h[axis]
                p[u] = -h[u] + 2 * h[u] * i / n; p[w] = -h[w] + 2 * h[w] * j / n
                return vid(p)
            for i in range(n):
                for j in range(n):
                    a, b, c, d = at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)
                    F += [(a, b, c), (a, c, d)] if sgn > 0 else [(a, c, b), (a, d, c)]
    with open(path + '.tmp', 'w') as f:
        for p in V: f.write("v %.12g %.12g %.12g\n" % tuple(p))
        for t in F: f.write("f %d %d %d\n" % t)
    os.replace(path + '.tmp', path)
    return os.path.abspath(path)
def boxb(name, h, pos, mu, q=None, v=None, extra=None):
    b = {"name":name,"box":list(h),"position":list(pos),"friction":mu}
    if BOXES != 'box':
        # The judge still measures the box ("_box"); the scene loads its mesh.
        del b["box"]; b["mesh"] = box_mesh(h); b["_box"] = list(h); b["scale"] = 1.0
    if q: b["orientation"]=q
    if v: b["velocity"]=list(v)
    if extra: b.update(extra)
    return b

def gen(kind, rng):
    """Returns (scene dict, judge info)."""
    if kind == 'stack':
        n = rng.randint(3, 6); h = rng.uniform(0.1, 0.6); mu = rng.uniform(0.4, 0.9)
        twist = rng.choice([0, 0, rng.uniform(3, 20)])
        bodies = [ground(4*h+1, 4*h+1, mu, (0,0,-0.25))]
        for k in range(n):
            bodies.append(boxb(f"box{k}", [h,h,h], [0,0,h*(2*k+1)], mu, qz(twist*k) if twist else None))
        return {"duration":10.0,"bodies":bodies}, dict(kind='stack', move=0.02, tiltlim=1.0, speed=0.05)
    if kind == 'pyramid':
        rows = rng.randint(3, 4); h = rng.uniform(0.2, 0.6); gap = rng.uniform(0.0, 0.04)*h; mu = rng.uniform(0.5, 0.9)
        bodies = [ground(rows*h*2+1, 2*h+1, mu)]
        pitch = 2*h+gap
        for r in range(rows):
            c = rows - r
            for i in range(c):
                bodies.append(boxb(f"box{r}{i}", [h,h,h], [(i-0.5*(c-1))*pitch, 0, h*(2*r+1)], mu))
        return {"duration":10.0,"bodies":bodies}, dict(kind='stack', move=0.05, tiltlim=2.0, speed=0.05)
    if kind == 'tower':
        # Boxes of different sizes and densities (each no larger than the one below), turned.
        n = rng.randint(2, 5); mu = rng.uniform(0.4, 0.9); z = 0.0; bodies = []; last = None
        for k in range(n):
            h = [rng.uniform(0.15, 0.5), rng.uniform(0.15, 0.5), rng.uniform(0.08, 0.4)]
            if last: h = [min(h[0], last[0]), min(h[1], last[1]), h[2]]
            bodies.append(boxb(f"box{k}", h, [0, 0, z + h[2]], mu, qz(rng.uniform(0, 90)),
                               extra={"density": rng.choice([100, 1000, 5000])}))
            z += 2 * h[2]; last = h
        bodies.insert(0, ground(3, 3, mu))
        return {"duration":10.0,"bodies":bodies}, dict(kind='stack', move=0.02, tiltlim=1.0, speed=0.05)
    if kind == 'slide':
        # Sliding friction tips the box unless its line of action stays inside the base: mu times
        # the height below the centre of mass under 80 % of the base's reach along the velocity.
        while True:
            h = [rng.uniform(0.2,0.6), rng.uniform(0.2,0.6), rng.uniform(0.15,0.5)]
            mu = rng.uniform(0.2, 0.6); v = rng.uniform(1.0, 3.0); ang = rng.uniform(0, 360); yaw = rng.uniform(0, 90)
            phi = math.radians(ang - yaw)
            reach = min(h[0] / max(1e-9, abs(math.cos(phi))), h[1] / max(1e-9, abs(math.sin(phi))))
            if mu * h[2] < 0.8 * reach: break
        d = v*v/(2*mu*G)
        dirv = [math.cos(math.radians(ang)), math.sin(math.radians(ang)), 0]
        L = d + 3
        bodies = [ground(L, L, mu), boxb("box", h, [-dirv[0]*d/2, -dirv[1]*d/2, h[2]], mu, qz(yaw), [v*dirv[0], v*dirv[1], 0])]
        return {"duration": v/(mu*G)+1.5, "bodies":bodies}, dict(kind='slide', dist=d, tiltlim=2.0)
    if kind in ('slope-rest', 'slope-slide'):
        # Neither resting nor sliding may tip the box: tan(theta) at rest, mu when sliding, under
        # 80 % of its half length over its half height.
        while True:
            mu = rng.uniform(0.3, 0.8); fa = math.degrees(math.atan(mu))
            th = rng.uniform(8, fa-5) if kind == 'slope-rest' else rng.uniform(fa+6, min(fa+25, 60))
            h = [rng.uniform(0.2,0.5)]*2 + [rng.uniform(0.15,0.5)]
            lever = math.tan(math.radians(th)) if kind == 'slope-rest' else mu
            if lever * h[2] < 0.8 * h[0]: break
        q = qy(th); n = rot(q,[0,0,1]); down = rot(q,[1,0,0])
        T = 4.0 if kind=='slope-rest' else 2.0
        a = G*(math.sin(math.radians(th)) - mu*math.cos(math.radians(th)))
        HL = 2.0 if kind=='slope-rest' else max(5.0, a*T*T/2 + 2)
        along = 0 if kind=='slope-rest' else -(HL-1.0)
        pos = [ (0.25+h[2])*n[i] + along*down[i] for i in range(3)]
        bodies = [ground(HL, 1.5, mu, (0,0,0), q), boxb("box", h, pos, mu, q)]
        j = dict(kind=kind, T=T, a=a, down=down)
        return {"duration":T, "bodies":bodies}, j
    if kind == 'drop':
        mesh = rng.choice(DROPS)
        V = load_obj(os.path.join(MESHES, f'{mesh}.obj'))
        lo=[min(v[i] for v in V) for i in range(3)]; hi=[max(v[i] for v in V) for i in range(3)]
        diag0=math.sqrt(sum((hi[i]-lo[i])**2 for i in range(3)))
        want=rng.uniform(0.3,1.5); sc=want/diag0
        ax=[rng.gauss(0,1) for _ in range(3)]; n=math.sqrt(sum(a*a for a in ax)); ang=rng.uniform(0,math.pi)
        q=[math.cos(ang/2)]+[math.sin(ang/2)*a/n for a in ax]
        W=[rot(q,[c*sc for c in v]) for v in V]
        zmin=min(w[2] for w in W); height=rng.uniform(0.05,1.0)
        cx=sum(w[0] for w in W)/len(W); cy=sum(w[1] for w in W)/len(W)
        body={"name":"mesh","mesh":os.path.abspath(os.path.join(MESHES, f"{mesh}.obj")),"scale":sc,"position":[-cx,-cy,height-zmin],"orientation":q,"friction":rng.uniform(0.3,0.8)}
        return {"duration":5.0,"bodies":[ground(2,2,0.6),body]}, dict(kind='drop', verts=[[c*sc for c in v] for v in V], diag=want)
    if kind == 'mass':
        # A heavy box on a light one (issue 21 point 3: mass ratios up to 1000), judged as a stack.
        ratio = rng.choice([10, 100, 1000]); mu = rng.uniform(0.4, 0.9)
        lo = [rng.uniform(0.2, 0.5), rng.uniform(0.2, 0.5), rng.uniform(0.1, 0.4)]
        hi = [rng.uniform(0.15, 1.0) * lo[0], rng.uniform(0.15, 1.0) * lo[1], rng.uniform(0.1, 0.5)]
        bodies = [ground(3, 3, mu), boxb("light", lo, [0, 0, lo[2]], mu, extra={"density": 10}),
                  boxb("heavy", hi, [0, 0, 2 * lo[2] + hi[2]], mu, qz(rng.uniform(0, 90)),
                       extra={"density": 10 * ratio})]
        return {"duration": 10.0, "bodies": bodies}, dict(kind='stack', move=0.02, tiltlim=1.0, speed=0.05)
    if kind in ('tumble', 'spin'):
        # tumble: a box thrown at the floor turned and spinning, judged as a drop; spin: a box
        # spinning about the vertical on the floor, which friction stops where it stands.
        h = [rng.uniform(0.1, 0.5), rng.uniform(0.1, 0.5), rng.uniform(0.05, 0.5)]; mu = rng.uniform(0.3, 0.8)
        corners = [[sx * h[0], sy * h[1], sz * h[2]] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)]
        diag = 2 * math.sqrt(sum(x * x for x in h))
        if kind == 'spin':
            w = rng.uniform(2, 12) * rng.choice([-1, 1])
            body = boxb("box", h, [0, 0, h[2]], mu, qz(rng.uniform(0, 90)), extra={"angular_velocity": [0, 0, w]})
            return {"duration": 6.0, "bodies": [ground(3, 3, mu), body]}, dict(kind='stack', move=0.05, tiltlim=2.0, speed=0.05)
        ax = [rng.gauss(0, 1) for _ in range(3)]; n = math.sqrt(sum(a * a for a in ax)); ang = rng.uniform(0, math.pi)
        q = [math.cos(ang / 2)] + [math.sin(ang / 2) * a / n for a in ax]
        zmin = min(rot(q, c)[2] for c in corners)
        body = boxb("box", h, [0, 0, rng.uniform(0.05, 1.0) - zmin], mu, q,
                    [rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-2, 0)],
                    extra={"angular_velocity": [rng.uniform(-6, 6) for _ in range(3)]})
        return {"duration": 6.0, "bodies": [ground(4, 4, mu), body]}, dict(kind='drop', verts=corners, diag=diag)
    if kind == 'overhang':
        # A box standing over the ground's -x edge, its centre of mass over the ground by 10-90 %
        # of its half length: it stands (judged as a stack's top).
        h = [rng.uniform(0.1, 0.5), rng.uniform(0.1, 0.5), rng.uniform(0.05, 0.5)]; mu = rng.uniform(0.4, 0.9)
        L = 2.0; inside = rng.uniform(0.1, 0.9) * h[0]
        bodies = [ground(L, L, mu), boxb("box", h, [-L + inside, rng.uniform(-1, 1), h[2]], mu)]
        return {"duration": 4.0, "bodies": bodies}, dict(kind='stack', move=0.02, tiltlim=1.0, speed=0.05)
    if kind == 'roll':
        # A ball rolling down a slope without slipping: a = 5/7 g sin(theta) (a solid ball; the
        # scene's ball is a 320-triangle icosphere, whose facets cost it a little).
        mu = rng.uniform(0.5, 0.9); th = rng.uniform(4, 20); r = rng.uniform(0.1, 0.5)
        q = qy(th); n = rot(q, [0, 0, 1]); down = rot(q, [1, 0, 0]); T = 2.0
        a = 5.0 / 7.0 * G * math.sin(math.radians(th)); HL = max(5.0, a * T * T / 2 + 2)
        pos = [(0.25 + r) * n[i] - (HL - 1.0) * down[i] for i in range(3)]
        bodies = [ground(HL, 1.5, mu, (0, 0, 0), q), {"name": "ball", "sphere": r, "position": pos, "friction": mu}]
        return {"duration": T, "bodies": bodies}, dict(kind='slope-slide', T=T, a=a, down=down)
    if kind == 'pile':
        # Boxes dropped turned onto each other and the floor: each comes to rest above the floor.
        n = rng.randint(3, 6); mu = rng.uniform(0.4, 0.9); bodies = [ground(3, 3, mu)]; z = 0.0
        for k in range(n):
            h = [rng.uniform(0.1, 0.3), rng.uniform(0.1, 0.3), rng.uniform(0.05, 0.3)]
            ax = [rng.gauss(0, 1) for _ in range(3)]; m = math.sqrt(sum(a * a for a in ax)); ang = rng.uniform(0, math.pi)
            q = [math.cos(ang / 2)] + [math.sin(ang / 2) * a / m for a in ax]
            rad = math.sqrt(sum(x * x for x in h)); z += rad + 0.02
            bodies.append(boxb(f"box{k}", h, [rng.uniform(-0.2, 0.2), rng.uniform(-0.2, 0.2), z], mu, q))
            z += rad
        return {"duration": 8.0, "bodies": bodies}, dict(kind='pile')
    raise ValueError(kind)

def scaled(scene, info, k):
    """Froude scaling: lengths x k, velocities and times x sqrt(k), angular velocities / sqrt(k)."""
    r = math.sqrt(k)
    for b in scene['bodies']:
        for key in ('box', '_box', 'position'):
            if key in b: b[key] = [x * k for x in b[key]]
        if 'scale' in b: b['scale'] *= k
        if 'sphere' in b: b['sphere'] *= k
        if 'velocity' in b: b['velocity'] = [x * r for x in b['velocity']]
        if 'angular_velocity' in b: b['angular_velocity'] = [x / r for x in b['angular_velocity']]
    scene['duration'] *= r
    for key in ('move', 'dist', 'diag'):
        if key in info: info[key] *= k
    for key in ('speed',):
        if key in info: info[key] *= r
    if 'T' in info: info['T'] *= r
    if 'verts' in info: info['verts'] = [[c * k for c in v] for v in info['verts']]
    info['length'] = k
    return scene, info

def load_obj(path):
    V=[]
    for line in open(path):
        if line.startswith('v '): V.append([float(x) for x in line.split()[1:4]])
    return V

def judge(traj, info, dt, scene=None):
    rows = list(csv.DictReader(open(traj)))
    names = sorted({r['body'] for r in rows if r['body']!='ground'})
    last = {}; first = {}
    for r in rows:
        if r['body']=='ground': continue
        b=r['body']
        if b not in first: first[b]=r
        last[b]=r
    P=lambda r:[float(r['px']),float(r['py']),float(r['pz'])]
    Q=lambda r:[float(r['qw']),float(r['qx']),float(r['qy']),float(r['qz'])]
    V=lambda r:[float(r['vx']),float(r['vy']),float(r['vz'])]
    dist=lambda a,b: math.sqrt(sum((x-y)**2 for x,y in zip(a,b)))
    fails=[]; err=None
    for b in names:
        for v in P(last[b])+V(last[b]):
            if not math.isfinite(v): return ['NaN'], float('nan')
    # Never through a static body (issue 17): a dynamic body's centre of mass inside a static box,
    # or under it within its footprint (fallen through a ground slab or a slope), at any frame. (The
    # probe's static bodies are grounds and slopes, which nothing rests under.)
    bodies = (scene or {}).get('bodies', [])
    dynamic = {x.get('name') for x in bodies if not x.get('static')}
    through = set()
    # A dropped mesh's frame origin can lie far from its geometry (the fandisk's is below its
    # bounding box): its vertices' centroid stands for it. Boxes are centred on their origin.
    centroid = [sum(v[i] for v in info['verts']) / len(info['verts']) for i in range(3)] if info.get('verts') else None
    def centre(r):
        if centroid is None: return P(r)
        return [P(r)[i] + rot(Q(r), centroid)[i] for i in range(3)]
    for sb in bodies:
        if not sb.get('static') or ('box' not in sb and '_box' not in sb): continue
        c = sb.get('position', [0, 0, 0]); hb = sb.get('box') or sb['_box']; qs = sb.get('orientation', [1, 0, 0, 0])
        qi = [qs[0], -qs[1], -qs[2], -qs[3]]
        for r in rows:
            if r['body'] in through or r['body'] not in dynamic: continue
            loc = rot(qi, [centre(r)[i] - c[i] for i in range(3)])
            if abs(loc[0]) < hb[0] and abs(loc[1]) < hb[1] and loc[2] < hb[2]:
                through.add(r['body']); fails.append(f"{r['body']} through {sb.get('name')} at t={float(r['time']):.2f}s")
    if info['kind']=='stack':
        # top = highest initial
        top = max(names, key=lambda b: P(first[b])[2])
        mv = dist(P(first[top]),P(last[top])); tl = tilt(Q(first[top]),Q(last[top])); sp = math.sqrt(sum(x*x for x in V(last[top])))
        worst = max(dist(P(first[b]),P(last[b])) for b in names)
        err = worst
        if mv > info['move']: fails.append(f"top moved {mv*100:.1f}cm")
        if tl > info['tiltlim']: fails.append(f"top tilt {tl:.1f}deg")
        if sp > info['speed']: fails.append(f"top speed {sp*100:.1f}cm/s")
    elif info['kind']=='slide':
        b=names[0]; d = dist(P(first[b])[:2]+[0],P(last[b])[:2]+[0]); tl=max(tilt(Q(first[b]),Q(r)) for r in rows if r['body']==b)
        err = abs(d-info['dist'])
        if abs(d-info['dist'])>0.1*info['dist']: fails.append(f"slid {d:.3f} vs {info['dist']:.3f}")
        if tl>info['tiltlim']: fails.append(f"tilt {tl:.1f}")
    elif info['kind']=='slope-rest':
        b=names[0]; d=dist(P(first[b]),P(last[b])); err=d
        if d>0.02*info.get('length',1): fails.append(f"moved {d*100:.1f}cm")
    elif info['kind']=='slope-slide':
        b=names[0]; p0=P(first[b]); p1=P(last[b]); s=sum((p1[i]-p0[i])*info['down'][i] for i in range(3))
        T=float(last[b]['time']); want=info['a']*T*T/2; err=abs(s-want)
        if abs(s-want)>0.1*want: fails.append(f"slid {s:.3f} vs {want:.3f}")
    elif info['kind']=='pile':
        # Every box at rest at the end (the judge above already caught any through the floor).
        err = max(math.sqrt(sum(x * x for x in V(last[b]))) for b in names)
        if err > 0.05 * math.sqrt(info.get('length', 1)): fails.append('not at rest %.2f m/s' % err)
    elif info['kind']=='drop':
        b=names[0]; worst=-1e9
        for r in rows:
            if r['body']!=b: continue
            p=P(r); q=Q(r); R=[rot(q,[1,0,0]),rot(q,[0,1,0]),rot(q,[0,0,1])]
            zs=[R[0][2]*v[0]+R[1][2]*v[1]+R[2][2]*v[2] for v in info['verts']]
            worst=max(worst,-(min(zs)+p[2])/info['diag'])
        err=worst
        lastp=P(last[b])
        if worst>0.01: fails.append(f"sank {worst*100:.2f}%")
        if math.sqrt(sum(x*x for x in V(last[b])))>0.05*math.sqrt(info.get('length',1)): fails.append('not at rest %.2f m/s'%math.sqrt(sum(x*x for x in V(last[b]))))
    return fails, err

def run_one(args):
    sid, scene, info, model, budget, bus, rate, outroot = args
    sc = dict(scene); sc['dt']=1.0/rate
    sc['bodies'] = [{k: v for k, v in b.items() if not k.startswith('_')} for b in scene['bodies']]; sc['contact_model']=model; sc['budget']=budget
    if bus: sc['budget_us']=bus
    d = os.path.join(outroot, f"{sid}_{model}_{budget}_{bus}_{rate}"); os.makedirs(d, exist_ok=True)
    f = os.path.join(d,'scene.json'); json.dump(sc, open(f,'w'))
    r = subprocess.run(['nice', CLOD,'simulate',f,'-o',os.path.join(d,'out')],capture_output=True,text=True,timeout=600)
    if r.returncode!=0: return (sid,model,budget,bus,rate,['exit %d: %s'%(r.returncode,r.stderr.strip()[-200:])],float('nan'))
    fails, err = judge(os.path.join(d,'out','trajectory.csv'), info, 1.0/rate, dict(sc, bodies=scene['bodies']))
    return (sid,model,budget,bus,rate,fails,err)

if __name__=='__main__':
    seed=int(sys.argv[1]); kinds=sys.argv[2].split(','); outroot=sys.argv[3]
    models=os.environ.get('MODELS','cfm,contact-tree,exact').split(',')
    budgets=[int(x) for x in os.environ.get('BUDGETS','16,64,256,1024,0').split(',') if x]
    buss=[float(x) for x in os.environ.get('BUS','50,200,1000').split(',') if x]
    rates=[float(x) for x in os.environ.get('RATES','240,60').split(',')]
    rng=random.Random(seed); jobs=[]
    os.makedirs(outroot, exist_ok=True); GROUND_DIR[0] = outroot
    for kind in kinds:
        scene, info = scaled(*gen(kind, rng), SCALE); sid=f"{kind}{seed}_{len(jobs)}"
        os.makedirs(outroot, exist_ok=True)
        with open(os.path.join(outroot, sid + '.json'), 'w') as f:
            json.dump({'scene': scene, 'info': {k: v for k, v in info.items() if k != 'verts'}}, f)
        for m in models:
            for rate in rates:
                for b in budgets: jobs.append((sid,scene,info,m,b,0,rate,outroot))
                for u in buss: jobs.append((sid,scene,info,m,0,u,rate,outroot))
    res=[]
    with cf.ThreadPoolExecutor(int(os.environ.get('J','2'))) as ex:
        for r in ex.map(run_one, jobs): res.append(r)
    # monotone check: per sid, model, rate: test budgets ordered 16..1024,0
    for r in res:
        if r[5]: print('FAIL', r[0], r[1], 'b=%d us=%g %gHz'%(r[2],r[3],r[4]), '; '.join(r[5]))
    from collections import defaultdict
    seq=defaultdict(dict)
    for r in res:
        if r[3]==0: seq[(r[0],r[1],r[4])][r[2]]=r[6]
    for k,v in seq.items():
        order=[b for b in budgets if b] + ([0] if 0 in budgets else [])
        for a,b in zip(order,order[1:]):
            ea, eb = v.get(a), v.get(b)
            if ea is None or eb is None: continue
            if not (eb <= ea + max(0.1*ea, 0.002*SCALE)): print('NONMONO', k, f'{a}->{b}', f'{ea:.4f}->{eb:.4f}')
    drops=[r for r in res if r[0].startswith('drop') and r[6]==r[6]]
    if drops:
        d=max(drops, key=lambda r: r[6])
        print('deepest sink %.2f%% (%s %s b=%d us=%g %gHz)' % (d[6]*100, d[0], d[1], d[2], d[3], d[4]))
    print('runs', len(res), 'failing', sum(1 for r in res if r[5]))
