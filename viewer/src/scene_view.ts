// The 3D view: renderer, +Z-up orbit camera, the bodies of scene.glb, sampling of the
// "simulation" animation at a time, and the debug layers of layers.json attached to the bodies
// (body-local layers are children of the body's node, so they move with it).
import * as THREE from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';
import { GLTFLoader, type GLTF } from 'three/addons/loaders/GLTFLoader.js';

import type { BodyLayers, OutputFolder } from './data';
import { ContactLayer, levelColor, makeCells, makeHalfspaces, makeSamples, makeSpheres } from './overlays';

// The simulator's frame is +Z up; the file keeps it, the camera follows it.
THREE.Object3D.DEFAULT_UP.set(0, 0, 1);

export const kBackground = 0x1b1f27;

export interface Body {
  index: number;
  name: string;
  isStatic: boolean;
  node: THREE.Object3D;
  layers: BodyLayers | null;
  overlay: THREE.Group; // holds this body's debug layers, in body-local coordinates
}

interface Channel {
  node: THREE.Object3D;
  path: 'position' | 'quaternion';
  interpolant: THREE.Interpolant;
}

export interface OverlaySettings {
  body: number; // -1 = every body
  sphereLevel: number; // -1 = none
  sphereStyle: 'wire' | 'transparent';
  cfmLevel: number; // -1 = none
  cells: number | 'all' | 'none'; // a depth, every depth, or hidden
  halfspaces: boolean;
}

const kPalette = [0xd9a066, 0x6fa8dc, 0x93c47d, 0xc27ba0, 0xe06666, 0x76a5af, 0xf6b26b, 0x8e7cc3];

export class SceneView {
  readonly renderer: THREE.WebGLRenderer;
  readonly scene = new THREE.Scene();
  readonly camera = new THREE.PerspectiveCamera(40, 1, 0.01, 1000);
  readonly controls: OrbitControls;
  bodies: Body[] = [];
  times: number[] = [0];
  folder: OutputFolder | null = null;
  diagonal = 1;
  private root: THREE.Object3D | null = null;
  private channels: Channel[] = [];
  private contacts: ContactLayer | null = null;
  private contactsOn = false;
  private frameIndex = 0;
  private time = 0;
  private xray = false;
  private dirty = true;

  constructor(private readonly container: HTMLElement) {
    this.renderer = new THREE.WebGLRenderer({ antialias: true });
    this.renderer.setPixelRatio(Math.min(window.devicePixelRatio, 2));
    container.appendChild(this.renderer.domElement);
    this.scene.background = new THREE.Color(kBackground);
    this.scene.add(new THREE.HemisphereLight(0xdfe8ff, 0x3a3430, 1.6));
    const sun = new THREE.DirectionalLight(0xffffff, 2.2);
    sun.position.set(3, -2, 5);
    this.scene.add(sun);
    this.controls = new OrbitControls(this.camera, this.renderer.domElement);
    this.controls.enableDamping = false;
    this.controls.addEventListener('change', () => (this.dirty = true));
    new ResizeObserver(() => this.resize()).observe(container);
    this.resize();
  }

  resize(): void {
    const w = Math.max(1, this.container.clientWidth), h = Math.max(1, this.container.clientHeight);
    this.renderer.setSize(w, h, false);
    this.camera.aspect = w / h;
    this.camera.updateProjectionMatrix();
    this.dirty = true;
  }

