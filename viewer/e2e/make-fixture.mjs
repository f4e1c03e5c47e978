// Writes a small output folder that follows the clod output-folder contract (docs/viewer-format.md):
// scene.glb (a static ground box and a box that falls, tips and lands, +Z up), layers.json
// (frames, contacts, a sphere tree, CFM samples and contact-tree cells for the falling box) and
// summary.json. It lets the viewer be developed and tested without the C++ exporter.
//
//   node e2e/make-fixture.mjs OUTDIR [--cells N]   (N: contact-tree cells to write, default ~1000,
//                                                    e.g. 100000 to check that big layers stay smooth)
import fs from 'node:fs';
import path from 'node:path';

const args = process.argv.slice(2);
const outDir = args.find((a) => !a.startsWith('--'));
if (!outDir) {
  console.error('usage: node e2e/make-fixture.mjs OUTDIR [--cells N]');
  process.exit(2);
}
const cellsArg = args.indexOf('--cells');
const wantedCells = cellsArg >= 0 ? Number(args[cellsArg + 1]) : 1000;
fs.mkdirSync(outDir, { recursive: true });

// ---- geometry ---------------------------------------------------------------------------------
// A box of half extents h, 24 vertices (per-face normals), counter-clockwise outward triangles.
function boxMesh(h) {
  const pos = [], nrm = [], idx = [];
  const faces = [
    [0, 1], [0, -1], [1, 1], [1, -1], [2, 1], [2, -1],
  ];
  for (const [axis, sign] of faces) {
    const u = (axis + 1) % 3, v = (axis + 2) % 3;
    const base = pos.length / 3;
    const corners = [[-1, -1], [1, -1], [1, 1], [-1, 1]];
    for (const [a, b] of corners) {
      const p = [0, 0, 0];
      p[axis] = sign * h[axis];
      p[u] = a * h[u];
      p[v] = b * h[v] * sign; // flip winding with the face direction so triangles stay outward
      pos.push(...p);
      const n = [0, 0, 0];
      n[axis] = sign;
      nrm.push(...n);
    }
    idx.push(base, base + 1, base + 2, base, base + 2, base + 3);
  }
  return { pos: new Float32Array(pos), nrm: new Float32Array(nrm), idx: new Uint32Array(idx) };
}

function quatAxisAngle(axis, angle) {
  const s = Math.sin(angle / 2);
  return [axis[0] * s, axis[1] * s, axis[2] * s, Math.cos(angle / 2)]; // glTF order x,y,z,w
}

// ---- the motion: a box falls from z=1.2, turning about x, and settles on the ground -----------
const groundHalf = [1, 1, 0.125];
const boxHalf = [0.15, 0.15, 0.15];
const frameCount = 91;
const dt = 1 / 30;
const times = [], translations = [], rotations = [], ke = [], pe = [], counts = [], spent = [], budget = [];
const contactData = [], offsets = [0];
const mass = 1000 * 8 * boxHalf[0] * boxHalf[1] * boxHalf[2];
const landing = 40;
for (let f = 0; f < frameCount; ++f) {
  const t = f * dt;
  times.push(t);
  const rest = groundHalf[2] + boxHalf[2];
  const fall = Math.min(f, landing) / landing;
  const z = 1.2 + (rest - 1.2) * fall * fall;
  const x = 0.3 * fall;
  const angle = (Math.PI / 2) * fall; // a quarter turn: lands flat again
  translations.push(x, 0, z);
  rotations.push(...quatAxisAngle([1, 0, 0], angle));
  const v = f < landing ? (2 * (1.2 - rest) * fall) / (landing * dt) : 0;
  ke.push(0.5 * mass * v * v);
  pe.push(mass * 9.81 * z);
  let n = 0;
  if (f >= landing) {
    for (const [sx, sy] of [[-1, -1], [1, -1], [1, 1], [-1, 1]]) {
      contactData.push(x + sx * boxHalf[0], sy * boxHalf[1], groundHalf[2], 0, 0, 1, 0.001);
      ++n;
    }
  }
  counts.push(n);
  offsets.push(offsets[offsets.length - 1] + n);
  spent.push(f >= landing - 2 ? 120 + 10 * (f % 3) : 8);
  budget.push(0);
}
const total = ke.map((k, i) => k + pe[i]);

