// @ts-check
// End-to-end: the real `vitrine serve` with a generated, ingested model, and
// the built viewer in headless Chromium (WebGL2 on SwiftShader).
import { after, before, test } from 'node:test';
import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';
import { createServer } from 'node:http';
import { launch, noticeMatching } from '../test/support/browser.mjs';
import { startService } from '../test/support/service.mjs';
import { wasmPath } from '../test/support/fixtures.mjs';
import { compareImages, foreground, rasterize } from '../test/support/raster.mjs';
import { VitrineCodec } from '../src/codec.js';
import { OrbitCamera } from '../src/camera.js';
import { vertexNormals } from '../src/geometry.js';

/** @typedef {import('playwright-core').Page} Page */
/** @typedef {import('../src/viewer.js').ViewerState} ViewerState */

const WIDTH = 640;
const HEIGHT = 480;
/** Phone budget for the capped case: a few levels of the 30 k-vertex torus. */
const PHONE_MAX_VERTICES = 3000;

/** @type {Awaited<ReturnType<typeof startService>>} */
let service;
/** @type {Awaited<ReturnType<typeof launch>>} */
let browser;
/** @type {any} */
let manifest;

before(async () => {
  service = await startService({
    models: [
      {
        slug: 'torus',
        title: 'Torus',
        description: 'A generated torus with a painted pattern.',
        kind: 'torus',
        kiloVertices: 30,
        colour: true,
        policy: 'open',
      },
      {
        slug: 'charted',
        title: 'Charted torus',
        kind: 'torus',
        kiloVertices: 30,
        colour: true,
        policy: 'open',
        ingestArgs: ['--charts', '4'],
      },
    ],
    serveArgs: ['--phone-max-vertices', String(PHONE_MAX_VERTICES)],
  });
  browser = await launch({ width: WIDTH, height: HEIGHT, hasTouch: true });
  manifest = await (await fetch(`${service.url}/api/models/torus`)).json();
  assert.ok(manifest.last_level >= 4, 'the test model has several levels');
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
 */
async function until(page, condition, timeout = 30_000) {
  await page.waitForFunction(
    (body) => {
      const s = /** @type {any} */ (document.querySelector('vitrine-viewer'))?.viewer?.state;
      return s ? new Function('s', `return (${body});`)(s) : false;
    },
    condition,
    { timeout, polling: 50 },
  );
  return state(page);
}

/** @param {Page} page @returns {Promise<ViewerState>} */
function state(page) {
  return page.evaluate(() => /** @type {any} */ (document.querySelector('vitrine-viewer')).viewer.state);
}

/**
 * The canvas's pixels (RGBA, bottom-up), drawn and read in one task (of the thread that draws).
 * @param {Page} page
 */
async function capture(page) {
  const { width, height, data } = await page.evaluate(async () => {
    // Drawn and read in the render worker, or on the main thread (the fallback).
    const { width, height, rgba } = await /** @type {any} */ (document.querySelector('vitrine-viewer')).viewer.renderer.capture();
    let binary = '';
    for (let i = 0; i < rgba.length; i += 0x8000) binary += String.fromCharCode(...rgba.subarray(i, i + 0x8000));
    return { width, height, data: btoa(binary) };
  });
  return { width, height, rgba: new Uint8Array(Buffer.from(data, 'base64')) };
}

/** @param {Page} page */
function camera(page) {
  return page.evaluate(() => {
    const c = /** @type {any} */ (document.querySelector('vitrine-viewer')).viewer.camera;
    return { state: structuredClone(c.state), radius: c.radius };
  });
}

/** @param {Page} page @param {string} selector */
function shadowText(page, selector) {
  return page.evaluate(
    (s) => /** @type {HTMLElement} */ (document.querySelector('vitrine-viewer')?.shadowRoot?.querySelector(s)).innerText,
    selector,
  );
}

/** @param {Page} page @param {string} selector */
function shadowHidden(page, selector) {
  return page.evaluate(
    (s) => /** @type {HTMLElement} */ (document.querySelector('vitrine-viewer')?.shadowRoot?.querySelector(s)).hidden,
    selector,
  );
}

/**
 * Fraction of foreground pixels inside a box given in fractions of the image.
 * @param {{ width: number, height: number, rgba: Uint8Array }} image
 * @param {[number, number, number, number]} box x0, y0, x1, y1 in 0..1
 */
function coverage(image, box) {
  const mask = foreground(image.rgba);
  let hit = 0;
  let all = 0;
  for (let y = Math.floor(box[1] * image.height); y < box[3] * image.height; y++) {
    for (let x = Math.floor(box[0] * image.width); x < box[2] * image.width; x++) {
      all++;
      hit += mask[y * image.width + x];
    }
  }
  return hit / all;
}

/** The last level, decoded in Node from what the service serves. */
async function finalLevelFromService() {
  const codec = await VitrineCodec.instantiate(readFileSync(wasmPath));
  const bytes = async (/** @type {string} */ url) =>
    new Uint8Array(await (await fetch(`${service.url}${url}`)).arrayBuffer());
  const decoder = codec.decoder(await bytes(manifest.levels[0].url));
  const base = decoder.level();
  for (const level of manifest.levels.slice(1)) decoder.apply(await bytes(level.url));
  const last = decoder.level();
  decoder.free();
  return { base, last };
}

test('the gallery lists the model with a link to its page', async () => {
  const { page, problems } = await open('/');
  const link = page.locator('a[href="/m/torus"]');
  await link.waitFor();
  assert.match(await link.innerText(), /Torus/);
  assert.deepEqual(problems, []);
  await page.close();
});

test('the base mesh is drawn at once, before any batch arrives', async () => {
  const page = await browser.context.newPage();
  /** @type {Array<() => void>} */
  const held = [];
  await page.route('**/batches/**', (route) => held.push(() => void route.continue()));
  await page.goto(`${service.url}/embed/torus`);
  const s = await until(page, 's.shownLevel === 0 && 0 in s.shownAtMs');
  assert.equal(s.decodedLevel, 0);
  const image = await capture(page);
  assert.equal(image.width, WIDTH);
  // The model sits in the middle with a margin all round.
  assert.ok(coverage(image, [0.3, 0.3, 0.7, 0.7]) > 0.2, 'model pixels in the middle');
  assert.equal(coverage(image, [0, 0, 1, 0.04]), 0, 'empty top rows');
  assert.equal(coverage(image, [0, 0.96, 1, 1]), 0, 'empty bottom rows');
  assert.match(await shadowText(page, '.progress'), new RegExp(`^Level 0 of ${manifest.last_level} · ${manifest.levels[0].vertices} vertices`));
  for (const release of held) release();
  await page.unroute('**/batches/**');
  await until(page, `s.status === 'complete'`);
  await page.close();
});

test('refines to level n of n; the image matches a direct load and a CPU reference', async (t) => {
  const { page, problems } = await open('/embed/torus');
  /** @type {string[]} */
  const batches = [];
  page.on('request', (r) => r.url().includes('/batches/') && batches.push(r.url()));
  const n = manifest.last_level;
  const s = await until(page, `s.status === 'complete'`);
  assert.equal(s.shownLevel, n);
  assert.equal(s.vertices, manifest.levels[n].vertices);
  assert.match(await shadowText(page, '.progress'), new RegExp(`^Level ${n} of ${n} · `));
  const progressive = await capture(page);
  const view = await camera(page);

  const direct = await open(`/embed/torus?level=${n}`);
  await until(direct.page, `s.status === 'complete'`);
  const once = await capture(direct.page);
  const same = compareImages(progressive.rgba, once.rgba);
  assert.ok(same.iou > 0.999 && same.meanDiff < 0.5, `progressive vs direct: ${JSON.stringify(same)}`);

  const { base, last } = await finalLevelFromService();
  const reference = new OrbitCamera({ min: [0, 0, 0], max: [1, 1, 1] });
  reference.radius = view.radius;
  reference.state = view.state;
  const cpu = rasterize({
    positions: last.positions,
    normals: vertexNormals(last.positions, last.indices),
    colours: last.colours,
    indices: last.indices,
    view: reference.view(),
    projection: reference.projection(WIDTH / HEIGHT),
    width: WIDTH,
    height: HEIGHT,
  });
  const score = compareImages(progressive.rgba, cpu);
  t.diagnostic(`progressive vs direct ${JSON.stringify(same)}; vs CPU reference ${JSON.stringify(score)}`);
  assert.ok(score.iou > 0.98, `silhouette vs CPU reference: ${JSON.stringify(score)}`);
  assert.ok(score.meanDiff < 2 && score.badFraction < 0.01, `shading vs CPU reference: ${JSON.stringify(score)}`);
  assert.ok(base.vertices < last.vertices);
  assert.deepEqual(problems, []);
  await page.close();
  await direct.page.close();
});

test('a charted stream is refined by the decode worker and a helper; the picture is one decoder\'s', async () => {
  const charted = await (await fetch(`${service.url}/api/models/charted`)).json();
  assert.equal(charted.stream_format, 5);
  const n = charted.last_level;
  /** @type {Record<number, { width: number, height: number, rgba: Uint8Array }>} */
  const images = {};
  for (const decoders of [1, 2, 4]) {
    const { page, problems } = await open(`/embed/charted?decoders=${decoders}`);
    /** @type {string[]} */
    const helpers = [];
    page.on('request', (r) => r.url().endsWith('/chart-worker.js') && helpers.push(r.url()));
    const s = await until(page, `s.status === 'complete'`);
    assert.equal(s.shownLevel, n);
    assert.equal(s.vertices, charted.levels[n].vertices);
    assert.equal(s.decoders, decoders, `${decoders} workers decode`);
    // The helper script is fetched once (the browser's cache serves the others).
    assert.equal(helpers.length > 0, decoders > 1, `helpers started: ${helpers.length}`);
    assert.deepEqual(problems, []);
    images[decoders] = await capture(page);
    await page.close();
  }
  for (const decoders of [2, 4]) {
    const same = compareImages(images[1].rgba, images[decoders].rgba);
    assert.ok(same.iou > 0.999 && same.meanDiff < 0.5, `${decoders} workers against one: ${JSON.stringify(same)}`);
  }
  // A plain stream never starts helpers.
  const plain = await open('/embed/torus?decoders=4');
  const s = await until(plain.page, `s.status === 'complete'`);
  assert.equal(s.decoders, 1);
  await plain.page.close();
});

test('a phone stops at its cap, says so, and fetches nothing above it', async () => {
  const capped = await (await fetch(`${service.url}/api/models/torus?device=phone`)).json();
  const cap = capped.cap.level;
  assert.ok(cap > 0 && cap < manifest.last_level, `cap ${cap}`);
  const page = await browser.context.newPage();
  /** @type {number[]} */
  const requested = [];
  page.on('request', (r) => {
    const m = r.url().match(/\/batches\/(\d+)/);
    if (m) requested.push(Number(m[1]));
  });
  await page.goto(`${service.url}/m/torus?device=phone`);
  const s = await until(page, `s.status === 'capped'`);
  assert.equal(s.shownLevel, cap);
  const notice = await shadowText(page, '.notice');
  assert.equal(notice, `Refinement limited to level ${cap} of ${manifest.last_level}: that is the most detail sent to a phone.`);
  assert.equal(await shadowHidden(page, '.notice'), false);
  await page.waitForTimeout(300);
  assert.ok(Math.max(...requested) <= cap, `requested ${requested}`);
  await page.close();
});

test('a load cap is retried and refinement resumes when it rises', async () => {
  const page = await browser.context.newPage();
  let manifests = 0;
  // The cap holds until the notice has been read: a retry every second
  // must not lift it while a loaded machine is still polling.
  let lifted = false;
  await page.route('**/api/models/torus*', async (route) => {
    manifests++;
    const response = await route.fetch();
    const body = await response.json();
    if (!lifted) {
      body.cap = { ...body.cap, level: 2, reason: 'load', retry_after_s: 1 };
    }
    await route.fulfill({ response, json: body });
  });
  await page.goto(`${service.url}/m/torus`);
  const capped = await until(page, `s.status === 'capped'`);
  assert.equal(capped.shownLevel, 2);
  await noticeMatching(page, /^Refinement limited to level 2 of \d+: the server is busy; trying again every 1 s\.$/);
  lifted = true;
  const done = await until(page, `s.status === 'complete'`, 15_000);
  assert.equal(done.shownLevel, manifest.last_level);
  assert.equal(await shadowHidden(page, '.notice'), true);
  assert.ok(manifests >= 2);
  // The vertex buffers were sized for level 2 and grew when the cap rose: the picture is the direct load's.
  await page.waitForFunction(() => /** @type {any} */ (document.querySelector('vitrine-viewer')).viewer.renderer.settled);
  const resumed = await capture(page);
  const direct = await open(`/m/torus?level=${manifest.last_level}`);
  await until(direct.page, `s.status === 'complete'`);
  const score = compareImages(resumed.rgba, (await capture(direct.page)).rgba);
  assert.ok(score.iou > 0.999 && score.meanDiff < 0.5, `resumed vs direct: ${JSON.stringify(score)}`);
  await page.close();
  await direct.page.close();
});

test('a visitor refused in a surge (503 busy, Retry-After) is told so, waits and loads', async () => {
  const page = await browser.context.newPage();
  let manifests = 0;
  /** @type {number[]} */
  const asked = [];
  await page.route('**/api/models/torus*', async (route) => {
    manifests++;
    asked.push(Date.now());
    if (manifests <= 2) {
      // What admission control answers (server/src/service/admission.rs).
      await route.fulfill({
        status: 503,
        headers: { 'retry-after': '1', 'cache-control': 'no-store' },
        json: { error: 'busy', message: 'many visitors are arriving; come back shortly', retry_after_s: 1 },
      });
    } else {
      await route.continue();
    }
  });
  await page.goto(`${service.url}/m/torus`);
  await page.waitForFunction(
    () => /** @type {any} */ (document.querySelector('vitrine-viewer'))?.shadowRoot?.querySelector('.notice')?.textContent === 'Many visitors are arriving: starting in 1 s',
    null,
    { timeout: 10_000, polling: 20 },
  );
  const done = await until(page, `s.status === 'complete'`, 20_000);
  assert.equal(done.shownLevel, manifest.last_level);
  assert.equal(manifests, 3);
  // Each retry waited Retry-After (1 s) plus up to 1 s of jitter.
  for (let i = 1; i < asked.length; i++) {
    const gap = asked[i] - asked[i - 1];
    assert.ok(gap >= 950 && gap < 2600, `retry ${i} after ${gap} ms`);
  }
  assert.equal(await shadowHidden(page, '.notice'), true);
  assert.equal(await shadowHidden(page, '.error'), true);
  await page.close();
});

/** @param {Page} page */
function thread(page) {
  return page.evaluate(() => /** @type {any} */ (document.querySelector('vitrine-viewer')).viewer.renderer.thread);
}

/**
 * What the page's canvas gives the main thread: a context (it draws there)
 * or the error of a canvas whose control went to a worker.
 * @param {Page} page
 */
function canvasOnMainThread(page) {
  return page.evaluate(() => {
    const canvas = /** @type {HTMLCanvasElement} */ (document.querySelector('vitrine-viewer')?.shadowRoot?.querySelector('canvas'));
    try {
      return canvas.getContext('webgl2') ? 'webgl2' : 'none';
    } catch (error) {
      return /** @type {Error} */ (error).name;
    }
  });
}

test('the render worker draws the canvas where OffscreenCanvas has WebGL2; ?offscreen=off draws the same on the main thread', async () => {
  const worker = await open('/embed/torus');
  await until(worker.page, `s.status === 'complete'`);
  assert.equal(await thread(worker.page), 'worker');
  // The canvas was handed over: the page cannot draw on it any more.
  assert.equal(await canvasOnMainThread(worker.page), 'InvalidStateError');
  const inWorker = await capture(worker.page);
  assert.ok(coverage(inWorker, [0.3, 0.3, 0.7, 0.7]) > 0.2, 'model pixels in the middle');

  const main = await open('/embed/torus?offscreen=off');
  await until(main.page, `s.status === 'complete'`);
  assert.equal(await thread(main.page), 'main');
  assert.equal(await canvasOnMainThread(main.page), 'webgl2');
  // Headless Chromium draws on SwiftShader, a CPU rasteriser: neither
  // renderer multisamples there (src/rasteriser.js), which the main
  // thread's own context confirms.
  const rasteriser = await main.page.evaluate(() => {
    const gl = /** @type {WebGL2RenderingContext} */ (document.createElement('canvas').getContext('webgl2'));
    const info = gl.getExtension('WEBGL_debug_renderer_info');
    return String(gl.getParameter(info ? info.UNMASKED_RENDERER_WEBGL : gl.RENDERER));
  });
  assert.match(rasteriser, /SwiftShader/);
  for (const page of [worker.page, main.page]) {
    assert.equal(await page.evaluate(() => /** @type {any} */ (document.querySelector('vitrine-viewer')).viewer.state.antialias), false);
  }
  const canvasAntialias = await main.page.evaluate(() => {
    const canvas = /** @type {HTMLCanvasElement} */ (document.querySelector('vitrine-viewer')?.shadowRoot?.querySelector('canvas'));
    return /** @type {WebGL2RenderingContext} */ (canvas.getContext('webgl2')).getContextAttributes()?.antialias;
  });
  assert.equal(canvasAntialias, false);
  // A page can still ask for it (the documentation's screenshots do).
  const forced = await open('/embed/torus?antialias=on');
  await until(forced.page, `s.status === 'complete'`);
  assert.equal(await forced.page.evaluate(() => /** @type {any} */ (document.querySelector('vitrine-viewer')).viewer.state.antialias), true);
  await forced.page.close();
  const onMain = await capture(main.page);
  const score = compareImages(inWorker.rgba, onMain.rgba);
  assert.ok(score.iou > 0.999 && score.meanDiff < 0.5, `worker vs main thread: ${JSON.stringify(score)}`);
  assert.deepEqual([...worker.problems, ...main.problems], []);
  await worker.page.close();
  await main.page.close();
});

test('where workers have no WebGL2, the viewer keeps its canvas and draws on the main thread', async () => {
  const page = await browser.context.newPage();
  /** @type {string[]} */
  const problems = [];
  page.on('pageerror', (e) => problems.push(e.message));
  await page.addInitScript(() => {
    // A render worker that answers as one without WebGL2 would (Safari 16.4: OffscreenCanvas, 2D only).
    const Original = window.Worker;
    /** @type {any} */ (window).Worker = function (/** @type {string | URL} */ url, /** @type {any} */ options) {
      if (!String(url).includes('render-worker')) return new Original(url, options);
      const stub = `postMessage({ type: 'ready', webgl2: false });`;
      return new Original(URL.createObjectURL(new Blob([stub], { type: 'text/javascript' })));
    };
  });
  await page.goto(`${service.url}/embed/torus`);
  const s = await until(page, `s.status === 'complete'`);
  assert.equal(s.shownLevel, manifest.last_level);
  assert.equal(await thread(page), 'main');
  assert.equal(await canvasOnMainThread(page), 'webgl2');
  const image = await capture(page);
  assert.ok(coverage(image, [0.3, 0.3, 0.7, 0.7]) > 0.2, 'model pixels in the middle');
  assert.deepEqual(problems, []);
  await page.close();
});

test('a lost WebGL context is restored with the model on the main thread too (fallback)', async () => {
  const { page } = await open('/embed/torus?offscreen=off');
  await until(page, `s.status === 'complete'`);
  assert.equal(await thread(page), 'main');
  const before = await capture(page);
  await page.evaluate(() => /** @type {any} */ (document.querySelector('vitrine-viewer')).viewer.renderer.loseContext());
  await page.waitForFunction(() => /** @type {any} */ (document.querySelector('vitrine-viewer')).viewer.renderer.lost);
  await page.evaluate(() => /** @type {any} */ (document.querySelector('vitrine-viewer')).viewer.renderer.restoreContext());
  await page.waitForFunction(() => {
    const r = /** @type {any} */ (document.querySelector('vitrine-viewer')).viewer.renderer;
    return !r.lost && r.settled;
  });
  const score = compareImages(before.rgba, (await capture(page)).rgba);
  assert.ok(score.iou > 0.999 && score.meanDiff < 0.5, JSON.stringify(score));
  await page.close();
});

test('touch: one finger turns, a pinch zooms, two fingers pan', async () => {
  const { page } = await open('/embed/torus');
  await until(page, `s.status === 'complete'`);
  const cdp = await browser.context.newCDPSession(page);
  /**
   * @param {'touchStart' | 'touchMove' | 'touchEnd'} type
   * @param {Array<[number, number]>} points
   */
  const touch = (type, points) =>
    cdp.send('Input.dispatchTouchEvent', {
      type,
      touchPoints: points.map(([x, y], id) => ({ x, y, id, radiusX: 5, radiusY: 5, force: 1 })),
    });
  /** @param {Array<[number, number]>} from @param {Array<[number, number]>} to */
  const gesture = async (from, to) => {
    await touch('touchStart', from);
    for (let step = 1; step <= 8; step++) {
      const t = step / 8;
      await touch('touchMove', from.map(([x, y], i) => [x + (to[i][0] - x) * t, y + (to[i][1] - y) * t]));
    }
    await touch('touchEnd', []);
  };
  const before = await camera(page);
  const image = await capture(page);
  await gesture([[320, 240]], [[420, 260]]);
  const turned = await camera(page);
  assert.ok(Math.abs(turned.state.yaw - before.state.yaw) > 0.3, `yaw ${before.state.yaw} → ${turned.state.yaw}`);
  assert.ok(Math.abs(turned.state.pitch - before.state.pitch) > 0.05, 'pitch');
  assert.equal(turned.state.distance, before.state.distance);
  const after = await capture(page);
  assert.ok(compareImages(image.rgba, after.rgba).meanDiff > 3, 'the picture changed');

  await gesture([[270, 240], [370, 240]], [[170, 240], [470, 240]]);
  const zoomed = await camera(page);
  assert.ok(zoomed.state.distance < 0.5 * turned.state.distance, `distance ${turned.state.distance} → ${zoomed.state.distance}`);
  assert.equal(zoomed.state.yaw, turned.state.yaw);

  await gesture([[270, 200], [370, 200]], [[270, 300], [370, 300]]);
  const panned = await camera(page);
  const moved = Math.hypot(...panned.state.target.map((/** @type {number} */ v, /** @type {number} */ k) => v - zoomed.state.target[k]));
  assert.ok(moved > 0.05 * panned.radius, `target moved ${moved}`);
  assert.ok(Math.abs(panned.state.distance - zoomed.state.distance) < 0.01 * zoomed.state.distance);
  await page.close();
});

/** @param {Page} page @returns {Promise<import('../src/renderer.js').FrameStats>} */
function frameStats(page) {
  return page.evaluate(() => /** @type {any} */ (document.querySelector('vitrine-viewer')).viewer.renderer.frameStats());
}

/**
 * Drags the mouse in circles over the canvas until `condition` (over the
 * viewer's state `s`) holds; the button stays down.
 * @param {Page} page
 * @param {string} condition
 */
async function dragUntil(page, condition) {
  await page.mouse.move(WIDTH / 2, HEIGHT / 2);
  await page.mouse.down();
  const end = Date.now() + 30_000;
  let met = false;
  for (let i = 0; !met && Date.now() < end; i++) {
    await page.mouse.move(WIDTH / 2 + 80 * Math.cos(i / 5), HEIGHT / 2 + 40 * Math.sin(i / 5));
    met = await page.evaluate((body) => new Function('s', `return (${body});`)(/** @type {any} */ (document.querySelector('vitrine-viewer')).viewer.state), condition);
  }
  assert.ok(met, `while dragging: ${condition}`);
}

test('while the view moves or is held a coarser level stands in (motion=coarse), the level itself at rest and in the wireframe', async () => {
  const last = manifest.levels[manifest.last_level];
  for (const path of ['/embed/torus?motion=coarse', '/embed/torus?motion=coarse&offscreen=off']) {
    const { page, problems } = await open(path);
    await until(page, `s.status === 'complete' && s.drawnLevel === ${manifest.last_level}`);
    const kept = await frameStats(page);
    // The finest level shown with at most a quarter of the last level's triangles (src/motion.js).
    assert.ok(kept.standInLevel !== null && kept.standInLevel < manifest.last_level, JSON.stringify(kept));
    const standIn = manifest.levels[kept.standInLevel];
    assert.ok(standIn.faces <= last.vertices / 2, `stand-in of ${standIn.faces} triangles for ${last.faces}`);
    assert.equal(kept.standInFrames, 0, 'nothing moved yet');
    await dragUntil(page, `s.drawnLevel === ${kept.standInLevel}`);
    // Picking (measurements, annotations) reads the level itself, not the stand-in.
    const picked = await page.evaluate(async () => {
      const viewer = /** @type {any} */ (document.querySelector('vitrine-viewer')).viewer;
      const drawn = viewer.state.drawnLevel;
      const target = viewer.camera.state.target;
      const eye = viewer.camera.basis().eye;
      const direction = target.map((/** @type {number} */ t, /** @type {number} */ k) => t - eye[k]);
      return { drawn, pick: await viewer.renderer.pick({ origin: eye, direction }, 0.01) };
    });
    // A drag that pauses is still a drag: the stand-in stays until the release.
    await page.waitForTimeout(800);
    assert.equal((await state(page)).drawnLevel, kept.standInLevel, 'held still, the pointer down');
    await page.mouse.up();
    assert.equal(picked.pick.level, manifest.last_level, `picked while level ${picked.drawn} was drawn`);
    const s = await state(page);
    assert.equal(s.shownLevel, manifest.last_level, 'the level on screen is still the last');
    // Once the view rests, the last level is drawn again.
    await until(page, `s.drawnLevel === ${manifest.last_level}`, 5_000);
    const moved = await frameStats(page);
    assert.ok(moved.standInFrames > 0, JSON.stringify(moved));
    // The wireframe shows the level's own triangles, moving or not.
    await page.locator('vitrine-viewer canvas').focus();
    await page.keyboard.press('w');
    await page.waitForFunction(() => /** @type {any} */ (document.querySelector('vitrine-viewer')).viewer.renderer.edges);
    const wired = await frameStats(page);
    await dragUntil(page, 'true');
    for (let i = 0; i < 5; i++) await page.mouse.move(100 + 20 * i, 100 + 10 * i);
    await page.mouse.up();
    assert.equal((await state(page)).drawnLevel, manifest.last_level);
    assert.equal((await frameStats(page)).standInFrames, wired.standInFrames, 'no stand-in in the wireframe');
    assert.deepEqual(problems, []);
    await page.close();
  }
  // `full` keeps no stand-in and draws the level in every frame.
  const { page } = await open('/embed/torus?motion=full');
  await until(page, `s.status === 'complete' && s.drawnLevel === ${manifest.last_level}`);
  await dragUntil(page, 'true');
  for (let i = 0; i < 5; i++) await page.mouse.move(100 + 20 * i, 100 + 10 * i);
  await page.mouse.up();
  const full = await frameStats(page);
  assert.equal(full.standInLevel, null);
  assert.equal(full.standInFrames, 0);
  // Every mode times the level's frames (auto decides on them).
  assert.equal(full.timedFrame?.triangles, last.faces);
  await page.close();
});

test('a damaged batch becomes a visible message, and retry recovers', async () => {
  const page = await browser.context.newPage();
  await page.route('**/batches/3*', async (route) => {
    const response = await route.fetch();
    const body = await response.body();
    for (let i = 16; i < body.length; i += 3) body[i] ^= 0x5a;
    await route.fulfill({ response, body });
  });
  await page.goto(`${service.url}/m/torus`);
  // Levels decoded before the damaged one still reach the screen (the render
  // worker may finish uploading level 2 after the error is reported).
  const s = await until(page, `s.status === 'error' && s.shownLevel >= 2`);
  assert.equal(s.shownLevel, 2);
  assert.equal(await shadowHidden(page, '.error'), false);
  assert.match(await shadowText(page, '.error p'), /^Could not show this model: could not decode level 3: the stream is damaged/);
  const image = await capture(page);
  assert.ok(coverage(image, [0.3, 0.3, 0.7, 0.7]) > 0.2, 'level 2 is still on screen');
  await page.unroute('**/batches/3*');
  await page.evaluate(() =>
    /** @type {HTMLElement} */ (document.querySelector('vitrine-viewer')?.shadowRoot?.querySelector('[data-action="retry"]')).click(),
  );
  await until(page, `s.status === 'complete'`);
  assert.equal(await shadowHidden(page, '.error'), true);
  await page.close();
});

test('a failed download becomes a visible message', async () => {
  const page = await browser.context.newPage();
  await page.route('**/batches/2*', (route) => route.abort('connectionreset'));
  await page.goto(`${service.url}/m/torus`);
  const s = await until(page, `s.status === 'error' && s.shownLevel >= 1`);
  assert.equal(s.shownLevel, 1);
  assert.match(await shadowText(page, '.error p'), /^Could not show this model: a download failed: could not fetch the batch 2/);
  await page.close();
});

test('a model stored in another stream format: the server\'s reason on screen and a vitrine-error event for the page', async () => {
  const page = await browser.context.newPage();
  await page.addInitScript(() => {
    document.addEventListener('vitrine-error', (event) => {
      /** @type {any} */ (window).__vitrineErrors = [...(/** @type {any} */ (window).__vitrineErrors ?? []), /** @type {any} */ (event).detail.message];
    });
  });
  // What `vitrine serve` answers for such a model (server/tests/service/story.rs
  // checks the real answer from a database written in an older format).
  const reason = "model 'torus' is stored in stream format 2; this server reads format 3: ingest it again (vitrine ingest) to show it";
  await page.route('**/api/models/torus*', (route) =>
    route.fulfill({ status: 409, contentType: 'application/json', body: JSON.stringify({ error: 'stale_format', message: reason, retry_after_s: null }) }),
  );
  await page.goto(`${service.url}/m/torus`);
  const s = await until(page, `s.status === 'error'`);
  assert.equal(s.firstFrameMs, null);
  const shown = await shadowText(page, '.error p');
  assert.ok(shown.includes(`409 for this model (${reason})`), shown);
  await page.waitForFunction(() => /** @type {any} */ (window).__vitrineErrors?.length === 1);
  const heard = await page.evaluate(() => /** @type {any} */ (window).__vitrineErrors[0]);
  assert.ok(heard.includes(reason), heard);
  await page.close();
});

test('a browser without WebGL2 gets a message, not a blank box', async () => {
  const page = await browser.context.newPage();
  await page.addInitScript(() => {
    // Without WebGL2 a browser has none in workers either: no OffscreenCanvas hand-over.
    /** @type {any} */ (HTMLCanvasElement.prototype).transferControlToOffscreen = undefined;
    const original = HTMLCanvasElement.prototype.getContext;
    /** @type {any} */ (HTMLCanvasElement.prototype).getContext = function (/** @type {string} */ type, /** @type {any} */ options) {
      return type === 'webgl2' ? null : original.call(this, type, options);
    };
  });
  await page.goto(`${service.url}/m/torus`);
  await until(page, `s.status === 'error'`);
  assert.match(await shadowText(page, '.error p'), /no WebGL2/);
  await page.close();
});

test('a lost WebGL context is restored with the model', async () => {
  const { page } = await open('/embed/torus');
  await until(page, `s.status === 'complete'`);
  const before = await capture(page);
  // WEBGL_lose_context on the context, wherever it lives (render worker or page).
  await page.evaluate(() => /** @type {any} */ (document.querySelector('vitrine-viewer')).viewer.renderer.loseContext());
  await page.waitForFunction(() => /** @type {any} */ (document.querySelector('vitrine-viewer')).viewer.renderer.lost);
  await page.evaluate(() => /** @type {any} */ (document.querySelector('vitrine-viewer')).viewer.renderer.restoreContext());
  await page.waitForFunction(() => {
    const r = /** @type {any} */ (document.querySelector('vitrine-viewer')).viewer.renderer;
    return !r.lost && r.settled;
  });
  const restored = await capture(page);
  const score = compareImages(before.rgba, restored.rgba);
  assert.ok(score.iou > 0.999 && score.meanDiff < 0.5, JSON.stringify(score));
  await page.close();
});

test('keyboard: W toggles the wireframe, arrows turn, R resets', async () => {
  const { page } = await open('/m/torus');
  await until(page, `s.status === 'complete'`);
  const canvas = page.locator('vitrine-viewer canvas');
  await canvas.focus();
  const shaded = await capture(page);
  await page.keyboard.press('w');
  await page.waitForFunction(() => /** @type {any} */ (document.querySelector('vitrine-viewer')).viewer.renderer.edges);
  const wired = await capture(page);
  assert.equal(await page.locator('vitrine-viewer button[data-action="wireframe"]').getAttribute('aria-pressed'), 'true');
  assert.ok(compareImages(shaded.rgba, wired.rgba).meanDiff > 5, 'wire lines drawn');
  const home = await camera(page);
  await page.keyboard.press('ArrowLeft');
  await page.keyboard.press('Shift+ArrowUp');
  await page.keyboard.press('-');
  const moved = await camera(page);
  assert.notEqual(moved.state.yaw, home.state.yaw);
  assert.notDeepEqual(moved.state.target, home.state.target);
  assert.ok(moved.state.distance > home.state.distance);
  await page.keyboard.press('r');
  assert.deepEqual((await camera(page)).state, home.state);
  await page.close();
});

test('the drawing buffer follows devicePixelRatio and resizes', async () => {
  const page = await browser.context.newPage();
  const cdp = await browser.context.newCDPSession(page);
  await cdp.send('Emulation.setDeviceMetricsOverride', { width: 500, height: 400, deviceScaleFactor: 2, mobile: false });
  await page.goto(`${service.url}/embed/torus`);
  await until(page, `s.status === 'complete'`);
  const size = () =>
    page.evaluate(() => {
      const c = /** @type {HTMLCanvasElement} */ (document.querySelector('vitrine-viewer')?.shadowRoot?.querySelector('canvas'));
      return [c.width, c.height, c.clientWidth, c.clientHeight];
    });
  let [w, h, cw, ch] = await size();
  assert.deepEqual([w, h], [2 * cw, 2 * ch]);
  await cdp.send('Emulation.setDeviceMetricsOverride', { width: 400, height: 300, deviceScaleFactor: 2, mobile: false });
  await page.waitForFunction(() => /** @type {HTMLCanvasElement} */ (document.querySelector('vitrine-viewer')?.shadowRoot?.querySelector('canvas')).width === 800);
  [w, h, cw, ch] = await size();
  assert.deepEqual([w, h, cw, ch], [800, 600, 400, 300]);
  // The drawing buffer itself (the render worker's OffscreenCanvas) followed.
  await page.waitForFunction(() => /** @type {any} */ (document.querySelector('vitrine-viewer')).viewer.renderer.settled);
  const image = await capture(page);
  assert.deepEqual([image.width, image.height], [800, 600]);
  assert.ok(coverage(image, [0.3, 0.3, 0.7, 0.7]) > 0.2, 'model pixels in the middle');
  await page.close();
});

test('the model page offers an iframe snippet; the element works on another site', async () => {
  const { page } = await open('/m/torus');
  const snippets = await page.locator('.embed pre').allInnerTexts();
  assert.match(snippets[0], new RegExp(`<iframe src="${service.url}/embed/torus"`));
  assert.match(snippets[1], /<vitrine-viewer src=/);
  await page.close();

  // A museum page on another origin (another loopback port, so Chromium's
  // local-network rules do not apply) pastes the element: the service's CORS
  // headers and the blob-URL worker make it work.
  const html = `<!doctype html><body style="margin:0"><script type="module" src="${service.url}/vitrine.js"></script>
<vitrine-viewer src="${service.url}/m/torus" style="width:400px;height:300px"></vitrine-viewer></body>`;
  const site = createServer((_, response) => response.writeHead(200, { 'content-type': 'text/html' }).end(html));
  await new Promise((resolve) => site.listen(0, '127.0.0.1', () => resolve(undefined)));
  const origin = `http://127.0.0.1:${/** @type {import('node:net').AddressInfo} */ (site.address()).port}`;
  const museum = await browser.context.newPage();
  await museum.goto(`${origin}/collection`);
  const s = await until(museum, `s.status === 'complete'`);
  assert.equal(s.shownLevel, manifest.last_level);
  await museum.close();
  site.close();
});
