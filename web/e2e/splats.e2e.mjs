// @ts-check
// End-to-end: the splat renderer and the splat worker in headless Chromium
// (WebGL2 on SwiftShader), on a static server: a point stream of two
// intersecting spheres (web/test/fixtures/two-spheres.vpts, written by
// codec/points/examples/splat_fixture.rs, like cube.vpts and l-block.vpts)
// level by level, a truncated one, a jittered cube and an L-shaped block
// with clipping on and off against their ray-cast silhouettes, a generated
// torus mesh as splats against its rasterized silhouette. The
// frame time of 1 M splats is a benchmark: bench/splat-frame.mjs.
import { after, before, test } from 'node:test';
import assert from 'node:assert/strict';
import { existsSync, readFileSync } from 'node:fs';
import { createServer } from 'node:http';
import { join } from 'node:path';
import { build } from 'esbuild';
import { launch } from '../test/support/browser.mjs';
import { fixture, fixturesDir, root } from '../test/support/fixtures.mjs';
import { splitStream } from '../src/codec.js';
import { foreground, rasterize } from '../test/support/raster.mjs';
import { boxMesh, castBoxes, silhouetteError } from '../test/support/solids.mjs';
import { vertexNormals } from '../src/geometry.js';
import { splitLevels } from '../src/splats/point-stream.js';

/** @typedef {import('playwright-core').Page} Page */

const WIDTH = 480;
const HEIGHT = 360;
const dist = join(root, 'web', 'dist');

/** @type {import('node:http').Server} */
let server;
let base = '';
/** @type {Awaited<ReturnType<typeof launch>>} */
let browser;

/** Level payloads by stream name: level 0 = header + first chunk, then one chunk each. */
const streams = new Map();
/** @type {Map<string, { payloads: Uint8Array[], levels: import('../test/support/fixtures.mjs').FixtureLevel[] }>} */
const meshes = new Map();

/** Two intersecting spheres, centres ±0.35 on x, radius 0.6. */
const SPHERES_BOX = { min: [-0.95, -0.6, -0.6], max: [0.95, 0.6, 0.6] };

before(async () => {
  if (!existsSync(join(dist, 'splat-worker.js'))) throw new Error('build the viewer first: npm run build');
  const harness = await build({
    entryPoints: [join(root, 'web', 'e2e', 'splats-harness.js')],
    bundle: true,
    format: 'esm',
    write: false,
    logLevel: 'warning',
  });
  const script = harness.outputFiles[0].text;
  const levels = splitLevels(new Uint8Array(readFileSync(join(fixturesDir, 'two-spheres.vpts'))));
  streams.set('spheres', levels);
  streams.set('cube', splitLevels(new Uint8Array(readFileSync(join(fixturesDir, 'cube.vpts')))));
  streams.set('lblock', splitLevels(new Uint8Array(readFileSync(join(fixturesDir, 'l-block.vpts')))));
  // Level 1 cut short: the decoder refuses it.
  streams.set('truncated', [levels[0], levels[1].subarray(0, levels[1].length >> 1), levels[2], levels[3]]);
  // A mesh model from a committed stream (the Rust encoder's), base then batches.
  const torus = fixture('torus');
  const { base: torusBase, batches } = splitStream(torus.stream);
  meshes.set('torus', { payloads: [torusBase, ...batches], levels: torus.levels });
  server = createServer((req, res) => {
    const path = new URL(req.url ?? '/', 'http://x').pathname;
    const level = /^\/levels\/(\w+)\/(\d+)$/.exec(path);
    if (path === '/favicon.ico') {
      res.writeHead(204);
      res.end();
    } else if (path === '/') {
      res.writeHead(200, { 'content-type': 'text/html' });
      res.end(`<!doctype html><body style="margin:0"><div id="root" style="position:relative;width:${WIDTH}px;height:${HEIGHT}px"></div><script type="module" src="/harness.js"></script></body>`);
    } else if (path.startsWith('/viewer/')) {
      // The viewer element on a page of its own, as another site embeds it.
      res.writeHead(200, { 'content-type': 'text/html' });
      res.end(`<!doctype html><body style="margin:0"><script type="module" src="/dist/vitrine.js"></script><vitrine-viewer src="/api/models/${path.slice(8)}" style="display:block;width:${WIDTH}px;height:${HEIGHT}px"></vitrine-viewer></body>`);
    } else if (path.startsWith('/api/models/') && streams.has(path.slice(12))) {
      res.writeHead(200, { 'content-type': 'application/json' });
      res.end(JSON.stringify(pointManifest(path.slice(12))));
    } else if (path === '/harness.js') {
      res.writeHead(200, { 'content-type': 'text/javascript' });
      res.end(script);
    } else if (path.startsWith('/api/models/') && meshes.has(path.slice(12))) {
      res.writeHead(200, { 'content-type': 'application/json' });
      res.end(JSON.stringify(meshManifest(path.slice(12))));
    } else if (level && streams.get(level[1])?.[Number(level[2])]) {
      res.writeHead(200, { 'content-type': 'application/octet-stream' });
      res.end(streams.get(level[1])[Number(level[2])]);
    } else if (level && meshes.get(level[1])?.payloads[Number(level[2])]) {
      res.writeHead(200, { 'content-type': 'application/octet-stream' });
      res.end(meshes.get(level[1])?.payloads[Number(level[2])]);
    } else if (path.startsWith('/dist/') && existsSync(join(dist, path.slice(6)))) {
      const type = path.endsWith('.wasm') ? 'application/wasm' : path.endsWith('.js') ? 'text/javascript' : 'application/octet-stream';
      res.writeHead(200, { 'content-type': type });
      res.end(readFileSync(join(dist, path.slice(6))));
    } else {
      res.writeHead(404);
      res.end();
    }
  });
  await new Promise((resolve) => server.listen(0, '127.0.0.1', () => resolve(null)));
  const address = /** @type {import('node:net').AddressInfo} */ (server.address());
  base = `http://127.0.0.1:${address.port}`;
  browser = await launch({ width: WIDTH, height: HEIGHT });
});

