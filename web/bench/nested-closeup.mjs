// @ts-check
// A close-up of a nested stream (format 6, issue 41) in headless Chromium
// against the real `vitrine serve`: the mesh given is ingested with
// `--charts nested` (or the shape given), the page opens on the home view
// with `?refine=view`, settles, then zooms onto one point of the surface.
// Reported: bytes fetched for the overview and for the close-up against
// the whole stream's, as the viewer counts them (the bodies the network
// carried: the part index compressed, as the service sends JSON), the most vertices resident, and the time from the
// zoom to the chart under the camera at the last phase's final depth, the
// occlusion depth map's cost, with
// DevTools network emulation at `--mbits` (default 10 Mbit/s; 0: loopback).
// A scan of tens of millions of vertices is ingested once, outside the
// bench (`vitrine ingest … --charts nested`), and served from its database
// with `--db sqlite:FILE --slug SLUG`. With `--reference PLY` (the whole
// stream decoded natively, `vitrine decode`), the leaf chart under the
// camera is checked bit for bit against it: every vertex a vertex of the
// final level (its three floats' bits), every triangle one of its
// triangles, same orientation. With `--orbit S`, the camera then orbits
// the model for S seconds: the most resident and shown are sampled, and
// every 15 s the charts shown are checked watertight (every open edge of
// a chart shown is run the other way by one other chart shown, by its end
// positions: on a closed scan, the open edges are the cuts).
//   node bench/nested-closeup.mjs MESH [--charts nested:2,2,5] [--target x,y,z] [--distance 0.05] [--budget N] [--mbits 10]
//   node bench/nested-closeup.mjs --db sqlite:big.db --slug scan [--reference final.ply] [--orbit 120] [--budget 750000] …
// (`--distance`: the camera's from the target, as a share of the model's diagonal)
import { readFileSync } from 'node:fs';
import { parseArgs } from 'node:util';
import { launch } from '../test/support/browser.mjs';
import { startService } from '../test/support/service.mjs';

const { values, positionals } = parseArgs({
  allowPositionals: true,
  options: {
    charts: { type: 'string', default: 'nested' },
    target: { type: 'string' },
    distance: { type: 'string' },
    budget: { type: 'string' },
    mbits: { type: 'string', default: '10' },
    db: { type: 'string' },
    slug: { type: 'string', default: 'scan' },
    reference: { type: 'string' },
    orbit: { type: 'string' },
    uniform: { type: 'boolean', default: false },
  },
});
const mesh = positionals[0] ?? values.db;
if (!mesh) throw new Error('usage: node bench/nested-closeup.mjs MESH|--db sqlite:FILE [--slug S] [--charts nested:TOP,FANOUT,PHASES] [--target x,y,z] [--distance d] [--budget N] [--mbits 10] [--reference PLY] [--orbit S]');
const mbits = Number(values.mbits);
const slug = values.db ? String(values.slug) : 'scan';

const t0 = performance.now();
const service = values.db
  ? await startService({ models: [], existingDb: values.db })
  : await startService({
      models: [{ slug, title: 'Nested scan', kind: 'file', file: mesh, ingestArgs: ['--charts', String(values.charts)] }],
    });
