// @ts-check
// End-to-end: views you can link to. A visitor turns the model, opens a
// note, sets a raking light and a section, and shares the view; the view
// link and the IIIF Content State link each open a fresh page at the same
// camera (the picture matches within a small pixel tolerance), with the same
// note open and the same section. Bad Content States — not base64url, not
// JSON, another site's manifest, a model this site does not have — give a
// message in the viewer and send no request to another host.
import { after, before, test } from 'node:test';
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import { launch } from '../test/support/browser.mjs';
import { vitrine } from '../test/support/fixtures.mjs';
import { compareImages } from '../test/support/raster.mjs';
import { startService } from '../test/support/service.mjs';

/** @typedef {import('playwright-core').Page} Page */

/** @type {Awaited<ReturnType<typeof startService>>} */
let service;
/** @type {Awaited<ReturnType<typeof launch>>} */
let browser;

before(async () => {
  service = await startService({
    models: [{ slug: 'torus', title: 'Torus', kind: 'torus', kiloVertices: 3, ingestArgs: ['--unit', 'mm', '--up', 'z'] }],
  });
  const printed = execFileSync(vitrine, ['token', 'create', '--db', service.db, '--scope', 'curator', '--label', 'e2e'], { encoding: 'utf8' });
  const token = printed.trim().split('\n').at(-1) ?? '';
  /** @type {Array<{ title: string, position: number[], normal: number[] }>} */
  const notes = [
    { title: 'Outer rim', position: [1.3, 0, 0], normal: [1, 0, 0] },
    { title: 'Inner rim', position: [0.7, 0, 0], normal: [-1, 0, 0] },
  ];
  for (const { title, position, normal } of notes) {
    const reply = await fetch(`${service.url}/api/models/torus/annotations`, {
      method: 'POST',
      headers: { Authorization: `Bearer ${token}`, 'Content-Type': 'application/json' },
      body: JSON.stringify({ title, text: `The *${title.toLowerCase()}*.`, position, normal }),
    });
    assert.equal(reply.status, 201, await reply.text());
  }
  browser = await launch({ width: 800, height: 600 });
});

after(async () => {
  await browser?.close();
  await service?.stop();
});

/**
 * A fresh page that records script errors, failed requests, error answers
 * and every request to another host (refused before it leaves).
 */
async function newPage() {
  const page = await browser.context.newPage();
  const origin = new URL(service.url).origin;
  /** @type {string[]} */
  const problems = [];
  /** @type {string[]} */
  const foreign = [];
  await page.route(
    (url) => url.origin !== origin,
    (route) => {
      foreign.push(route.request().url());
      return route.abort();
    },
  );
  page.on('pageerror', (e) => problems.push(`error: ${e.message}`));
  page.on('requestfailed', (r) => problems.push(`failed: ${r.url()} ${r.failure()?.errorText}`));
  page.on('response', (r) => {
    // Every 4xx counts: a page asks for no study results its manifest does not link.
    if (r.status() >= 400) problems.push(`${r.status()}: ${r.url()}`);
  });
  return { page, problems, foreign };
}

/** Until the last level is on screen, any shared view applied, and the frame drawn. @param {Page} page */
async function untilSettled(page) {
  await page.waitForFunction(
    () => {
      const v = /** @type {any} */ (document.querySelector('vitrine-viewer'))?.viewer;
      return v?.state.status === 'complete' && v.annotations.list.length === 2;
    },
    undefined,
    { timeout: 60_000, polling: 50 },
  );
  await page.evaluate(() => /** @type {any} */ (document.querySelector('vitrine-viewer')).viewer.share.applied);
  await page.waitForFunction(() => /** @type {any} */ (document.querySelector('vitrine-viewer')).viewer.renderer.settled, undefined, {
    timeout: 30_000,
    polling: 50,
  });
}

/** The picture on the canvas, RGBA. @param {Page} page */
async function capture(page) {
  const data = await page.evaluate(async () => {
    const { rgba } = await /** @type {any} */ (document.querySelector('vitrine-viewer')).viewer.renderer.capture();
    let binary = '';
    for (let i = 0; i < rgba.length; i += 0x8000) binary += String.fromCharCode(...rgba.subarray(i, i + 0x8000));
    return btoa(binary);
  });
  return new Uint8Array(Buffer.from(data, 'base64'));
}

