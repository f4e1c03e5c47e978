// Entry point: finds the data (served: ./data/ or ?data=URL; file:// or a failed fetch: a folder
// picker / drop zone), wires the controls, runs the render loop and exposes window.__clod, a
// small hook for the browser test (viewer/e2e/viewer.e2e.mjs).
import './style.css';

import { Chart } from './chart';
import { fetchFolder, filesFromDrop, readFiles, type OutputFolder } from './data';
import { kBackground, SceneView, type OverlaySettings } from './scene_view';

const $ = <T extends HTMLElement>(id: string) => document.getElementById(id) as T;

export type LayerName = 'contacts' | 'spheres' | 'cfm' | 'cells' | 'halfspaces' | 'xray';

/** The test hook. Everything here reflects what is on screen after the last render. */
export interface ClodHook {
  ready: Promise<void>;
  error: string | null;
  bodyCount: number;
  frameCount: number;
  background: number[];
  frame(): number;
  setFrame(i: number): void;
  toggle(layer: LayerName, on?: boolean): boolean;
  contactsInFrame(i: number): number;
  shownContacts(): number;
  shownCounts(): { spheres: number; samples: number; cells: number };
  bodyNames(): string[];
  bodyPositions(): number[][];
  bodyScreenPoints(perBody?: number): { body: number; name: string; points: number[][] }[];
}

const view = new SceneView($('view'));
const chart = new Chart($('chart') as HTMLCanvasElement, (t) => {
  pause();
  view.setTime(t);
  updateReadouts();
});

let playing = false;
let speed = 1;
let lastTick = 0;
let shownCounts = { spheres: 0, samples: 0, cells: 0 };
const overlay: OverlaySettings = { body: -1, sphereLevel: -1, sphereStyle: 'wire', cfmLevel: -1, cells: 'none', halfspaces: false };

let resolveReady!: () => void;
let rejectReady!: (e: Error) => void;
const hook: ClodHook = {
  ready: new Promise<void>((res, rej) => ((resolveReady = res), (rejectReady = rej))),
  error: null,
  bodyCount: 0,
  frameCount: 0,
  background: [(kBackground >> 16) & 255, (kBackground >> 8) & 255, kBackground & 255],
  frame: () => view.currentFrame,
  setFrame: (i) => {
    pause();
    view.setFrame(i);
    updateReadouts();
    view.render(true);
  },
  toggle: (layer, on) => {
    const state = toggleLayer(layer, on);
    view.render(true);
    return state;
  },
  contactsInFrame: (i) => {
    const o = view.folder?.layers?.contacts?.frame_offsets;
    return o && i + 1 < o.length ? o[i + 1] - o[i] : 0;
  },
  shownContacts: () => view.shownContacts,
  shownCounts: () => ({ ...shownCounts }),
  bodyNames: () => view.bodies.map((b) => b.name),
  bodyPositions: () => view.bodyPositions(),
  bodyScreenPoints: (perBody = 24) => view.bodyScreenPoints(perBody),
};
(window as unknown as { __clod: ClodHook }).__clod = hook;
hook.ready.catch(() => undefined); // a failed load is reported through hook.error and the page

// ---- controls ---------------------------------------------------------------------------------
const playButton = $('play') as HTMLButtonElement;
const scrub = $('scrub') as HTMLInputElement;

function play(): void {
  if (view.frameCount < 2) return;
  if (view.currentFrame >= view.frameCount - 1) view.setFrame(0);
  playing = true;
  lastTick = performance.now();
  playButton.textContent = '⏸';
}
function pause(): void {
  playing = false;
  playButton.textContent = '▶';
}
playButton.addEventListener('click', () => (playing ? pause() : play()));
scrub.addEventListener('input', () => {
  pause();
  view.setFrame(Number(scrub.value));
  updateReadouts();
});
($('speed') as HTMLSelectElement).addEventListener('change', (e) => (speed = Number((e.target as HTMLSelectElement).value)));
window.addEventListener('keydown', (e) => {
  if ((e.target as HTMLElement).tagName === 'SELECT' || (e.target as HTMLElement).tagName === 'INPUT') return;
  if (e.code === 'Space') {
    e.preventDefault();
    if (playing) pause();
    else play();
  } else if (e.code === 'ArrowRight' || e.code === 'ArrowLeft') {
    pause();
    view.setFrame(view.currentFrame + (e.code === 'ArrowRight' ? 1 : -1));
    updateReadouts();
  }
});