if (!values.db) console.error(`ingested ${mesh} in ${((performance.now() - t0) / 1000).toFixed(1)} s`);
const browser = await launch({ width: 800, height: 600 });
try {
  const manifest = await (await fetch(`${service.url}/api/models/${slug}`)).json();
  if (!manifest.nested_parts) throw new Error(`not a nested stream (format ${manifest.stream_format})`);
  const whole = manifest.levels.reduce((/** @type {number} */ n, /** @type {{ bytes: number }} */ l) => n + l.bytes, 0);
  const page = await browser.context.newPage();
  const cdp = await browser.context.newCDPSession(page);
  await cdp.send('Network.enable');
  await cdp.send('Network.setCacheDisabled', { cacheDisabled: true });
  if (mbits > 0) {
    const bytesPerSecond = (mbits * 1e6) / 8;
    await cdp.send('Network.emulateNetworkConditions', { offline: false, latency: 20, downloadThroughput: bytesPerSecond, uploadThroughput: bytesPerSecond });
  }
  const budget = values.budget ? `&vertex-budget=${values.budget}` : '';
  const started = performance.now();
  await page.goto(`${service.url}/m/${slug}?refine=view${budget}`);
  const overview = await settled(page, 600_000);
  const overviewMs = performance.now() - started;
  // The first frame, on the page's clock (from its navigation).
  const firstFrameMs = await page.evaluate(() => /** @type {any} */ (document.querySelector('vitrine-viewer')).viewer.state.firstFrameMs);
  let maxShown = overview.shownTriangles;
  // The close-up: a point of the surface (default: the bounds' centre pushed
  // out along +z to the model's front, as the home view faces it).
  const bounds = manifest.bounds ?? { min: [-1, -1, -1], max: [1, 1, 1] };
  const size = Math.hypot(...bounds.max.map((/** @type {number} */ v, /** @type {number} */ k) => v - bounds.min[k]));
  const target = values.target
    ? values.target.split(',').map(Number)
    : [(bounds.min[0] + bounds.max[0]) / 2, (bounds.min[1] + bounds.max[1]) / 2, bounds.max[2]];
  const distance = size * (values.distance ? Number(values.distance) : 0.05);
  let maxResident = overview.resident;
  // The depth map's cost (occlusion.js), as sampled: the slowest seen.
  let maxOcclusionMs = overview.occlusionMs;
  const zoomed = performance.now();
  await page.evaluate(
    ({ target, distance }) => {
      const v = /** @type {any} */ (document.querySelector('vitrine-viewer')).viewer;
      v.camera.state = { target, distance, yaw: 0, pitch: 0 };
      v.renderer.requestFrame();
      v.cameraMoved();
    },
    { target, distance },
  );
  // Wait for the close-up to settle, sampling the most resident on the way.
  let closeup = overview;
  let finalMs = null;
  for (;;) {
    await new Promise((r) => setTimeout(r, 200));
    const s = await page.evaluate(() => /** @type {any} */ (document.querySelector('vitrine-viewer')).viewer.partsState());
    maxResident = Math.max(maxResident, s.resident);
    maxShown = Math.max(maxShown, s.shownTriangles);
    maxOcclusionMs = Math.max(maxOcclusionMs, s.occlusionMs);
    if (finalMs === null && s.deepestPhase === s.phases - 1 && s.depths[s.phases - 1].some((/** @type {number} */ d) => d === s.finalDepth)) {
      finalMs = performance.now() - zoomed;
    }
    closeup = s;
    // The camera reaches the decode worker within 150 ms: a state settled after a second is the close-up's.
    if (s.settled && performance.now() - zoomed > 1000) break;
    if (performance.now() - zoomed > 600_000) throw new Error('the close-up did not settle in 10 minutes');
  }
  const mb = (/** @type {number} */ n) => `${(n / 1e6).toFixed(2)} MB`;
  console.log(`nested close-up of ${mesh} (${values.charts}; ${manifest.levels.at(-1).vertices} vertices, ${mbits > 0 ? `${mbits} Mbit/s` : 'loopback'}; ${distance.toPrecision(3)} from ${target.map((v) => v.toPrecision(3)).join(', ')}):`);
  console.log(`  whole stream              ${mb(whole)}`);
  console.log(`  first frame               ${(firstFrameMs / 1000).toFixed(2)} s after navigation`);
  const pct = (/** @type {number} */ n) => `${((100 * n) / whole).toFixed(1)} %`;
  console.log(`  overview settled          ${(overviewMs / 1000).toFixed(1)} s, ${mb(overview.bytesFetched)} (${pct(overview.bytesFetched)}), ${overview.shownTriangles} triangles shown, ${overview.resident} vertices resident`);
  console.log(`  after the close-up        ${mb(closeup.bytesFetched)} (${pct(closeup.bytesFetched)}), ${mb(closeup.bytesFetched - overview.bytesFetched)} for the zoom`);
  console.log(`  zoom to the final depth   ${finalMs === null ? 'not reached' : `${(finalMs / 1000).toFixed(1)} s`}`);
  console.log(`  resident at most          ${maxResident} vertices (budget ${closeup.budget}); ${closeup.evictions} subtrees folded back`);
  console.log(`  shown at most             ${maxShown} triangles`);
  console.log(`  charts shown per phase    ${closeup.shownCharts.join(' ')} of ${closeup.charts.join(' ')}`);
  console.log(`  occlusion                 ${closeup.hiddenCharts} charts shown hidden; ${closeup.occlusionMaps} depth maps, the last ${closeup.occlusionMs.toFixed(1)} ms (slowest ${maxOcclusionMs.toFixed(1)} ms)`);
  const leaves = closeup.depths[closeup.phases - 1];
  const atFinal = leaves.filter((/** @type {number} */ d) => d === closeup.finalDepth).length;
  console.log(`  leaves at the final depth ${atFinal} of ${leaves.length} (depths ${leaves.join(' ')} of ${closeup.finalDepth})`);
  if (values.reference) await checkLeaf(page, closeup, target, values.reference);
  console.log(`  watertight after the zoom ${describeSeams(await seams(page))}`);
  if (values.orbit) await orbit(page, Number(values.orbit), bounds, size);
  if (values.uniform) await uniform(cdpOptions(mbits), slug, manifest);
} finally {
  await browser.close();
  await service.stop();
}

