// @ts-check
// End-to-end (issue 22, the viewer): the real `vitrine serve` with a box of
// known size (40 × 30 × 20, written by the test, ingested with --quality)
// and headless Chromium. Gallery thumbnails; annotations at the same
// surface point at the base level and the last; a measurement of the box's
// edge within one quantization step, with the level's error; raking light;
// the section plane; the PNG snapshot; the layout from 320 px to 1920 px.
import { after, before, test } from 'node:test';
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import { readFileSync } from 'node:fs';
import { join } from 'node:path';
import { launch } from '../test/support/browser.mjs';
import { writeBox } from '../test/support/box.mjs';
import { vitrine } from '../test/support/fixtures.mjs';
import { foreground } from '../test/support/raster.mjs';
import { startService } from '../test/support/service.mjs';
import { OrbitCamera } from '../src/camera.js';
import { diagonal, formatReading, levelHausdorff, measurement } from '../src/measure.js';
import { projectPoint } from '../src/pick.js';
import { readTextChunks } from '../src/png-text.js';

/** @typedef {import('playwright-core').Page} Page */

const WIDTH = 640;
const HEIGHT = 480;
/** A desktop window, for the tests that click on the model. */
const WIDE = { width: 1280, height: 800 };
/** @type {[number, number, number]} */
const SIZE = [40, 30, 20];
/** A long credit line (258 of the server's 300 bytes), for the layout. */
const CREDIT =
  'Scan: Museo Nacional de Arqueología y Etnología, Departamento de Conservación; photogrammetry by the ' +
  'Digital Heritage Laboratory, 2019, with the support of the Ministry of Culture and Sports; 3D processing and ' +
  'colour calibration by the Conservation Studio';
/** The snapshot's `Copyright` text chunk. */
const NOTICE = `${CREDIT}. Licence: CC BY-NC-SA 4.0 (https://creativecommons.org/licenses/by-nc-sa/4.0/)`;

/** @type {Awaited<ReturnType<typeof startService>>} */
let service;
/** @type {Awaited<ReturnType<typeof launch>>} */
let browser;
/** @type {any} */
let manifest;
/** One quantization step of the box's stream (header bytes 20–23, codec/core/FORMAT.md). */
let step = 0;

before(async () => {
  const { mkdtempSync } = await import('node:fs');
  const { tmpdir } = await import('node:os');
  const file = join(mkdtempSync(join(tmpdir(), 'vitrine-box-')), 'box.ply');
  writeBox(file, SIZE);
  service = await startService({
    models: [{ slug: 'box', title: 'Box', description: 'A 40 × 30 × 20 box.', kind: 'file', file, quality: true, ingestArgs: ['--credit', CREDIT, '--licence', 'CC-BY-NC-SA-4.0'] }],
  });
  browser = await launch({ width: WIDTH, height: HEIGHT });
  manifest = await (await fetch(`${service.url}/api/models/box`)).json();
  const base = new Uint8Array(await (await fetch(new URL(manifest.levels[0].url, `${service.url}/api/models/box`))).arrayBuffer());
  step = new DataView(base.buffer).getFloat32(20, true);
  assert.ok(step > 0 && step < 0.01, `quantization step ${step}`);
});

after(async () => {
  await browser?.close();
  await service?.stop();
});

/**
 * @param {string} path
 * @param {{ width?: number, height?: number }} [size]
 */
async function open(path, size) {
  const page = await browser.context.newPage();
  if (size) await page.setViewportSize({ width: size.width ?? WIDTH, height: size.height ?? HEIGHT });
  /** @type {string[]} */
  const problems = [];
  page.on('pageerror', (e) => problems.push(e.message));
  return { page, problems, go: () => page.goto(`${service.url}${path}`) };
}

/**
 * @param {Page} page
 * @param {string} condition over `v` (the element's viewer) and `s` (its state)
 */
async function until(page, condition, timeout = 20_000) {
  await page.waitForFunction(
    (body) => {
      const v = /** @type {any} */ (document.querySelector('vitrine-viewer'))?.viewer;
      return v ? new Function('v', 's', `return (${body});`)(v, v.state) : false;
    },
    condition,
    { timeout, polling: 50 },
  );
}

