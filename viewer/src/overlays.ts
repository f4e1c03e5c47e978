// Debug-layer geometry: everything is built once per folder into flat typed arrays and drawn
// instanced (spheres, half-spaces), as one instanced line set (contact-tree cells) or as
// Points/LineSegments (CFM samples, contacts), so ~10^5 items cost one draw call each.
import * as THREE from 'three';

/** Colour ramp for depths/levels: blue (coarse) -> green -> orange -> red (fine). */
export function rampColor(t: number, out = new THREE.Color()): THREE.Color {
  const u = Math.min(1, Math.max(0, t));
  return out.setHSL((1 - u) * 0.62, 0.85, 0.55);
}

const kLevelColors = [0x4fc3f7, 0x81c784, 0xffb74d, 0xe57373, 0xba68c8, 0x4db6ac, 0xf06292, 0xa1887f];
export function levelColor(level: number): THREE.Color {
  return new THREE.Color(kLevelColors[level % kLevelColors.length]);
}

/** One sphere-tree level (flat [cx,cy,cz,r,...], body-local) as instanced spheres. */
export function makeSpheres(flat: number[], color: THREE.Color, style: 'wire' | 'transparent'): THREE.InstancedMesh {
  const count = Math.floor(flat.length / 4);
  // Wireframe shows nesting best; a coarser sphere keeps 10^5 instances cheap.
  const geometry = style === 'wire' ? new THREE.IcosahedronGeometry(1, 1) : new THREE.IcosahedronGeometry(1, 3);
  const material =
    style === 'wire'
      ? new THREE.MeshBasicMaterial({ color, wireframe: true, transparent: true, opacity: 0.55, depthWrite: false })
      : new THREE.MeshLambertMaterial({ color, transparent: true, opacity: 0.22, depthWrite: false, side: THREE.DoubleSide });
  const mesh = new THREE.InstancedMesh(geometry, material, count);
  const m = new THREE.Matrix4();
  for (let i = 0; i < count; ++i) {
    const r = flat[4 * i + 3];
    m.makeScale(r, r, r).setPosition(flat[4 * i], flat[4 * i + 1], flat[4 * i + 2]);
    mesh.setMatrixAt(i, m);
  }
  mesh.instanceMatrix.needsUpdate = true;
  mesh.computeBoundingSphere();
  mesh.renderOrder = 2;
  return mesh;
}

/** CFM samples as points coloured by their stored normal: rgb = 0.5 * n + 0.5. */
export function makeSamples(points: number[], normals: number[], sizePx: number): THREE.Points {
  const n = Math.floor(points.length / 3);
  const positions = new Float32Array(points.slice(0, 3 * n));
  const colors = new Float32Array(3 * n);
  const c = new THREE.Color();
  for (let i = 0; i < n; ++i) {
    // rgb = 0.5 n + 0.5 as displayed (sRGB) values: convert to the linear working space so the
    // renderer's output conversion gives back exactly these numbers on screen.
    const [x, y, z] = [normals[3 * i] ?? 0, normals[3 * i + 1] ?? 0, normals[3 * i + 2] ?? 0];
    c.setRGB(0.5 * x + 0.5, 0.5 * y + 0.5, 0.5 * z + 0.5, THREE.SRGBColorSpace);
    colors.set([c.r, c.g, c.b], 3 * i);
  }
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute('position', new THREE.BufferAttribute(positions, 3));
  geometry.setAttribute('color', new THREE.BufferAttribute(colors, 3));
  const material = new THREE.PointsMaterial({ size: sizePx, sizeAttenuation: false, vertexColors: true });
  const pts = new THREE.Points(geometry, material);
  pts.renderOrder = 3;
  return pts;
}

// Unit cube edges (12 segments), instanced by a tiny shader: position = centre + half * corner.
const kCubeEdges = (() => {
  const c = [-1, 1];
  const out: number[] = [];
  for (const a of c)
    for (const b of c) {
      out.push(-1, a, b, 1, a, b); // along x
      out.push(a, -1, b, a, 1, b); // along y
      out.push(a, b, -1, a, b, 1); // along z
    }
  return new Float32Array(out);
})();