/**
 * Emulated network conditions at `mbits` (0: none).
 * @param {number} mbits
 */
function cdpOptions(mbits) {
  const bytesPerSecond = (mbits * 1e6) / 8;
  return mbits > 0 ? { offline: false, latency: 20, downloadThroughput: bytesPerSecond, uploadThroughput: bytesPerSecond } : null;
}

/**
 * Today's uniform refinement of the same model for comparison
 * (`?refine=uniform`, the same network): the time from navigation to the
 * last level on screen, and the bytes it fetched.
 * @param {ReturnType<typeof cdpOptions>} conditions
 * @param {string} slug
 * @param {any} manifest
 */
async function uniform(conditions, slug, manifest) {
  const page = await browser.context.newPage();
  const cdp = await browser.context.newCDPSession(page);
  await cdp.send('Network.enable');
  await cdp.send('Network.setCacheDisabled', { cacheDisabled: true });
  if (conditions) await cdp.send('Network.emulateNetworkConditions', conditions);
  const last = manifest.levels.length - 1;
  const started = performance.now();
  await page.goto(`${service.url}/m/${slug}?refine=uniform`);
  await page.waitForFunction((last) => /** @type {any} */ (document.querySelector('vitrine-viewer'))?.viewer?.state.shownLevel === last, last, { timeout: 600_000, polling: 100 });
  const ms = performance.now() - started;
  const received = await page.evaluate(() => /** @type {any} */ (document.querySelector('vitrine-viewer')).viewer.state.received);
  console.log(`  uniform refinement        the last level on screen ${(ms / 1000).toFixed(1)} s after navigation, ${(received / 1e6).toFixed(2)} MB fetched`);
  await page.close();
}

/**
 * The leaf of the last phase nearest the close-up's target, at the final
 * depth, against the whole stream decoded natively: every vertex one of the
 * final level's (bit for bit), every triangle one of its triangles with
 * the same orientation. Throws on the first difference.
 * @param {import('playwright-core').Page} page
 * @param {any} state
 * @param {number[]} target
 * @param {string} reference a binary little-endian PLY, float x y z, int or uint triangles
 */