/** @param {Page} page */
async function capture(page) {
  const { width, height, data } = await page.evaluate(async () => {
    const { width, height, rgba } = await /** @type {any} */ (document.querySelector('vitrine-viewer')).viewer.renderer.capture();
    let binary = '';
    for (let i = 0; i < rgba.length; i += 0x8000) binary += String.fromCharCode(...rgba.subarray(i, i + 0x8000));
    return { width, height, data: btoa(binary) };
  });
  return { width, height, rgba: new Uint8Array(Buffer.from(data, 'base64')) };
}

/** @param {Page} page @param {string} action */
function tool(page, action) {
  return page.locator(`vitrine-viewer .tools button[data-action="${action}"]`);
}

test('the gallery shows each model\'s thumbnail in a fixed box (a placeholder without one)', async (t) => {
  const { models } = await (await fetch(`${service.url}/api/models`)).json();
  const { page, problems, go } = await open('/');
  await go();
  await page.waitForSelector('.models .thumb');
  const seen = await page.evaluate(async () => {
    const box = /** @type {HTMLElement} */ (document.querySelector('.models .thumb'));
    const img = box.querySelector('img');
    if (img) await img.decode().catch(() => {});
    const r = box.getBoundingClientRect();
    return { ratio: r.height / r.width, img: img ? { alt: img.alt, loading: img.loading, natural: img.naturalWidth } : null, placeholder: box.classList.contains('thumb-none') };
  });
  assert.ok(Math.abs(seen.ratio - 0.75) < 0.02, `4:3 box: ${seen.ratio}`);
  assert.deepEqual(problems, []);
  const url = models[0].thumbnail;
  if (typeof url !== 'string') {
    assert.ok(seen.placeholder && seen.img === null, 'a neutral placeholder without a thumbnail');
    await page.close();
    t.skip('the server lists no thumbnail (before the curators-server branch): placeholder checked only');
    return;
  }
  assert.ok(seen.img, 'an <img> for the thumbnail');
  assert.match(seen.img.alt, /Box/);
  assert.equal(seen.img.loading, 'lazy');
  assert.ok(seen.img.natural > 0, 'the thumbnail decoded');
  await page.close();
});

/** The annotations of the tests: on the front (+z) face, on the back face, and one with a saved view. */
const NOTES = [
  { id: 1, title: 'Front', text: 'the *front* face', html: '<p>the <em>front</em> face</p>', position: [20, 15, 20], normal: [0, 0, 1], view: null },
  // On the back face, but with a normal towards the camera: only the ray cast can hide it.
  { id: 2, title: 'Behind', text: 'hidden by the box', position: [20, 15, 0], normal: [0, 0, 1], view: null },
  { id: 3, title: 'Top', text: 'the top', position: [10, 30, 10], normal: [0, 1, 0], view: { target: [20, 15, 10], distance: 120, yaw: 0, pitch: 1.2 } },
];

/**
 * Loads `/m/box?level=…` and reads where each marker is, once the occlusion
 * test has run on that level, and whether the canvas shows the model there.
 * @param {Page} page
 * @param {number} level
 */
async function markersAt(page, level) {
  await page.goto(`${service.url}/m/box?level=${level}`);
  await until(page, `s.shownLevel === ${level} && v.annotations.checked?.level === ${level} && v.annotations.list.length === 3`);
  /** @type {Array<{ id: number, x: number, y: number, visible: boolean }>} */
  const placed = await page.evaluate(() => /** @type {any} */ (document.querySelector('vitrine-viewer')).viewer.annotations.placed);
  const image = await capture(page);
  const mask = foreground(image.rgba);
  const ratio = image.width / (await page.evaluate(() => /** @type {any} */ (document.querySelector('vitrine-viewer')).viewer.ui.canvas.clientWidth));
  const onModel = placed.map((p) => mask[(image.height - 1 - Math.round(p.y * ratio)) * image.width + Math.round(p.x * ratio)] === 1);
  return { placed, onModel };
}

