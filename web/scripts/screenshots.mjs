// @ts-check
// Screenshots of the viewer for docs/screenshots/: the gallery; the model
// page at the base level (batches held back), at the final level, in clay and
// wireframe, capped on a phone, and with a damaged batch. Headless
// Chromium, WebGL2 on SwiftShader, the real service.
//   node scripts/screenshots.mjs [--kilo-vertices 200]
import { mkdirSync } from 'node:fs';
import { join } from 'node:path';
import { parseArgs } from 'node:util';
import { launch } from '../test/support/browser.mjs';
import { root } from '../test/support/fixtures.mjs';
import { startService } from '../test/support/service.mjs';

const { values } = parseArgs({ options: { 'kilo-vertices': { type: 'string', default: '200' } } });
const out = join(root, 'docs', 'screenshots');
mkdirSync(out, { recursive: true });
const service = await startService({
  models: [
    {
      slug: 'torus',
      title: 'Painted torus',
      description: 'A generated torus with a per-vertex colour pattern, standing in for a scanned object.',
      kind: 'torus',
      kiloVertices: Number(values['kilo-vertices']),
      colour: true,
      policy: 'open',
    },
    {
      slug: 'plate',
      title: 'Plate with three tunnels',
      description: 'Genus 3, sharp edges, no colour: shown in clay grey.',
      kind: 'plate',
      kiloVertices: 50,
      policy: 'open',
    },
  ],
  serveArgs: ['--phone-max-vertices', '20000'],
});
const browser = await launch({ width: 960, height: 600 });

/** @param {import('playwright-core').Page} page @param {string} status */
const settled = (page, status) =>
  page.waitForFunction(
    (s) => /** @type {any} */ (document.querySelector('vitrine-viewer'))?.viewer?.state.status === s,
    status,
    { timeout: 120_000 },
  );

/** @param {string} path @param {string} file @param {(page: import('playwright-core').Page) => Promise<unknown>} ready */
async function shot(path, file, ready) {
  const page = await browser.context.newPage();
  // Multisampled as on a GPU: headless Chromium's SwiftShader goes without by default (src/rasteriser.js).
  const url = new URL(path, service.url);
  url.searchParams.set('antialias', 'on');
  await page.goto(url.href);
  await ready(page);
  await page.waitForTimeout(300);
  await page.screenshot({ path: join(out, file) });
  console.log(join(out, file));
  await page.close();
}

try {
  await shot('/', 'gallery.png', async (page) => void (await page.locator('a[href="/m/torus"]').waitFor()));
  await shot('/m/torus', 'viewer-base.png', async (page) => {
    await page.route('**/batches/**', () => {}); // never answered: the base mesh stays on screen
    await page.reload();
    await page.waitForFunction(() => /** @type {any} */ (document.querySelector('vitrine-viewer'))?.viewer?.state.shownLevel === 0);
  });
  await shot('/m/torus', 'viewer-final.png', (page) => settled(page, 'complete'));
  await shot('/m/plate', 'viewer-clay.png', (page) => settled(page, 'complete'));
  await shot('/m/plate?level=6', 'viewer-clay-wireframe.png', async (page) => {
    await settled(page, 'complete');
    await page.locator('vitrine-viewer canvas').focus();
    await page.keyboard.press('w');
    // The renderer (a render worker or the main thread's) reports its wire
    // edges uploaded and the level settled on the GPU.
    await page.waitForFunction(() => {
      const r = /** @type {any} */ (document.querySelector('vitrine-viewer')).viewer.renderer;
      return r.edges && r.settled;
    });
  });
  await shot('/m/torus?device=phone', 'viewer-capped-phone.png', (page) => settled(page, 'capped'));
  await shot('/m/torus', 'viewer-decode-error.png', async (page) => {
    await page.route('**/batches/3*', async (route) => {
      const response = await route.fetch();
      const body = await response.body();
      for (let i = 16; i < body.length; i += 3) body[i] ^= 0x5a;
      await route.fulfill({ response, body });
    });
    await page.reload();
    await settled(page, 'error');
  });
} finally {
  await browser.close();
  await service.stop();
}
