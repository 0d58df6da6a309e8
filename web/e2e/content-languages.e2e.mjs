// @ts-check
// End-to-end: a model's own words in the visitor's language (issue 43). A
// model ingested in English (`--language en`) with a Portuguese title,
// description and credit (`vitrine texts`): under ?lang=pt the viewer, the
// tab's title, the gallery and the served page head (<title>, og:title,
// JSON-LD) and oEmbed are in Portuguese, each text marked lang="pt"; under
// ?lang=de, with no German, the English texts with lang="en"; the switch
// changes them in place. In /admin a curator adds a Spanish title with the
// keyboard, saves, and the page under ?lang=es shows it; a malformed tag
// shows the server's refusal.
import { after, before, test } from 'node:test';
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import { launch } from '../test/support/browser.mjs';
import { vitrine } from '../test/support/fixtures.mjs';
import { startService } from '../test/support/service.mjs';

/** @typedef {import('playwright-core').Page} Page */

const EN = {
  title: 'Oil lamp',
  description: 'A Roman oil lamp of fired clay, first century.',
  credit: 'Scan: Test Museum',
};
const PT = {
  title: 'Lucerna',
  description: 'Lucerna romana de barro cozido, século I.',
  credit: 'Digitalização: Museu de Teste',
};
const ES_TITLE = 'Lucerna romana';

/** @type {Awaited<ReturnType<typeof startService>>} */
let service;
/** @type {Awaited<ReturnType<typeof launch>>} */
let browser;
/** @type {string} */
let token;

before(async () => {
  service = await startService({
    models: [
      {
        slug: 'lamp',
        title: EN.title,
        description: EN.description,
        kind: 'torus',
        kiloVertices: 3,
        ingestArgs: ['--language', 'en', '--credit', EN.credit, '--licence', 'CC-BY-4.0'],
        texts: [['pt', '--title', PT.title, '--description', PT.description, '--credit', PT.credit]],
      },
    ],
  });
  const printed = execFileSync(vitrine, ['token', 'create', '--db', service.db, '--scope', 'curator', '--label', 'e2e'], { encoding: 'utf8' });
  token = printed.trim().split('\n').at(-1) ?? '';
  browser = await launch({ width: 1000, height: 800 });
});

after(async () => {
  await browser?.close();
  await service?.stop();
});

/**
 * A fresh page that records script errors, console errors, failed requests
 * and error answers (but those `expected` returns true for).
 * @param {(status: number, url: string) => boolean} [expected]
 */
async function newPage(expected = () => false) {
  const page = await browser.context.newPage();
  /** @type {string[]} */
  const problems = [];
  page.on('pageerror', (e) => problems.push(`error: ${e.message}`));
  page.on('console', (m) => {
    // An error answer is also logged as "Failed to load resource": the answers are judged below.
    if (m.type() === 'error' && !m.text().startsWith('Failed to load resource')) problems.push(`console: ${m.text()}`);
  });
  page.on('requestfailed', (r) => problems.push(`failed: ${r.url()} ${r.failure()?.errorText}`));
  page.on('response', (r) => {
    // Every 4xx counts: a page asks for no study results its manifest does not link.
    if (r.status() >= 400 && !expected(r.status(), r.url())) problems.push(`${r.status()}: ${r.url()}`);
  });
  return { page, problems };
}

/**
 * @param {Page} page
 * @param {{ complete?: boolean }} [options] wait for every level, not the first drawn
 */
async function untilDrawn(page, { complete = false } = {}) {
  await page.waitForFunction(
    (complete) => {
      const state = /** @type {any} */ (document.querySelector('vitrine-viewer'))?.viewer?.state;
      return complete ? state?.status === 'complete' : state?.shownLevel >= 0;
    },
    complete,
    { timeout: 60_000, polling: 50 },
  );
}

/**
 * The model's texts as the viewer shows them, each with its lang and dir.
 * @param {Page} page
 */