after(async () => {
  await browser?.close();
  await new Promise((resolve) => server?.close(resolve));
});

async function open() {
  const page = await browser.context.newPage();
  /** @type {string[]} */
  const problems = [];
  page.on('pageerror', (e) => problems.push(e.message));
  page.on('console', (m) => m.type() === 'error' && problems.push(m.text()));
  await page.goto(`${base}/`);
  await page.waitForFunction(() => 'harness' in window);
  return { page, problems };
}

/**
 * @param {Page} page
 * @param {Partial<import('../src/splats/splat-renderer.js').SplatOptions>} options
 */
async function capture(page, options) {
  const c = await page.evaluate((o) => /** @type {any} */ (window).harness.capture(o), options);
  return { ...c, rgba: new Uint8Array(Buffer.from(c.data, 'base64')) };
}

/** Pixels where red and blue both show (a blend), far above green. @param {Uint8Array} rgba */
function purple(rgba) {
  let n = 0;
  for (let p = 0; p < rgba.length; p += 4) {
    const [r, g, b] = [rgba[p], rgba[p + 1], rgba[p + 2]];
    if (Math.min(r, b) - g > 40) n++;
  }
  return n;
}

/**
 * A manifest as the server describes a point-cloud model (kind `points`,
 * level k's URL serving its chunk), written here: the server side is
 * another engineer's, not yet on this branch.
 * @param {string} name
 */
function pointManifest(name) {
  const levels = streams.get(name);
  const counts = [3169, 10088, 22446, 24000];
  return {
    slug: name,
    kind: 'points',
    title: 'Two spheres',
    description: 'Red and blue, intersecting.',
    has_colour: true,
    last_level: levels.length - 1,
    levels: levels.map((/** @type {Uint8Array} */ b, /** @type {number} */ k) => ({
      level: k, vertices: counts[k], faces: 0, bytes: b.length, url: `/levels/${name}/${k}`, allowed: true,
    })),
    colour: { mode: 'vertex' },
    visitor: { device: 'desktop', audience: 'public' },
    cap: { level: levels.length - 1, reason: null, retry_after_s: null },
    up: 'y',
    bounds: SPHERES_BOX,
  };
}

