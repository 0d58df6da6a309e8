// @ts-check
// End-to-end: a point-cloud model against the real `vitrine serve` — a
// generated, coloured jittered cube (`vitrine sample cloud --colour`)
// ingested into a fresh SQLite file — and the built viewer in headless
// Chromium (WebGL2 on SwiftShader): the first level on screen while the
// later levels are held back, refined to the last; a cut batch is the
// viewer's error state; a 503 with Retry-After and a load cap are handled
// as for a mesh; the mesh-only tools are hidden; the gallery lists it.
import { after, before, test } from 'node:test';
import assert from 'node:assert/strict';
import { launch, noticeMatching } from '../test/support/browser.mjs';
import { startService } from '../test/support/service.mjs';
import { foreground } from '../test/support/raster.mjs';

/** @typedef {import('playwright-core').Page} Page */
/** @typedef {import('../src/viewer.js').ViewerState} ViewerState */

const WIDTH = 480;
const HEIGHT = 360;

/** @type {Awaited<ReturnType<typeof startService>>} */
let service;
/** @type {Awaited<ReturnType<typeof launch>>} */
let browser;
/** @type {any} */
let manifest;

before(async () => {
  service = await startService({
    models: [{ slug: 'cube', title: 'Jittered cube', description: 'A generated point cloud.', kind: 'cloud', kiloVertices: 20, colour: true }],
  });
  browser = await launch({ width: WIDTH, height: HEIGHT });
  manifest = await (await fetch(`${service.url}/api/models/cube`)).json();
  assert.equal(manifest.kind, 'points');
  assert.ok(manifest.last_level >= 2, `the cloud has several levels (${manifest.last_level + 1})`);
});

after(async () => {
  await browser?.close();
  await service?.stop();
});

/** @param {Page} page */
function watch(page) {
  /** @type {string[]} */
  const problems = [];
  page.on('pageerror', (e) => problems.push(e.message));
  // The levels the page hears of, in order (the embedding page's event).
  return page
    .addInitScript(() => {
      /** @type {any} */ (window).levels = [];
      document.addEventListener('vitrine-level', (e) => /** @type {any} */ (window).levels.push(/** @type {CustomEvent} */ (e).detail.level));
    })
    .then(() => problems);
}

/**
 * @param {Page} page
 * @param {string} condition JS expression over `s` (the viewer's state)
 * @param {number} [timeout]
 * @returns {Promise<ViewerState>}
 */
async function until(page, condition, timeout = 60_000) {
  await page.waitForFunction(
    (body) => {
      const s = /** @type {any} */ (document.querySelector('vitrine-viewer'))?.viewer?.state;
      return s ? new Function('s', `return (${body});`)(s) : false;
    },
    condition,
    { timeout, polling: 50 },
  );
  return page.evaluate(() => /** @type {any} */ (document.querySelector('vitrine-viewer')).viewer.state);
}

/** The splat canvas's pixels, drawn and read now. @param {Page} page */
async function capture(page) {
  const c = await page.evaluate(() => {
    const { width, height, rgba } = /** @type {any} */ (document.querySelector('vitrine-viewer')).viewer.points.view.capture();
    let binary = '';
    for (let i = 0; i < rgba.length; i += 0x8000) binary += String.fromCharCode(...rgba.subarray(i, i + 0x8000));
    return { width, height, data: btoa(binary) };
  });
  return { ...c, rgba: new Uint8Array(Buffer.from(c.data, 'base64')) };
}

/** @param {Uint8Array} mask */
const count = (mask) => mask.reduce((s, v) => s + v, 0);

/** @param {Page} page @param {string} selector */
function shadow(page, selector) {
  return page.evaluate((s) => {
    const e = /** @type {HTMLElement | null} */ (document.querySelector('vitrine-viewer')?.shadowRoot?.querySelector(s) ?? null);
    return e ? { hidden: e.hidden || getComputedStyle(e).display === 'none', text: e.innerText } : null;
  }, selector);
}

test('a point-cloud model page draws its first level at once, while the later levels are held back, and refines to the last', async () => {
  const page = await browser.context.newPage();
  const problems = await watch(page);
  /** @type {Array<() => void>} */
  const held = [];
  await page.route('**/batches/**', (route) => held.push(() => void route.continue()));
  await page.goto(`${service.url}/m/cube`);
  const first = await until(page, 's.shownLevel === 0');
  assert.equal(first.status, 'refining');
  assert.equal(first.antialias, false, 'the splat view says it does not multisample');
  assert.deepEqual(Object.keys(first.shownAtMs).map(Number), [0], 'only the first level was drawn');
  assert.equal(first.vertices, manifest.levels[0].points ?? manifest.levels[0].vertices);
  const coarse = await capture(page);
  const coarseShown = count(foreground(coarse.rgba));
  assert.ok(coarseShown > 0.05 * coarse.width * coarse.height, `the first level covers the view (${coarseShown} px)`);
  assert.ok(held.length >= 1, 'a later level was asked for and held');
  for (const release of held) release();
  await page.unroute('**/batches/**');
  const done = await until(page, "s.status === 'complete'");
  assert.equal(done.shownLevel, manifest.last_level);
  assert.equal(done.vertices, manifest.levels[manifest.last_level].points ?? manifest.levels[manifest.last_level].vertices);
  const levels = Array.from({ length: manifest.last_level + 1 }, (_, k) => k);
  assert.deepEqual(Object.keys(done.shownAtMs).map(Number), levels, 'every level was drawn');
  await page.waitForFunction((n) => /** @type {any} */ (window).levels.length === n, levels.length);
  assert.deepEqual(await page.evaluate(() => /** @type {any} */ (window).levels), levels, 'a vitrine-level event per level, in order');
  const fine = await capture(page);
  const fineShown = count(foreground(fine.rgba));
  let changed = 0;
  for (let p = 0; p < fine.rgba.length; p += 4) if (Math.abs(fine.rgba[p] - coarse.rgba[p]) + Math.abs(fine.rgba[p + 1] - coarse.rgba[p + 1]) + Math.abs(fine.rgba[p + 2] - coarse.rgba[p + 2]) > 24) changed++;
  console.log(`# cube: level 0 ${coarseShown} px, level ${manifest.last_level} ${fineShown} px, ${changed} px changed`);
  assert.ok(fineShown > 0.05 * fine.width * fine.height, `the last level covers the view (${fineShown} px)`);
  assert.ok(changed > 0.01 * fine.width * fine.height, `refinement changed the picture (${changed} px)`);
  assert.equal((await shadow(page, '.error'))?.hidden, true);
  assert.deepEqual(problems, []);
  await page.close();
});