  /** Replaces the shown folder. Throws if scene.glb cannot be parsed. */
  async load(folder: OutputFolder): Promise<void> {
    const gltf = await new Promise<GLTF>((resolve, reject) =>
      new GLTFLoader().parse(folder.glb, '', resolve, (e) => reject(new Error(`scene.glb: ${e.message ?? e}`))),
    );
    if (this.root) this.scene.remove(this.root);
    this.folder = folder;
    this.root = gltf.scene;
    this.scene.add(gltf.scene);

    // Bodies: the nodes carrying extras.body (the contract), else the scene's top-level nodes.
    const nodes: THREE.Object3D[] = [];
    gltf.scene.traverse((o) => {
      const a = gltf.parser.associations.get(o);
      if (a && a.nodes !== undefined) nodes[a.nodes] = o;
    });
    let bodyNodes = nodes.filter((o) => o && typeof o.userData.body === 'number');
    if (bodyNodes.length === 0) bodyNodes = [...gltf.scene.children];
    bodyNodes.sort((a, b) => (a.userData.body ?? 0) - (b.userData.body ?? 0));
    const layerBodies = folder.layers?.bodies ?? [];
    this.bodies = bodyNodes.map((node, i) => {
      const nodeIndex = nodes.indexOf(node);
      const layers = layerBodies.find((b) => b.node === nodeIndex) ?? layerBodies[i] ?? null;
      const isStatic = node.userData.static === true;
      // Our own materials: readable colours, static bodies grey (the file may carry none).
      const color = isStatic ? 0x8a8f98 : kPalette[i % kPalette.length];
      node.traverse((o) => {
        if ((o as THREE.Mesh).isMesh)
          (o as THREE.Mesh).material = new THREE.MeshStandardMaterial({ color, roughness: 0.75, metalness: 0.0 });
      });
      const overlay = new THREE.Group();
      overlay.name = 'overlay';
      node.add(overlay);
      return { index: i, name: node.userData.name ?? node.name ?? `body ${i}`, isStatic, node, layers, overlay };
    });
    this.setXray(this.xray);

    // Animation: sample its tracks directly (clamped at both ends) instead of an AnimationMixer,
    // so any time, including the last frame, maps to exactly one pose.
    this.channels = [];
    const clip = gltf.animations.find((c) => c.name === 'simulation') ?? gltf.animations[0];
    for (const track of clip?.tracks ?? []) {
      const { nodeName, propertyName } = THREE.PropertyBinding.parseTrackName(track.name);
      const node = THREE.PropertyBinding.findNode(gltf.scene, nodeName) as THREE.Object3D | null;
      if (!node || (propertyName !== 'position' && propertyName !== 'quaternion')) continue;
      // createInterpolant() is public in three.js but missing from its typings.
      const interpolant = (track as unknown as { createInterpolant(): THREE.Interpolant }).createInterpolant();
      this.channels.push({ node, path: propertyName, interpolant });
    }
    const frameTimes = folder.layers?.frames?.time;
    const trackTimes = clip?.tracks[0]?.times;
    this.times = frameTimes && frameTimes.length > 0 ? frameTimes : trackTimes && trackTimes.length > 0 ? Array.from(trackTimes) : [0];

    this.frameCamera();
    const c = folder.layers?.contacts;
    let maxPerFrame = 0;
    if (c) for (let f = 0; f + 1 < c.frame_offsets.length; ++f) maxPerFrame = Math.max(maxPerFrame, c.frame_offsets[f + 1] - c.frame_offsets[f]);
    if (this.contacts) this.scene.remove(this.contacts.group);
    this.contacts = c ? new ContactLayer(maxPerFrame) : null;
    if (this.contacts) {
      this.contacts.group.visible = this.contactsOn;
      this.scene.add(this.contacts.group);
    }
    this.setFrame(0);
  }

  get frameCount(): number {
    return this.times.length;
  }
  get duration(): number {
    return this.times[this.times.length - 1] - this.times[0];
  }
  get currentFrame(): number {
    return this.frameIndex;
  }
  get currentTime(): number {
    return this.time;
  }
  get hasContacts(): boolean {
    return this.contacts !== null;
  }
  get shownContacts(): number {
    return this.contacts && this.contacts.group.visible ? this.contacts.shown : 0;
  }

  setFrame(i: number): void {
    const f = Math.min(Math.max(0, Math.round(i)), this.frameCount - 1);
    this.setTime(this.times[f]);
  }

