// @ts-check
// CCC colour (issue #5) in headless Chromium: the fragment shader's lookup
// against its JavaScript twin on a hand-made complex (a page of its own that
// loads the viewer's modules; nothing test-only in the service), then the
// real `vitrine serve` with a painted torus ingested in `ccc` mode.
import { after, before, test } from 'node:test';
import assert from 'node:assert/strict';
import { readFileSync, mkdirSync, writeFileSync } from 'node:fs';
import { createServer } from 'node:http';
import { join } from 'node:path';
import { launch } from '../test/support/browser.mjs';
import { root, wasmPath } from '../test/support/fixtures.mjs';
import { startService } from '../test/support/service.mjs';
import { encodePng, quadComplex } from '../test/support/ccc-fixtures.mjs';
import { foreground, rasterize } from '../test/support/raster.mjs';
import { CellComplex } from '../src/ccc.js';
import { OrbitCamera } from '../src/camera.js';
import { VitrineCodec } from '../src/codec.js';
import { vertexNormals } from '../src/geometry.js';
import { decodePng } from '../src/png.js';

/** @typedef {import('playwright-core').Page} Page */

const WIDTH = 480;
const HEIGHT = 360;
const SCREENSHOTS = join(root, 'docs', 'screenshots');

/** @type {Awaited<ReturnType<typeof launch>>} */
let browser;
/** @type {Awaited<ReturnType<typeof startService>>} */
let service;
/** @type {any} */
let manifest;

before(async () => {
  service = await startService({
    models: [
      {
        slug: 'painted',
        title: 'Painted torus',
        description: 'A generated torus; its colour lives in a cubic cell complex texture shared by every level.',
        kind: 'torus',
        kiloVertices: 30,
        colour: true,
        colourMode: 'ccc',
        policy: 'open',
      },
    ],
  });
  browser = await launch({ width: WIDTH, height: HEIGHT });
  manifest = await (await fetch(`${service.url}/api/models/painted`)).json();
  assert.equal(manifest.colour.mode, 'ccc');
  assert.equal(manifest.has_colour, false, 'in ccc mode the stream carries geometry only');
  assert.ok(manifest.last_level >= 4, 'the test model has several levels');
});

after(async () => {
  await browser?.close();
  await service?.stop();
});

/**
 * @param {Page} page
 * @param {string} condition JS expression over `s` (the viewer's state)
 * @param {number} [timeout]
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
  return page.evaluate(() => /** @type {import('../src/viewer.js').ViewerState} */ (/** @type {any} */ (document.querySelector('vitrine-viewer')).viewer.state));
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
function colourPill(page) {
  return page.evaluate(() => {
    const pill = /** @type {HTMLElement} */ (document.querySelector('vitrine-viewer')?.shadowRoot?.querySelector('.colour'));
    return { text: pill.innerText, hidden: pill.hidden };
  });
}

/**
 * Chromaticity r/(r+g+b), g/(r+g+b) per pixel: the viewer's lighting scales
 * a colour (albedo^2.2 · light, then ^(1/2.2)), so two levels whose normals
 * differ still agree here where their colours agree.
 * @param {Uint8Array} rgba
 * @param {number} p pixel
 */
function chroma(rgba, p) {
  const sum = rgba[4 * p] + rgba[4 * p + 1] + rgba[4 * p + 2] + 1e-9;
  return [rgba[4 * p] / sum, rgba[4 * p + 1] / sum];
}

/**
 * Saves a capture (RGBA rows bottom-up, as gl.readPixels gives them) as a PNG.
 * @param {string} path
 * @param {number} width
 * @param {number} height
 * @param {Uint8Array} rgba
 */
function writePng(path, width, height, rgba) {
  const data = new Uint8Array(rgba.length);
  for (let y = 0; y < height; y++) data.set(rgba.subarray((height - 1 - y) * width * 4, (height - y) * width * 4), y * width * 4);
  writeFileSync(path, encodePng({ width, height, channels: 4, data }, { filters: [1] }));
}

/**
 * Max channel difference per pixel between two RGBA images, over the pixels
 * both draw, away from the silhouettes (antialiased edges blend in the
 * background).
 * @param {Uint8Array} a
 * @param {Uint8Array} b
 * @param {number} width
 */
