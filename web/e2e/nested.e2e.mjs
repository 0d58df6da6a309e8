// @ts-check
// End-to-end: view-dependent refinement of a nested stream (format 6, issue
// 41). A 40 k-vertex sphere cut into a tree of charts (4 top charts, each
// split in 2, 3 phases), served by the real `vitrine serve`; the page opens
// zoomed onto the front of the sphere with `?refine=view`. The chart under
// the camera reaches the last phase at its final depth, bit for bit the
// whole decoder's chart; the charts behind stay coarser (hidden behind the
// front: at the depth they were made at); fewer bytes than
// the whole stream; resident vertices within the budget, also a budget
// small enough to make the viewer fold subtrees back; a phone capped below
// the last level fetches nothing past its cap; refinement by view is the
// default for a nested stream, `?refine=uniform` decodes it batch by batch.
import { after, before, test } from 'node:test';
import assert from 'node:assert/strict';
import { launch } from '../test/support/browser.mjs';
import { startService } from '../test/support/service.mjs';
import { lookAt, openRecorded, settledParts, some, wholeDecoder } from '../test/support/refinement.mjs';

/** @typedef {import('playwright-core').Page} Page */
/** @typedef {import('../src/nested-refinement.js').NestedState} NestedState */

/**
 * Zoomed onto the sphere's front, 0.2 above its surface (view-state.js:
 * target, distance, yaw, pitch): near enough that the last level's bulk
 * error, a grid step or so on this smooth sphere, is over a pixel there.
 */
const CAMERA = 'camera=0,0,1,0.2,0,0';

/** A phone's cap here: the sphere's last level (41 k vertices) is past it, the one before is not. */
const PHONE_MAX_VERTICES = 20_000;

/** @type {Awaited<ReturnType<typeof startService>>} */
let service;
/** @type {Awaited<ReturnType<typeof launch>>} */
let browser;
/** @type {any} */
let manifest;