/**
 * A mesh model's manifest, as the server writes one.
 * @param {string} name
 */
function meshManifest(name) {
  const { payloads, levels } = /** @type {{ payloads: Uint8Array[], levels: any[] }} */ (meshes.get(name));
  return {
    slug: name,
    title: 'Torus',
    description: 'A generated torus.',
    has_colour: false,
    last_level: levels.length - 1,
    levels: levels.map((l, k) => ({ level: k, vertices: l.vertices, faces: l.faces, bytes: payloads[k].length, url: `/levels/${name}/${k}`, allowed: true })),
    colour: { mode: 'none' },
    visitor: { device: 'desktop', audience: 'public' },
    cap: { level: levels.length - 1, reason: null, retry_after_s: null },
  };
}

/** @param {Uint8Array} mask */
const count = (mask) => mask.reduce((s, v) => s + v, 0);

test('two intersecting spheres as splats: refined level by level, no blended pixel with surface ids, some without', async () => {
  const { page, problems } = await open();
  const levels = streams.get('spheres');
  const messages = await page.evaluate(
    ({ b, box }) => /** @type {any} */ (window).harness.points(`${b}/levels/spheres/0`, [1, 2, 3].map((k) => `${b}/levels/spheres/${k}`), box),
    { b: base, box: SPHERES_BOX },
  );
  assert.equal(levels.length, 4);
  const splats = messages.filter((/** @type {any} */ m) => m.type === 'splats');
  assert.deepEqual(splats.map((/** @type {any} */ m) => m.level), [0, 1, 2, 3], JSON.stringify(messages));
  assert.ok(splats.every((/** @type {any} */ m, /** @type {number} */ i) => i === 0 || m.count > splats[i - 1].count), 'each level adds points');
  assert.equal(splats[3].count, 24000);
  assert.equal(messages.at(-1).type, 'done');

  const ids = await capture(page, { surfaceIds: true, clipping: true });
  const shown = count(foreground(ids.rgba));
  assert.ok(shown > 0.1 * WIDTH * HEIGHT, `the spheres cover the view (${shown} pixels)`);
  const blendedWith = purple(ids.rgba);
  const plain = await capture(page, { surfaceIds: false, clipping: false });
  const blendedWithout = purple(plain.rgba);
  console.log(`# spheres: ${shown} foreground pixels; blended (purple) pixels: ${blendedWith} with surface ids, ${blendedWithout} without`);
  assert.equal(blendedWith, 0, 'no blended pixel with surface ids');
  assert.ok(blendedWithout > 0, 'plain splatting blends the two spheres where they cross');
  assert.deepEqual(problems, []);
  await page.close();
});

/** The cube fixture, [−0.5, 0.5]³. @type {import('../test/support/solids.mjs').Box} */
const CUBE = { min: [-0.5, -0.5, -0.5], max: [0.5, 0.5, 0.5] };
/**
 * The L-block fixture (codec/points/src/testing.rs, `l_block_faces`) as two
 * boxes: its concave crease along x = y = 0, its inner corners at
 * (0, 0, ±0.5). @type {import('../test/support/solids.mjs').Box[]}
 */
const L_BLOCK = [
  { min: [-1, -1, -0.5], max: [1, 0, 0.5] },
  { min: [-1, 0, -0.5], max: [0, 1, 0.5] },
];

/**
 * Loads a point stream's every level into the harness.
 * @param {Page} page @param {string} name @param {import('../src/geometry.js').Bounds} box
 */
async function loadPoints(page, name, box) {
  const levels = streams.get(name);
  const messages = await page.evaluate(
    ({ b, n, k, box }) => /** @type {any} */ (window).harness.points(`${b}/levels/${n}/0`, Array.from({ length: k - 1 }, (_, i) => `${b}/levels/${n}/${i + 1}`), box),
    { b: base, n: name, k: levels.length, box },
  );
  assert.equal(messages.at(-1).type, 'done', JSON.stringify(messages));
}