/** What the tests compare besides the picture. @param {Page} page */
function viewState(page) {
  return page.evaluate(() => {
    const v = /** @type {any} */ (document.querySelector('vitrine-viewer')).viewer;
    return {
      camera: structuredClone(v.camera.state),
      note: v.annotations.pane.hidden ? null : (v.annotations.selected?.title ?? null),
      section: v.inspection.currentSection() ?? null,
      plane: v.look.section,
      light: v.look.light,
    };
  });
}

/** @param {any} a @param {any} b */
function closeCamera(a, b) {
  const d = Math.max(...a.target.map((/** @type {number} */ x, /** @type {number} */ k) => Math.abs(x - b.target[k])), Math.abs(a.distance - b.distance) / a.distance);
  const angle = Math.max(Math.abs(Math.atan2(Math.sin(a.yaw - b.yaw), Math.cos(a.yaw - b.yaw))), Math.abs(a.pitch - b.pitch));
  return d < 1e-5 && angle < 1e-5;
}

/** The shadow root's element, for Playwright's role queries (they pierce open shadow roots). @param {Page} page */
const viewer = (page) => page.locator('vitrine-viewer');

test('a view link and a IIIF Content State link open at the saved view: camera, note, section', { timeout: 240_000 }, async () => {
  const { page, problems, foreign } = await newPage();
  await page.goto(`${service.url}/m/torus`);
  await untilSettled(page);
  const v = viewer(page);
  // The visitor's own moves: keys on the canvas, a note, a raking light, a section.
  await v.locator('canvas').focus();
  for (const key of ['ArrowLeft', 'ArrowLeft', 'ArrowUp', '+']) await page.keyboard.press(key);
  await v.getByRole('button', { name: 'Notes', exact: true }).click();
  await v.getByRole('button', { name: 'Inner rim', exact: true }).click();
  await v.getByRole('button', { name: 'Light', exact: true }).click();
  await v.getByRole('button', { name: 'Raking ←' }).click();
  await v.getByRole('button', { name: 'Section', exact: true }).click();
  await v.locator('.section').getByRole('button', { name: 'Y', exact: true }).click();
  await v.locator('.section input[type="range"]').evaluate((input) => {
    /** @type {HTMLInputElement} */ (input).value = '620';
    input.dispatchEvent(new Event('input'));
  });
  await page.waitForFunction(() => /** @type {any} */ (document.querySelector('vitrine-viewer')).viewer.renderer.settled);
  const original = await viewState(page);
  assert.equal(original.note, 'Inner rim');
  assert.deepEqual(original.section, { axis: 'y', fraction: 0.62, flip: false });
  const picture = await capture(page);

  // Share: a keyboard-operable button with its name; the pane offers both links.
  const share = v.getByRole('button', { name: 'Share', exact: true });
  assert.equal(await share.getAttribute('title'), 'Share this view');
  await share.focus();
  await page.keyboard.press('Enter');
  const viewLink = await v.getByLabel('Link to this view').inputValue();
  const stateLink = await v.getByLabel('IIIF Content State link (for IIIF viewers)').inputValue();
  assert.match(viewLink, /\/m\/torus\?lang=en#camera=[^&]+&light=[^&]+&section=y,0\.62,0&note=\d+$/);
  assert.match(stateLink, /\/m\/torus\?lang=en&iiif-content=[A-Za-z0-9_-]+#light=[^&]+&section=y,0\.62,0$/);
  // The Content State is the specification's shape: a contentState Annotation on the Scene.
  const encoded = new URL(stateLink).searchParams.get('iiif-content') ?? '';
  const state = JSON.parse(Buffer.from(encoded, 'base64url').toString('utf8'));
  assert.deepEqual(state.motivation, ['contentState']);
  assert.equal(state.body.type, 'PerspectiveCamera');
  assert.match(state.target[0].source.id, /\/iiif\/torus\/scene$/);
  assert.match(state.target[0].source.partOf[0].id, /\/iiif\/torus\/manifest$/);
  assert.match(state.target[1].id, /\/iiif\/torus\/annotations\/\d+$/);
  assert.deepEqual(problems, []);
  assert.deepEqual(foreign, []);

  for (const [what, link] of [
    ['view link', viewLink],
    ['Content State link', stateLink],
  ]) {
    const opened = await newPage();
    await opened.page.goto(link);
    await untilSettled(opened.page);
    const restored = await viewState(opened.page);
    assert.ok(closeCamera(original.camera, restored.camera), `${what}: ${JSON.stringify([original.camera, restored.camera])}`);
    assert.equal(restored.note, 'Inner rim', what);
    assert.deepEqual(restored.section, original.section, what);
    assert.deepEqual(restored.plane, original.plane, what);
    const score = compareImages(picture, await capture(opened.page));
    assert.ok(score.foreground > 1000, `${what}: the model is drawn`);
    assert.ok(score.iou > 0.995 && score.meanDiff < 1.5, `${what}: ${JSON.stringify(score)}`);
    assert.deepEqual(opened.problems, [], what);
    assert.deepEqual(opened.foreign, [], what);
    await opened.page.close();
  }
  await page.close();
});

test('the element takes the same view in its view attribute', { timeout: 120_000 }, async () => {
  const { page, problems } = await newPage();
  const view = 'camera=0,0,0,4,1.2,0.3&section=x,0.5,1';
  await page.goto(`${service.url}/embed/torus#${view}`);
  await untilSettled(page);
  const state = await viewState(page);
  assert.ok(closeCamera(state.camera, { target: [0, 0, 0], distance: 4, yaw: 1.2, pitch: 0.3 }), JSON.stringify(state.camera));
  assert.deepEqual(state.section, { axis: 'x', fraction: 0.5, flip: true });
  assert.equal(await page.locator('vitrine-viewer').getAttribute('view'), view);
  assert.deepEqual(problems, []);
  await page.close();
});

/** @param {object} json */
const encode = (json) => Buffer.from(JSON.stringify(json)).toString('base64url');

test('bad Content States: a message in the viewer, no request to another host', { timeout: 240_000 }, async () => {
  const contentState = (/** @type {string} */ manifest) => ({
    '@context': 'http://iiif.io/api/presentation/4/context.json',
    type: 'Annotation',
    motivation: ['contentState'],
    target: { id: manifest, type: 'Manifest' },
  });
  /** @type {Array<[string, string, RegExp]>} */
  const cases = [
    ['not base64url', 'not*base64!', /is not base64url/],
    ['not JSON', Buffer.from('{"type": "Annotation", ').toString('base64url'), /is not JSON/],
    ['another site', encode(contentState('https://iiif.example.org/iiif/torus/manifest')), /names another site \(iiif\.example\.org\)/],
    ['another site, as a plain URI', 'https://iiif.example.org/iiif/torus/manifest', /names another site/],
    ['another model', encode(contentState(`${service.url}/iiif/nope/manifest`)), /is for another model \(nope\)/],
  ];
  for (const [what, value, message] of cases) {
    const { page, problems, foreign } = await newPage();
    await page.goto(`${service.url}/m/torus?iiif-content=${encodeURIComponent(value)}`);
    await page.waitForFunction(
      (source) => new RegExp(source).test(/** @type {HTMLElement} */ (document.querySelector('vitrine-viewer')?.shadowRoot?.querySelector('.notice'))?.innerText ?? ''),
      message.source,
      { timeout: 30_000, polling: 50 },
    );
    assert.deepEqual(foreign, [], `${what}: no request to another host`);
    assert.deepEqual(problems, [], what);
    await page.close();
  }
  // The site's own entry: `/?iiif-content=` opens the model it names, or says the site has none such.
  const unknown = await newPage();
  await unknown.page.goto(`${service.url}/?iiif-content=${encode(contentState(`${service.url}/iiif/nope/manifest`))}`);
  await unknown.page.getByRole('alert').filter({ hasText: 'This site has no model “nope”' }).waitFor();
  assert.deepEqual(unknown.foreign, []);
  assert.deepEqual(unknown.problems, []);
  await unknown.page.close();
  const known = await newPage();
  await known.page.goto(`${service.url}/?iiif-content=${encode(contentState(`${service.url}/iiif/torus/manifest`))}`);
  await untilSettled(known.page);
  assert.deepEqual(known.problems, []);
  await known.page.close();
});

test('Share in Portuguese: the control and the message are translated', { timeout: 120_000 }, async () => {
  const { page, problems } = await newPage();
  await page.goto(`${service.url}/m/torus?lang=pt&iiif-content=not*base64`);
  const v = viewer(page);
  await v.getByRole('button', { name: 'Compartilhar', exact: true }).waitFor();
  await page.waitForFunction(
    () => /base64url/.test(/** @type {HTMLElement} */ (document.querySelector('vitrine-viewer')?.shadowRoot?.querySelector('.notice'))?.innerText ?? ''),
    undefined,
    { timeout: 30_000 },
  );
  const notice = await page.evaluate(() => /** @type {HTMLElement} */ (document.querySelector('vitrine-viewer')?.shadowRoot?.querySelector('.notice')).innerText);
  assert.match(notice, /^Não foi possível ler a visualização deste link/);
  assert.deepEqual(problems, []);
  await page.close();
});
