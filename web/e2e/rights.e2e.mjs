// @ts-check
// End-to-end: the credit line. Models ingested with `vitrine ingest --credit
// … --licence CC-BY-4.0` show the credit and the licence linked to its deed
// on the model page, the embed page and the element on another site; a
// model without rights shows none; markup in a credit stays text; a
// snapshot carries the title, the credit and licence, and the page in its
// PNG text chunks.
import { after, before, test } from 'node:test';
import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';
import { createServer } from 'node:http';
import { launch } from '../test/support/browser.mjs';
import { startService } from '../test/support/service.mjs';
import { readTextChunks } from '../src/png-text.js';

/** @typedef {import('playwright-core').Page} Page */

const DEED = 'https://creativecommons.org/licenses/by/4.0/';
const MARKUP = '<img src=x onerror="window.pwned=1"> <b>Scan</b> & Co';

/** @type {Awaited<ReturnType<typeof startService>>} */
let service;
/** @type {Awaited<ReturnType<typeof launch>>} */
let browser;

before(async () => {
  /** @param {string} slug @param {string} title @param {string[]} [ingestArgs] */
  const torus = (slug, title, ingestArgs = []) => ({ slug, title, kind: /** @type {const} */ ('torus'), kiloVertices: 3, ingestArgs });
  service = await startService({
    models: [
      torus('credited', 'Credited torus', ['--credit', 'Scan: Test Museum', '--licence', 'CC-BY-4.0']),
      torus('plain', 'Plain torus'),
      torus('markup', 'Markup torus', ['--credit', MARKUP]),
      { ...torus('shared', 'Shared torus', ['--licence', 'CC0-1.0']), policy: 'open-download' },
    ],
  });
  browser = await launch({ width: 640, height: 480 });
});

after(async () => {
  await browser?.close();
  await service?.stop();
});

/**
 * Opens a page with the viewer and waits until it has read the manifest
 * (the credit line is set then), or with `drawn` until a level is on screen.
 * @param {string} url
 */
async function open(url, { drawn = false } = {}) {
  const page = await browser.context.newPage();
  /** @type {string[]} */
  const problems = [];
  page.on('pageerror', (e) => problems.push(e.message));
  await page.goto(url);
  await page.waitForFunction(
    (drawn) => {
      const viewer = /** @type {any} */ (document.querySelector('vitrine-viewer'))?.viewer;
      return drawn ? viewer?.state.shownLevel >= 0 : Boolean(viewer?.manifest);
    },
    drawn,
    { timeout: 30_000, polling: 50 },
  );
  return { page, problems };
}

/**
 * The credit line as a visitor meets it.
 * @param {Page} page
 */
function creditSeen(page) {
  return page.evaluate(() => {
    const host = /** @type {HTMLElement} */ (document.querySelector('vitrine-viewer'));
    const credit = /** @type {HTMLElement} */ (host.shadowRoot?.querySelector('.credit'));
    const link = credit.querySelector('a');
    const r = credit.getBoundingClientRect();
    const h = host.getBoundingClientRect();
    return {
      shown: credit.offsetParent !== null && !credit.hidden,
      text: credit.textContent,
      label: credit.getAttribute('aria-label'),
      // Elements other than the line's own spans and link: any would have come from the text.
      elements: [...credit.querySelectorAll(':not(span, a)')].map((e) => e.tagName),
      link: link && { href: link.getAttribute('href'), rel: link.rel, target: link.target, text: link.textContent },
      inside: r.left >= h.left && r.right <= h.right + 0.5 && r.bottom <= h.bottom + 0.5,
      // The bottom of the view: its lower edge in the last 30 px of the viewer.
      atBottom: h.bottom - r.bottom < 30,
      fontSize: parseFloat(getComputedStyle(/** @type {Element} */ (credit.firstElementChild ?? credit)).fontSize),
    };
  });
}

/** @param {ReturnType<typeof creditSeen> extends Promise<infer T> ? T : never} seen */
function assertCredited(seen) {
  assert.ok(seen.shown, 'the credit line is shown');
  assert.equal(seen.text, 'Scan: Test Museum · CC BY 4.0');
  assert.equal(seen.label, 'Credit and licence');
  assert.deepEqual(seen.link, { href: DEED, rel: 'license noopener', target: '_blank', text: 'CC BY 4.0' });
  assert.ok(seen.inside && seen.atBottom, `at the bottom of the view: ${JSON.stringify(seen)}`);
  assert.ok(seen.fontSize <= 13, `small text: ${seen.fontSize}px`);
}

test('the model page shows the credit and the licence linked to its deed; Tab reaches the link', async () => {
  const { page, problems } = await open(`${service.url}/m/credited`);
  assertCredited(await creditSeen(page));
  // The API's rights are what the line shows.
  const { rights } = await (await fetch(`${service.url}/api/models/credited`)).json();
  assert.deepEqual(rights, { credit: 'Scan: Test Museum', licence: { id: 'CC-BY-4.0', name: 'CC BY 4.0', url: DEED } });
  let reached = false;
  for (let i = 0; i < 40 && !reached; i++) {
    await page.keyboard.press('Tab');
    reached = await page.evaluate(() => document.querySelector('vitrine-viewer')?.shadowRoot?.activeElement?.closest('.credit') != null);
  }
  assert.ok(reached, 'the licence link is in the tab order');
  assert.deepEqual(problems, []);
  await page.close();
});

