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
import { root } from '../test/support/fixtures.mjs';
import { encodePng, quadComplex } from '../test/support/ccc-fixtures.mjs';
import { foreground, rasterize } from '../test/support/raster.mjs';
import { CellComplex } from '../src/ccc.js';
import { OrbitCamera } from '../src/camera.js';

/** @typedef {import('playwright-core').Page} Page */

const WIDTH = 480;
const HEIGHT = 360;
const SCREENSHOTS = join(root, 'docs', 'screenshots');

/** @type {Awaited<ReturnType<typeof launch>>} */
let browser;

before(async () => {
  browser = await launch({ width: WIDTH, height: HEIGHT });
});

after(async () => {
  await browser?.close();
});

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
    if (/^\/src\/[a-z]+\.js$/.test(path)) {
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