const contactsBox = $('contacts') as HTMLInputElement;
const xrayBox = $('xray') as HTMLInputElement;
const halfspacesBox = $('halfspaces') as HTMLInputElement;
contactsBox.addEventListener('change', () => toggleLayer('contacts', contactsBox.checked));
xrayBox.addEventListener('change', () => toggleLayer('xray', xrayBox.checked));
halfspacesBox.addEventListener('change', () => toggleLayer('halfspaces', halfspacesBox.checked));
for (const id of ['body', 'spheres', 'sphere-style', 'cfm', 'cells'])
  $(id).addEventListener('change', () => readOverlayControls());

function readOverlayControls(): void {
  overlay.body = Number(($('body') as HTMLSelectElement).value);
  overlay.sphereLevel = Number(($('spheres') as HTMLSelectElement).value);
  overlay.sphereStyle = ($('sphere-style') as HTMLSelectElement).value as 'wire' | 'transparent';
  overlay.cfmLevel = Number(($('cfm') as HTMLSelectElement).value);
  const cells = ($('cells') as HTMLSelectElement).value;
  overlay.cells = cells === 'none' || cells === 'all' ? cells : Number(cells);
  overlay.halfspaces = halfspacesBox.checked;
  applyOverlays();
}

function applyOverlays(): void {
  shownCounts = view.setOverlays(overlay);
  const parts: string[] = [];
  if (shownCounts.spheres) parts.push(`${shownCounts.spheres.toLocaleString('en')} spheres`);
  if (shownCounts.samples) parts.push(`${shownCounts.samples.toLocaleString('en')} samples`);
  if (shownCounts.cells) parts.push(`${shownCounts.cells.toLocaleString('en')} cells`);
  $('counts').textContent = parts.join(' · ');
}

/** Sets a layer on/off (flips it without `on`); returns the new state. */
function toggleLayer(layer: LayerName, on?: boolean): boolean {
  const select = (id: string, value: string) => {
    const s = $(id) as HTMLSelectElement;
    if ([...s.options].some((o) => o.value === value)) s.value = value;
  };
  const firstReal = (id: string) => [...($(id) as HTMLSelectElement).options].find((o) => o.value !== '-1' && o.value !== 'none')?.value;
  let state = false;
  switch (layer) {
    case 'contacts':
      state = on ?? !contactsBox.checked;
      contactsBox.checked = state;
      view.setContactsVisible(state);
      break;
    case 'xray':
      state = on ?? !xrayBox.checked;
      xrayBox.checked = state;
      view.setXray(state);
      break;
    case 'halfspaces':
      state = on ?? !halfspacesBox.checked;
      halfspacesBox.checked = state;
      if (state && overlay.cells === 'none') select('cells', 'all');
      break;
    case 'spheres':
    case 'cfm':
    case 'cells': {
      const id = layer;
      const off = layer === 'cells' ? 'none' : '-1';
      state = on ?? ($(id) as HTMLSelectElement).value === off;
      select(id, state ? (layer === 'cells' ? 'all' : firstReal(id) ?? off) : off);
      state = ($(id) as HTMLSelectElement).value !== off;
      break;
    }
  }
  if (layer !== 'contacts' && layer !== 'xray') readOverlayControls();
  updateReadouts();
  return state;
}

function fillSelect(id: string, options: [string, string][], rowId: string): void {
  const s = $(id) as HTMLSelectElement;
  s.replaceChildren(...options.map(([value, label]) => new Option(label, value)));
  $(rowId).hidden = options.length <= 1;
}