/** @param {Page} page */
async function checkAnnotations(page) {
  const base = await markersAt(page, 0);
  const last = await markersAt(page, manifest.last_level);
  for (const seen of [base, last]) {
    assert.deepEqual(seen.placed.map((p) => p.visible), [true, false, true], `front and top shown, the back hidden: ${JSON.stringify(seen.placed)}`);
    assert.ok(seen.onModel[0] && seen.onModel[2], 'the markers are on the model');
  }
  for (const k of [0, 2]) {
    const d = Math.hypot(base.placed[k].x - last.placed[k].x, base.placed[k].y - last.placed[k].y);
    assert.ok(d <= 3, `note ${k + 1}: ${d.toFixed(2)} px between the base level and the last`);
  }
  // Keyboard: Tab reaches the marker, Enter selects it; the live region announces it.
  const marker = page.locator('vitrine-viewer .marker[aria-label="Note 1: Front"]');
  await marker.focus();
  await page.keyboard.press('Enter');
  const shown = await page.evaluate(() => {
    const root = /** @type {ShadowRoot} */ (document.querySelector('vitrine-viewer')?.shadowRoot);
    return {
      live: root.querySelector('.live')?.textContent,
      em: root.querySelector('.note-body em')?.textContent ?? null,
      tag: root.activeElement?.className,
    };
  });
  assert.equal(shown.tag, 'marker', 'the marker is a focusable button');
  // The server's HTML as text (or the Markdown source where a server sends no HTML).
  assert.match(String(shown.live), /^Front\. the \*?front\*? face/);
  // The top note's saved view is restored from the list.
  await page.locator('vitrine-viewer .note-item', { hasText: 'Top' }).focus();
  await page.keyboard.press('Enter');
  const camera = await page.evaluate(() => /** @type {any} */ (document.querySelector('vitrine-viewer')).viewer.camera.state);
  assert.deepEqual(camera, NOTES[2].view);
  return shown;
}

test('annotations (served by a stub of the route) sit on the same surface point at the base level and the last', async () => {
  const { page, problems } = await open('/');
  await page.route('**/api/models/box/annotations', (route) => route.fulfill({ json: NOTES }));
  const shown = await checkAnnotations(page);
  assert.equal(shown.em, 'front', 'the server\'s HTML is rendered');
  assert.deepEqual(problems, []);
  await page.close();
});

test('a Z-up manifest stands the model on its end; the notes stay on its surface', async () => {
  const { page, problems } = await open('/', WIDE);
  await page.route('**/api/models/box/annotations', (route) => route.fulfill({ json: NOTES }));
  // The manifest as the curators-server branch sends it: up axis, unit, bounds.
  await page.route(
    (url) => url.pathname === '/api/models/box',
    async (route) => {
      const json = await (await route.fetch()).json();
      await route.fulfill({ json: { ...json, up: 'z', unit: 'mm', bounds: { min: [0, 0, 0], max: SIZE } } });
    },
  );
  const seen = await markersAt(page, manifest.last_level);
  const box = await page.evaluate(() => /** @type {any} */ (document.querySelector('vitrine-viewer')).viewer.camera.box);
  assert.deepEqual(box.max.map((/** @type {number} */ v, /** @type {number} */ k) => v - box.min[k]), [40, 20, 30], 'model z is up');
  // Front (+z) is now the top, seen from above; Top (+y) faces away; Behind is under the box.
  assert.deepEqual(seen.placed.map((p) => p.visible), [true, false, false], JSON.stringify(seen.placed));
  assert.ok(seen.onModel[0], 'the marker is on the model');
  await zoomOut(page);
  // The front vertical edge: model z, now upright.
  const reading = await measureBetween(page, [40, 0, 0], [40, 0, 20]);
  assert.ok(Math.abs(reading.reading.value - 20) <= step, `edge ${reading.reading.value}: ${JSON.stringify(reading.reading.points)}`);
  assert.match(reading.text, /^20\.0+ mm ± 0\.0+\d mm at this level$/);
  assert.deepEqual(problems, []);
  await page.close();
});

test('annotations created through the API (curator token) appear at their point', async (t) => {
  const probe = await fetch(`${service.url}/api/models/box/annotations`);
  if (probe.status === 404) {
    t.skip('the server has no annotations route (before the curators-server branch is merged)');
    return;
  }
  const out = execFileSync(vitrine, ['token', 'create', '--db', service.db, '--scope', 'curator', '--label', 'e2e'], { encoding: 'utf8' });
  const token = out.trim().split('\n').at(-1)?.trim();
  for (const note of NOTES) {
    // The server renders and sanitises the Markdown itself; a note without a view sends none.
    const { id: _, html: __, view, ...fields } = /** @type {any} */ (note);
    const body = view ? { ...fields, view } : fields;
    const response = await fetch(`${service.url}/api/models/box/annotations`, {
      method: 'POST',
      headers: { authorization: `Bearer ${token}`, 'content-type': 'application/json' },
      body: JSON.stringify(body),
    });
    assert.ok(response.ok, `POST: ${response.status} ${await response.text()}`);
  }
  const { page, problems } = await open('/');
  await checkAnnotations(page);
  assert.deepEqual(problems, []);
  await page.close();
});