async function checkLeaf(page, state, target, reference) {
  const last = state.phases - 1;
  const leaf = await page.evaluate(
    async ({ last, depths, finalDepth, target }) => {
      const v = /** @type {any} */ (document.querySelector('vitrine-viewer')).viewer;
      let best = null;
      for (const [chart, depth] of depths.entries()) {
        if (depth !== finalDepth) continue;
        const c = await v.partChart(chart, last);
        for (let i = 0; i < c.positions.length; i += 3) {
          const d = Math.hypot(c.positions[i] - target[0], c.positions[i + 1] - target[1], c.positions[i + 2] - target[2]);
          if (!best || d < best.d) best = { d, chart };
        }
      }
      if (!best) return null;
      const c = await v.partChart(best.chart, last);
      return { chart: best.chart, depth: c.depth, positions: Array.from(new Uint32Array(c.positions.buffer, c.positions.byteOffset, c.positions.length)), indices: Array.from(c.indices) };
    },
    { last, depths: state.depths[last], finalDepth: state.finalDepth, target },
  );
  if (!leaf) throw new Error('no leaf at the final depth to check');
  const ply = readPly(reference);
  /** @param {number} a @param {number} b @param {number} c */
  const key3 = (a, b, c) => `${a},${b},${c}`;
  // Vertices by position: at 12 bits a dense scan has distinct vertices on
  // one grid point, so both sides are compared on positions, each
  // position's first leaf vertex standing for all.
  const ours = new Map();
  const canonical = new Int32Array(leaf.positions.length / 3);
  for (let i = 0; i < leaf.positions.length; i += 3) {
    const key = key3(leaf.positions[i], leaf.positions[i + 1], leaf.positions[i + 2]);
    if (!ours.has(key)) ours.set(key, i / 3);
    canonical[i / 3] = ours.get(key);
  }
  // The reference's vertices that are the leaf's: reference index to leaf position.
  const toLeaf = new Int32Array(ply.vertices).fill(-1);
  const seen = new Set();
  for (let v = 0; v < ply.vertices; v++) {
    const id = ours.get(key3(ply.xyz[3 * v], ply.xyz[3 * v + 1], ply.xyz[3 * v + 2]));
    if (id !== undefined) {
      toLeaf[v] = id;
      seen.add(id);
    }
  }
  if (seen.size !== ours.size) throw new Error(`leaf ${leaf.chart}: ${ours.size - seen.size} of its ${ours.size} positions are not the final level's`);
  /** A triangle as its smallest-first rotation, so that orientation counts. @param {number} a @param {number} b @param {number} c */
  const tri = (a, b, c) => (a < b && a < c ? key3(a, b, c) : b < c ? key3(b, c, a) : key3(c, a, b));
  const theirs = new Set();
  for (let f = 0; f < ply.faces.length; f += 3) {
    const [a, b, c] = [toLeaf[ply.faces[f]], toLeaf[ply.faces[f + 1]], toLeaf[ply.faces[f + 2]]];
    if (a >= 0 && b >= 0 && c >= 0) theirs.add(tri(a, b, c));
  }
  let missing = 0;
  for (let t = 0; t < leaf.indices.length; t += 3) {
    if (!theirs.has(tri(canonical[leaf.indices[t]], canonical[leaf.indices[t + 1]], canonical[leaf.indices[t + 2]]))) missing++;
  }
  if (missing > 0) throw new Error(`leaf ${leaf.chart}: ${missing} of its ${leaf.indices.length / 3} triangles are not the final level's`);
  console.log(`  bit for bit               leaf ${leaf.chart} (depth ${leaf.depth}): its ${leaf.positions.length / 3} vertices (${ours.size} positions) and ${leaf.indices.length / 3} triangles are the final level's (${ply.vertices} vertices, ${ply.faces.length / 3} triangles)`);
}

/**
 * A binary little-endian PLY's float positions (as their bits) and triangles.
 * @param {string} path
 */