function differences(a, b, width) {
  const ma = foreground(a);
  const mb = foreground(b);
  const inside = (/** @type {number} */ p) =>
    [p, p - 1, p + 1, p - width, p + width].every((q) => q >= 0 && q < ma.length && ma[q] && mb[q]);
  /** @type {number[]} */
  const out = [];
  for (let p = 0; p < ma.length; p++) {
    if (!inside(p)) continue;
    out.push(Math.max(...[0, 1, 2].map((k) => Math.abs(a[4 * p + k] - b[4 * p + k]))));
  }
  return out;
}

test('the shader finds the colours its JavaScript twin finds on a hand-made complex', async (t) => {
  const fixture = quadComplex();
  const { parameters: p } = fixture;
  // A low-resolution atlas: 2×2 blocks averaged (any content will do; both sides sample the same).
  const f = p.low_res_factor;
  const low = { width: Math.ceil(p.atlas.width / f), height: Math.ceil(p.atlas.height / f), channels: 3, data: new Uint8Array(0) };
  low.data = new Uint8Array(low.width * low.height * 3);
  for (let y = 0; y < low.height; y++) {
    for (let x = 0; x < low.width; x++) {
      for (let k = 0; k < 3; k++) {
        let sum = 0;
        for (let j = 0; j < f; j++) for (let i = 0; i < f; i++) sum += fixture.atlas.data[3 * ((y * f + j) * p.atlas.width + x * f + i) + k];
        low.data[3 * (y * low.width + x) + k] = Math.round(sum / (f * f));
      }
    }
  }
  const files = {
    '/cells.png': encodePng(fixture.cells, { filters: [1, 4] }),
    '/atlas.png': encodePng(fixture.atlas),
    '/atlas-low.png': encodePng(low),
  };
  // A quad at z = 0 across both cubes: x from −0.95 (in the cell) to 0.95 (the empty cube).
  const quad = { positions: [-0.95, -0.45, 0, 0.95, -0.45, 0, 0.95, 0.45, 0, -0.95, 0.45, 0], indices: [0, 1, 2, 0, 2, 3] };
  const bounds = { min: [-0.95, -0.45, 0], max: [0.95, 0.45, 0] };
  const orbit = { yaw: 0.25, pitch: 0.2 };
  const harness = `<!doctype html><meta charset="utf-8"><canvas width="${WIDTH}" height="${HEIGHT}"></canvas>
<script type="module">
import { Renderer } from '/src/renderer.js';
import { OrbitCamera } from '/src/camera.js';
import { decodePng } from '/src/png.js';
window.draw = async (atlasUrl, resolution) => {
  const bytes = async (url) => new Uint8Array(await (await fetch(url)).arrayBuffer());
  const camera = new OrbitCamera(${JSON.stringify(bounds)});
  Object.assign(camera.state, ${JSON.stringify(orbit)});
  let swapped;
  const ready = new Promise((resolve) => (swapped = resolve));
  const renderer = new Renderer(document.querySelector('canvas'), camera, { onSwap: swapped });
  const positions = new Float32Array(${JSON.stringify(quad.positions)});
  renderer.show({ type: 'level', level: 0, vertices: 4, faces: 2, positions,
    normals: new Int16Array([0, 0, 32767, 0, 0, 32767, 0, 0, 32767, 0, 0, 32767]), colours: null,
    indices: new Uint32Array(${JSON.stringify(quad.indices)}), edges: null, baseBounds: ${JSON.stringify(bounds)},
    received: 0, decodeMs: 0, deriveMs: 0 });
  await ready;
  // The viewer's own decoding: cell texture by src/png.js, colour texture by createImageBitmap.
  const cells = await decodePng(await bytes('/cells.png'));
  const atlas = await createImageBitmap(new Blob([await bytes(atlasUrl)]),
    { colorSpaceConversion: 'none', premultiplyAlpha: 'none', imageOrientation: 'from-image' });
  renderer.setColourMapping({ parameters: ${JSON.stringify(p)}, cells });
  renderer.setColourAtlas(atlas, resolution);
  const { rgba } = renderer.capture();
  return { rgba: Array.from(rgba), resolution: renderer.colourResolution };
};
</script>`;
  const site = createServer((request, response) => {
    const path = new URL(request.url ?? '/', 'http://x').pathname;
    if (path === '/') return void response.writeHead(200, { 'content-type': 'text/html' }).end(harness);
    if (path === '/favicon.ico') return void response.writeHead(204).end();
    if (path in files) return void response.writeHead(200, { 'content-type': 'image/png' }).end(files[/** @type {keyof typeof files} */ (path)]);
    if (/^\/src\/[a-z-]+\.js$/.test(path)) {
      return void response.writeHead(200, { 'content-type': 'text/javascript' }).end(readFileSync(join(root, 'web', path)));
    }
    response.writeHead(404).end();
  });
  await new Promise((resolve) => site.listen(0, '127.0.0.1', () => resolve(undefined)));
  const origin = `http://127.0.0.1:${/** @type {import('node:net').AddressInfo} */ (site.address()).port}`;
  const complex = new CellComplex(p, fixture.cells);
  const camera = new OrbitCamera(/** @type {any} */ (bounds));
  Object.assign(camera.state, orbit);
  try {
    for (const [url, atlas, resolution] of /** @type {const} */ ([['/atlas-low.png', low, 'low'], ['/atlas.png', fixture.atlas, 'full']])) {
      const page = await browser.context.newPage();
      /** @type {string[]} */
      const problems = [];
      page.on('pageerror', (e) => problems.push(e.message));
      page.on('console', (m) => m.type() === 'error' && problems.push(m.text()));
      await page.goto(origin);
      await page.waitForFunction(() => 'draw' in window);
      const drawn = await page.evaluate(([u, r]) => /** @type {any} */ (window).draw(u, r), [url, resolution]);
      assert.equal(drawn.resolution, resolution);
      const gpu = new Uint8Array(drawn.rgba);
      /** @type {Record<string, number>} */
      const regions = {};
      const cpu = rasterize({
        positions: new Float32Array(quad.positions),
        normals: new Int16Array([0, 0, 32767, 0, 0, 32767, 0, 0, 32767, 0, 0, 32767]),
        colours: null,
        indices: new Uint32Array(quad.indices),
        view: camera.view(),
        projection: camera.projection(WIDTH / HEIGHT),
        width: WIDTH,
        height: HEIGHT,
        albedoAt: (point) => {
          const found = complex.lookup(point);
          const key = found.kind === 'tile' ? `face ${found.face}` : found.kind;
          regions[key] = (regions[key] ?? 0) + 1;
          return complex.colourAt(point, atlas);
        },
      });
      const diffs = differences(gpu, cpu, WIDTH);
      const off = diffs.filter((d) => d > 6).length / diffs.length;
      const mean = diffs.reduce((s, d) => s + d, 0) / diffs.length;
      t.diagnostic(`${resolution}: ${diffs.length} pixels, mean max-channel difference ${mean.toFixed(2)}, ${(100 * off).toFixed(2)} % off by more than 6; regions ${JSON.stringify(regions)}`);
      for (const region of ['face 0', 'face 1', 'face 2', 'face 4', 'mean', 'fallback']) {
        assert.ok((regions[region] ?? 0) > 200, `the quad shows ${region}: ${JSON.stringify(regions)}`);
      }
      assert.ok(diffs.length > 0.15 * WIDTH * HEIGHT, 'the quad fills the view');
      // Only the lines where the exit face or the cube changes may differ (a pixel's worth of float rounding).
      assert.ok(off < 0.01 && mean < 1, `shader vs JavaScript twin (${resolution}): mean ${mean}, off ${off}`);
      assert.deepEqual(problems, []);
      if (resolution === 'full') {
        mkdirSync(SCREENSHOTS, { recursive: true });
        writePng(join(SCREENSHOTS, 'ccc-quad-shader.png'), WIDTH, HEIGHT, gpu);
      }
      await page.close();
    }
  } finally {
    site.close();
  }
});