/**
 * The page's camera as a Node camera, the canvas's box on the page and its CSS size.
 * @param {Page} page
 */
async function view(page) {
  const seen = await page.evaluate(() => {
    const v = /** @type {any} */ (document.querySelector('vitrine-viewer')).viewer;
    const r = v.ui.canvas.getBoundingClientRect();
    return { state: structuredClone(v.camera.state), radius: v.camera.radius, model: v.look.model, left: r.left, top: r.top, width: v.ui.canvas.clientWidth, height: v.ui.canvas.clientHeight };
  });
  const camera = new OrbitCamera({ min: [0, 0, 0], max: [1, 1, 1] });
  camera.state = seen.state;
  camera.radius = seen.radius;
  /** @param {number[]} p model coordinates → page coordinates */
  const toPage = (p) => {
    const s = projectPoint(camera, seen.model, p, seen.width, seen.height);
    return { x: seen.left + s.x, y: seen.top + s.y };
  };
  return { ...seen, camera, toPage };
}

/**
 * Zooms out a little, so that no panel covers the model's corners.
 * @param {Page} page
 */
function zoomOut(page) {
  return page.evaluate(() => {
    const v = /** @type {any} */ (document.querySelector('vitrine-viewer')).viewer;
    v.camera.state.distance *= 1.5;
    v.renderer.requestFrame();
  });
}

/**
 * Clicks two model points (each moved `inset` px towards the box's centre on screen) in the measure mode.
 * @param {Page} page
 * @param {number[]} a
 * @param {number[]} b
 */
async function measureBetween(page, a, b, inset = 3) {
  await tool(page, 'measure').click();
  const { toPage } = await view(page);
  const centre = toPage(SIZE.map((v) => v / 2));
  for (const p of [a, b]) {
    const s = toPage(p);
    const d = Math.hypot(centre.x - s.x, centre.y - s.y);
    await page.mouse.click(s.x + (inset * (centre.x - s.x)) / d, s.y + (inset * (centre.y - s.y)) / d);
  }
  await until(page, 'v.inspection.reading !== null && (v.inspection.reading.surface !== null || v.ui.shadow.querySelector(".measure-surface").textContent)').catch(async (error) => {
    const points = await page.evaluate(() => /** @type {any} */ (document.querySelector('vitrine-viewer')).viewer.inspection.points);
    throw new Error(`${error.message}; picked ${JSON.stringify(points)}`);
  });
  return page.evaluate(() => {
    const v = /** @type {any} */ (document.querySelector('vitrine-viewer')).viewer;
    const root = v.ui.shadow;
    return {
      reading: v.inspection.reading,
      pickMs: v.inspection.pickMs,
      text: root.querySelector('.measure-reading').textContent,
      surfaceText: root.querySelector('.measure-surface').textContent,
      refine: { hidden: root.querySelector('.refine').hidden, text: root.querySelector('.refine').textContent },
    };
  });
}

test('a measurement of the box\'s edge reads 40 within one quantization step, with the level\'s error', async (t) => {
  // Wide enough that the panes under the toolbar leave the model clear.
  const { page, problems, go } = await open('/m/box', WIDE);
  await go();
  await until(page, `s.status === 'complete'`);
  await zoomOut(page);
  // The top front edge, (0, 30, 20) to (40, 30, 20): both corners in view from the home view.
  const seen = await measureBetween(page, [0, 30, 20], [40, 30, 20]);
  const { value, level, surface } = seen.reading;
  t.diagnostic(`read ${value} (step ${step}), along the surface ${surface}, pick ${seen.pickMs?.toFixed(1)} ms: ${seen.text}`);
  assert.equal(level, manifest.last_level);
  assert.ok(Math.abs(value - 40) <= step, `edge ${value} vs 40 ± ${step}`);
  const h = levelHausdorff(manifest, level);
  assert.ok(h !== null && h > 0, 'the ingest measured this level\'s error');
  const expected = measurement(seen.reading.points[0], seen.reading.points[1], { hausdorff: h, diagonal: diagonal(manifest.bounds ?? { min: [0, 0, 0], max: SIZE }) });
  assert.equal(seen.text, formatReading(value, expected.error, manifest.unit ?? null));
  assert.match(seen.text, / ± .* at this level$/);
  // Along the surface the edge is the shortest path too.
  assert.ok(Math.abs(surface - 40) < 0.4, `along the surface ${surface}`);
  assert.match(seen.surfaceText, /^Along the surface: 40\./);
  assert.equal(seen.refine.hidden, true, 'no finer level to offer');
  assert.deepEqual(problems, []);
  await page.close();
});