/** Contact-tree cells ([cx,cy,cz,half,depth,...], body-local) as wire boxes coloured by depth. */
export function makeCells(cells: number[], depthFilter: number | null): { object: THREE.LineSegments; count: number; maxDepth: number } {
  const total = Math.floor(cells.length / 5);
  let maxDepth = 0;
  for (let i = 0; i < total; ++i) maxDepth = Math.max(maxDepth, cells[5 * i + 4]);
  const picked: number[] = [];
  for (let i = 0; i < total; ++i) if (depthFilter === null || cells[5 * i + 4] === depthFilter) picked.push(i);
  const offsets = new Float32Array(4 * picked.length);
  const colors = new Float32Array(3 * picked.length);
  const c = new THREE.Color();
  // One colour per depth, computed once: 10^5 cells then cost a plain copy loop.
  const ramp = Array.from({ length: maxDepth + 1 }, (_, d) => rampColor(maxDepth > 0 ? d / maxDepth : 1, new THREE.Color()));
  for (let k = 0; k < picked.length; ++k) {
    const o = 5 * picked[k];
    offsets[4 * k] = cells[o];
    offsets[4 * k + 1] = cells[o + 1];
    offsets[4 * k + 2] = cells[o + 2];
    offsets[4 * k + 3] = cells[o + 3];
    c.copy(ramp[Math.max(0, Math.min(maxDepth, Math.round(cells[o + 4])))]);
    colors[3 * k] = c.r;
    colors[3 * k + 1] = c.g;
    colors[3 * k + 2] = c.b;
  }
  const geometry = new THREE.InstancedBufferGeometry();
  geometry.setAttribute('position', new THREE.BufferAttribute(kCubeEdges, 3));
  geometry.setAttribute('cell', new THREE.InstancedBufferAttribute(offsets, 4));
  geometry.setAttribute('cellColor', new THREE.InstancedBufferAttribute(colors, 3));
  geometry.instanceCount = picked.length;
  const material = new THREE.ShaderMaterial({
    vertexShader: `
      attribute vec4 cell;
      attribute vec3 cellColor;
      varying vec3 vColor;
      void main() {
        vColor = cellColor;
        gl_Position = projectionMatrix * modelViewMatrix * vec4(cell.xyz + cell.w * position, 1.0);
      }`,
    fragmentShader: `
      varying vec3 vColor;
      void main() {
        gl_FragColor = vec4(vColor, 0.8);
        #include <colorspace_fragment>
      }`,
    transparent: true,
    depthWrite: false,
  });
  const object = new THREE.LineSegments(geometry, material);
  object.frustumCulled = false; // the instanced extent is not in the geometry's bounds
  object.renderOrder = 2;
  return { object, count: picked.length, maxDepth };
}