  /** Poses the bodies at time t (seconds, clamped) and shows that frame's contacts. */
  setTime(t: number): void {
    const t0 = this.times[0], t1 = this.times[this.times.length - 1];
    this.time = Math.min(Math.max(t, t0), t1);
    for (const ch of this.channels) {
      const v = ch.interpolant.evaluate(this.time);
      if (ch.path === 'position') ch.node.position.fromArray(v);
      else ch.node.quaternion.fromArray(v).normalize();
    }
    // The frame shown is the last one at or before t.
    let lo = 0, hi = this.times.length - 1;
    while (lo < hi) {
      const mid = (lo + hi + 1) >> 1;
      if (this.times[mid] <= this.time + 1e-9) lo = mid;
      else hi = mid - 1;
    }
    this.frameIndex = lo;
    const c = this.folder?.layers?.contacts;
    if (this.contacts && c && lo + 1 < c.frame_offsets.length)
      this.contacts.show(c.data, c.frame_offsets[lo], c.frame_offsets[lo + 1], 0.08 * this.diagonal);
    this.dirty = true;
  }

  setContactsVisible(on: boolean): void {
    this.contactsOn = on;
    if (this.contacts) this.contacts.group.visible = on;
    this.dirty = true;
  }

  setXray(on: boolean): void {
    this.xray = on;
    for (const b of this.bodies)
      b.node.traverse((o) => {
        const m = (o as THREE.Mesh).material as THREE.MeshStandardMaterial | undefined;
        if (!(o as THREE.Mesh).isMesh || !m) return;
        m.transparent = on;
        m.opacity = on ? 0.3 : 1;
        m.depthWrite = !on;
        m.needsUpdate = true;
      });
    this.dirty = true;
  }

  /** Rebuilds the body-local debug layers; returns how many items each kind shows. */
  setOverlays(s: OverlaySettings): { spheres: number; samples: number; cells: number } {
    const shown = { spheres: 0, samples: 0, cells: 0 };
    for (const b of this.bodies) {
      for (const child of [...b.overlay.children]) {
        b.overlay.remove(child);
        disposeObject(child);
      }
      if (!b.layers || (s.body >= 0 && s.body !== b.index)) continue;
      const levels = b.layers.sphere_tree?.levels;
      if (levels && s.sphereLevel >= 0 && s.sphereLevel < levels.length) {
        const mesh = makeSpheres(levels[s.sphereLevel], levelColor(s.sphereLevel), s.sphereStyle);
        mesh.name = 'spheres';
        b.overlay.add(mesh);
        shown.spheres += mesh.count;
      }
      const samples = b.layers.cfm_samples?.find((x) => x.level === s.cfmLevel);
      if (samples) {
        const pts = makeSamples(samples.points, samples.normals, 4);
        pts.name = 'cfm';
        b.overlay.add(pts);
        shown.samples += samples.points.length / 3;
      }
      const tree = b.layers.contact_tree;
      if (tree && s.cells !== 'none') {
        const depth = s.cells === 'all' ? null : s.cells;
        const cells = makeCells(tree.cells, depth);
        cells.object.name = 'cells';
        b.overlay.add(cells.object);
        shown.cells += cells.count;
        if (s.halfspaces && tree.halfspaces) {
          const planes = makeHalfspaces(tree.cells, tree.halfspaces, depth);
          planes.name = 'halfspaces';
          b.overlay.add(planes);
        }
      }
    }
    this.dirty = true;
    return shown;
  }