// ---- glb --------------------------------------------------------------------------------------
const chunks = [];
let byteLength = 0;
const bufferViews = [], accessors = [];
function addView(typed, target) {
  while (byteLength % 4) {
    chunks.push(new Uint8Array(1));
    byteLength += 1;
  }
  const bytes = new Uint8Array(typed.buffer, typed.byteOffset, typed.byteLength);
  bufferViews.push({ buffer: 0, byteOffset: byteLength, byteLength: bytes.length, ...(target ? { target } : {}) });
  chunks.push(bytes);
  byteLength += bytes.length;
  return bufferViews.length - 1;
}
function addAccessor(typed, type, componentType, target, withBounds) {
  const width = { SCALAR: 1, VEC3: 3, VEC4: 4 }[type];
  const acc = { bufferView: addView(typed, target), componentType, count: typed.length / width, type };
  if (withBounds) {
    const min = Array(width).fill(Infinity), max = Array(width).fill(-Infinity);
    for (let i = 0; i < typed.length; ++i) {
      min[i % width] = Math.min(min[i % width], typed[i]);
      max[i % width] = Math.max(max[i % width], typed[i]);
    }
    Object.assign(acc, { min, max });
  }
  accessors.push(acc);
  return accessors.length - 1;
}
const kFloat = 5126, kUint = 5125;
const meshes = [];
for (const half of [groundHalf, boxHalf]) {
  const m = boxMesh(half);
  meshes.push({
    primitives: [{
      attributes: { POSITION: addAccessor(m.pos, 'VEC3', kFloat, 34962, true), NORMAL: addAccessor(m.nrm, 'VEC3', kFloat, 34962) },
      indices: addAccessor(m.idx, 'SCALAR', kUint, 34963),
    }],
  });
}
const timeAcc = addAccessor(new Float32Array(times), 'SCALAR', kFloat, undefined, true);
const trAcc = addAccessor(new Float32Array(translations), 'VEC3', kFloat);
const rotAcc = addAccessor(new Float32Array(rotations), 'VEC4', kFloat);
const gltf = {
  asset: { version: '2.0', generator: 'clod viewer fixture (make-fixture.mjs)' },
  scene: 0,
  scenes: [{ nodes: [0, 1] }],
  nodes: [
    { name: 'ground', mesh: 0, translation: [0, 0, 0], rotation: [0, 0, 0, 1], extras: { body: 0, static: true } },
    { name: 'box', mesh: 1, translation: translations.slice(0, 3), rotation: rotations.slice(0, 4), extras: { body: 1, static: false } },
  ],
  meshes,
  accessors,
  bufferViews,
  buffers: [{ byteLength }],
  animations: [{
    name: 'simulation',
    samplers: [
      { input: timeAcc, output: trAcc, interpolation: 'LINEAR' },
      { input: timeAcc, output: rotAcc, interpolation: 'LINEAR' },
    ],
    channels: [
      { sampler: 0, target: { node: 1, path: 'translation' } },
      { sampler: 1, target: { node: 1, path: 'rotation' } },
    ],
  }],
};
function pad(buf, fill) {
  const extra = (4 - (buf.length % 4)) % 4;
  return Buffer.concat([buf, Buffer.alloc(extra, fill)]);
}
const json = pad(Buffer.from(JSON.stringify(gltf)), 0x20);
const bin = pad(Buffer.concat(chunks.map((c) => Buffer.from(c.buffer, c.byteOffset, c.byteLength))), 0);
const header = Buffer.alloc(12);
header.writeUInt32LE(0x46546c67, 0);
header.writeUInt32LE(2, 4);
header.writeUInt32LE(12 + 8 + json.length + 8 + bin.length, 8);
const chunkHeader = (len, type) => {
  const b = Buffer.alloc(8);
  b.writeUInt32LE(len, 0);
  b.writeUInt32LE(type, 4);
  return b;
};
fs.writeFileSync(path.join(outDir, 'scene.glb'),
  Buffer.concat([header, chunkHeader(json.length, 0x4e4f534a), json, chunkHeader(bin.length, 0x004e4942), bin]));

