// @ts-check
// Screenshots of a real scan in the viewer at its base level, a middle level
// and the final level, for looking at by eye (issue #5: the Bali mask in ccc
// mode). Runs against a running `vitrine serve` (e.g. `bash scripts/demo.sh`,
// which ingests the mask when ../shared/data is there); batches past the
// wanted level are held back so that level stays on screen.
//   node scripts/scan-screenshots.mjs [--url http://127.0.0.1:8080] [--slug bali-mask]
import { mkdirSync } from 'node:fs';
import { join } from 'node:path';
import { parseArgs } from 'node:util';
import { launch } from '../test/support/browser.mjs';
import { root } from '../test/support/fixtures.mjs';

const { values } = parseArgs({
  options: {
    url: { type: 'string', default: 'http://127.0.0.1:8080' },
    slug: { type: 'string', default: 'bali-mask' },
  },
});
const manifest = await (await fetch(`${values.url}/api/models/${values.slug}`)).json();
const last = manifest.levels.length - 1;
const out = join(root, 'docs', 'screenshots');
mkdirSync(out, { recursive: true });
const browser = await launch({ width: 800, height: 640 });
try {
  /** @type {[string, number][]} */
  const shots = [['base', 0], ['middle', Math.round(last / 2)], ['final', last]];
  for (const [name, level] of shots) {
    const page = await browser.context.newPage();
    await page.route('**/batches/**', (route) => {
      const batch = Number(new URL(route.request().url()).pathname.split('/').pop());
      if (batch <= level) return route.continue();
      // Never answered: the wanted level stays on screen.
    });
    await page.goto(`${values.url}/m/${values.slug}?antialias=on`);
    await page.waitForFunction(
      (want) => {
        const v = /** @type {any} */ (document.querySelector('vitrine-viewer'))?.viewer;
        return v?.state.shownLevel === want && v?.state.colour === 'full';
      },
      level,
      { timeout: 120_000 },
    );
    await page.waitForTimeout(500);
    const file = join(out, `viewer-ccc-${values.slug}-${name}.png`);
    await page.screenshot({ path: file });
    console.log(`${file}: level ${level} of ${last}, ${manifest.levels[level].vertices} vertices`);
    await page.close();
  }
} finally {
  await browser.close();
}