  /**
   * Points the camera, from the front-right and above, at everything the moving bodies reach
   * over the animation (static bodies such as a ground box are context, not the subject), or at
   * the whole scene when nothing moves.
   */
  frameCamera(): void {
    const all = new THREE.Box3(), moving = new THREE.Box3();
    const saved = this.time;
    const steps = Math.min(this.times.length, 64);
    for (let k = 0; k < steps; ++k) {
      this.setTime(this.times[Math.round((k * (this.times.length - 1)) / Math.max(1, steps - 1))]);
      for (const b of this.bodies) {
        all.expandByObject(b.node);
        if (!b.isStatic) moving.expandByObject(b.node);
      }
    }
    this.setTime(saved);
    if (all.isEmpty()) all.setFromCenterAndSize(new THREE.Vector3(), new THREE.Vector3(1, 1, 1));
    const subject = moving.isEmpty() ? all : moving;
    const centre = subject.getCenter(new THREE.Vector3());
    const radius = Math.max(1e-6, subject.getSize(new THREE.Vector3()).length() / 2);
    this.diagonal = 2 * radius;
    const distance = (radius / Math.sin(THREE.MathUtils.degToRad(this.camera.fov / 2))) * 1.1;
    this.camera.position.copy(centre).add(new THREE.Vector3(0.55, -1.0, 0.45).normalize().multiplyScalar(distance));
    this.camera.near = distance / 200;
    this.camera.far = distance * 10 + all.getSize(new THREE.Vector3()).length() * 4;
    this.camera.updateProjectionMatrix();
    this.controls.target.copy(centre);
    this.controls.update();
    this.dirty = true;
  }

  /** Renders if anything changed since the last frame (or always with force). */
  render(force = false): void {
    if (!force && !this.dirty) return;
    this.dirty = false;
    this.renderer.render(this.scene, this.camera);
  }

  /** World positions of the bodies' origins at the current time. */
  bodyPositions(): number[][] {
    return this.bodies.map((b) => b.node.getWorldPosition(new THREE.Vector3()).toArray());
  }

  /**
   * Page (CSS pixel) coordinates of up to `perBody` triangle centroids of each body, for a test
   * that checks that pixels were drawn where the bodies are. Centroids are strictly inside their
   * triangles, so the body (or something in front of it) covers them.
   */
  bodyScreenPoints(perBody: number): { body: number; name: string; points: number[][] }[] {
    this.scene.updateMatrixWorld(true);
    const rect = this.renderer.domElement.getBoundingClientRect();
    const a = new THREE.Vector3(), b = new THREE.Vector3(), c = new THREE.Vector3();
    return this.bodies.map((body) => {
      const points: number[][] = [];
      body.node.traverse((o) => {
        const mesh = o as THREE.Mesh;
        if (!mesh.isMesh || o.parent?.name === 'overlay' || o.name === 'overlay') return;
        const pos = mesh.geometry.getAttribute('position');
        const index = mesh.geometry.getIndex();
        const triangles = index ? index.count / 3 : pos.count / 3;
        const stride = Math.max(1, Math.floor(triangles / perBody));
        for (let t = 0; t < triangles && points.length < perBody; t += stride) {
          const v = [0, 1, 2].map((k) => (index ? index.getX(3 * t + k) : 3 * t + k));
          a.fromBufferAttribute(pos, v[0]);
          b.fromBufferAttribute(pos, v[1]);
          c.fromBufferAttribute(pos, v[2]);
          a.add(b).add(c).divideScalar(3).applyMatrix4(mesh.matrixWorld).project(this.camera);
          if (Math.abs(a.x) > 0.98 || Math.abs(a.y) > 0.98 || a.z < -1 || a.z > 1) continue;
          points.push([rect.left + ((a.x + 1) / 2) * rect.width, rect.top + ((1 - a.y) / 2) * rect.height]);
        }
      });
      return { body: body.index, name: body.name, points };
    });
  }
}

function disposeObject(o: THREE.Object3D): void {
  o.traverse((x) => {
    const withGeometry = x as THREE.Mesh;
    withGeometry.geometry?.dispose();
    const m = withGeometry.material;
    if (Array.isArray(m)) m.forEach((mm) => mm.dispose());
    else m?.dispose();
  });
}