function shownTexts(page) {
  return page.evaluate(() => {
    const root = /** @type {ShadowRoot} */ (document.querySelector('vitrine-viewer')?.shadowRoot);
    const read = (/** @type {string} */ selector) => {
      const node = /** @type {HTMLElement | null} */ (root.querySelector(selector));
      return node && { text: node.textContent, lang: node.getAttribute('lang'), dir: node.getAttribute('dir') };
    };
    return {
      title: read('.panel h1'),
      description: read('.panel p.description'),
      credit: read('.credit-text'),
      canvas: root.querySelector('canvas')?.getAttribute('aria-label') ?? null,
      tab: document.title,
    };
  });
}

/**
 * @param {string} text
 * @param {string} lang
 * @param {string | null} dir
 */
function marked(text, lang, dir = null) {
  return { text, lang, dir };
}

/** The JSON-LD `name` of a served page, as text. @param {string} html */
function structuredName(html) {
  const json = html.match(/<script type="application\/ld\+json">(.*?)<\/script>/s)?.[1];
  assert.ok(json, 'the page has JSON-LD');
  const name = JSON.parse(json).name;
  return typeof name === 'string' ? { text: name, lang: null } : { text: name['@value'], lang: name['@language'] };
}

/** @param {string} html @param {string} property */
function meta(html, property) {
  const tag = html.match(new RegExp(`<meta (?:property|name)="${property}" content="([^"]*)"`));
  return tag?.[1] ?? null;
}

test('?lang=pt: the Portuguese title, description and credit, marked lang="pt", in the viewer and the tab', async () => {
  const { page, problems } = await newPage();
  await page.goto(`${service.url}/m/lamp?lang=pt`);
  await untilDrawn(page);
  await page.waitForFunction((title) => document.title.startsWith(title), PT.title);
  const seen = await shownTexts(page);
  assert.deepEqual(seen.title, marked(PT.title, 'pt'));
  assert.deepEqual(seen.description, marked(PT.description, 'pt'));
  assert.deepEqual(seen.credit, marked(PT.credit, 'pt'));
  assert.match(String(seen.canvas), new RegExp(PT.title));
  assert.match(seen.tab, /^Lucerna · /);
  assert.deepEqual(problems, []);
  await page.close();
});

test('?lang=de, no German given: the English texts, marked lang="en" and dir="auto"; the switch turns them Portuguese in place', async () => {
  const { page, problems } = await newPage();
  await page.goto(`${service.url}/m/lamp?lang=de`);
  // Every level in first: a batch still on its way after the switch is
  // the refinement's, not a fetch the switch made.
  await untilDrawn(page, { complete: true });
  await page.waitForFunction((title) => document.title.startsWith(title), EN.title);
  const seen = await shownTexts(page);
  assert.deepEqual(seen.title, marked(EN.title, 'en', 'auto'));
  assert.deepEqual(seen.description, marked(EN.description, 'en', 'auto'));
  assert.deepEqual(seen.credit, marked(EN.credit, 'en', 'auto'));
  const requests = /** @type {string[]} */ ([]);
  page.on('request', (r) => requests.push(r.url()));
  await page.locator('vitrine-viewer select.language').selectOption('pt');
  await page.waitForFunction((title) => document.title.startsWith(title), PT.title);
  const switched = await shownTexts(page);
  assert.deepEqual(switched.title, marked(PT.title, 'pt'));
  assert.deepEqual(switched.description, marked(PT.description, 'pt'));
  assert.deepEqual(switched.credit, marked(PT.credit, 'pt'));
  assert.deepEqual(requests, [], 'nothing fetched again');
  assert.deepEqual(problems, []);
  await page.close();
});

test('the gallery names the model in the visitor’s language', async () => {
  const { page, problems } = await newPage();
  for (const [lang, title, marking] of [['pt', PT.title, 'pt'], ['de', EN.title, 'en']]) {
    await page.goto(`${service.url}/?lang=${lang}`);
    const card = page.locator('ul.models li strong');
    await card.waitFor();
    assert.equal(await card.textContent(), title);
    assert.equal(await card.getAttribute('lang'), marking);
  }
  assert.deepEqual(problems, []);
  await page.close();
});

