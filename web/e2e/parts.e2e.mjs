// @ts-check
// End-to-end: view-dependent refinement of a charted stream (issue 41). A
// 40 k-vertex sphere cut into 16 charts, served by the real `vitrine serve`;
// the page opens zoomed onto the front of the sphere with `?refine=view`.
// The chart under the camera reaches the final depth, bit for bit the whole
// decoder's chart; the charts behind stay shallower; fewer bytes than the
// whole stream; resident vertices within the budget, also a budget small
// enough to make the viewer give charts back.
import { after, before, test } from 'node:test';
import assert from 'node:assert/strict';
import { launch } from '../test/support/browser.mjs';
import { startService } from '../test/support/service.mjs';
import { lookAt, openRecorded, settledParts, some, wholeDecoder } from '../test/support/refinement.mjs';

/** @typedef {import('playwright-core').Page} Page */
/** @typedef {import('../src/part-refinement.js').PartsState} PartsState */

/**
 * Zoomed onto the sphere's front, 0.2 above its surface (view-state.js:
 * target, distance, yaw, pitch): near enough that the last level's bulk
 * error, a grid step or so on this smooth sphere, is over a pixel there.
 */
const CAMERA = 'camera=0,0,1,0.2,0,0';

/** A phone's budget here: the sphere's last level (41 k vertices) is past it, the one before is not. */
const PHONE_MAX_VERTICES = 20_000;

/** @type {Awaited<ReturnType<typeof startService>>} */
let service;
/** @type {Awaited<ReturnType<typeof launch>>} */
let browser;
/** @type {any} */
let manifest;

before(async () => {
  service = await startService({
    models: [{ slug: 'ball', title: 'Charted sphere', kind: 'sphere', kiloVertices: 40, colour: true, ingestArgs: ['--charts', '16'] }],
    // A phone is capped one level short of the last (the third test).
    serveArgs: ['--phone-max-vertices', String(PHONE_MAX_VERTICES)],
  });
  browser = await launch({ width: 640, height: 480 });
  manifest = await (await fetch(`${service.url}/api/models/ball`)).json();
  assert.equal(manifest.stream_format, 5);
  assert.ok(manifest.parts, 'the manifest links the part index');
});

after(async () => {
  await browser?.close();
  await service?.stop();
});

/**
 * Opens the model page, recording every failed request and console error.
 * @param {string} query
 * @param {string} [view] the page's fragment (view-state.js)
 */