test('on a coarse level the measurement offers to refine, and refining reaches the last level', async () => {
  const { page, problems, go } = await open('/m/box?level=1', WIDE);
  await go();
  await until(page, `s.shownLevel === 1`);
  const seen = await measureBetween(page, [5, 5, 20], [35, 25, 20], 0);
  assert.equal(seen.reading.level, 1);
  assert.equal(seen.refine.hidden, false);
  assert.equal(seen.refine.text, 'Refine to measure more precisely');
  const h = /** @type {number} */ (levelHausdorff(manifest, 1));
  assert.ok(seen.reading.error > 2 * /** @type {number} */ (levelHausdorff(manifest, manifest.last_level)) * 50, 'a coarse level\'s error is larger');
  assert.ok(Math.abs(seen.reading.error - 2 * h * diagonal({ min: [0, 0, 0], max: SIZE })) < 1e-3 * seen.reading.error);
  await page.locator('vitrine-viewer .refine').click();
  await until(page, `s.shownLevel === ${manifest.last_level}`);
  assert.deepEqual(problems, []);
  await page.close();
});

/**
 * Mean absolute difference (0–255) over pixels that are foreground in either image.
 * @param {Uint8Array} a @param {Uint8Array} b
 */
function shadingDifference(a, b) {
  const fa = foreground(a);
  const fb = foreground(b);
  let sum = 0;
  let n = 0;
  for (let p = 0; p < fa.length; p++) {
    if (!fa[p] && !fb[p]) continue;
    for (let c = 0; c < 3; c++) sum += Math.abs(a[4 * p + c] - b[4 * p + c]);
    n += 3;
  }
  return sum / Math.max(1, n);
}

test('raking light changes the shading; the section hides the cut half; the snapshot is a PNG of the canvas', async () => {
  const { page, problems, go } = await open('/m/box');
  await go();
  await until(page, `s.status === 'complete'`);
  const studio = await capture(page);
  await tool(page, 'light').click();
  await page.locator('vitrine-viewer [data-raking="left"]').click();
  const raking = await capture(page);
  const lit = shadingDifference(studio.rgba, raking.rgba);
  assert.ok(lit > 10, `raking light vs studio: mean difference ${lit.toFixed(1)}`);
  await page.locator('vitrine-viewer .light .studio').click();
  assert.ok(shadingDifference(studio.rgba, (await capture(page)).rgba) < 0.5, 'the studio preset gives the picture back');

  // Face on, the plane x = 20 is the middle column: the right half is cut away.
  await page.evaluate(() => {
    const v = /** @type {any} */ (document.querySelector('vitrine-viewer')).viewer;
    v.camera.state = { ...v.camera.state, yaw: 0, pitch: 0 };
    v.renderer.requestFrame();
  });
  const whole = await capture(page);
  await tool(page, 'section').click();
  const cut = await capture(page);
  /** @param {{ width: number, height: number, rgba: Uint8Array }} image @param {number} from @param {number} to */
  const columns = (image, from, to) => {
    const mask = foreground(image.rgba);
    let n = 0;
    for (let y = 0; y < image.height; y++) for (let x = from; x < to; x++) n += mask[y * image.width + x];
    return n;
  };
  const w = cut.width;
  assert.ok(columns(whole, Math.ceil(w / 2) + 2, w) > 1000, 'the model reaches the right half before the cut');
  assert.equal(columns(cut, Math.ceil(w / 2) + 2, w), 0, 'nothing is drawn beyond the plane');
  assert.ok(columns(cut, 0, Math.floor(w / 2) - 2) > 0.9 * columns(whole, 0, Math.floor(w / 2) - 2), 'the near half stays');

  const [download] = await Promise.all([page.waitForEvent('download'), tool(page, 'snapshot').click()]);
  assert.equal(download.suggestedFilename(), 'box.png');
  const png = readFileSync(/** @type {string} */ (await download.path()));
  assert.deepEqual([...png.subarray(0, 8)], [137, 80, 78, 71, 13, 10, 26, 10], 'PNG signature');
  assert.equal(png.subarray(12, 16).toString('latin1'), 'IHDR');
  assert.deepEqual([png.readUInt32BE(16), png.readUInt32BE(20)], [cut.width, cut.height], 'the canvas\'s size');
  assert.deepEqual(
    readTextChunks(new Uint8Array(png)).map((c) => [c.keyword, c.text]),
    [['Title', 'Box'], ['Copyright', NOTICE], ['Comment', `Snapshot from ${service.url}/m/box`]],
  );
  assert.deepEqual(problems, []);
  await page.close();
});