test("a cut batch of the point stream shows the viewer's error state over the first level", async () => {
  const page = await browser.context.newPage();
  await page.route('**/batches/1*', async (route) => {
    const response = await route.fetch();
    const body = await response.body();
    await route.fulfill({ response, body: body.subarray(0, body.length >> 1), headers: { ...response.headers(), 'content-length': String(body.length >> 1) } });
  });
  await page.goto(`${service.url}/m/cube`);
  const state = await until(page, "s.status === 'error'");
  assert.equal(state.shownLevel, 0, 'the first level stays on screen');
  assert.match(String(state.message), /could not decode level 2 of the point stream/);
  const error = await shadow(page, '.error');
  assert.equal(error?.hidden, false, 'the error is on screen');
  assert.match(String(error?.text), /Could not show this model/);
  // Try again, with the batch whole: the model loads.
  await page.unroute('**/batches/1*');
  await page.evaluate(() => /** @type {HTMLElement} */ (document.querySelector('vitrine-viewer')?.shadowRoot?.querySelector('[data-action="retry"]')).click());
  const done = await until(page, "s.status === 'complete'");
  assert.equal(done.shownLevel, manifest.last_level);
  assert.equal((await shadow(page, '.error'))?.hidden, true);
  await page.close();
});

test('a batch answered 503 with Retry-After is waited for and fetched again', async () => {
  const page = await browser.context.newPage();
  let asked = 0;
  await page.route('**/batches/1*', async (route) => {
    if (++asked === 1) {
      await route.fulfill({ status: 503, headers: { 'retry-after': '1' }, json: { error: 'unavailable', message: 'shedding load', retry_after_s: 1 } });
    } else await route.continue();
  });
  await page.goto(`${service.url}/m/cube`);
  const done = await until(page, "s.status === 'complete'");
  assert.equal(done.shownLevel, manifest.last_level);
  assert.equal(asked, 2);
  await page.close();
});

test('a batch refused by a load cap holds the cloud at the level before, says so, and resumes', async () => {
  const page = await browser.context.newPage();
  // The cap holds until the notice has been read: a retry every second
  // must not lift it while a loaded machine is still polling.
  let lifted = false;
  let refused = 0;
  await page.route('**/batches/2*', async (route) => {
    if (!lifted) {
      refused++;
      await route.fulfill({
        status: 429,
        headers: { 'retry-after': '1' },
        json: { error: 'level_capped', reason: 'load', message: 'the server is busy', retry_after_s: 1 },
      });
    } else await route.continue();
  });
  await page.goto(`${service.url}/m/cube`);
  const capped = await until(page, "s.status === 'capped'");
  assert.equal(capped.shownLevel, 1);
  const expected = /^Refinement limited to level 1 of \d+: the server is busy; trying again every 1 s\.$/;
  await noticeMatching(page, expected);
  lifted = true;
  const done = await until(page, "s.status === 'complete'", 30_000);
  assert.equal(done.shownLevel, manifest.last_level);
  assert.equal((await shadow(page, '.notice'))?.hidden, true);
  assert.ok(refused >= 1);
  await page.close();
});

test('the tools that read a mesh are hidden on a point model', async () => {
  const page = await browser.context.newPage();
  await page.goto(`${service.url}/m/cube`);
  await until(page, 's.shownLevel >= 0');
  for (const action of ['wireframe', 'relief', 'measure', 'splats']) {
    assert.equal((await shadow(page, `[data-action="${action}"]`))?.hidden, true, `${action} hidden`);
  }
  for (const action of ['reset', 'fullscreen']) {
    assert.equal((await shadow(page, `[data-action="${action}"]`))?.hidden, false, `${action} shown`);
  }
  await page.close();
});

test('the gallery lists the point cloud', async () => {
  const page = await browser.context.newPage();
  await page.goto(`${service.url}/`);
  await page.getByRole('link', { name: /Jittered cube/ }).first().waitFor({ timeout: 30_000 });
  await page.close();
});