test('ccc: the base mesh is drawn first; the cell and low-resolution colour textures follow, then the full one', async (t) => {
  const page = await browser.context.newPage();
  /** @type {string[]} */
  const problems = [];
  page.on('pageerror', (e) => problems.push(e.message));
  /** @type {Map<string, () => void>} */
  const held = new Map();
  /** @type {string[]} */
  const requested = [];
  await page.route('**/api/textures/**', (route) => {
    const url = route.request().url();
    requested.push(url);
    held.set(new URL(url).pathname, () => void route.continue());
  });
  // Multisampled as on a GPU (SwiftShader otherwise goes without): the
  // screenshots below are the documentation's.
  await page.goto(`${service.url}/embed/painted?antialias=on`);
  let s = await until(page, '0 in s.shownAtMs');
  assert.equal(s.colour, 'loading', 'the base mesh is on screen before any colour texture arrives');
  const clay = await capture(page);
  assert.deepEqual(await colourPill(page), { text: 'Colour texture loading…', hidden: false });
  // Requested only after the base mesh's first frame: they never compete with it.
  s = await until(page, 's.colourAtMs.requested !== undefined');
  assert.ok(/** @type {number} */ (s.colourAtMs.requested) >= /** @type {number} */ (s.firstFrameMs));
  await page.waitForTimeout(200);
  const { cell_texture: cell, colour_texture: full, colour_texture_low: low } = manifest.colour;
  const path = (/** @type {{ url: string }} */ t) => new URL(t.url, service.url).pathname;
  assert.deepEqual([...held.keys()].sort(), [path(cell), path(low)].sort(), 'cell and low-resolution textures first, in parallel');
  held.get(path(cell))?.();
  held.get(path(low))?.();
  // Drawn with the low-resolution texture (frames are drawn by the render worker, on its own clock).
  s = await until(page, `s.colour === 'low' && s.colourAtMs.low !== undefined`);
  await page.waitForTimeout(200);
  assert.ok(held.has(path(full)), 'the full-resolution texture is asked for once the low one is in');
  assert.equal((await state(page)).colour, 'low', 'held back: still low resolution');
  assert.match((await colourPill(page)).text, /low resolution/);
  const lowImage = await capture(page);
  mkdirSync(SCREENSHOTS, { recursive: true });
  await page.screenshot({ path: join(SCREENSHOTS, 'viewer-ccc-low-resolution.png') });
  held.get(path(full))?.();
  s = await until(page, `s.colour === 'full' && s.status === 'complete' && s.colourAtMs.full !== undefined`);
  assert.ok(/** @type {number} */ (s.colourAtMs.full) > /** @type {number} */ (s.colourAtMs.low));
  assert.deepEqual(await colourPill(page), { text: 'Colour: full resolution', hidden: false });
  // The same picture, sharper: low and full resolution agree in colour.
  const fullImage = await capture(page);
  const score = chromaDifference(lowImage.rgba, fullImage.rgba, WIDTH);
  const control = chromaDifference(clay.rgba, fullImage.rgba, WIDTH);
  t.diagnostic(`low vs full resolution ${JSON.stringify(score)}; clay base mesh vs full ${JSON.stringify(control)}`);
  // The low-resolution atlas (1/4 of each side) blurs the pattern's edges; the colours are the same.
  assert.ok(score.mean < 0.035 && score.far < 0.06, `low vs full resolution: ${JSON.stringify(score)}`);
  assert.ok(control.far > 0.5, `the measure tells clay from paint: ${JSON.stringify(control)}`);
  assert.equal(requested.length, 3);
  assert.deepEqual(problems, []);
  await page.close();
});