test('the embed page and the element on another site carry the credit', async () => {
  const embed = await open(`${service.url}/embed/credited`);
  assertCredited(await creditSeen(embed.page));
  assert.deepEqual(embed.problems, []);
  await embed.page.close();

  const html = `<!doctype html><body style="margin:0"><script type="module" src="${service.url}/vitrine.js"></script>
<vitrine-viewer src="${service.url}/m/credited" style="width:400px;height:300px"></vitrine-viewer></body>`;
  const site = createServer((_, response) => response.writeHead(200, { 'content-type': 'text/html' }).end(html));
  await new Promise((resolve) => site.listen(0, '127.0.0.1', () => resolve(undefined)));
  const origin = `http://127.0.0.1:${/** @type {import('node:net').AddressInfo} */ (site.address()).port}`;
  const museum = await open(`${origin}/collection`);
  assertCredited(await creditSeen(museum.page));
  await museum.page.close();
  site.close();
});

test('a model without rights shows no credit line; a credit with markup is shown as text', async () => {
  const plain = await open(`${service.url}/m/plain`);
  const seen = await creditSeen(plain.page);
  assert.equal(seen.shown, false, 'no credit element on screen');
  assert.equal(seen.text, '');
  assert.equal(await plain.page.evaluate(() => document.querySelector('vitrine-viewer')?.shadowRoot?.querySelector('a[rel~="license"]') ?? null), null);
  await plain.page.close();

  const marked = await open(`${service.url}/m/markup`);
  const text = await creditSeen(marked.page);
  assert.ok(text.shown);
  assert.equal(text.text, MARKUP, 'the credit as typed, no licence');
  assert.deepEqual(text.elements, [], 'no element made from the credit');
  assert.equal(await marked.page.evaluate(() => /** @type {any} */ (window).pwned ?? null), null);
  await marked.page.close();
});

/**
 * Clicks Snapshot and reads the text chunks of the PNG it saves.
 * @param {Page} page
 */
async function snapshotText(page) {
  const button = page.locator('vitrine-viewer .tools button[data-action="snapshot"]');
  const [download] = await Promise.all([page.waitForEvent('download'), button.click()]);
  return readTextChunks(new Uint8Array(readFileSync(/** @type {string} */ (await download.path()))));
}

test('a snapshot carries the title, the credit and licence, and the model page in PNG text chunks', async () => {
  const { page, problems } = await open(`${service.url}/m/credited`, { drawn: true });
  assert.deepEqual(await snapshotText(page), [
    { type: 'tEXt', keyword: 'Title', text: 'Credited torus' },
    { type: 'tEXt', keyword: 'Copyright', text: `Scan: Test Museum. Licence: CC BY 4.0 (${DEED})` },
    { type: 'tEXt', keyword: 'Comment', text: `Snapshot from ${service.url}/m/credited` },
  ]);
  await page.close();
  const plain = await open(`${service.url}/m/plain`, { drawn: true });
  assert.deepEqual(
    (await snapshotText(plain.page)).map((c) => c.keyword),
    ['Title', 'Comment'],
    'no Copyright without rights',
  );
  assert.deepEqual([...problems, ...plain.problems], []);
  await plain.page.close();
});

test('where the policy offers downloads, the line offers the GLB of the level the visitor may take', async () => {
  const { page, problems } = await open(`${service.url}/m/shared`);
  const seen = await page.evaluate(() => {
    const credit = /** @type {HTMLElement} */ (document.querySelector('vitrine-viewer')?.shadowRoot?.querySelector('.credit'));
    const link = /** @type {HTMLAnchorElement | null} */ (credit.querySelector('.credit-download a'));
    return { text: credit.textContent, href: link?.href ?? null, download: link?.hasAttribute('download') ?? false };
  });
  const manifest = await (await fetch(`${service.url}/api/models/shared`)).json();
  assert.equal(manifest.download.level, manifest.cap.level);
  assert.match(seen.text ?? '', /^CC0 1\.0 Universal · Download GLB, [\d.,]+ (kB|MB)$/);
  assert.ok(seen.download, 'a download link');
  assert.equal(seen.href, new URL(manifest.download.url, service.url).href);
  // What the link fetches is the GLB the line announced, of about that size.
  const file = await page.evaluate(async (href) => {
    const response = await fetch(/** @type {string} */ (href));
    const bytes = new Uint8Array(await response.arrayBuffer());
    return { status: response.status, magic: String.fromCharCode(...bytes.subarray(0, 4)), length: bytes.length };
  }, seen.href);
  assert.equal(file.status, 200);
  assert.equal(file.magic, 'glTF');
  assert.ok(manifest.download.bytes >= file.length && manifest.download.bytes - file.length < 2048, `${manifest.download.bytes} for ${file.length}`);
  // No policy, no link: the credited model's line has none.
  const other = await open(`${service.url}/m/credited`);
  assert.equal(await other.page.evaluate(() => document.querySelector('vitrine-viewer')?.shadowRoot?.querySelector('.credit-download') ?? null), null);
  assert.deepEqual(problems, []);
  await page.close();
  await other.page.close();
});