/**
 * Silhouette error and holes, summed over `views`, with clipping on and
 * off and surface ids on in both, against the boxes' ray-cast truth.
 * @param {Page} page
 * @param {import('../test/support/solids.mjs').Box[]} boxes
 * @param {Partial<import('../src/camera.js').OrbitState>[]} views
 */
async function clippingOnAndOff(page, boxes, views) {
  const sum = { on: { error: 0, holes: 0, inside: 0 }, off: { error: 0, holes: 0, inside: 0 } };
  for (const view of views) {
    await page.evaluate((v) => /** @type {any} */ (window).harness.orbit(v), view);
    for (const clipping of [true, false]) {
      const c = await capture(page, { surfaceIds: true, clipping });
      const truth = castBoxes(c, boxes);
      const e = silhouetteError(foreground(c.rgba), truth, c.width);
      const into = clipping ? sum.on : sum.off;
      into.error += e.error;
      into.holes += e.holes;
      into.inside += e.inside;
    }
  }
  return sum;
}

test('a jittered cube as splats, surface ids on: clipping halves the silhouette error at the edges, no hole on the faces', async () => {
  const { page, problems } = await open();
  await loadPoints(page, 'cube', CUBE);
  // Views from every side, none along an axis: each shows three faces,
  // their edges and a corner.
  const views = [
    { yaw: 0.5, pitch: 0.4 },
    { yaw: 2.3, pitch: -0.5 },
    { yaw: -1.0, pitch: 0.7 },
    { yaw: 3.8, pitch: 0.25 },
  ];
  const { on, off } = await clippingOnAndOff(page, [CUBE], views);
  const less = 1 - on.error / off.error;
  console.log(`# cube, ${views.length} views: silhouette error ${on.error} px clipped, ${off.error} px unclipped (${(100 * less).toFixed(1)} % less); hole pixels ${on.holes} clipped, ${off.holes} unclipped, of ${on.inside} inside`);
  assert.ok(off.error > 500, `unclipped splats barely stick out (${off.error} px)`);
  assert.ok(on.error * 2 <= off.error, `clipping removes too little: ${on.error} against ${off.error}`);
  assert.equal(on.holes, 0, 'pixels of the faces no clipped splat covers');
  assert.deepEqual(problems, []);
  await page.close();
});

// What is measured: hole pixels (with clipping: 0, the concave crease and
// the inner corners included, also in close-ups of the corners) and the
// silhouette error with clipping against without (at least halved; the
// block's outline is its convex edges). The corner split drops 3 splats
// at the inner corners from clipping; with this sample the images show no
// hole without the split either (its neighbours cover the bare spots),
// which tests/corners.rs in codec/points checks splat by splat.
test('an L-shaped block as splats: its concave crease and inner corners stay covered with clipping, its convex edges cut', async () => {
  const { page, problems } = await open();
  await loadPoints(page, 'lblock', { min: [-1, -1, -0.5], max: [1, 1, 0.5] });
  // Views into the notch (x > 0, y > 0), from above the top inner corner
  // (z > 0: cos yaw > 0) and below the bottom one (z < 0).
  const views = [
    { yaw: 0.7, pitch: 0.5 },
    { yaw: 0.4, pitch: 0.9 },
    { yaw: 1.1, pitch: 0.3 },
    { yaw: 2.4, pitch: 0.6 },
  ];
  const { on, off } = await clippingOnAndOff(page, L_BLOCK, views);
  const less = 1 - on.error / off.error;
  console.log(`# L-block, ${views.length} views into the notch: silhouette error ${on.error} px clipped, ${off.error} px unclipped (${(100 * less).toFixed(1)} % less); hole pixels ${on.holes} clipped, ${off.holes} unclipped, of ${on.inside} inside`);
  // Close-ups of the inner corners, where a splat's partners lie on a
  // convex edge and the concave crease at once.
  const closeUps = [
    { target: /** @type {[number, number, number]} */ ([0, 0, 0.5]), distance: 0.3, yaw: 0.7, pitch: 0.5 },
    { target: /** @type {[number, number, number]} */ ([0, 0, 0.5]), distance: 0.3, yaw: 0.5, pitch: 0.8 },
    { target: /** @type {[number, number, number]} */ ([0, 0, -0.5]), distance: 0.3, yaw: 2.4, pitch: 0.6 },
  ];
  const corner = await clippingOnAndOff(page, L_BLOCK, closeUps);
  console.log(`# L-block, ${closeUps.length} close-ups of the inner corners: hole pixels ${corner.on.holes} clipped, ${corner.off.holes} unclipped, of ${corner.on.inside} inside`);
  assert.equal(on.holes, 0, 'pixels of the faces, crease included, no clipped splat covers');
  assert.equal(corner.on.holes, 0, 'pixels at the inner corners no clipped splat covers');
  assert.ok(on.error * 2 <= off.error, `clipping removes too little: ${on.error} against ${off.error}`);
  assert.deepEqual(problems, []);
  await page.close();
});