function readPly(path) {
  const bytes = readFileSync(path);
  const end = bytes.indexOf('end_header\n') + 'end_header\n'.length;
  const header = bytes.subarray(0, end).toString('latin1');
  if (!/format binary_little_endian/.test(header)) throw new Error(`${path}: not a binary little-endian PLY`);
  const vertices = Number(/element vertex (\d+)/.exec(header)?.[1]);
  const faceCount = Number(/element face (\d+)/.exec(header)?.[1] ?? 0);
  const vertexProps = header.split('element vertex')[1].split('element')[0].match(/property \w+ \w+/g) ?? [];
  const sizes = { float: 4, float32: 4, uchar: 1, uint8: 1, int: 4, int32: 4, uint: 4, uint32: 4, double: 8 };
  const stride = vertexProps.reduce((n, p) => n + (sizes[/** @type {keyof typeof sizes} */ (p.split(' ')[1])] ?? 0), 0);
  if (!/property float(?:32)? x\nproperty float(?:32)? y\nproperty float(?:32)? z/.test(header)) throw new Error(`${path}: x, y, z are not its first float properties`);
  const view = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
  const xyz = new Uint32Array(3 * vertices);
  for (let v = 0; v < vertices; v++) for (let k = 0; k < 3; k++) xyz[3 * v + k] = view.getUint32(end + v * stride + 4 * k, true);
  const faces = new Uint32Array(3 * faceCount);
  let at = end + vertices * stride;
  for (let f = 0; f < faceCount; f++) {
    if (bytes[at] !== 3) throw new Error(`${path}: face ${f} is not a triangle`);
    for (let k = 0; k < 3; k++) faces[3 * f + k] = view.getUint32(at + 1 + 4 * k, true);
    at += 13;
  }
  return { vertices, xyz, faces };
}

/**
 * The charts shown, matched along their borders: each chart's own open
 * edges (used by one of its triangles) by their end positions; an open
 * edge that no other chart shown runs the other way is a crack, one run
 * the other way by two charts or more an overlap. On a closed scan every
 * open edge of a chart lies on a cut, so every one must be matched.
 * The charts shown may change while they are read: then read again.
 * (Interior vertices are not welded by position: at 12 bits a dense scan
 * has distinct vertices on one grid point.)
 * @param {import('playwright-core').Page} page
 */
async function seams(page) {
  for (let attempt = 1; ; attempt++) {
    try {
      return await seamsOnce(page);
    } catch (error) {
      if (attempt >= 10 || !/is not held/.test(String(error))) throw error;
    }
  }
}

/** @param {import('playwright-core').Page} page */
function seamsOnce(page) {
  return page.evaluate(async () => {
    const v = /** @type {any} */ (document.querySelector('vitrine-viewer')).viewer;
    const state = v.partsState();
    /** @type {Map<string, number>} directed open edge "from|to" by position: charts that have it */
    const open = new Map();
    let triangles = 0;
    for (const [phase, chart] of state.shown) {
      const c = await v.partChart(chart, phase);
      const bits = new Uint32Array(c.positions.buffer, c.positions.byteOffset, c.positions.length);
      /** @param {number} i */
      const at = (i) => `${bits[3 * i]},${bits[3 * i + 1]},${bits[3 * i + 2]}`;
      /** @type {Map<number, number>} local edge a * n + b (a < b): uses */
      const uses = new Map();
      const n = c.positions.length / 3;
      const edge = (/** @type {number} */ a, /** @type {number} */ b) => (a < b ? a * n + b : b * n + a);
      for (let t = 0; t < c.indices.length; t += 3) {
        triangles++;
        for (let k = 0; k < 3; k++) {
          const e = edge(c.indices[t + k], c.indices[t + ((k + 1) % 3)]);
          uses.set(e, (uses.get(e) ?? 0) + 1);
        }
      }
      for (let t = 0; t < c.indices.length; t += 3) {
        for (let k = 0; k < 3; k++) {
          const a = c.indices[t + k];
          const b = c.indices[t + ((k + 1) % 3)];
          if (uses.get(edge(a, b)) !== 1) continue;
          const key = `${at(a)}|${at(b)}`;
          open.set(key, (open.get(key) ?? 0) + 1);
        }
      }
    }
    // Per pair of end positions, as many open edges one way as the other
    // (distinct vertices on one grid point give several of each).
    let unbalanced = 0;
    let matched = 0;
    let zeroLength = 0;
    for (const [key, count] of open) {
      const [from, to] = key.split('|');
      if (from === to) {
        zeroLength += count;
        continue;
      }
      if (from > to) continue; // each pair once, from its smaller end
      const back = open.get(`${to}|${from}`) ?? 0;
      matched += Math.min(count, back);
      unbalanced += Math.abs(count - back);
    }
    for (const [key, count] of open) {
      const [from, to] = key.split('|');
      if (from > to && !open.has(`${to}|${from}`)) unbalanced += count;
    }
    return { charts: state.shown.length, triangles, matched, unbalanced, zeroLength };
  });
}