/** Shows only the controls for layers the folder has. */
function setUpControls(folder: OutputFolder): void {
  const bodies = view.bodies;
  const withLayers = bodies.filter((b) => b.layers && (b.layers.sphere_tree || b.layers.cfm_samples || b.layers.contact_tree));
  fillSelect('body', [['-1', 'all bodies'], ...withLayers.map((b): [string, string] => [String(b.index), b.name])], 'body-row');
  let levels = 0;
  const cfmLevels = new Set<number>();
  let maxDepth = -1;
  for (const b of bodies) {
    levels = Math.max(levels, b.layers?.sphere_tree?.levels.length ?? 0);
    for (const s of b.layers?.cfm_samples ?? []) cfmLevels.add(s.level);
    const cells = b.layers?.contact_tree?.cells ?? [];
    for (let i = 4; i < cells.length; i += 5) maxDepth = Math.max(maxDepth, cells[i]);
  }
  fillSelect('spheres', [['-1', 'none'], ...Array.from({ length: levels }, (_, l): [string, string] => [String(l), `level ${l}`])], 'spheres-row');
  fillSelect('cfm', [['-1', 'none'], ...[...cfmLevels].sort((a, b) => a - b).map((l): [string, string] => [String(l), `level ${l}`])], 'cfm-row');
  fillSelect('cells', maxDepth < 0 ? [['none', 'none']] : [['none', 'none'], ['all', 'all depths'],
    ...Array.from({ length: maxDepth + 1 }, (_, d): [string, string] => [String(d), `depth ${d}`])], 'cells-row');
  $('halfspaces-row').hidden = !bodies.some((b) => b.layers?.contact_tree?.halfspaces);
  $('contacts-row').hidden = !view.hasContacts;
  $('playback').hidden = view.frameCount < 2;
  contactsBox.checked = false;
  view.setContactsVisible(false);
  halfspacesBox.checked = false;
  readOverlayControls();
  scrub.max = String(view.frameCount - 1);
  const hasChart = chart.setData(folder.layers);
  ($('chart') as HTMLCanvasElement).hidden = !hasChart;
  view.resize();
  const plural = (n: number, one: string, many: string) => `${n} ${n === 1 ? one : many}`;
  $('info').textContent = `${folder.label} · ${plural(bodies.length, 'body', 'bodies')} · ${plural(view.frameCount, 'frame', 'frames')}` +
    (view.frameCount > 1 ? ` · ${view.duration.toFixed(2)} s` : '');
}

function updateReadouts(): void {
  scrub.value = String(view.currentFrame);
  $('time').textContent = `t = ${view.currentTime.toFixed(3)} s · frame ${view.currentFrame + 1}/${view.frameCount}`;
  $('contacts-count').textContent = view.hasContacts ? `(${hook.contactsInFrame(view.currentFrame)} in this frame)` : '';
  chart.setCursor(view.currentTime);
}

// ---- loading ----------------------------------------------------------------------------------
async function show(folder: OutputFolder): Promise<void> {
  pause();
  await view.load(folder);
  hook.bodyCount = view.bodies.length;
  hook.frameCount = view.frameCount;
  setUpControls(folder);
  updateReadouts();
  $('picker').hidden = true;
  document.title = `clod viewer · ${folder.label}`;
  view.render(true);
}

function showPicker(reason: string, error = ''): void {
  $('picker').hidden = false;
  $('picker-reason').textContent = reason;
  $('picker-error').textContent = error;
}

async function loadFiles(files: File[]): Promise<void> {
  try {
    await show(await readFiles(files));
    resolveReady();
  } catch (e) {
    showPicker('', (e as Error).message);
  }
}

for (const id of ['folder-input', 'files-input']) {
  const input = $(id) as HTMLInputElement;
  input.addEventListener('change', () => input.files && loadFiles(Array.from(input.files)));
}
$('open').addEventListener('click', () => showPicker('Open another output folder.'));
$('picker').addEventListener('click', (e) => {
  if (e.target === $('picker') && hook.bodyCount > 0) $('picker').hidden = true;
});
window.addEventListener('dragover', (e) => {
  e.preventDefault();
  $('picker').hidden = false;
  $('picker').classList.add('drag');
});
window.addEventListener('dragleave', () => $('picker').classList.remove('drag'));
window.addEventListener('drop', async (e) => {
  e.preventDefault();
  $('picker').classList.remove('drag');
  if (e.dataTransfer) await loadFiles(await filesFromDrop(e.dataTransfer));
});

async function start(): Promise<void> {
  const param = new URLSearchParams(location.search).get('data');
  if (location.protocol === 'file:' && !param) {
    showPicker('This page was opened from a file, where it may not read neighbouring files by itself.');
    return;
  }
  let base = param ?? './data/';
  if (!base.endsWith('/')) base += '/';
  try {
    await show({ ...(await fetchFolder(new URL(base, location.href).href)), label: base.replace(/^\.\//, '') });
    resolveReady();
  } catch (e) {
    hook.error = (e as Error).message;
    showPicker(`Could not load ${base}.`, hook.error);
    rejectReady(e as Error);
  }
}

// ---- render loop ------------------------------------------------------------------------------
function tick(now: number): void {
  if (playing) {
    const dt = Math.min(0.1, (now - lastTick) / 1000);
    const t = view.currentTime + dt * speed;
    if (t >= view.times[view.times.length - 1]) {
      view.setTime(view.times[view.times.length - 1]);
      pause();
    } else {
      view.setTime(t);
    }
    updateReadouts();
  }
  lastTick = now;
  view.render();
  requestAnimationFrame(tick);
}
requestAnimationFrame(tick);
void start();