test('on the main thread (?offscreen=off) the snapshot is a PNG of the canvas too', async () => {
  const { page, problems, go } = await open('/m/box?offscreen=off');
  await go();
  await until(page, `s.status === 'complete' && v.renderer?.thread === 'main'`);
  const [download] = await Promise.all([page.waitForEvent('download'), tool(page, 'snapshot').click()]);
  const png = readFileSync(/** @type {string} */ (await download.path()));
  const size = await page.evaluate(() => {
    const c = /** @type {any} */ (document.querySelector('vitrine-viewer')).viewer.ui.canvas;
    return [c.width, c.height];
  });
  assert.deepEqual([...png.subarray(0, 8)], [137, 80, 78, 71, 13, 10, 26, 10], 'PNG signature');
  assert.deepEqual([png.readUInt32BE(16), png.readUInt32BE(20)], size);
  assert.equal(readTextChunks(new Uint8Array(png)).find((c) => c.keyword === 'Copyright')?.text, NOTICE);
  assert.deepEqual(problems, []);
  await page.close();
});

test('nothing overlaps from 320 px to 1920 px, portrait and landscape, with a long credit line', async () => {
  // One page, resized: the layout follows the window (and the load is paid once).
  const { page, problems, go } = await open('/m/box', { width: 320, height: 568 });
  await page.route('**/api/models/box/annotations', (route) => route.fulfill({ json: NOTES }));
  await go();
  await until(page, `s.shownLevel >= 0 && v.annotations.list.length === 3`);
  await tool(page, 'measure').click();
  const sizes = [[320, 568], [568, 320], [390, 844], [844, 390], [768, 1024], [1024, 768], [1920, 1080], [1080, 1920]];
  for (const [width, height] of sizes) {
    await page.setViewportSize({ width, height });
    await page.waitForFunction((w) => document.querySelector('vitrine-viewer')?.getBoundingClientRect().width === w, width);
    const boxes = await page.evaluate(() => {
      const host = /** @type {Element} */ (document.querySelector('vitrine-viewer'));
      const root = /** @type {ShadowRoot} */ (host.shadowRoot);
      const shown = (/** @type {Element} */ e) => /** @type {HTMLElement} */ (e).offsetParent !== null;
      const parts = [
        ...[...root.querySelectorAll('.panel, .tools button, .panes > *, .status > *, .credit')].filter(shown),
      ];
      const box = (/** @type {Element} */ e) => {
        const r = e.getBoundingClientRect();
        return { name: `${e.className || e.tagName} ${/** @type {HTMLElement} */ (e).innerText.slice(0, 16)}`, left: r.left, top: r.top, right: r.right, bottom: r.bottom };
      };
      return { host: box(host), parts: parts.map(box) };
    });
    const where = `${width}×${height}`;
    assert.ok(boxes.parts.length >= 13, `${where}: ${boxes.parts.length} parts`);
    assert.ok(boxes.parts.some((p) => p.name.startsWith('credit Scan: Museo')), `${where}: the credit line is shown`);
    for (const p of boxes.parts) {
      const inside = p.left >= boxes.host.left - 0.5 && p.right <= boxes.host.right + 0.5 && p.top >= boxes.host.top - 0.5 && p.bottom <= boxes.host.bottom + 0.5;
      assert.ok(inside, `${where}: ${p.name} ${JSON.stringify(p)} inside ${JSON.stringify(boxes.host)}`);
    }
    for (let i = 0; i < boxes.parts.length; i++) {
      for (let j = i + 1; j < boxes.parts.length; j++) {
        const a = boxes.parts[i];
        const b = boxes.parts[j];
        const overlap = a.left < b.right - 0.5 && b.left < a.right - 0.5 && a.top < b.bottom - 0.5 && b.top < a.bottom - 0.5;
        assert.ok(!overlap, `${where}: ${a.name} ${JSON.stringify(a)} overlaps ${b.name} ${JSON.stringify(b)}`);
      }
    }
  }
  assert.deepEqual(problems, []);
  await page.close();
});
