// @ts-check
// End-to-end: the viewer in the museum's languages. The server writes the
// page's <html lang dir> from ?lang= or Accept-Language before any script
// runs; the viewer's controls follow in that language; Arabic lays the
// chrome out right to left without overlaps; the switch changes the
// language in place (no reload, no failed request), keeps the choice and
// puts it in the address. A museum's own words, from the service's
// configuration file, take the place of the catalogue's.
import { after, before, test } from 'node:test';
import assert from 'node:assert/strict';
import { mkdtempSync, rmSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { launch } from '../test/support/browser.mjs';
import { startService } from '../test/support/service.mjs';

/** @typedef {import('playwright-core').Page} Page */

/** @type {Awaited<ReturnType<typeof startService>>} */
let service;
/** @type {Awaited<ReturnType<typeof launch>>} */
let browser;

before(async () => {
  service = await startService({
    models: [{ slug: 'torus', title: 'Torus', kind: 'torus', kiloVertices: 3, ingestArgs: ['--credit', 'Scan: Museu da Inconfidência', '--licence', 'CC-BY-4.0'] }],
  });
  browser = await launch({ width: 800, height: 600 });
});

after(async () => {
  await browser?.close();
  await service?.stop();
});

/**
 * A fresh page that records what went wrong: script errors, failed
 * requests and error answers.
 * @param {Record<string, string>} [headers]
 */
async function newPage(headers) {
  const page = await browser.context.newPage();
  if (headers) await page.setExtraHTTPHeaders(headers);
  /** @type {string[]} */
  const problems = [];
  page.on('pageerror', (e) => problems.push(`error: ${e.message}`));
  page.on('requestfailed', (r) => problems.push(`failed: ${r.url()} ${r.failure()?.errorText}`));
  page.on('response', (r) => {
    // Every 4xx counts: a page asks for no study results its manifest does not link.
    if (r.status() >= 400) problems.push(`${r.status()}: ${r.url()}`);
  });
  return { page, problems };
}

/**
 * Until a level is on screen, or with `complete` until the last one is (no request is due then).
 * @param {Page} page
 */
async function untilDrawn(page, { complete = false } = {}) {
  await page.waitForFunction(
    (complete) => {
      const state = /** @type {any} */ (document.querySelector('vitrine-viewer'))?.viewer?.state;
      return complete ? state?.status === 'complete' : state?.shownLevel >= 0;
    },
    complete,
    { timeout: 30_000, polling: 50 },
  );
}

/**
 * What a visitor reads of the page and the viewer's chrome.
 * @param {Page} page
 */
function chrome(page) {
  return page.evaluate(() => {
    const root = /** @type {ShadowRoot} */ (document.querySelector('vitrine-viewer')?.shadowRoot);
    const text = (/** @type {string} */ selector) => /** @type {HTMLElement | null} */ (root.querySelector(selector))?.innerText ?? null;
    return {
      lang: document.documentElement.lang,
      dir: document.documentElement.dir,
      reset: text('[data-action="reset"]'),
      resetTitle: root.querySelector('[data-action="reset"]')?.getAttribute('title'),
      canvas: root.querySelector('canvas')?.getAttribute('aria-label'),
      progress: text('.progress'),
      switchValue: /** @type {HTMLSelectElement} */ (root.querySelector('select.language')).value,
      switchLabel: root.querySelector('select.language')?.getAttribute('aria-label'),
      back: document.querySelector('header a')?.textContent ?? null,
    };
  });
}

/** @param {string} path @param {Record<string, string>} [headers] */
async function served(path, headers = {}) {
  const response = await fetch(`${service.url}${path}`, { headers });
  return { html: await response.text(), vary: response.headers.get('vary') ?? '' };
}

test('?lang=pt: the server says lang="pt", the controls are in Portuguese', async () => {
  const { html, vary } = await served('/m/torus?lang=pt', { 'Accept-Language': 'de' });
  assert.match(html, /<html lang="pt" dir="ltr">/);
  assert.doesNotMatch(vary, /Accept-Language/i, 'chosen by the address, not the header');
  const { page, problems } = await newPage();
  await page.goto(`${service.url}/m/torus?lang=pt`);
  await untilDrawn(page);
  await page.waitForFunction(() => /Nível/.test(document.querySelector('vitrine-viewer')?.shadowRoot?.querySelector('.progress')?.textContent ?? ''));
  const seen = await chrome(page);
  assert.equal(seen.lang, 'pt');
  assert.equal(seen.dir, 'ltr');
  assert.equal(seen.reset, 'Redefinir');
  assert.equal(seen.resetTitle, 'Redefinir a visualização (R)');
  assert.match(String(seen.canvas), /^Visualização 3D/);
  assert.match(String(seen.progress), /^Nível \d+ de \d+ · [\d.]+ vértices · [\d.,]+ (bytes|kB|MB) recebidos$/);
  assert.equal(seen.switchValue, 'pt');
  assert.equal(seen.switchLabel, 'Idioma');
  assert.equal(seen.back, '← Todos os modelos');
  assert.deepEqual(problems, []);
  await page.close();
});

test('Accept-Language: es gives lang="es" (Vary: Accept-Language) and Spanish controls', async () => {
  const { html, vary } = await served('/m/torus', { 'Accept-Language': 'ja, es-MX;q=0.9, en;q=0.5' });
  assert.match(html, /<html lang="es" dir="ltr">/);
  assert.match(vary, /Accept-Language/i);
  for (const path of ['/', '/embed/torus', '/admin']) {
    const page = await served(path, { 'Accept-Language': 'es' });
    assert.match(page.html, /<html lang="es" dir="ltr">/, path);
  }
  assert.match((await served('/m/torus')).html, /<html lang="en" dir="ltr">/, 'English without a header');
  const { page, problems } = await newPage({ 'Accept-Language': 'es' });
  await page.goto(`${service.url}/m/torus`);
  await untilDrawn(page);
  const seen = await chrome(page);
  assert.equal(seen.lang, 'es');
  assert.equal(seen.reset, 'Restablecer');
  assert.match(String(seen.canvas), /^Vista 3D/);
  assert.equal(seen.switchValue, 'es');
  assert.equal(seen.back, '← Todos los modelos');
  assert.deepEqual(problems, []);
  await page.close();
});

test('?lang=ar: right to left, Arabic controls, nothing overlaps', async () => {
  const { html } = await served('/m/torus?lang=ar');
  assert.match(html, /<html lang="ar" dir="rtl">/);
  const { page, problems } = await newPage();
  await page.goto(`${service.url}/m/torus?lang=ar`);
  await untilDrawn(page);
  const seen = await chrome(page);
  assert.deepEqual([seen.lang, seen.dir, seen.reset], ['ar', 'rtl', 'إعادة الضبط']);
  // The measurement pane open too: the toolbar, a pane, the status and the credit at once.
  await page.locator('vitrine-viewer [data-action="measure"]').click();
  for (const [width, height] of [[800, 600], [390, 844], [320, 568], [1280, 800]]) {
    await page.setViewportSize({ width, height });
    await page.waitForFunction((w) => document.querySelector('vitrine-viewer')?.getBoundingClientRect().width === w, width);
    const boxes = await page.evaluate(() => {
      const host = /** @type {Element} */ (document.querySelector('vitrine-viewer'));
      const root = /** @type {ShadowRoot} */ (host.shadowRoot);
      const shown = (/** @type {Element} */ e) => /** @type {HTMLElement} */ (e).offsetParent !== null;
      const parts = [...root.querySelectorAll('.panel, .tools button, .tools select, .panes > *, .status > *, .credit')].filter(shown);
      const box = (/** @type {Element} */ e) => {
        const r = e.getBoundingClientRect();
        const name = `${e.className || e.tagName} ${/** @type {HTMLElement} */ (e).innerText.slice(0, 16)}`;
        return { name, direction: getComputedStyle(e).direction, left: r.left, top: r.top, right: r.right, bottom: r.bottom };
      };
      return { host: box(host), parts: parts.map(box) };
    });
    const where = `${width}×${height}`;
    const language = boxes.parts.find((p) => p.name.startsWith('language'));
    assert.ok(language, `${where}: the language switch is shown`);
    assert.ok(language.right - language.left >= 24 && language.bottom - language.top >= 24, `${where}: the switch is at least 24 × 24 px`);
    for (const p of boxes.parts) {
      assert.equal(p.direction, 'rtl', `${where}: ${p.name} is laid out right to left`);
      const inside = p.left >= boxes.host.left - 0.5 && p.right <= boxes.host.right + 0.5 && p.top >= boxes.host.top - 0.5 && p.bottom <= boxes.host.bottom + 0.5;
      assert.ok(inside, `${where}: ${p.name} ${JSON.stringify(p)} inside ${JSON.stringify(boxes.host)}`);
    }
    for (let i = 0; i < boxes.parts.length; i++) {
      for (let j = i + 1; j < boxes.parts.length; j++) {
        const [a, b] = [boxes.parts[i], boxes.parts[j]];
        const overlap = a.left < b.right - 0.5 && b.left < a.right - 0.5 && a.top < b.bottom - 0.5 && b.top < a.bottom - 0.5;
        assert.ok(!overlap, `${where}: ${a.name} ${JSON.stringify(a)} overlaps ${b.name} ${JSON.stringify(b)}`);
      }
    }
  }
  assert.deepEqual(problems, []);
  await page.close();
});

test('the switch changes the language in place, keeps it and puts it in the address', async () => {
  const { page, problems } = await newPage();
  await page.goto(`${service.url}/m/torus`);
  await untilDrawn(page, { complete: true });
  assert.equal((await chrome(page)).reset, 'Reset');
  // A mark on the window: a reload would lose it.
  await page.evaluate(() => (/** @type {any} */ (window).beforeSwitch = true));
  const requests = /** @type {string[]} */ ([]);
  page.on('request', (r) => requests.push(r.url()));
  // By keyboard, as a visitor without a mouse would: focus the switch, choose with the arrows.
  const select = page.locator('vitrine-viewer select.language');
  await select.focus();
  await select.selectOption('fr');
  await page.waitForFunction(() => document.documentElement.lang === 'fr');
  const seen = await chrome(page);
  assert.equal(seen.reset, 'Réinitialiser');
  assert.equal(seen.back, '← Tous les modèles');
  assert.match(String(seen.progress), /^Niveau \d+ sur \d+ · /);
  assert.equal(await page.evaluate(() => /** @type {any} */ (window).beforeSwitch), true, 'no reload');
  assert.deepEqual(requests, [], 'the switch asks the server for nothing');
  assert.equal(new URL(page.url()).searchParams.get('lang'), 'fr');
  assert.equal(await page.evaluate(() => localStorage.getItem('vitrine-lang')), 'fr');
  // Back to Arabic: the direction follows.
  await select.selectOption('ar');
  assert.deepEqual(await page.evaluate(() => [document.documentElement.lang, document.documentElement.dir]), ['ar', 'rtl']);
  await select.selectOption('de');
  assert.deepEqual(problems, [], 'nothing failed while switching');
  // The choice is kept: the same page without ?lang= opens in it (leaving
  // the page may cut short what it still had in flight).
  await page.goto(`${service.url}/m/torus`);
  await untilDrawn(page);
  assert.equal((await chrome(page)).reset, 'Zurücksetzen');
  await page.evaluate(() => localStorage.removeItem('vitrine-lang'));
  // (The assertion above narrowed the list's type to empty: it has grown since.)
  const unexpected = /** @type {string[]} */ (problems).filter((p) => !p.endsWith('net::ERR_ABORTED'));
  assert.deepEqual(unexpected, []);
  await page.close();
});

test("a museum's own words from the configuration file replace the viewer's, per language", async () => {
  const dir = mkdtempSync(join(tmpdir(), 'vitrine-strings-'));
  const file = join(dir, 'vitrine.toml');
  writeFileSync(
    file,
    '[ui.strings.en]\n"gallery.intro" = "Stories from our collection, in 3D."\n\n' +
      '[ui.strings.pt.gallery]\nintro = "Histórias do nosso acervo, em 3D."\n',
  );
  const own = await startService({ models: [], serveArgs: ['--config', file] });
  try {
    const page = await browser.context.newPage();
    const intro = async (/** @type {string} */ lang) => {
      await page.goto(`${own.url}/?lang=${lang}`);
      return page.locator('header p').innerText();
    };
    assert.equal(await intro('en'), 'Stories from our collection, in 3D.');
    assert.equal(await intro('pt'), 'Histórias do nosso acervo, em 3D.');
    assert.match(await intro('de'), /^3D-Scans aus der Sammlung/, 'the catalogue where the museum gives nothing');
    await page.close();
  } finally {
    await own.stop();
    rmSync(dir, { recursive: true, force: true });
  }
});