/** @param {{ charts: number, triangles: number, matched: number, unbalanced: number, zeroLength: number }} s */
function describeSeams(s) {
  return `${s.charts} charts, ${s.triangles} triangles: ${s.matched} open edges matched the other way, ${s.unbalanced} not (cracks or overlaps, or the scan's own border), ${s.zeroLength} of no length`;
}

/**
 * Orbits the model for `seconds`: a full turn around its centre at a
 * distance swinging between a close pass and the whole object, a camera
 * every 100 ms (as a visitor's drag sends them). The most resident and
 * shown are sampled; every 15 s the charts shown are checked watertight.
 * @param {import('playwright-core').Page} page
 * @param {number} seconds
 * @param {{ min: number[], max: number[] }} bounds
 * @param {number} size the diagonal
 */
async function orbit(page, seconds, bounds, size) {
  const centre = bounds.min.map((v, k) => (v + bounds.max[k]) / 2);
  const start = performance.now();
  let maxResident = 0;
  let maxShown = 0;
  let budget = 0;
  let checks = 0;
  let bad = 0;
  let nextCheck = 15_000;
  let bytes = 0;
  for (;;) {
    const t = performance.now() - start;
    if (t > seconds * 1000) break;
    const turn = t / (seconds * 1000);
    const yaw = 2 * Math.PI * turn;
    const pitch = 0.4 * Math.sin(4 * Math.PI * turn);
    const distance = size * (0.35 + 0.5 * (1 + Math.cos(6 * Math.PI * turn)) / 2);
    const s = await page.evaluate(
      ({ target, distance, yaw, pitch }) => {
        const v = /** @type {any} */ (document.querySelector('vitrine-viewer')).viewer;
        v.camera.state = { target, distance, yaw, pitch };
        v.renderer.requestFrame();
        v.cameraMoved();
        return v.partsState();
      },
      { target: centre, distance, yaw, pitch },
    );
    maxResident = Math.max(maxResident, s.resident);
    maxShown = Math.max(maxShown, s.shownTriangles);
    budget = s.budget;
    bytes = s.bytesFetched;
    if (t >= nextCheck) {
      nextCheck += 15_000;
      const seam = await seams(page);
      checks++;
      if (seam.unbalanced) {
        bad++;
        console.log(`  orbit at ${(t / 1000).toFixed(0)} s: ${describeSeams(seam)}`);
      }
    }
    await new Promise((r) => setTimeout(r, 100));
  }
  const seam = await seams(page);
  checks++;
  if (seam.unbalanced) bad++;
  console.log(`  orbit ${seconds} s           resident at most ${maxResident} vertices (budget ${budget}), shown at most ${maxShown} triangles; ${(bytes / 1e6).toFixed(2)} MB fetched in all`);
  console.log(`  orbit watertight          ${checks - bad} of ${checks} checks; the last: ${describeSeams(seam)}`);
}

/**
 * @param {import('playwright-core').Page} page
 * @param {number} timeout
 */
async function settled(page, timeout) {
  await page.waitForFunction(
    () => {
      const v = /** @type {any} */ (document.querySelector('vitrine-viewer'))?.viewer;
      const p = v?.partsState();
      if (v?.state.status === 'error') throw new Error(v.state.message);
      return p && p.settled && v.state.shownLevel >= p.level;
    },
    undefined,
    { timeout, polling: 250 },
  );
  return page.evaluate(() => /** @type {any} */ (document.querySelector('vitrine-viewer')).viewer.partsState());
}
