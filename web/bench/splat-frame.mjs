// @ts-check
// Frame time of N splats (1 M by default, at 1920×1080 by default: issue
// 42's measurement) in headless Chromium, WebGL2 on
// SwiftShader (a CPU renderer: minutes for a few frames, not a GPU's time):
// points on a unit sphere drawn by the splat renderer's three passes
// without preprocessing (e2e/splats-harness.js `synthetic`), the mean of
// `--frames` frames after one warm-up frame. A benchmark, not a test: the
// end-to-end run (npm run test:e2e) does not pay for it.
//   node build.mjs && node bench/splat-frame.mjs [--splats 1000000] [--frames 2] [--width 1920] [--height 1080]
import { existsSync, readFileSync } from 'node:fs';
import { createServer } from 'node:http';
import { join } from 'node:path';
import { parseArgs } from 'node:util';
import { build } from 'esbuild';
import { launch } from '../test/support/browser.mjs';
import { root } from '../test/support/fixtures.mjs';

const { values } = parseArgs({
  options: {
    splats: { type: 'string', default: '1000000' },
    frames: { type: 'string', default: '2' },
    width: { type: 'string', default: '1920' },
    height: { type: 'string', default: '1080' },
  },
});
const splats = Number(values.splats);
const frames = Number(values.frames);
const WIDTH = Number(values.width);
const HEIGHT = Number(values.height);
const dist = join(root, 'web', 'dist');
if (!existsSync(join(dist, 'splat-worker.js'))) throw new Error('build the viewer first: node build.mjs');

const harness = await build({
  entryPoints: [join(root, 'web', 'e2e', 'splats-harness.js')],
  bundle: true,
  format: 'esm',
  write: false,
  logLevel: 'warning',
});
const script = harness.outputFiles[0].text;
const server = createServer((req, res) => {
  const path = new URL(req.url ?? '/', 'http://x').pathname;
  if (path === '/favicon.ico') {
    res.writeHead(204);
    res.end();
  } else if (path === '/') {
    res.writeHead(200, { 'content-type': 'text/html' });
    res.end(`<!doctype html><body style="margin:0"><div id="root" style="position:relative;width:${WIDTH}px;height:${HEIGHT}px"></div><script type="module" src="/harness.js"></script></body>`);
  } else if (path === '/harness.js') {
    res.writeHead(200, { 'content-type': 'text/javascript' });
    res.end(script);
  } else if (path.startsWith('/dist/') && existsSync(join(dist, path.slice(6)))) {
    const type = path.endsWith('.wasm') ? 'application/wasm' : path.endsWith('.js') ? 'text/javascript' : 'application/octet-stream';
    res.writeHead(200, { 'content-type': type });
    res.end(readFileSync(join(dist, path.slice(6))));
  } else {
    res.writeHead(404);
    res.end();
  }
});
await new Promise((resolve) => server.listen(0, '127.0.0.1', () => resolve(null)));
const address = /** @type {import('node:net').AddressInfo} */ (server.address());
const browser = await launch({ width: WIDTH, height: HEIGHT });
try {
  const page = await browser.context.newPage();
  /** @type {string[]} */
  const problems = [];
  page.on('pageerror', (e) => problems.push(e.message));
  page.on('console', (m) => m.type() === 'error' && problems.push(m.text()));
  await page.goto(`http://127.0.0.1:${address.port}/`);
  await page.waitForFunction(() => 'harness' in window);
  const ms = await page.evaluate(
    ({ n, f }) => {
      const h = /** @type {any} */ (window).harness;
      h.synthetic(n);
      h.frameTime(1);
      const ms = h.frameTime(f);
      h.view.destroy();
      return ms;
    },
    { n: splats, f: frames },
  );
  if (problems.length > 0) throw new Error(`the page reported: ${problems.join('; ')}`);
  console.log(`${splats} splats, ${WIDTH}x${HEIGHT}, headless Chromium (SwiftShader): ${ms.toFixed(1)} ms per frame (${frames} frames after a warm-up)`);
} finally {
  await browser.close();
  await new Promise((resolve) => server.close(resolve));
}