test('a truncated point stream is a decode error at its level, not a hang', async () => {
  const { page } = await open();
  const messages = await page.evaluate(
    ({ b, box }) => /** @type {any} */ (window).harness.points(`${b}/levels/truncated/0`, [1, 2, 3].map((k) => `${b}/levels/truncated/${k}`), box),
    { b: base, box: SPHERES_BOX },
  );
  const last = messages.at(-1);
  assert.equal(last.type, 'error', JSON.stringify(messages));
  assert.equal(last.level, 1);
  assert.match(last.message, /truncated|corrupt/i);
  assert.deepEqual(messages.filter((/** @type {any} */ m) => m.type === 'splats').map((/** @type {any} */ m) => m.level), [0]);
  await page.close();
});

/** A torus (R = 1, r = 0.35) as a triangle mesh. */
function torus(segments = 96, rings = 40) {
  const positions = [];
  const indices = [];
  for (let i = 0; i < segments; i++) {
    const u = (2 * Math.PI * i) / segments;
    for (let j = 0; j < rings; j++) {
      const v = (2 * Math.PI * j) / rings;
      const w = 1 + 0.35 * Math.cos(v);
      positions.push(w * Math.cos(u), 0.35 * Math.sin(v), w * Math.sin(u));
      const a = i * rings + j;
      const b = ((i + 1) % segments) * rings + j;
      const c = ((i + 1) % segments) * rings + ((j + 1) % rings);
      const d = i * rings + ((j + 1) % rings);
      indices.push(a, d, b, b, d, c);
    }
  }
  return { positions, indices };
}

test("a mesh level's splat view renders, its silhouette close to the mesh's", async () => {
  const { page, problems } = await open();
  const { positions, indices } = torus();
  const box = { min: [-1.35, -0.35, -1.35], max: [1.35, 0.35, 1.35] };
  await page.evaluate(({ p, i, box }) => /** @type {any} */ (window).harness.mesh(p, i, box, {}), { p: positions, i: indices, box });
  const splats = await capture(page, { surfaceIds: true, clipping: true });
  const p32 = new Float32Array(positions);
  const i32 = new Uint32Array(indices);
  const mesh = rasterize({
    positions: p32,
    normals: vertexNormals(p32, i32),
    colours: null,
    indices: i32,
    view: new Float32Array(splats.view),
    projection: new Float32Array(splats.projection),
    width: splats.width,
    height: splats.height,
  });
  const a = foreground(splats.rgba);
  const b = foreground(mesh);
  let both = 0;
  let either = 0;
  for (let p = 0; p < a.length; p++) {
    both += a[p] & b[p];
    either += a[p] | b[p];
  }
  const iou = both / Math.max(1, either);
  console.log(`# torus: splat silhouette ${count(a)} px, mesh ${count(b)} px, IoU ${iou.toFixed(3)}`);
  assert.ok(count(a) > 0.05 * a.length, 'the splats differ from the background');
  assert.ok(iou > 0.9, `silhouette IoU ${iou}`);
  assert.deepEqual(problems, []);
  await page.close();
});