/** @param {Page} page */
function state(page) {
  return page.evaluate(() => /** @type {import('../src/viewer.js').ViewerState} */ (/** @type {any} */ (document.querySelector('vitrine-viewer')).viewer.state));
}

/**
 * How far the colours of image `a` are from those of image `b`, pixel by
 * pixel, over the interior of both silhouettes: the chromaticity distance to
 * the nearest match in b's 3×3 neighbourhood (a level whose silhouette or
 * texel edges sit a pixel away is not penalised for it). Dark pixels, whose
 * chromaticity is noise, are left out.
 * @param {Uint8Array} a
 * @param {Uint8Array} b
 * @param {number} width
 * @returns {{ pixels: number, mean: number, far: number }} far: fraction off by more than 0.08
 */
function chromaDifference(a, b, width) {
  const ma = foreground(a);
  const mb = foreground(b);
  const bright = (/** @type {Uint8Array} */ img, /** @type {number} */ p) => img[4 * p] + img[4 * p + 1] + img[4 * p + 2] > 60;
  let n = 0;
  let sum = 0;
  let far = 0;
  for (let p = width + 1; p < ma.length - width - 1; p++) {
    const around = [p, p - 1, p + 1, p - width, p + width, p - width - 1, p - width + 1, p + width - 1, p + width + 1];
    if (!around.every((q) => ma[q] && mb[q]) || !bright(a, p)) continue;
    const [ra, ga] = chroma(a, p);
    let d = Infinity;
    for (const q of around) {
      if (!bright(b, q)) continue;
      const [rb, gb] = chroma(b, q);
      d = Math.min(d, Math.max(Math.abs(ra - rb), Math.abs(ga - gb)));
    }
    if (d === Infinity) continue;
    n++;
    sum += d;
    if (d > 0.08) far++;
  }
  return { pixels: n, mean: sum / Math.max(1, n), far: far / Math.max(1, n) };
}