test('the served page head and oEmbed follow ?lang=pt, the default texts otherwise', async () => {
  const pt = await (await fetch(`${service.url}/m/lamp?lang=pt`)).text();
  assert.match(pt, /<title>Lucerna\b[^<]*<\/title>/);
  assert.equal(meta(pt, 'og:title'), PT.title);
  assert.equal(meta(pt, 'og:description'), PT.description);
  assert.match(String(meta(pt, 'og:locale')), /^pt/);
  assert.deepEqual(structuredName(pt), { text: PT.title, lang: 'pt' });
  const de = await (await fetch(`${service.url}/m/lamp?lang=de`)).text();
  assert.match(de, /<title>Oil lamp\b[^<]*<\/title>/);
  assert.equal(meta(de, 'og:title'), EN.title);
  assert.equal(structuredName(de).text, EN.title);

  const page = encodeURIComponent(`${service.url}/m/lamp`);
  const oembed = await fetch(`${service.url}/api/oembed?url=${page}&lang=pt`);
  assert.equal(oembed.status, 200);
  assert.equal((await oembed.json()).title, PT.title);
  const english = await (await fetch(`${service.url}/api/oembed?url=${page}&lang=de`)).json();
  assert.equal(english.title, EN.title);
});

test('in /admin a curator adds a Spanish title with the keyboard and saves; the page under ?lang=es shows it', { timeout: 120_000 }, async () => {
  // The malformed tag below is refused on purpose.
  const { page, problems } = await newPage((status, url) => status === 422 && url.endsWith('/versions/1/texts'));
  await page.goto(`${service.url}/admin?lang=en`);
  await page.getByLabel('Token (from vitrine token create --scope curator)').fill(token);
  await page.getByRole('button', { name: 'Use token' }).click();
  await page.getByRole('button', { name: 'Versions of lamp' }).click();
  await page.getByRole('button', { name: 'Texts in other languages (version 1)' }).click();
  await page.getByText(`Original title: ${EN.title}`).waitFor();
  assert.equal(await page.getByLabel(/^Language of the original title/).inputValue(), 'en');
  assert.equal(await page.getByLabel('Language of translation 1 (a tag such as es or fr-CA)').inputValue(), 'pt');
  assert.equal(await page.getByLabel('Title (translation 1)').inputValue(), PT.title);
  assert.equal(await page.getByLabel('Credit line (translation 1)').inputValue(), PT.credit);

  // By keyboard: to "Add a language", Enter; the new language's tag has the focus.
  await page.getByRole('button', { name: 'Add a language' }).focus();
  await page.keyboard.press('Enter');
  await page.keyboard.type('not a tag!');
  await page.keyboard.press('Tab');
  await page.keyboard.type(ES_TITLE);
  await page.getByRole('button', { name: 'Save the texts of version 1' }).click();
  const status = page.locator('section.texts p[role="status"]');
  await page.waitForFunction(() => /^Not saved: /.test(document.querySelector('section.texts p[role="status"]')?.textContent ?? ''));
  const refusal = String(await status.textContent());
  assert.doesNotMatch(refusal, /the server answered/, `the server's own message: ${refusal}`);

  const tag = page.getByLabel('Language of translation 2 (a tag such as es or fr-CA)');
  await tag.fill('es');
  await tag.press('Tab');
  assert.equal(await page.getByLabel('Title (translation 2)').inputValue(), ES_TITLE);
  await page.getByRole('button', { name: 'Save the texts of version 1' }).press('Enter');
  await page.getByText('Texts saved.').waitFor();
  assert.deepEqual(problems, []);

  const manifest = await (await fetch(`${service.url}/api/models/lamp`)).json();
  assert.equal(manifest.language, 'en');
  assert.equal(manifest.translations.es.title, ES_TITLE);
  assert.equal(manifest.translations.pt.title, PT.title, 'the save kept the Portuguese texts');

  const visitor = await newPage();
  await visitor.page.goto(`${service.url}/m/lamp?lang=es`);
  await untilDrawn(visitor.page);
  await visitor.page.waitForFunction((title) => document.title.startsWith(title), ES_TITLE);
  const seen = await shownTexts(visitor.page);
  assert.deepEqual(seen.title, marked(ES_TITLE, 'es'));
  assert.deepEqual(seen.description, marked(EN.description, 'en', 'auto'), 'no Spanish description: the English one');
  assert.deepEqual(visitor.problems, []);
  await visitor.page.close();
  await page.close();
});