test("a mesh level with sharp edges as splats keeps its edges: split vertices and crease planes against vertex normals", async () => {
  const { page, problems } = await open();
  // A slab like a sherd: its rims are sharp 90° edges between faces.
  /** @type {import('../test/support/solids.mjs').Box} */
  const slab = { min: [-0.6, -0.15, -0.4], max: [0.6, 0.15, 0.4] };
  const { positions, indices } = boxMesh(slab, 16);
  const views = [
    { yaw: 0.5, pitch: 0.4 },
    { yaw: 2.2, pitch: -0.6 },
    { yaw: -0.9, pitch: 0.9 },
  ];
  /** @param {number} threshold */
  const measure = async (threshold) => {
    await page.evaluate(({ p, i, box, w }) => /** @type {any} */ (window).harness.mesh(p, i, box, {}, w), { p: positions, i: indices, box: slab, w: threshold });
    const sum = { error: 0, holes: 0, inside: 0 };
    for (const view of views) {
      await page.evaluate((v) => /** @type {any} */ (window).harness.orbit(v), view);
      const c = await capture(page, { surfaceIds: true, clipping: true });
      const e = silhouetteError(foreground(c.rgba), castBoxes(c, [slab]), c.width);
      sum.error += e.error;
      sum.holes += e.holes;
      sum.inside += e.inside;
    }
    return sum;
  };
  const features = await measure(0.9);
  // Below −1 no edge is sharp: the splats a mesh level had before (vertex
  // normals averaged across the rims, one surface, nothing clipped).
  const plain = await measure(-2);
  console.log(`# slab mesh (${positions.length / 3} vertices), ${views.length} views: silhouette error ${features.error} px with the seed's features, ${plain.error} px without (${(100 * (1 - features.error / plain.error)).toFixed(1)} % less); hole pixels ${features.holes} and ${plain.holes}, of ${features.inside} inside`);
  assert.ok(features.error * 2 <= plain.error, `the edges stay soft: ${features.error} against ${plain.error}`);
  assert.equal(features.holes, 0, 'pixels of the faces no splat covers');
  assert.deepEqual(problems, []);
  await page.close();
});

/**
 * @param {Page} page
 * @param {string} condition JS expression over `s` (the viewer's state)
 */
async function until(page, condition) {
  await page.waitForFunction(
    (body) => {
      const s = /** @type {any} */ (document.querySelector('vitrine-viewer'))?.viewer?.state;
      return s ? new Function('s', `return (${body});`)(s) : false;
    },
    condition,
    { timeout: 60_000, polling: 50 },
  );
  return page.evaluate(() => /** @type {any} */ (document.querySelector('vitrine-viewer')).viewer.state);
}

test('a point-cloud model in the viewer: first level at once, refined level by level, drawn as splats', async () => {
  const page = await browser.context.newPage();
  /** @type {string[]} */
  const problems = [];
  page.on('pageerror', (e) => problems.push(e.message));
  await page.goto(`${base}/viewer/spheres`);
  const first = await until(page, 's.shownLevel >= 0');
  assert.equal(first.status === 'refining' || first.status === 'complete', true, first.status);
  const state = await until(page, "s.status === 'complete'");
  assert.equal(state.shownLevel, 3);
  assert.equal(state.vertices, 24000);
  assert.deepEqual(Object.keys(state.shownAtMs).map(Number), [0, 1, 2, 3], 'every level was drawn');
  assert.ok(state.firstFrameMs !== null);
  const c = await page.evaluate(() => {
    const { width, height, rgba } = /** @type {any} */ (document.querySelector('vitrine-viewer')).viewer.points.view.capture();
    let binary = '';
    for (let i = 0; i < rgba.length; i += 0x8000) binary += String.fromCharCode(...rgba.subarray(i, i + 0x8000));
    return { width, height, data: btoa(binary) };
  });
  const rgba = new Uint8Array(Buffer.from(c.data, 'base64'));
  const shown = count(foreground(rgba));
  console.log(`# viewer, point model: ${shown} of ${c.width * c.height} pixels show the spheres; ${purple(rgba)} blended`);
  assert.ok(shown > 0.1 * c.width * c.height, `the splats cover the view (${shown} px)`);
  assert.equal(purple(rgba), 0);
  assert.deepEqual(problems, []);
  await page.close();
});