/**
 * The colour atlas and the cell texture as Chromium decodes them (colour
 * management off: the atlas as the GPU gets it), the cell texture as
 * src/png.js decodes it, and the complex built from it.
 * @param {Page} page
 */
async function loadComplex(page) {
  const { cell_texture: cell, colour_texture: full, parameters } = manifest.colour;
  const decoded = await page.evaluate(async (urls) => {
    /** @param {string} url */
    const pixels = async (url) => {
      const blob = await (await fetch(url)).blob();
      const bitmap = await createImageBitmap(blob, { colorSpaceConversion: 'none', premultiplyAlpha: 'none' });
      const canvas = new OffscreenCanvas(bitmap.width, bitmap.height);
      const context = /** @type {OffscreenCanvasRenderingContext2D} */ (canvas.getContext('2d'));
      context.drawImage(bitmap, 0, 0);
      const data = context.getImageData(0, 0, bitmap.width, bitmap.height).data;
      let binary = '';
      for (let i = 0; i < data.length; i += 0x8000) binary += String.fromCharCode(...data.subarray(i, i + 0x8000));
      return { width: bitmap.width, height: bitmap.height, data: btoa(binary) };
    };
    return { atlas: await pixels(urls[0]), cells: await pixels(urls[1]) };
  }, [full.url, cell.url]);
  const rgba = (/** @type {{ width: number, height: number, data: string }} */ d) => ({
    width: d.width,
    height: d.height,
    channels: 4,
    data: new Uint8Array(Buffer.from(d.data, 'base64')),
  });
  const cellBytes = new Uint8Array(await (await fetch(`${service.url}${cell.url}`)).arrayBuffer());
  const cells = await decodePng(cellBytes);
  return { complex: new CellComplex(parameters, cells), cells, browserCells: rgba(decoded.cells), atlas: rgba(decoded.atlas) };
}

/** @type {Promise<ReturnType<import('../src/codec.js').StreamDecoder['level']>[]> | undefined} */
let decodedLevels;

/**
 * Every level as the WebAssembly decoder builds it from the served base
 * mesh and batches: one decoder applies each batch once, for all the tests.
 */
function decodeLevels() {
  decodedLevels ??= (async () => {
    const codec = await VitrineCodec.instantiate(readFileSync(wasmPath));
    const bytes = async (/** @type {string} */ url) => new Uint8Array(await (await fetch(`${service.url}${url}`)).arrayBuffer());
    const decoder = codec.decoder(await bytes(manifest.levels[0].url));
    const levels = [decoder.level()];
    for (const level of manifest.levels.slice(1)) {
      decoder.apply(await bytes(level.url));
      levels.push(decoder.level());
    }
    decoder.free();
    return levels;
  })();
  return decodedLevels;
}

/**
 * A CPU rendering of `level` from the page's camera, each fragment coloured
 * by the JavaScript twin of the shader's lookup; `kinds` counts the lookups'
 * outcomes.
 * @param {Page} page
 * @param {{ positions: Float32Array, indices: Uint32Array }} level
 * @param {{ complex: CellComplex, atlas: { width: number, height: number, channels: number, data: Uint8Array } }} colour
 * @param {Record<string, number>} kinds
 */
