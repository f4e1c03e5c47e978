// End-to-end test of the viewer in Debian's headless Chromium (playwright-core, never a
// downloaded browser). It loads a served output folder and checks, against the folder's own
// files read here independently of the page:
//   - the scene has as many bodies as summary.json, with the same names, in order;
//   - stepping the animation moves the dynamic bodies and leaves static ones in place, and
//     the last frame matches summary.json's final positions (when the last frame is the end);
//   - the contact layer is empty when off and shows exactly layers.json's contacts of a frame when on;
//   - the sphere-tree, CFM and contact-tree layers show as many items as layers.json holds;
//   - a screenshot has pixels drawn where the bodies project and background elsewhere;
//   - with --page-file: the built page opened from file:// offers the picker and loads the
//     folder's files chosen there.
//
//   node e2e/viewer.e2e.mjs --url http://127.0.0.1:PORT/ --out OUTDIR [--screenshot FILE.png]
//                           [--page-file viewer/dist/index.html]
// Exits 0 when every check passes, 1 otherwise (each failure is printed).
import fs from 'node:fs';
import path from 'node:path';
import { chromium } from 'playwright-core';

const argv = process.argv.slice(2);
const arg = (name, fallback) => {
  const i = argv.indexOf(name);
  return i >= 0 && i + 1 < argv.length ? argv[i + 1] : fallback;
};
const url = arg('--url');
const outDir = arg('--out');
const screenshotPath = arg('--screenshot', path.join(outDir ?? '.', 'viewer-e2e.png'));
const pageFile = arg('--page-file');
const chromiumPath = process.env.CHROMIUM_PATH || '/usr/bin/chromium';
if (!url || !outDir) {
  console.error('usage: node e2e/viewer.e2e.mjs --url URL --out OUTDIR [--screenshot FILE.png]');
  process.exit(2);
}

// A hung browser must not hang CI.
const watchdog = setTimeout(() => {
  console.error('viewer e2e: FAILED: timed out after 120 s');
  process.exit(1);
}, 120_000);

const failures = [];
const check = (ok, what) => {
  console.log(`${ok ? 'ok  ' : 'FAIL'} ${what}`);
  if (!ok) failures.push(what);
};

const summary = JSON.parse(fs.readFileSync(path.join(outDir, 'summary.json'), 'utf8'));
const layersPath = path.join(outDir, 'layers.json');
const layers = fs.existsSync(layersPath) ? JSON.parse(fs.readFileSync(layersPath, 'utf8')) : null;

// The glTF's own JSON chunk (header 12 bytes, then chunk length, type "JSON", data): which
// nodes are bodies, which are static, and the animation's channels.
function readGlbJson(file) {
  const b = fs.readFileSync(file);
  if (b.readUInt32LE(0) !== 0x46546c67 || b.readUInt32LE(16) !== 0x4e4f534a) throw new Error(`${file}: not a binary glTF`);
  return JSON.parse(b.subarray(20, 20 + b.readUInt32LE(12)).toString('utf8'));
}
const gltf = readGlbJson(path.join(outDir, 'scene.glb'));
const bodyNodes = (gltf.nodes ?? []).filter((n) => typeof n.extras?.body === 'number').sort((a, b) => a.extras.body - b.extras.body);
const staticByBody = bodyNodes.map((n) => n.extras.static === true);