/** Per-cell half-spaces (n.x = offset) as small squares in their planes, coloured by depth. */
export function makeHalfspaces(cells: number[], halfspaces: number[], depthFilter: number | null): THREE.InstancedMesh {
  const total = Math.min(Math.floor(cells.length / 5), Math.floor(halfspaces.length / 4));
  let maxDepth = 0;
  for (let i = 0; i < total; ++i) maxDepth = Math.max(maxDepth, cells[5 * i + 4]);
  const picked: number[] = [];
  for (let i = 0; i < total; ++i) if (depthFilter === null || cells[5 * i + 4] === depthFilter) picked.push(i);
  const mesh = new THREE.InstancedMesh(
    new THREE.PlaneGeometry(2, 2),
    new THREE.MeshBasicMaterial({ transparent: true, opacity: 0.35, side: THREE.DoubleSide, depthWrite: false }),
    picked.length,
  );
  const zAxis = new THREE.Vector3(0, 0, 1);
  const n = new THREE.Vector3(), centre = new THREE.Vector3(), q = new THREE.Quaternion(), s = new THREE.Vector3();
  const m = new THREE.Matrix4();
  const ramp = Array.from({ length: maxDepth + 1 }, (_, d) => rampColor(maxDepth > 0 ? d / maxDepth : 1, new THREE.Color()));
  picked.forEach((i, k) => {
    n.set(halfspaces[4 * i], halfspaces[4 * i + 1], halfspaces[4 * i + 2]);
    const len = n.length();
    if (len > 0) n.divideScalar(len);
    else n.copy(zAxis);
    const offset = halfspaces[4 * i + 3] / (len > 0 ? len : 1);
    centre.set(cells[5 * i], cells[5 * i + 1], cells[5 * i + 2]);
    centre.addScaledVector(n, offset - n.dot(centre)); // project the cell centre onto the plane
    q.setFromUnitVectors(zAxis, n);
    const half = cells[5 * i + 3];
    m.compose(centre, q, s.set(half, half, half));
    mesh.setMatrixAt(k, m);
    mesh.setColorAt(k, ramp[Math.max(0, Math.min(maxDepth, Math.round(cells[5 * i + 4])))]);
  });
  mesh.instanceMatrix.needsUpdate = true;
  if (mesh.instanceColor) mesh.instanceColor.needsUpdate = true;
  mesh.computeBoundingSphere();
  mesh.renderOrder = 2;
  return mesh;
}

/** Contacts of one frame: points and normal segments, in preallocated buffers (world frame). */
export class ContactLayer {
  readonly group = new THREE.Group();
  private readonly points: THREE.Points;
  private readonly lines: THREE.LineSegments;
  private readonly capacity: number;
  shown = 0;

  constructor(maxPerFrame: number) {
    this.capacity = Math.max(1, maxPerFrame);
    const pGeo = new THREE.BufferGeometry();
    pGeo.setAttribute('position', new THREE.BufferAttribute(new Float32Array(3 * this.capacity), 3));
    const lGeo = new THREE.BufferGeometry();
    lGeo.setAttribute('position', new THREE.BufferAttribute(new Float32Array(6 * this.capacity), 3));
    // Drawn on top of the bodies: a contact sits on (or inside) a surface and would be hidden.
    this.points = new THREE.Points(pGeo, new THREE.PointsMaterial({ color: 0xff3b30, size: 7, sizeAttenuation: false, depthTest: false }));
    this.lines = new THREE.LineSegments(lGeo, new THREE.LineBasicMaterial({ color: 0xffe066, depthTest: false }));
    this.points.frustumCulled = this.lines.frustumCulled = false;
    this.points.renderOrder = this.lines.renderOrder = 10;
    this.group.add(this.points, this.lines);
    this.group.name = 'contacts';
  }

  /** Shows data[7*begin .. 7*end) (px,py,pz,nx,ny,nz,depth) with normals `normalLength` long. */
  show(data: number[], begin: number, end: number, normalLength: number): void {
    const n = Math.min(end - begin, this.capacity);
    const p = this.points.geometry.getAttribute('position') as THREE.BufferAttribute;
    const l = this.lines.geometry.getAttribute('position') as THREE.BufferAttribute;
    for (let k = 0; k < n; ++k) {
      const o = 7 * (begin + k);
      const [px, py, pz, nx, ny, nz] = [data[o], data[o + 1], data[o + 2], data[o + 3], data[o + 4], data[o + 5]];
      p.setXYZ(k, px, py, pz);
      l.setXYZ(2 * k, px, py, pz);
      l.setXYZ(2 * k + 1, px + normalLength * nx, py + normalLength * ny, pz + normalLength * nz);
    }
    p.needsUpdate = l.needsUpdate = true;
    this.points.geometry.setDrawRange(0, n);
    this.lines.geometry.setDrawRange(0, 2 * n);
    this.shown = n;
  }
}