async function open(query, view = CAMERA) {
  const { page, problems, requests } = await openRecorded(browser.context);
  // Each change of depth, timed from the navigation (the element's vitrine-parts event).
  await page.addInitScript(() => {
    const log = /** @type {[number, number[]][]} */ ([]);
    /** @type {any} */ (window).partsLog = log;
    document.addEventListener('vitrine-parts', (e) => log.push([performance.now(), /** @type {CustomEvent} */ (e).detail.depths]));
  });
  const started = Date.now();
  await page.goto(`${service.url}/m/ball?${query}${view ? `#${view}` : ''}`);
  return { page, problems, started, requests };
}

/** @param {Page} page @returns {Promise<PartsState & { status: string }>} */
function settled(page) {
  return settledParts(page);
}

/**
 * Every chart's vertices as the page holds them.
 * @param {Page} page
 * @param {number} charts
 * @returns {Promise<{ depth: number, positions: number[] }[]>}
 */
function pageCharts(page, charts) {
  return page.evaluate(async (n) => {
    const v = /** @type {any} */ (document.querySelector('vitrine-viewer')).viewer;
    const out = [];
    for (let k = 0; k < n; k++) {
      const c = await v.partChart(k);
      out.push({ depth: c.depth, positions: Array.from(c.positions) });
    }
    return out;
  }, charts);
}

test('the charts in view refine to the final level, the ones behind stay coarse, bit for bit the whole decoder', async () => {
  const { page, problems, started } = await open('refine=view');
  const state = await settled(page);
  const elapsed = Date.now() - started;
  assert.equal(state.status === 'error', false, String(/** @type {any} */ (state).message));
  const charts = await pageCharts(page, state.charts);
  const log = /** @type {[number, number[]][]} */ (await page.evaluate(() => /** @type {any} */ (window).partsLog));
  const whole = manifest.levels.reduce((/** @type {number} */ n, /** @type {{ bytes: number }} */ l) => n + l.bytes, 0);
  console.log(
    `parts: settled in ${elapsed} ms; depths ${state.depths.join(' ')} of ${state.finalDepth}; ` +
      `${state.resident} vertices resident (budget ${state.budget}); ${state.bytesFetched} of ${whole} bytes`,
  );
  // The chart under the camera's target (0, 0, 1), and those wholly behind the sphere.
  const front = charts.findIndex((c) => some(c.positions, (x, y, z) => Math.hypot(x, y, z - 1) < 0.05));
  assert.ok(front >= 0, 'a chart holds the point the camera looks at');
  const finalAt = log.find(([, depths]) => depths[front] === state.finalDepth)?.[0];
  console.log(`parts: the chart in view at the final depth ${Math.round(finalAt ?? NaN)} ms after navigation`);
  assert.equal(charts[front].depth, state.finalDepth, 'the chart in view reaches the final level');
  const behind = charts.filter((c) => !some(c.positions, (_x, _y, z) => z > 0.1));
  assert.ok(behind.length > 0, 'some charts lie behind the sphere');
  for (const c of behind) assert.ok(c.depth < state.finalDepth, `a chart behind stays shallower (${c.depth})`);
  assert.ok(state.resident <= state.budget);
  assert.ok(state.bytesFetched < whole, `${state.bytesFetched} bytes fetched, the whole stream is ${whole}`);
  // Bit for bit the chart a whole decoder makes at the last level.
  const { decoder } = await wholeDecoder(`${service.url}/api/models/ball`, manifest);
  const mine = new Float32Array(charts[front].positions);
  const theirs = decoder.chartView(front).positions.slice();
  assert.deepEqual(Buffer.from(mine.buffer), Buffer.from(theirs.buffer), 'the chart in view is the whole decoder chart');
  decoder.free();
  assert.deepEqual(problems, []);
  await page.close();
});

test('a small vertex budget: charts given back, never more resident than the budget', async () => {
  const budget = 12_000;
  // From the home view, the whole sphere refines evenly until the budget is spent.
  const { page, problems } = await open(`refine=view&vertex-budget=${budget}`, '');
  const first = await settled(page);
  assert.equal(first.budget, budget);
  assert.ok(first.resident <= budget, `${first.resident} resident, budget ${budget}`);
  // Right up to the front: the charts under the camera want more than the
  // rest would miss at the cut, so the rest give their vertices back.
  await lookAt(page, [0, 0, 1], 0.03);
  await page.waitForFunction(() => /** @type {any} */ (document.querySelector('vitrine-viewer')).viewer.partsState().evictions > 0, undefined, {
    timeout: 15_000,
    polling: 100,
  });
  const second = await settled(page);
  console.log(
    `parts, budget ${budget}: ${first.resident} resident at home (depths ${first.depths.join(' ')}), ` +
      `${second.resident} up close (depths ${second.depths.join(' ')}), ${second.evictions} charts given back`,
  );
  assert.ok(second.resident <= budget, `${second.resident} resident, budget ${budget}`);
  const charts = await pageCharts(page, second.charts);
  const front = charts.findIndex((c) => some(c.positions, (x, y, z) => Math.hypot(x, y, z - 1) < 0.05));
  assert.ok(charts[front].depth > first.depths[front], 'the chart under the camera refined further');
  assert.ok(Math.min(...second.depths) < Math.min(...first.depths), 'charts were reset to the cut');
  assert.deepEqual(problems, []);
  await page.close();
});

test('a phone capped below the last level: no part past the cap, the cap announced', async () => {
  const { page, problems, requests } = await open('refine=view&device=phone');
  await settled(page);
  await page.waitForFunction(() => /** @type {any} */ (document.querySelector('vitrine-viewer')).viewer.state.status === 'capped', undefined, {
    timeout: 10_000,
  });
  const state = await settled(page);
  const phone = await (await fetch(`${service.url}/api/models/ball?device=phone`)).json();
  const cap = phone.cap.level;
  assert.ok(cap < phone.last_level, `the phone is capped (${cap} of ${phone.last_level})`);
  assert.equal(state.status, 'capped');
  assert.equal(state.budget, 500_000, "a phone's default budget");
  const deepest = state.firstLevel - 1 + Math.max(...state.depths);
  assert.equal(deepest, cap, 'the charts in view refine up to the cap');
  const levels = requests.map((url) => Number(url.match(/\/batches\/(\d+)/)?.[1] ?? 0));
  assert.ok(Math.max(...levels) <= cap, 'nothing past the cap is requested');
  assert.deepEqual(problems, []);
  await page.close();
});