async function cpuRendering(page, level, { complex, atlas }, kinds) {
  const view = await page.evaluate(() => {
    const c = /** @type {any} */ (document.querySelector('vitrine-viewer')).viewer.camera;
    return { state: structuredClone(c.state), radius: c.radius };
  });
  const reference = new OrbitCamera({ min: [0, 0, 0], max: [1, 1, 1] });
  reference.radius = view.radius;
  reference.state = view.state;
  return rasterize({
    positions: level.positions,
    normals: vertexNormals(level.positions, level.indices),
    colours: null,
    indices: level.indices,
    view: reference.view(),
    projection: reference.projection(WIDTH / HEIGHT),
    width: WIDTH,
    height: HEIGHT,
    albedoAt: (point) => {
      const kind = complex.lookup(point).kind;
      kinds[kind] = (kinds[kind] ?? 0) + 1;
      return complex.colourAt(point, atlas);
    },
  });
}

/**
 * How far a GPU capture is from a CPU rendering of the same level: the mean
 * max-channel difference, and the fraction of pixels off by more than 24.
 * @param {Uint8Array} gpu
 * @param {Uint8Array} cpu
 */
function gpuVsCpu(gpu, cpu) {
  const diffs = differences(gpu, cpu, WIDTH);
  return {
    pixels: diffs.length,
    mean: diffs.reduce((s, d) => s + d, 0) / Math.max(1, diffs.length),
    off: diffs.filter((d) => d > 24).length / Math.max(1, diffs.length),
  };
}

test('ccc: every level shows the painted colours: each matches a CPU rendering of its own geometry, and the final level\'s colours (screenshots of base and final)', async (t) => {
  const n = manifest.last_level;
  /** @type {Uint8Array[]} */
  const images = [];
  /** @type {Awaited<ReturnType<typeof loadComplex>> | undefined} */
  let colour;
  for (let k = 0; k <= n; k++) {
    const page = await browser.context.newPage();
    await page.goto(`${service.url}/embed/painted?level=${k}&antialias=on`);
    await until(page, `s.status === 'complete' && s.colour === 'full' && s.shownLevel === ${k}`);
    const gpu = (await capture(page)).rgba;
    images.push(gpu);
    if (k === 0 || k === n) {
      mkdirSync(SCREENSHOTS, { recursive: true });
      await page.screenshot({ path: join(SCREENSHOTS, k === 0 ? 'viewer-ccc-base.png' : 'viewer-ccc-final.png') });
    }
    // The texture is shared by every level: the coarse surfaces, wherever
    // they lie, must be coloured just as the lookup colours them.
    colour ??= await loadComplex(page);
    /** @type {Record<string, number>} */
    const kinds = {};
    const score = gpuVsCpu(gpu, await cpuRendering(page, (await decodeLevels())[k], colour, kinds));
    t.diagnostic(`level ${k} of ${n} (${manifest.levels[k].vertices} vertices), GPU vs CPU rendering of this level: ${JSON.stringify(score)}; lookups ${JSON.stringify(kinds)}`);
    assert.ok(score.pixels > 0.1 * WIDTH * HEIGHT, `level ${k}: the model is in view`);
    assert.ok(score.mean < 3 && score.off < 0.01, `level ${k}, GPU vs CPU rendering: ${JSON.stringify(score)}`);
    await page.close();
  }
  const last = images[n];
  for (let k = 0; k < n; k++) {
    const score = chromaDifference(images[k], last, WIDTH);
    t.diagnostic(`level ${k} of ${n} vs final: ${JSON.stringify(score)}`);
    // The colours are the painted ones at every level. Below 2 % of the
    // vertices the silhouette and the checks' borders move with the coarse
    // geometry (10 % of the pixels cross a border at this torus's base), so
    // only the mean is bounded there; the comparison above with each level's
    // own rendering is what checks where its colours land. The home view
    // fits the model's box to the view (issue 22), so the torus covers ~40 %
    // more pixels than with the old bounding-sphere fit, and the base's
    // mean went from 0.029 to 0.032: the coarse levels' mean gets 0.035.
    const coarse = manifest.levels[k].vertices < 0.02 * manifest.levels[n].vertices;
    assert.ok(score.mean < (coarse ? 0.035 : 0.03) && (coarse || score.far < 0.05), `level ${k} vs final: ${JSON.stringify(score)}`);
  }
});

