// @ts-check
// End-to-end: the relief view (issue 18). On the real service, the Relief
// button (keyboard) colours the model by its average normal deviation θ,
// computed in the decode worker, on a viridis ramp; the legend shows the
// scale in degrees; switching it off gives the normal picture back. On a
// phone-sized page the legend stays clear of the buttons and the title.
import { after, before, test } from 'node:test';
import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';
import { launch } from '../test/support/browser.mjs';
import { startService } from '../test/support/service.mjs';
import { wasmPath } from '../test/support/fixtures.mjs';
import { compareImages, foreground } from '../test/support/raster.mjs';
import { VitrineCodec } from '../src/codec.js';
import { RELIEF_AMBIENT, normalDeviation, reliefColour, reliefTop } from '../src/relief.js';

/** @typedef {import('playwright-core').Page} Page */
/** @typedef {import('../src/viewer.js').ViewerState} ViewerState */
/** @typedef {{ width: number, height: number, rgba: Uint8Array }} Image */

/** @type {Awaited<ReturnType<typeof startService>>} */
let service;
/** @type {Awaited<ReturnType<typeof launch>>} */
let browser;
/** @type {any} */
let manifest;

before(async () => {
  service = await startService({
    models: [
      // Genus 3 with sharp edges, in clay: the edges' bands stand out, and clay is grey.
      { slug: 'plate', title: 'Plate', kind: 'plate', kiloVertices: 20, policy: 'open' },
    ],
  });
  browser = await launch({ width: 800, height: 600 });
  manifest = await (await fetch(`${service.url}/api/models/plate`)).json();
});

after(async () => {
  await browser?.close();
  await service?.stop();
});

