// @ts-check
// End-to-end: curators' notes in the visitor's language (issue 43). A note
// created through the API in English with a Portuguese translation: under
// ?lang=pt the list and the note show the Portuguese title and text, marked
// lang="pt"; under ?lang=de, with no German, the English with lang="en"
// (and dir="auto"), and the switch turns them Portuguese in place. A
// curator (the token given in /admin) opens "Translate this note" under the
// note, adds Spanish with the keyboard, saves, and ?lang=es shows it; the
// open editor has no axe-core violation, and a tag in the note's own
// language is refused before anything is sent. No failed request and no
// console error anywhere.
import { after, before, test } from 'node:test';
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import { readFileSync } from 'node:fs';
import { createRequire } from 'node:module';
import { launch } from '../test/support/browser.mjs';
import { vitrine } from '../test/support/fixtures.mjs';
import { startService } from '../test/support/service.mjs';

/** @typedef {import('playwright-core').Page} Page */

const AXE_SOURCE = readFileSync(createRequire(import.meta.url).resolve('axe-core/axe.min.js'), 'utf8');
/** The rule sets of WCAG 2.0, 2.1 and 2.2 at levels A and AA (axe's tags). */
const WCAG_TAGS = ['wcag2a', 'wcag2aa', 'wcag21a', 'wcag21aa', 'wcag22a', 'wcag22aa'];

const EN = { title: 'Gilded rim', text: 'The *rim* was gilded after firing.', html: '<em>rim</em>' };
const PT = { title: 'Borda dourada', text: 'A *borda* foi dourada depois da queima.', html: '<em>borda</em>' };
const ES = { title: 'Borde dorado', text: 'El *borde* se doró después de la cocción.', html: '<em>borde</em>' };

/** @type {Awaited<ReturnType<typeof startService>>} */
let service;
/** @type {Awaited<ReturnType<typeof launch>>} */
let browser;
/** @type {string} */
let token;
/** @type {number} */
let noteId;

before(async () => {
  service = await startService({ models: [{ slug: 'bowl', title: 'Bowl', kind: 'torus', kiloVertices: 3 }] });
  const printed = execFileSync(vitrine, ['token', 'create', '--db', service.db, '--scope', 'curator', '--label', 'e2e'], { encoding: 'utf8' });
  token = printed.trim().split('\n').at(-1)?.trim() ?? '';
  const { bounds } = await (await fetch(`${service.url}/api/models/bowl`)).json();
  const centre = [0, 1, 2].map((k) => (bounds.min[k] + bounds.max[k]) / 2);
  const response = await fetch(`${service.url}/api/models/bowl/annotations`, {
    method: 'POST',
    headers: { authorization: `Bearer ${token}`, 'content-type': 'application/json' },
    body: JSON.stringify({
      title: EN.title,
      text: EN.text,
      position: [bounds.max[0], centre[1], centre[2]],
      normal: [1, 0, 0],
      language: 'en',
      translations: { pt: { title: PT.title, text: PT.text } },
    }),
  });
  const answer = await response.text();
  assert.ok(response.ok, `POST annotation: ${response.status} ${answer}`);
  const created = JSON.parse(answer);
  noteId = created.id;
  assert.equal(created.language, 'en');
  assert.equal(created.translations.pt.title, PT.title);
  assert.match(created.translations.pt.html, new RegExp(PT.html));
  browser = await launch({ width: 1000, height: 800 });
});

after(async () => {
  await browser?.close();
  await service?.stop();
});

/** A fresh page that records script errors, console errors, failed requests and error answers. */
async function newPage() {
  const page = await browser.context.newPage();
  /** @type {string[]} */
  const problems = [];
  page.on('pageerror', (e) => problems.push(`error: ${e.message}`));
  page.on('console', (m) => {
    if (m.type() === 'error') problems.push(`console: ${m.text()}`);
  });
  page.on('requestfailed', (r) => problems.push(`failed: ${r.url()} ${r.failure()?.errorText}`));
  page.on('response', (r) => {
    if (r.status() >= 400) problems.push(`${r.status()}: ${r.url()}`);
  });
  return { page, problems };
}

/** Opens the model page and its notes pane, once the notes are in. @param {Page} page @param {string} query */
async function openNotes(page, query) {
  await page.goto(`${service.url}/m/bowl${query}`);
  await page.waitForFunction(() => /** @type {any} */ (document.querySelector('vitrine-viewer'))?.viewer?.annotations.list.length > 0, null, {
    timeout: 60_000,
    polling: 50,
  });
  await page.locator('vitrine-viewer button[data-action="notes"]').click();
  await page.locator('vitrine-viewer .note-item').first().click();
}

/**
 * The note as the viewer shows it: the list's item and the detail, each with its lang and dir.
 * @param {Page} page
 */
function shownNote(page) {
  return page.evaluate(() => {
    const root = /** @type {ShadowRoot} */ (document.querySelector('vitrine-viewer')?.shadowRoot);
    const read = (/** @type {string} */ selector) => {
      const node = /** @type {HTMLElement} */ (root.querySelector(selector));
      return { text: node.textContent, lang: node.getAttribute('lang'), dir: node.getAttribute('dir') };
    };
    return {
      item: read('.note-item'),
      title: read('.note-detail h3'),
      body: { ...read('.note-body'), html: /** @type {HTMLElement} */ (root.querySelector('.note-body')).innerHTML },
    };
  });
}

/**
 * @param {Awaited<ReturnType<typeof shownNote>>} seen
 * @param {{ title: string, html: string }} words
 * @param {string} lang
 * @param {string | null} dir
 */