test('ccc: the final level matches a CPU rendering with the JavaScript lookup; the cell texture reaches it byte for byte', async (t) => {
  const page = await browser.context.newPage();
  await page.goto(`${service.url}/embed/painted`);
  const s = await until(page, `s.status === 'complete' && s.colour === 'full'`);
  // A step the viewer skipped (the low-resolution texture, when the full one is cached) has no time.
  const since = (/** @type {number | undefined} */ ms) => (ms === undefined ? 'skipped' : `+${Math.round(ms - /** @type {number} */ (s.firstFrameMs))} ms`);
  t.diagnostic(
    `after the base mesh's first frame: textures requested ${since(s.colourAtMs.requested)}, low-resolution colour drawn ${since(s.colourAtMs.low)}, full ${since(s.colourAtMs.full)}; last level drawn ${since(s.shownAtMs[manifest.last_level])}`,
  );
  const gpu = await capture(page);
  const colour = await loadComplex(page);
  // src/png.js against Chromium's own decoding of the cell texture.
  const { cells, browserCells } = colour;
  assert.deepEqual([cells.width, cells.height, cells.channels], [browserCells.width, browserCells.height, 3]);
  for (let i = 0; i < cells.width * cells.height; i++) {
    for (let k = 0; k < 3; k++) {
      if (cells.data[3 * i + k] !== browserCells.data[4 * i + k]) assert.fail(`cell texel ${i} channel ${k} differs from Chromium's decoding`);
    }
  }
  /** @type {Record<string, number>} */
  const kinds = {};
  const cpu = await cpuRendering(page, (await decodeLevels())[manifest.last_level], colour, kinds);
  const { pixels, mean, off } = gpuVsCpu(gpu.rgba, cpu);
  t.diagnostic(`GPU vs CPU reference: ${pixels} pixels, mean max-channel difference ${mean.toFixed(2)}, ${(100 * off).toFixed(2)} % off by more than 24; lookups ${JSON.stringify(kinds)}`);
  assert.ok((kinds.tile ?? 0) > 0.95 * Object.values(kinds).reduce((a, b) => a + b, 0), `nearly every fragment finds a tile: ${JSON.stringify(kinds)}`);
  assert.ok(mean < 3 && off < 0.01, `GPU vs CPU reference: mean ${mean}, off ${off}`);
  await page.close();
});

test('ccc: a colour texture that cannot be loaded leaves the model on screen, with a note', async () => {
  const page = await browser.context.newPage();
  await page.route(`**${manifest.colour.cell_texture.url}`, (route) => route.fulfill({ status: 500, body: 'no' }));
  await page.goto(`${service.url}/embed/painted`);
  const s = await until(page, `s.status === 'complete' && s.colourError !== null`);
  assert.equal(s.colour, 'none');
  assert.equal(s.shownLevel, manifest.last_level);
  const pill = await colourPill(page);
  assert.equal(pill.hidden, false);
  assert.match(pill.text, /could not be loaded: the server answered 500/);
  await page.close();
});

test('ccc: a lost WebGL context is restored with its colour textures', async () => {
  const page = await browser.context.newPage();
  await page.goto(`${service.url}/embed/painted`);
  await until(page, `s.status === 'complete' && s.colour === 'full'`);
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
  const diffs = differences(before.rgba, restored.rgba, WIDTH);
  const mean = diffs.reduce((s, d) => s + d, 0) / diffs.length;
  assert.ok(diffs.length > 0.1 * WIDTH * HEIGHT && mean < 0.5, `restored vs before: mean ${mean} over ${diffs.length} pixels`);
  assert.equal(await page.evaluate(() => /** @type {any} */ (document.querySelector('vitrine-viewer')).viewer.renderer.colourResolution), 'full');
  await page.close();
});
