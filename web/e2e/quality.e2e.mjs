// @ts-check
// End-to-end: the quality chart on the model page (issue #5). A model
// ingested with `vitrine ingest --quality` has a curve in its manifest; the
// page plots it and moves the chart's marker to each level as it arrives. A
// model without a curve shows no chart.
import { after, before, test } from 'node:test';
import assert from 'node:assert/strict';
import { launch } from '../test/support/browser.mjs';
import { startService } from '../test/support/service.mjs';

/** @typedef {import('playwright-core').Page} Page */

/** @type {Awaited<ReturnType<typeof startService>>} */
let service;
/** @type {Awaited<ReturnType<typeof launch>>} */
let browser;

before(async () => {
  service = await startService({
    models: [
      { slug: 'measured', title: 'Measured', kind: 'torus', kiloVertices: 8, colour: true, quality: true },
      { slug: 'unmeasured', title: 'Unmeasured', kind: 'torus', kiloVertices: 8, colour: true },
    ],
  });
  browser = await launch({ width: 800, height: 600 });
});

after(async () => {
  await browser?.close();
  await service?.stop();
});

/** @param {string} slug */
async function manifest(slug) {
  return (await fetch(`${service.url}/api/models/${slug}`)).json();
}

/**
 * The chart as the visitor sees it, and the level on screen, read together.
 * @param {Page} page
 */
function chart(page) {
  return page.evaluate(() => {
    const element = /** @type {any} */ (document.querySelector('vitrine-viewer'));
    const root = element.shadowRoot;
    const figure = /** @type {HTMLElement | null} */ (root.querySelector('.quality'));
    const marker = /** @type {SVGElement | null} */ (root.querySelector('.quality [data-marker]'));
    return {
      shownLevel: /** @type {number} */ (element.viewer?.state.shownLevel ?? -1),
      inPanel: Boolean(figure && root.querySelector('.panel')?.contains(figure)),
      visible: Boolean(figure && !figure.hidden && figure.getBoundingClientRect().height > 0),
      series: [...root.querySelectorAll('.quality polyline')].map((l) => l.getAttribute('data-series')),
      marker: marker ? Number(marker.dataset.level) : null,
      caption: root.querySelector('.quality p')?.textContent ?? '',
    };
  });
}

test('a model ingested with --quality: the chart is in the panel and its marker follows each level', async () => {
  const m = await manifest('measured');
  assert.equal(m.quality?.length, m.levels.length, 'one point per level in the manifest');
  assert.ok(m.last_level >= 3, `several levels (${m.last_level})`);
  const page = await browser.context.newPage();
  /** @type {string[]} */
  const problems = [];
  page.on('pageerror', (e) => problems.push(e.message));
  // Batches are held and let through one at a time, so each level is on
  // screen on its own before the next arrives.
  /** @type {Map<number, () => void>} */
  const held = new Map();
  await page.route('**/batches/**', (route) => {
    const k = Number(route.request().url().match(/\/batches\/(\d+)/)?.[1]);
    held.set(k, () => void route.continue());
  });
  await page.goto(`${service.url}/m/measured`);
  /** @type {number[]} */
  const markers = [];
  for (let level = 0; level <= m.last_level; level++) {
    if (level > 0) {
      const deadline = Date.now() + 30_000;
      while (!held.has(level)) {
        assert.ok(Date.now() < deadline, `batch ${level} was never requested`);
        await new Promise((resolve) => setTimeout(resolve, 20));
      }
      /** @type {() => void} */ (held.get(level))();
    }
    await page.waitForFunction(
      (k) => /** @type {any} */ (document.querySelector('vitrine-viewer'))?.viewer?.state.shownLevel >= k,
      level,
      { timeout: 30_000, polling: 20 },
    );
    const seen = await chart(page);
    assert.equal(seen.shownLevel, level, 'no level skipped while batches are held');
    assert.ok(seen.visible && seen.inPanel, `the chart is shown in the info panel: ${JSON.stringify(seen)}`);
    assert.deepEqual(seen.series, ['image_rmse', 'roy_rmse']);
    assert.equal(seen.marker, level, `the marker stands at level ${level}`);
    assert.match(seen.caption, new RegExp(`^Level ${level}: image RMSE \\d`));
    markers.push(/** @type {number} */ (seen.marker));
  }
  assert.deepEqual(
    markers,
    m.levels.map((/** @type {{ level: number }} */ l) => l.level),
  );
  assert.deepEqual(problems, []);
  await page.close();
});

test('a model without a curve shows no chart', async () => {
  const m = await manifest('unmeasured');
  assert.equal(m.quality, undefined);
  const page = await browser.context.newPage();
  await page.goto(`${service.url}/m/unmeasured`);
  await page.waitForFunction(
    () => /** @type {any} */ (document.querySelector('vitrine-viewer'))?.viewer?.state.status === 'complete',
    null,
    { timeout: 60_000 },
  );
  const seen = await chart(page);
  assert.equal(seen.visible, false);
  assert.deepEqual(seen.series, []);
  assert.equal(seen.marker, null);
  await page.close();
});