/** @param {string} path */
async function open(path) {
  const page = await browser.context.newPage();
  /** @type {string[]} */
  const problems = [];
  page.on('pageerror', (e) => problems.push(e.message));
  await page.goto(`${service.url}${path}`);
  return { page, problems };
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

/** @param {Page} page @returns {Promise<Image>} */
async function capture(page) {
  const { width, height, data } = await page.evaluate(async () => {
    const { width, height, rgba } = await /** @type {any} */ (document.querySelector('vitrine-viewer')).viewer.renderer.capture();
    let binary = '';
    for (let i = 0; i < rgba.length; i += 0x8000) binary += String.fromCharCode(...rgba.subarray(i, i + 0x8000));
    return { width, height, data: btoa(binary) };
  });
  return { width, height, rgba: new Uint8Array(Buffer.from(data, 'base64')) };
}

/** What the visitor sees of the legend and the buttons. @param {Page} page */
function chrome(page) {
  return page.evaluate(() => {
    const root = /** @type {ShadowRoot} */ (document.querySelector('vitrine-viewer')?.shadowRoot);
    const legend = /** @type {HTMLElement} */ (root.querySelector('.legend'));
    const box = (/** @type {Element} */ e) => {
      const r = e.getBoundingClientRect();
      return { left: r.left, top: r.top, right: r.right, bottom: r.bottom, width: r.width, height: r.height };
    };
    return {
      pressed: root.querySelector('[data-action="relief"]')?.getAttribute('aria-pressed'),
      legendHidden: legend.hidden,
      legend: box(legend),
      label: legend.getAttribute('aria-label'),
      title: /** @type {HTMLElement} */ (legend.querySelector('.legend-title')).innerText,
      ticks: [...legend.querySelectorAll('.legend-ticks span')].map((s) => /** @type {HTMLElement} */ (s).innerText),
      buttons: [...root.querySelectorAll('.tools button')]
        .filter((b) => /** @type {HTMLElement} */ (b).offsetParent !== null)
        .map((b) => ({ text: /** @type {HTMLElement} */ (b).innerText, ...box(b) })),
      panel: box(/** @type {Element} */ (root.querySelector('.panel'))),
      host: box(/** @type {Element} */ (document.querySelector('vitrine-viewer'))),
    };
  });
}

/**
 * Interior foreground pixels (the pixel and its four neighbours off the
 * background: no antialiased silhouette), as [r, g, b] 0..255.
 * @param {Image} image
 */
function interior(image) {
  const mask = foreground(image.rgba);
  const { width, height, rgba } = image;
  /** @type {number[][]} */
  const pixels = [];
  for (let y = 1; y < height - 1; y++) {
    for (let x = 1; x < width - 1; x++) {
      const p = y * width + x;
      if (mask[p] && mask[p - 1] && mask[p + 1] && mask[p - width] && mask[p + width]) {
        pixels.push([rgba[4 * p], rgba[4 * p + 1], rgba[4 * p + 2]]);
      }
    }
  }
  return pixels;
}

/** Samples of the lit ramp: k · reliefColour(t), as the shader's head-light can make them. */
const LIT_RAMP = (() => {
  /** @type {Array<{ t: number, rgb: number[] }>} */
  const samples = [];
  for (let i = 0; i <= 128; i++) {
    for (let j = 0; j <= 16; j++) {
      const k = RELIEF_AMBIENT + ((1 - RELIEF_AMBIENT) * j) / 16;
      samples.push({ t: i / 128, rgb: reliefColour(i / 128).map((c) => 255 * k * c) });
    }
  }
  return samples;
})();

/**
 * The ramp position of a pixel, if it is a lit ramp colour (within 10 of
 * 255 on every channel), else null.
 * @param {number[]} pixel
 */
function onRamp(pixel) {
  let best = Infinity;
  let t = 0;
  for (const s of LIT_RAMP) {
    const d = Math.max(Math.abs(pixel[0] - s.rgb[0]), Math.abs(pixel[1] - s.rgb[1]), Math.abs(pixel[2] - s.rgb[2]));
    if (d < best) {
      best = d;
      t = s.t;
    }
  }
  return best <= 10 ? t : null;
}

/** Chroma (max − min channel) of a pixel. @param {number[]} p */
function chroma(p) {
  return Math.max(...p) - Math.min(...p);
}

/** The last level as the service serves it, decoded in Node. */
async function lastLevel() {
  const codec = await VitrineCodec.instantiate(readFileSync(wasmPath));
  const bytes = async (/** @type {string} */ url) => new Uint8Array(await (await fetch(`${service.url}${url}`)).arrayBuffer());
  const decoder = codec.decoder(await bytes(manifest.levels[0].url));
  for (const level of manifest.levels.slice(1)) decoder.apply(await bytes(level.url));
  const last = decoder.level();
  decoder.free();
  return last;
}

test('Relief (keyboard): θ on the ramp with a legend in degrees; switched off, the normal view again', async (t) => {
  const { page, problems } = await open('/m/plate');
  const done = await until(page, `s.status === 'complete'`);
  assert.equal(done.shownLevel, manifest.last_level);
  const normal = await capture(page);
  let seen = await chrome(page);
  assert.equal(seen.pressed, 'false');
  assert.equal(seen.legendHidden, true);

  // The button takes the keyboard like any other: focus it, press Enter.
  const button = page.locator('vitrine-viewer button[data-action="relief"]');
  await button.focus();
  await page.keyboard.press('Enter');
  const on = await until(page, `s.relief && s.reliefTop !== null`);
  await page.waitForFunction(() => /** @type {any} */ (document.querySelector('vitrine-viewer')).viewer.renderer.settled);
  seen = await chrome(page);
  assert.equal(seen.pressed, 'true');
  assert.equal(seen.legendHidden, false);
  assert.ok(seen.legend.width > 100 && seen.legend.height > 20, `legend box ${JSON.stringify(seen.legend)}`);
  assert.equal(
    seen.label,
    `Relief legend: normal deviation θ from 0° (dark purple) to ${on.reliefTop}° or more (yellow), the 98th percentile of this level`,
  );
  assert.match(seen.title, /Normal deviation θ/);
  // Tick labels are text in degrees, from 0° to the scale's top.
  assert.ok(seen.ticks.length >= 2, `ticks ${seen.ticks}`);
  assert.equal(seen.ticks[0], '0°');
  for (const tick of seen.ticks) assert.match(tick, /^(≥ )?\d+(\.\d+)?°$/);
  assert.equal(seen.ticks[seen.ticks.length - 1], `≥ ${on.reliefTop}°`);

  // The worker's scale is the one Node computes from the same level.
  const last = await lastLevel();
  const theta = normalDeviation(last.positions, last.indices);
  assert.equal(on.reliefTop, reliefTop(theta));

  // The picture: the same silhouette, grey clay turned into ramp colours.
  const relief = await capture(page);
  const score = compareImages(normal.rgba, relief.rgba);
  t.diagnostic(`scale top ${on.reliefTop}°, ticks ${seen.ticks.join(' ')}; normal vs relief ${JSON.stringify(score)}`);
  assert.ok(score.iou > 0.995, `silhouette: ${JSON.stringify(score)}`);
  assert.ok(score.meanDiff > 20, `colours changed: ${JSON.stringify(score)}`);
  const clay = interior(normal);
  const coloured = interior(relief);
  const chromatic = (/** @type {number[][]} */ ps) => ps.filter((p) => chroma(p) > 40).length / ps.length;
  assert.ok(chromatic(clay) < 0.01, `clay is grey: ${chromatic(clay)}`);
  assert.ok(chromatic(coloured) > 0.9, `relief is coloured: ${chromatic(coloured)}`);
  const positions = coloured.map(onRamp);
  const fitted = /** @type {number[]} */ (positions.filter((p) => p !== null));
  t.diagnostic(`${fitted.length} of ${coloured.length} interior pixels on the lit ramp`);
  assert.ok(fitted.length > 0.95 * coloured.length, `pixels on the ramp: ${fitted.length} of ${coloured.length}`);
  // Both ends of the scale are on screen: flat faces low, the bands beside the edges high.
  assert.ok(fitted.filter((x) => x < 0.2).length > 0.2 * fitted.length, 'low θ (the flat faces)');
  assert.ok(fitted.some((x) => x > 0.7), 'high θ (beside the edges)');

  // Enter again: off, and the normal picture back.
  await page.keyboard.press('Enter');
  await until(page, `!s.relief && s.reliefTop === null`);
  seen = await chrome(page);
  assert.equal(seen.pressed, 'false');
  assert.equal(seen.legendHidden, true);
  const back = compareImages(normal.rgba, (await capture(page)).rgba);
  assert.ok(back.iou > 0.999 && back.meanDiff < 0.5, `normal view restored: ${JSON.stringify(back)}`);
  assert.deepEqual(problems, []);
  await page.close();
});

test('switched on while refining: every later level arrives with its θ, the legend follows the level on screen', async () => {
  const page = await browser.context.newPage();
  /** @type {Array<() => void>} */
  const held = [];
  await page.route('**/batches/**', (route) => held.push(() => void route.continue()));
  await page.goto(`${service.url}/m/plate`);
  await until(page, `s.shownLevel === 0`);
  await page.locator('vitrine-viewer button[data-action="relief"]').click();
  const base = await until(page, `s.reliefTop !== null`);
  assert.equal(base.shownLevel, 0);
  // Every change of the legend from now on: a level drawn without its θ
  // would show "computing" until θ came after it.
  await page.evaluate(() => {
    const title = /** @type {Element} */ (document.querySelector('vitrine-viewer')?.shadowRoot?.querySelector('.legend-title'));
    const texts = (/** @type {any} */ (window).__legend = /** @type {string[]} */ ([]));
    new MutationObserver(() => texts.push(String(title.textContent))).observe(title, { childList: true, characterData: true, subtree: true });
  });
  for (const release of held.splice(0)) release();
  await page.unroute('**/batches/**');
  const done = await until(page, `s.status === 'complete' && s.reliefTop !== null`);
  assert.equal(done.shownLevel, manifest.last_level);
  assert.ok(Object.keys(done.shownAtMs).length > 2, `levels drawn: ${Object.keys(done.shownAtMs)}`);
  const texts = await page.evaluate(() => /** @type {string[]} */ (/** @type {any} */ (window).__legend));
  assert.ok(!texts.some((text) => /computing/.test(text)), `legend while refining: ${JSON.stringify(texts)}`);
  await page.waitForFunction(() => /** @type {any} */ (document.querySelector('vitrine-viewer')).viewer.renderer.settled);
  const seen = await chrome(page);
  assert.equal(seen.ticks[seen.ticks.length - 1], `≥ ${done.reliefTop}°`);
  const last = await lastLevel();
  assert.equal(done.reliefTop, reliefTop(normalDeviation(last.positions, last.indices)));
  await page.close();
});

test('on a phone (390 px wide) the legend is on screen and clear of the buttons and the title', async () => {
  const page = await browser.context.newPage();
  await page.setViewportSize({ width: 390, height: 844 });
  await page.goto(`${service.url}/m/plate`);
  await until(page, `s.shownLevel >= 0`);
  await page.locator('vitrine-viewer button[data-action="relief"]').click();
  await until(page, `s.reliefTop !== null`);
  const seen = await chrome(page);
  assert.equal(seen.legendHidden, false);
  assert.ok(seen.buttons.some((b) => b.text === 'Relief'), `buttons ${seen.buttons.map((b) => b.text)}`);
  const { legend, host } = seen;
  assert.ok(legend.left >= host.left && legend.right <= host.right, `legend inside the viewer: ${JSON.stringify(legend)}`);
  assert.ok(legend.top >= host.top && legend.bottom <= host.bottom, `legend inside the viewer: ${JSON.stringify(legend)}`);
  for (const b of seen.buttons) {
    assert.ok(b.right <= host.right && b.left >= host.left, `${b.text} on screen: ${JSON.stringify(b)}`);
    const overlap = legend.left < b.right && b.left < legend.right && legend.top < b.bottom && b.top < legend.bottom;
    assert.ok(!overlap, `legend ${JSON.stringify(legend)} overlaps ${b.text} ${JSON.stringify(b)}`);
    // The title panel moves under the buttons on a narrow screen.
    assert.ok(seen.panel.top >= b.bottom, `panel ${JSON.stringify(seen.panel)} beside ${b.text} ${JSON.stringify(b)}`);
  }
  assert.ok(seen.panel.bottom <= legend.top, `panel ${JSON.stringify(seen.panel)} above the legend ${JSON.stringify(legend)}`);
  await page.close();
});

test('on the main thread (?offscreen=off) the relief view is the render worker\'s picture', async () => {
  /** @type {Image[]} */
  const images = [];
  for (const path of ['/m/plate', '/m/plate?offscreen=off']) {
    const { page, problems } = await open(path);
    await until(page, `s.status === 'complete'`);
    await page.locator('vitrine-viewer button[data-action="relief"]').click();
    await until(page, `s.reliefTop !== null`);
    await page.waitForFunction(() => /** @type {any} */ (document.querySelector('vitrine-viewer')).viewer.renderer.settled);
    const thread = await page.evaluate(() => /** @type {any} */ (document.querySelector('vitrine-viewer')).viewer.renderer.thread);
    assert.equal(thread, path.includes('offscreen=off') ? 'main' : 'worker');
    images.push(await capture(page));
    assert.deepEqual(problems, []);
    await page.close();
  }
  const score = compareImages(images[0].rgba, images[1].rgba);
  assert.ok(score.iou > 0.999 && score.meanDiff < 0.5, `worker vs main thread: ${JSON.stringify(score)}`);
});