test('a truncated point stream in the viewer shows its error state', async () => {
  const page = await browser.context.newPage();
  await page.goto(`${base}/viewer/truncated`);
  const state = await until(page, "s.status === 'error'");
  assert.equal(state.shownLevel, 0, 'the first level stays on screen');
  assert.match(state.message, /could not decode level 2 of the point stream/);
  const error = await page.evaluate(() => {
    const e = /** @type {HTMLElement} */ (document.querySelector('vitrine-viewer')?.shadowRoot?.querySelector('.error'));
    return { hidden: e.hidden, text: e.innerText };
  });
  assert.equal(error.hidden, false);
  assert.match(error.text, /Could not show this model/);
  await page.close();
});

/** @param {Page} page @param {'renderer' | 'splats'} which */
async function viewerCapture(page, which) {
  const c = await page.evaluate(async (w) => {
    const viewer = /** @type {any} */ (document.querySelector('vitrine-viewer')).viewer;
    const { width, height, rgba } = w === 'renderer' ? await viewer.renderer.capture() : viewer.meshSplats.view.capture();
    let binary = '';
    for (let i = 0; i < rgba.length; i += 0x8000) binary += String.fromCharCode(...rgba.subarray(i, i + 0x8000));
    return { width, height, data: btoa(binary) };
  }, which);
  return { ...c, rgba: new Uint8Array(Buffer.from(c.data, 'base64')) };
}

test("the viewer's Splats view of a mesh model: drawn over the mesh, silhouette close to it; off, the mesh as before", async () => {
  const page = await browser.context.newPage();
  /** @type {string[]} */
  const problems = [];
  page.on('pageerror', (e) => problems.push(e.message));
  await page.goto(`${base}/viewer/torus`);
  const state = await until(page, "s.status === 'complete'");
  const mesh = await viewerCapture(page, 'renderer');
  await page.evaluate(() => /** @type {HTMLElement} */ (document.querySelector('vitrine-viewer')?.shadowRoot?.querySelector('[data-action="splats"]')).click());
  await page.waitForFunction((last) => /** @type {any} */ (document.querySelector('vitrine-viewer')).viewer.meshSplats.level === last, state.shownLevel, { timeout: 30_000 });
  const pressed = await page.evaluate(() => document.querySelector('vitrine-viewer')?.shadowRoot?.querySelector('[data-action="splats"]')?.getAttribute('aria-pressed'));
  assert.equal(pressed, 'true');
  const splats = await viewerCapture(page, 'splats');
  const a = foreground(splats.rgba);
  const b = foreground(mesh.rgba);
  let both = 0;
  let either = 0;
  for (let p = 0; p < a.length; p++) {
    both += a[p] & b[p];
    either += a[p] | b[p];
  }
  const iou = both / Math.max(1, either);
  console.log(`# viewer, mesh splat view (${state.vertices} vertices): splats ${count(a)} px, mesh ${count(b)} px, IoU ${iou.toFixed(3)}`);
  assert.ok(count(a) > 0.02 * a.length, 'the splats differ from the background');
  assert.ok(iou > 0.85, `silhouette IoU ${iou}`);
  // Off: the splat canvas is gone and the mesh renders as it did.
  await page.evaluate(() => /** @type {any} */ (document.querySelector('vitrine-viewer')).viewer.setSplatView(false));
  const canvases = await page.evaluate(() => document.querySelector('vitrine-viewer')?.shadowRoot?.querySelectorAll('canvas').length);
  assert.equal(canvases, 1);
  const again = await viewerCapture(page, 'renderer');
  assert.deepEqual(again.rgba, mesh.rgba);
  assert.deepEqual(problems, []);
  await page.close();
});

test('without float render targets the point model says why', async () => {
  const page = await browser.context.newPage();
  await page.addInitScript(() => {
    const proto = /** @type {any} */ (WebGL2RenderingContext.prototype);
    const get = proto.getExtension;
    proto.getExtension = function (/** @type {string} */ name) {
      return name === 'EXT_color_buffer_float' ? null : get.call(this, name);
    };
  });
  await page.goto(`${base}/viewer/spheres`);
  const state = await until(page, "s.status === 'error'");
  assert.match(state.message, /float render targets \(EXT_color_buffer_float\)/);
  await page.close();
});