// ---- layers.json ------------------------------------------------------------------------------
// Sphere tree of the box: root sphere, then 8 octant spheres, then 64.
const levels = [];
for (let l = 0; l < 3; ++l) {
  const n = 1 << l, level = [];
  for (let i = 0; i < n; ++i)
    for (let j = 0; j < n; ++j)
      for (let k = 0; k < n; ++k) {
        const c = [i, j, k].map((q, a) => -boxHalf[a] + ((2 * q + 1) * boxHalf[a]) / n);
        level.push(...c, Math.hypot(...boxHalf) / n);
      }
  levels.push(level);
}
// CFM samples on the root sphere (polar, 16 stacks): normal of the nearest box face.
const points = [], normals = [];
const r0 = levels[0][3];
for (let s = 0; s <= 16; ++s) {
  const phi = (Math.PI * s) / 16;
  const ring = Math.max(1, Math.round(32 * Math.sin(phi)));
  for (let q = 0; q < ring; ++q) {
    const th = (2 * Math.PI * q) / ring;
    const d = [Math.sin(phi) * Math.cos(th), Math.sin(phi) * Math.sin(th), Math.cos(phi)];
    points.push(...d.map((c) => c * r0));
    const scaled = d.map((c, a) => Math.abs(c) / boxHalf[a]);
    const axis = scaled.indexOf(Math.max(...scaled));
    const n = [0, 0, 0];
    n[axis] = Math.sign(d[axis]) || 1;
    normals.push(...n);
  }
}
// Contact-tree cells: octree cells of the box's bounding cube that the surface crosses, down to
// the depth that gives about `wantedCells` cells; half-space = the nearest face's plane.
const cells = [], halfspaces = [];
const cube = Math.max(...boxHalf) * 1.25;
let depth = 1;
while (6 * 4 ** depth < wantedCells && depth < 10) ++depth;
function visit(c, half, d) {
  const inside = (p) => Math.max(...p.map((v, a) => Math.abs(v) - boxHalf[a]));
  const dist = inside(c);
  if (Math.abs(dist) > half * Math.sqrt(3)) return; // the surface cannot cross this cell
  cells.push(...c, half, d);
  const scaled = c.map((v, a) => Math.abs(v) / boxHalf[a]);
  const axis = scaled.indexOf(Math.max(...scaled));
  const n = [0, 0, 0];
  n[axis] = Math.sign(c[axis]) || 1;
  halfspaces.push(...n, boxHalf[axis]);
  if (d === depth) return;
  for (let o = 0; o < 8; ++o)
    visit(c.map((v, a) => v + ((o >> a) & 1 ? half / 2 : -half / 2)), half / 2, d + 1);
}
visit([0, 0, 0], cube, 0);
const layers = {
  format: 'clod-layers',
  version: 1,
  frames: { time: times, kinetic_energy: ke, potential_energy: pe, total_energy: total, contacts: counts, tests_spent: spent, tests_budget: budget },
  contacts: { frame_offsets: offsets, data: contactData },
  bodies: [
    { name: 'ground', node: 0 },
    {
      name: 'box', node: 1,
      sphere_tree: { levels },
      cfm_samples: [{ level: 0, points, normals }],
      contact_tree: { cells, halfspaces },
    },
  ],
};
fs.writeFileSync(path.join(outDir, 'layers.json'), JSON.stringify(layers));

// ---- summary.json (the fields the viewer and its test read) ----------------------------------
const last = frameCount - 1;
const summary = {
  bodies: [
    { name: 'ground', position: [0, 0, 0], orientation: [1, 0, 0, 0] },
    { name: 'box', position: translations.slice(3 * last, 3 * last + 3),
      orientation: [rotations[4 * last + 3], ...rotations.slice(4 * last, 4 * last + 3)] },
  ],
  steps: last,
  dt,
};
fs.writeFileSync(path.join(outDir, 'summary.json'), JSON.stringify(summary, null, 2));
console.log(`fixture: 2 bodies, ${frameCount} frames, ${cells.length / 5} contact-tree cells -> ${outDir}`);
