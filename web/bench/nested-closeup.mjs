// @ts-check
// A close-up of a nested stream (format 6, issue 41) in headless Chromium
// against the real `vitrine serve`: the mesh given is ingested with
// `--charts nested` (or the shape given), the page opens on the home view
// with `?refine=view`, settles, then zooms onto one point of the surface.
// Reported: bytes fetched for the overview and for the close-up against
// the whole stream's, the most vertices resident, and the time from the
// zoom to the chart under the camera at the last phase's final depth, the
// occlusion depth map's cost, with
// DevTools network emulation at `--mbits` (default 10 Mbit/s; 0: loopback).
// Keep meshes to 2 M vertices or fewer on a small machine.
//   node bench/nested-closeup.mjs MESH [--charts nested:2,2,5] [--target x,y,z] [--distance 0.05] [--budget N] [--mbits 10]
// (`--distance`: the camera's from the target, as a share of the model's diagonal)
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
  },
});
const mesh = positionals[0];
if (!mesh) throw new Error('usage: node bench/nested-closeup.mjs MESH [--charts nested:TOP,FANOUT,PHASES] [--target x,y,z] [--distance d] [--budget N] [--mbits 10]');
const mbits = Number(values.mbits);

const t0 = performance.now();
const service = await startService({
  models: [{ slug: 'scan', title: 'Nested scan', kind: 'file', file: mesh, ingestArgs: ['--charts', String(values.charts)] }],
});
console.error(`ingested ${mesh} in ${((performance.now() - t0) / 1000).toFixed(1)} s`);
const browser = await launch({ width: 800, height: 600 });
try {
  const manifest = await (await fetch(`${service.url}/api/models/scan`)).json();
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
  await page.goto(`${service.url}/m/scan?refine=view${budget}`);
  const overview = await settled(page, 600_000);
  const overviewMs = performance.now() - started;
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
  console.log(`  overview settled          ${(overviewMs / 1000).toFixed(1)} s, ${mb(overview.bytesFetched)} (${((100 * overview.bytesFetched) / whole).toFixed(1)} %)`);
  console.log(`  after the close-up        ${mb(closeup.bytesFetched)} (${((100 * closeup.bytesFetched) / whole).toFixed(1)} %), ${mb(closeup.bytesFetched - overview.bytesFetched)} for the zoom`);
  console.log(`  zoom to the final depth   ${finalMs === null ? 'not reached' : `${(finalMs / 1000).toFixed(1)} s`}`);
  console.log(`  resident at most          ${maxResident} vertices (budget ${closeup.budget}); ${closeup.evictions} subtrees folded back`);
  console.log(`  charts shown per phase    ${closeup.shownCharts.join(' ')} of ${closeup.charts.join(' ')}`);
  console.log(`  occlusion                 ${closeup.hiddenCharts} charts shown hidden; ${closeup.occlusionMaps} depth maps, the last ${closeup.occlusionMs.toFixed(1)} ms (slowest ${maxOcclusionMs.toFixed(1)} ms)`);
  const leaves = closeup.depths[closeup.phases - 1];
  const atFinal = leaves.filter((/** @type {number} */ d) => d === closeup.finalDepth).length;
  console.log(`  leaves at the final depth ${atFinal} of ${leaves.length} (depths ${leaves.join(' ')} of ${closeup.finalDepth})`);
} finally {
  await browser.close();
  await service.stop();
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