before(async () => {
  service = await startService({
    models: [{ slug: 'tree', title: 'Nested sphere', kind: 'sphere', kiloVertices: 40, colour: true, ingestArgs: ['--charts', 'nested:4,2,3'] }],
    // A phone is capped one level short of the last (the third test).
    serveArgs: ['--phone-max-vertices', String(PHONE_MAX_VERTICES)],
  });
  browser = await launch({ width: 640, height: 480 });
  manifest = await (await fetch(`${service.url}/api/models/tree`)).json();
  assert.equal(manifest.stream_format, 6);
  assert.ok(manifest.nested_parts, 'the manifest links the nested part index');
  assert.equal(manifest.parts, undefined);
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
  const started = Date.now();
  await page.goto(`${service.url}/m/tree?${query}${view ? `#${view}` : ''}`);
  return { page, problems, started, requests };
}

/** @param {Page} page @returns {Promise<NestedState & { status: string, message?: string }>} */
function settled(page) {
  return settledParts(page, 40_000);
}

/**
 * Every chart held, as the page holds it.
 * @param {Page} page
 * @param {number[][]} depths the state's
 * @returns {Promise<{ phase: number, chart: number, depth: number, positions: number[], indices: number[] }[]>}
 */
function pageCharts(page, depths) {
  return page.evaluate(async (depths) => {
    const v = /** @type {any} */ (document.querySelector('vitrine-viewer')).viewer;
    const out = [];
    for (const [phase, charts] of depths.entries()) {
      for (const [chart, depth] of charts.entries()) {
        if (depth < 0) continue;
        const c = await v.partChart(chart, phase);
        out.push({ phase, chart, depth: c.depth, positions: Array.from(c.positions), indices: Array.from(c.indices) });
      }
    }
    return out;
  }, depths);
}

test('the chart under the camera goes down to the last phase, the ones behind stay coarse, bit for bit the whole decoder', async () => {
  const { page, problems, started } = await open('refine=view');
  const state = await settled(page);
  const elapsed = Date.now() - started;
  assert.equal(state.status === 'error', false, String(state.message));
  assert.equal(state.kind, 'nested');
  assert.ok(state.phases >= 3, `${state.phases} phases`);
  const whole = manifest.levels.reduce((/** @type {number} */ n, /** @type {{ bytes: number }} */ l) => n + l.bytes, 0);
  console.log(
    `nested: settled in ${elapsed} ms; charts held per phase ${state.residentCharts.join(' ')} of ${state.charts.join(' ')}, ` +
      `shown ${state.shownCharts.join(' ')}; ${state.resident} vertices resident (budget ${state.budget}); ` +
      `${state.bytesFetched} of ${whole} bytes`,
  );
  const last = state.phases - 1;
  const charts = await pageCharts(page, state.depths);
  // The leaf under the camera's target (0, 0, 1).
  const front = charts.find((c) => c.phase === last && some(c.positions, (x, y, z) => Math.hypot(x, y, z - 1) < 0.05));
  assert.ok(front, 'a chart of the last phase holds the point the camera looks at');
  assert.equal(front.depth, state.finalDepth, 'the chart in view reaches the final depth');
  // Charts held wholly behind the sphere: none of the last phase at its final depth.
  const behind = charts.filter((c) => !some(c.positions, (_x, _y, z) => z > 0.1));
  assert.ok(behind.length > 0, 'some charts held lie behind the sphere');
  for (const c of behind) assert.ok(c.phase < last || c.depth < state.finalDepth, `a chart behind stays coarser (phase ${c.phase}, depth ${c.depth})`);
  // Hidden behind the front (occlusion.js), they do not refine at all: each
  // stays at the depth it was made at (the cut, or its parent's split).
  for (const c of behind) assert.equal(c.depth, 0, `a chart behind the sphere applies no part (phase ${c.phase}, chart ${c.chart}, depth ${c.depth})`);
  console.log(`nested: ${behind.length} charts held wholly behind the sphere, all at depth 0; ${state.hiddenCharts} charts shown hidden; depth map ${state.occlusionMs.toFixed(2)} ms, ${state.occlusionMaps} made`);
  assert.ok(state.resident <= state.budget);
  // The index (its rows for every part) counts among the bytes fetched as
  // the network carried it: compressed JSON, as the page's own fetch of it
  // measures (its resource timing).
  const indexBytes = await page.evaluate(async (address) => {
    const url = new URL(address, location.href).href;
    await (await fetch(url, { cache: 'no-store' })).arrayBuffer();
    const entry = /** @type {PerformanceResourceTiming | undefined} */ (performance.getEntriesByName(url, 'resource').at(-1));
    return { carried: entry?.encodedBodySize ?? 0, decoded: entry?.decodedBodySize ?? 0 };
  }, manifest.nested_parts);
  assert.ok(indexBytes.carried > 0 && indexBytes.carried < indexBytes.decoded, `the part index is sent compressed (${JSON.stringify(indexBytes)})`);
  console.log(`nested: ${state.bytesFetched - indexBytes.carried} bytes of the stream fetched, ${indexBytes.carried} of the part index (${indexBytes.decoded} decoded); leaves at depths ${state.depths[last].join(' ')}`);
  assert.ok(state.bytesFetched < whole, `${state.bytesFetched} bytes fetched, the whole stream is ${whole}`);
  // Bit for bit the chart a whole decoder makes at the last level.
  const { codec, decoder } = await wholeDecoder(`${service.url}/api/models/tree`, manifest);
  const theirs = decoder.chartView(front.chart).positions.slice();
  assert.deepEqual(Buffer.from(new Float32Array(front.positions).buffer), Buffer.from(theirs.buffer), 'its positions are the whole decoder chart');
  const e = codec.exports;
  const ptr = e.chart_buffer_ptr(decoder.handle, front.chart, 2);
  const len = e.chart_buffer_len(decoder.handle, front.chart, 2);
  const indices = new Uint32Array(e.memory.buffer.slice(ptr, ptr + 4 * len));
  assert.deepEqual(Array.from(indices), front.indices, 'its triangles are the whole decoder chart');
  decoder.free();
  assert.deepEqual(problems, []);
  await page.close();
});

test('a small vertex budget: subtrees folded back, never more resident than the budget', async () => {
  // From the home view, the whole sphere refines until the budget is spent.
  const probe = await open('refine=view', '');
  const home = await settled(probe.page);
  await probe.page.close();
  const budget = Math.round(home.resident * 0.8);
  const { page, problems } = await open(`refine=view&vertex-budget=${budget}`, '');
  const first = await settled(page);
  assert.equal(first.budget, budget);
  assert.ok(first.resident <= budget, `${first.resident} resident, budget ${budget}`);
  // Right up to the front: the charts under the camera want more than the
  // rest would miss folded back, so the rest fold.
  await lookAt(page, [0, 0, 1], 0.03);
  await page.waitForFunction(() => /** @type {any} */ (document.querySelector('vitrine-viewer')).viewer.partsState().evictions > 0, undefined, {
    timeout: 20_000,
    polling: 100,
  });
  const second = await settled(page);
  console.log(
    `nested, budget ${budget}: ${first.resident} resident at home (shown per phase ${first.shownCharts.join(' ')}), ` +
      `${second.resident} up close (shown ${second.shownCharts.join(' ')}), ${second.evictions} subtrees folded back`,
  );
  assert.ok(second.resident <= budget, `${second.resident} resident, budget ${budget}`);
  assert.ok(second.evictions > 0);
  assert.deepEqual(problems, []);
  await page.close();
});

test('a phone capped below the last level: no part or split entry past the cap, the cap announced', async () => {
  const { page, problems, requests } = await open('refine=view&device=phone');
  await settled(page);
  await page.waitForFunction(() => /** @type {any} */ (document.querySelector('vitrine-viewer')).viewer.state.status === 'capped', undefined, {
    timeout: 10_000,
  });
  const state = await settled(page);
  const phone = await (await fetch(`${service.url}/api/models/tree?device=phone`)).json();
  const cap = phone.cap.level;
  assert.ok(cap < phone.last_level, `the phone is capped (${cap} of ${phone.last_level})`);
  assert.equal(state.status, 'capped');
  assert.equal(state.level, cap, 'the chart in view refines up to the cap');
  assert.equal(state.deepestPhase, state.phases - 1);
  const levels = requests.map((url) => Number(url.match(/\/batches\/(\d+)/)?.[1] ?? 0));
  assert.ok(Math.max(...levels) <= cap, 'nothing past the cap is requested');
  assert.ok(requests.some((url) => /\/splits\//.test(url)), 'split entries were fetched');
  assert.deepEqual(problems, []);
  await page.close();
});

test('a nested stream refines by view without ?refine, and batch by batch with ?refine=uniform', async () => {
  const byDefault = await open('', CAMERA);
  const shown = await settled(byDefault.page);
  assert.equal(shown.kind, 'nested', 'refined by view without being asked');
  assert.deepEqual(byDefault.problems, []);
  await byDefault.page.close();

  const { page, problems, requests } = await open('refine=uniform', '');
  await page.waitForFunction(() => /** @type {any} */ (document.querySelector('vitrine-viewer'))?.viewer?.state.status === 'complete', undefined, {
    timeout: 30_000,
  });
  const state = await page.evaluate(() => {
    const v = /** @type {any} */ (document.querySelector('vitrine-viewer')).viewer;
    return { shownLevel: v.state.shownLevel, parts: v.partsState() };
  });
  assert.equal(state.shownLevel, manifest.last_level);
  assert.equal(state.parts, null, 'no refinement by parts');
  assert.ok(!requests.some((url) => /\/parts|\/splits\/|\/head$/.test(new URL(url).pathname)), 'neither the part index nor any piece is fetched');
  assert.deepEqual(problems, []);
  await page.close();
});