function assertShown(seen, words, lang, dir) {
  assert.deepEqual(seen.item, { text: words.title, lang, dir });
  assert.deepEqual(seen.title, { text: words.title, lang, dir });
  assert.equal(seen.body.lang, lang);
  assert.equal(seen.body.dir, dir);
  assert.match(seen.body.html, new RegExp(words.html), 'the served html of that language');
}

/** axe-core's violations of the WCAG A and AA rules on the page as it is now. @param {Page} page */
async function violations(page) {
  if (!(await page.evaluate(() => 'axe' in window))) await page.addScriptTag({ content: AXE_SOURCE });
  /** @type {string[]} */
  const found = await page.evaluate(async (tags) => {
    const result = await /** @type {any} */ (window).axe.run(document, { runOnly: { type: 'tag', values: tags }, resultTypes: ['violations'] });
    return result.violations.flatMap((/** @type {any} */ v) =>
      v.nodes.map((/** @type {any} */ n) => `${v.id} (${v.impact}): ${v.help} at ${JSON.stringify(n.target)}: ${n.failureSummary}`),
    );
  }, WCAG_TAGS);
  return found;
}

test('?lang=pt: the note’s Portuguese title and text, marked lang="pt"', async () => {
  const { page, problems } = await newPage();
  await openNotes(page, '?lang=pt');
  assertShown(await shownNote(page), PT, 'pt', null);
  assert.match(String(await page.locator('vitrine-viewer .live').first().textContent()), /^Borda dourada\. A borda/);
  assert.deepEqual(problems, []);
  await page.close();
});

test('?lang=de, no German: the English, marked lang="en" and dir="auto"; the switch turns it Portuguese in place', async () => {
  const { page, problems } = await newPage();
  await openNotes(page, '?lang=de');
  assertShown(await shownNote(page), EN, 'en', 'auto');
  assert.equal(await page.locator('vitrine-viewer button[data-action="notes"]').getAttribute('aria-pressed'), 'true');
  // Visitors see no editor: the page holds no curator token.
  assert.equal(await page.locator('vitrine-viewer .note-curation button').first().isVisible(), false);
  const requests = /** @type {string[]} */ ([]);
  page.on('request', (r) => requests.push(r.url()));
  await page.locator('vitrine-viewer select.language').selectOption('pt');
  await page.waitForFunction(() => document.documentElement.lang === 'pt');
  assertShown(await shownNote(page), PT, 'pt', null);
  assert.deepEqual(requests, [], 'nothing fetched again');
  assert.deepEqual(problems, []);
  await page.close();
});

test('a curator adds a Spanish translation under the note, with the keyboard; ?lang=es shows it', { timeout: 240_000 }, async () => {
  const { page, problems } = await newPage();
  // The switch of the test before kept Portuguese for this browser: English asked for by name.
  await page.goto(`${service.url}/admin?lang=en`);
  await page.getByLabel('Token (from vitrine token create --scope curator)').fill(token);
  await page.getByRole('button', { name: 'Use token' }).click();
  await openNotes(page, '?lang=en');
  // Leaving /admin cuts its requests in flight short (the jobs it polls, the
  // model list it may still be loading): those alone may be aborted.
  const left = problems.splice(0).filter((p) => !/^failed: \S+\/api\/(jobs|models)\S* net::ERR_ABORTED$/.test(p));
  assert.deepEqual(left, []);
  const opener = page.getByRole('button', { name: 'Translate this note' });
  await opener.click();
  assert.equal(await opener.getAttribute('aria-expanded'), 'true');
  const first = page.getByLabel('Language of translation 1 (a tag such as es or fr-CA)');
  assert.equal(await first.inputValue(), 'pt');
  assert.equal(await page.getByLabel('Title (translation 1)').inputValue(), PT.title);
  assert.equal(await page.getByLabel('Text in Markdown (translation 1)').inputValue(), PT.text);
  assert.ok(await first.evaluate((node) => node === /** @type {ShadowRoot} */ (node.getRootNode()).activeElement), 'the focus is in the form');
  assert.deepEqual(await violations(page), [], 'axe-core on the open editor');

  // A tag in the note's own language is refused before anything is sent.
  await page.getByRole('button', { name: 'Add a language' }).focus();
  await page.keyboard.press('Enter');
  await page.keyboard.type('en');
  await page.keyboard.press('Tab');
  await page.keyboard.type('Rim');
  await page.getByRole('button', { name: 'Save the translations' }).click();
  await page.getByText('Not saved: the note is already written in en').waitFor();

  await page.getByLabel('Language of translation 2 (a tag such as es or fr-CA)').fill('es');
  assert.equal(await page.getByLabel('Title (translation 2)').getAttribute('lang'), 'es', 'the fields speak the tag typed');
  await page.getByLabel('Title (translation 2)').fill(ES.title);
  await page.getByLabel('Text in Markdown (translation 2)').fill(ES.text);
  await page.getByRole('button', { name: 'Save the translations' }).focus();
  await page.keyboard.press('Enter');
  await page.getByText('Translations saved.').waitFor();
  assert.deepEqual(await violations(page), [], 'axe-core after saving');

  const notes = await (await fetch(`${service.url}/api/models/bowl/annotations`)).json();
  const note = notes.find((/** @type {any} */ n) => n.id === noteId);
  assert.equal(note.language, 'en', 'its own language kept');
  assert.equal(note.title, EN.title);
  assert.deepEqual(Object.keys(note.translations).sort(), ['es', 'pt']);
  assert.equal(note.translations.es.title, ES.title);
  assert.match(note.translations.es.html, new RegExp(ES.html));

  await openNotes(page, '?lang=es');
  assertShown(await shownNote(page), ES, 'es', null);
  assert.deepEqual(problems, []);
  await page.close();
});