const browser = await chromium.launch({
  executablePath: chromiumPath,
  headless: true,
  // Root in a VM: no sandbox. No GPU: WebGL through ANGLE's SwiftShader (software) backend.
  args: ['--no-sandbox', '--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--ignore-gpu-blocklist'],
  timeout: 30_000,
});
try {
  const page = await browser.newPage({ viewport: { width: 1280, height: 760 }, deviceScaleFactor: 1 });
  const pageErrors = [];
  page.on('pageerror', (e) => pageErrors.push(String(e)));
  page.on('console', (m) => m.type() === 'error' && pageErrors.push(m.text()));
  await page.goto(url, { waitUntil: 'load', timeout: 30_000 });
  await page.waitForFunction(() => window.__clod !== undefined, null, { timeout: 15_000 });
  const loadError = await page.evaluate(() => window.__clod.ready.then(() => null, (e) => String(e)));
  check(loadError === null, `the page loads the folder (${loadError ?? 'ready'})`);
  if (loadError !== null) throw new Error(loadError);

  // Bodies: count and names from summary.json.
  const hook = await page.evaluate(() => ({ bodyCount: window.__clod.bodyCount, frameCount: window.__clod.frameCount, names: window.__clod.bodyNames() }));
  const expectedNames = summary.bodies.map((b) => b.name);
  check(hook.bodyCount === expectedNames.length, `scene has ${hook.bodyCount} bodies, summary.json ${expectedNames.length}`);
  check(JSON.stringify(hook.names) === JSON.stringify(expectedNames), `body names ${JSON.stringify(hook.names)} match summary.json`);
  check(hook.frameCount >= 2, `the animation has ${hook.frameCount} frames`);
  if (layers?.frames) check(hook.frameCount === layers.frames.time.length, `frame count matches layers.json (${layers.frames.time.length})`);

  // Stepping moves bodies. Motion scale: the largest distance any body travels; a dynamic body
  // that falls under gravity moves far more than float32 storage noise (~1e-7 relative).
  const last = hook.frameCount - 1;
  const posAt = (f) => page.evaluate((i) => (window.__clod.setFrame(i), window.__clod.bodyPositions()), f);
  const p0 = await posAt(0), p1 = await posAt(Math.floor(last / 2)), pL = await posAt(last);
  const dist = (a, b) => Math.hypot(a[0] - b[0], a[1] - b[1], a[2] - b[2]);
  const moved = p0.map((p, i) => Math.max(dist(p, p1[i]), dist(p, pL[i])));
  check(moved.some((d) => d > 1e-3), `stepping the animation moves a body (max ${Math.max(...moved).toExponential(2)} m)`);
  check(bodyNodes.length === expectedNames.length, `scene.glb has ${bodyNodes.length} body nodes (extras.body)`);
  staticByBody.forEach((isStatic, i) => isStatic && check(moved[i] === 0, `static body '${expectedNames[i]}' stays put`));
  staticByBody.forEach((isStatic, i) => !isStatic && check(moved[i] > 0, `dynamic body '${expectedNames[i]}' moves`));

  // Play: the frame advances on its own.
  const startFrame = await page.evaluate(() => (window.__clod.setFrame(0), window.__clod.frame()));
  await page.click('#play');
  await page.waitForTimeout(800);
  const playedTo = await page.evaluate(() => window.__clod.frame());
  await page.click('#play');
  check(playedTo > startFrame, `the play button advances the animation (frame ${startFrame} -> ${playedTo})`);
  // The last frame is the final state when frames run to steps*dt; compare with summary.json.
  const endTime = summary.steps * summary.dt;
  const lastTime = layers?.frames?.time?.[last];
  if (Number.isFinite(endTime) && lastTime !== undefined && Math.abs(lastTime - endTime) < 1e-6) {
    // Tolerance: float32 keyframes (rel. 6e-8) over positions of a few metres, plus JSON rounding.
    const scale = Math.max(1, ...summary.bodies.flatMap((b) => b.position.map(Math.abs)));
    const err = Math.max(...summary.bodies.map((b, i) => dist(b.position, pL[i])));
    check(err <= 1e-5 * scale, `last frame matches summary.json's final positions (error ${err.toExponential(2)} m)`);
  } else {
    console.log('skip final-position check: the last frame is not at steps*dt');
  }

  // Contacts: the frame with most contacts, per layers.json (read here, not from the page).
  if (layers?.contacts) {
    const off = layers.contacts.frame_offsets;
    let best = 0;
    for (let f = 0; f + 1 < off.length; ++f) if (off[f + 1] - off[f] > off[best + 1] - off[best]) best = f;
    const expected = off[best + 1] - off[best];
    check(expected > 0, `layers.json has contacts (frame ${best}: ${expected})`);
    const before = await page.evaluate((f) => (window.__clod.setFrame(f), window.__clod.toggle('contacts', false), window.__clod.shownContacts()), best);
    check(before === 0, `no contacts shown while the layer is off (${before})`);
    const after = await page.evaluate(() => (window.__clod.toggle('contacts', true), window.__clod.shownContacts()));
    check(after === expected, `toggling the contact layer shows frame ${best}'s ${expected} contacts (${after})`);
  } else {
    check(false, 'layers.json has a contacts layer');
  }

  // Body-local layers: counts from layers.json.
  const bodiesL = layers?.bodies ?? [];
  const sum = (f) => bodiesL.reduce((acc, b) => acc + f(b), 0);
  const spheres0 = sum((b) => (b.sphere_tree?.levels?.[0]?.length ?? 0) / 4);
  const minCfmLevel = Math.min(...bodiesL.flatMap((b) => (b.cfm_samples ?? []).map((s) => s.level)));
  const samples = sum((b) => (b.cfm_samples ?? []).filter((s) => s.level === minCfmLevel).reduce((a, s) => a + s.points.length / 3, 0));
  const cells = sum((b) => (b.contact_tree?.cells?.length ?? 0) / 5);
  for (const [layer, key, expected] of [['spheres', 'spheres', spheres0], ['cfm', 'samples', samples], ['cells', 'cells', cells]]) {
    if (!expected) {
      console.log(`skip ${layer}: layers.json has none`);
      continue;
    }
    const shown = await page.evaluate(([l, k]) => (window.__clod.toggle(l, true), window.__clod.shownCounts()[k]), [layer, key]);
    await page.evaluate((l) => window.__clod.toggle(l, false), layer);
    check(shown === expected, `the ${layer} layer shows ${expected} items (${shown})`);
  }

  // Screenshot mid-animation with contacts on; pixels must be drawn where the bodies project.
  const shotFrame = await page.evaluate(() => {
    const h = window.__clod;
    let best = Math.floor(h.frameCount / 2);
    for (let f = 0; f < h.frameCount; ++f) if (h.contactsInFrame(f) > 0) { best = f; break; }
    best = Math.min(h.frameCount - 1, best + Math.floor((h.frameCount - best) / 4));
    h.setFrame(best);
    h.toggle('contacts', true);
    return best;
  });
  await page.waitForTimeout(300); // let the compositor present the last render
  const png = await page.screenshot({ path: screenshotPath, type: 'png' });
  const pixelCheck = await page.evaluate(async (b64) => {
    const img = new Image();
    img.src = `data:image/png;base64,${b64}`;
    await img.decode();
    const c = document.createElement('canvas');
    c.width = img.width;
    c.height = img.height;
    const ctx = c.getContext('2d', { willReadFrequently: true });
    ctx.drawImage(img, 0, 0);
    const bg = window.__clod.background;
    const differs = (x, y) => {
      const d = ctx.getImageData(Math.round(x), Math.round(y), 1, 1).data;
      return Math.max(Math.abs(d[0] - bg[0]), Math.abs(d[1] - bg[1]), Math.abs(d[2] - bg[2])) > 16;
    };
    const perBody = window.__clod.bodyScreenPoints(32).map((b) => ({
      name: b.name, total: b.points.length, drawn: b.points.filter(([x, y]) => differs(x, y)).length,
    }));
    // Background share of the 3D view, on a coarse grid.
    const r = document.querySelector('#view canvas').getBoundingClientRect();
    let bgCount = 0, total = 0;
    for (let y = r.top + 2; y < r.bottom - 2; y += 8)
      for (let x = r.left + 2; x < r.right - 2; x += 8, ++total) if (!differs(x, y)) ++bgCount;
    return { perBody, backgroundShare: bgCount / Math.max(1, total) };
  }, png.toString('base64'));
  for (const b of pixelCheck.perBody)
    check(b.total > 0 && b.drawn >= 0.8 * b.total, `screenshot (frame ${shotFrame}) has pixels drawn where '${b.name}' projects (${b.drawn}/${b.total})`);
  check(pixelCheck.backgroundShare > 0.01 && pixelCheck.backgroundShare < 0.99,
    `screenshot shows both background and scene (background ${(100 * pixelCheck.backgroundShare).toFixed(1)} %)`);
  check(pageErrors.length === 0, `no errors in the page${pageErrors.length ? ': ' + pageErrors.join(' | ') : ''}`);
  console.log(`screenshot: ${screenshotPath}`);

  if (pageFile) {
    // Offline mode: file:// cannot fetch neighbours, so the page must offer the picker.
    const offline = await browser.newPage({ viewport: { width: 1024, height: 640 } });
    const offlineErrors = [];
    offline.on('pageerror', (e) => offlineErrors.push(String(e)));
    await offline.goto(`file://${path.resolve(pageFile)}`, { waitUntil: 'load', timeout: 30_000 });
    await offline.waitForFunction(() => window.__clod !== undefined, null, { timeout: 15_000 });
    check(await offline.isVisible('#picker'), 'the page opened from file:// shows the folder picker');
    const files = ['scene.glb', 'layers.json', 'summary.json'].map((f) => path.join(outDir, f)).filter((f) => fs.existsSync(f));
    await offline.setInputFiles('#files-input', files);
    const offlineLoad = await offline.evaluate(() =>
      Promise.race([window.__clod.ready.then(() => null, (e) => String(e)), new Promise((r) => setTimeout(() => r('timeout'), 30_000))]));
    const offlineBodies = await offline.evaluate(() => window.__clod.bodyCount);
    check(offlineLoad === null && offlineBodies === expectedNames.length,
      `from file://, picking the folder's files loads ${offlineBodies} bodies (${offlineLoad ?? 'ready'})`);
    check(offlineErrors.length === 0, `no errors in the file:// page${offlineErrors.length ? ': ' + offlineErrors.join(' | ') : ''}`);
  }
} catch (e) {
  failures.push(String(e));
  console.error(`viewer e2e: ${e}`);
} finally {
  await browser.close();
  clearTimeout(watchdog);
}
if (failures.length) {
  console.error(`viewer e2e: FAILED (${failures.length} check${failures.length > 1 ? 's' : ''})`);
  process.exit(1);
}
console.log('viewer e2e: all checks passed');
