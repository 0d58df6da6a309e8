// @ts-check
// End-to-end: a guided tour of five steps is recorded through /admin (the
// curator frames each view in the editor's viewer with the keyboard, adds
// it, writes its title and text, reorders, saves), appears in the IIIF
// Manifest as a Range, plays end to end for a visitor by keyboard alone
// (Tab to the Tour button, Enter, P, then ← and Home), moves at once under
// prefers-reduced-motion, and a link to step 3 opens there.
import { after, before, test } from 'node:test';
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import { launch } from '../test/support/browser.mjs';
import { vitrine } from '../test/support/fixtures.mjs';
import { startService } from '../test/support/service.mjs';

/** @typedef {import('playwright-core').Page} Page */

/** @type {Awaited<ReturnType<typeof startService>>} */
let service;
/** @type {Awaited<ReturnType<typeof launch>>} */
let browser;
/** @type {string} */
let token;

before(async () => {
  service = await startService({ models: [{ slug: 'torus', title: 'Torus', kind: 'torus', kiloVertices: 3 }] });
  const printed = execFileSync(vitrine, ['token', 'create', '--db', service.db, '--scope', 'curator', '--label', 'e2e'], { encoding: 'utf8' });
  token = printed.trim().split('\n').at(-1) ?? '';
  browser = await launch({ width: 1000, height: 900 });
});

after(async () => {
  await browser?.close();
  await service?.stop();
});

async function newPage() {
  const page = await browser.context.newPage();
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

/** @param {Page} page @param {string} selector the viewer element */
async function untilComplete(page, selector = 'vitrine-viewer') {
  await page.waitForFunction((s) => /** @type {any} */ (document.querySelector(s))?.viewer?.state.status === 'complete', selector, {
    timeout: 60_000,
    polling: 50,
  });
}

/** The camera of a saved view's fragment. @param {string} view */
function cameraOf(view) {
  const [tx, ty, tz, distance, yaw, pitch] = (new URLSearchParams(view).get('camera') ?? '').split(',').map(Number);
  return { target: [tx, ty, tz], distance, yaw, pitch };
}

/** @param {Page} page */
function player(page) {
  return page.evaluate(() => {
    const v = /** @type {any} */ (document.querySelector('vitrine-viewer')).viewer;
    return {
      index: v.tours.index,
      playing: v.tours.playing,
      moving: v.tours.moving,
      open: !v.tours.pane.hidden,
      count: v.tours.count.innerText,
      heading: v.tours.heading.innerText,
      camera: structuredClone(v.camera.state),
    };
  });
}

/** @param {any} a @param {any} b */
function sameCamera(a, b) {
  const d = Math.max(...a.target.map((/** @type {number} */ x, /** @type {number} */ k) => Math.abs(x - b.target[k])), Math.abs(a.distance - b.distance));
  return d < 1e-6 && Math.abs(Math.atan2(Math.sin(a.yaw - b.yaw), Math.cos(a.yaw - b.yaw))) < 1e-6 && Math.abs(a.pitch - b.pitch) < 1e-6;
}

/** @type {{ id: number, steps: Array<{ view: string, title: Record<string, string> }> }} */
let recorded;

test('a curator records a tour of five steps in /admin; it is served and in the Manifest', { timeout: 240_000 }, async () => {
  const { page, problems } = await newPage();
  await page.goto(`${service.url}/admin`);
  await page.getByLabel('Token (from vitrine token create --scope curator)').fill(token);
  await page.getByRole('button', { name: 'Use token' }).click();
  await page.getByRole('button', { name: 'Tours of torus' }).click();
  await page.getByText('No tours yet.').waitFor();
  await page.getByRole('button', { name: 'New tour' }).click();
  await untilComplete(page, '.tour-viewer');
  await page.getByLabel('Tour title').fill('Around the ring');
  const canvas = page.locator('.tour-viewer canvas');
  for (let n = 1; n <= 5; n++) {
    // Each step a different view: the curator turns the model with the keys.
    await canvas.focus();
    for (let k = 0; k < 3; k++) await page.keyboard.press(n % 2 ? 'ArrowLeft' : 'ArrowUp');
    await page.getByRole('button', { name: 'Add the view on screen as a step' }).click();
    await page.getByLabel(`Title of step ${n}`, { exact: true }).fill(`Step ${n}`);
    await page.getByLabel(`Text of step ${n} (Markdown)`, { exact: true }).fill(`The **view** number ${n}.`);
  }
  // In Portuguese too, for the first step.
  await page.getByLabel('Language of the texts you write').selectOption('pt');
  await page.getByLabel('Title of step 1', { exact: true }).fill('Etapa 1');
  await page.getByLabel('Language of the texts you write').selectOption('en');
  // Reorder: step 5 up, then back down.
  await page.getByRole('button', { name: 'Move step 5 up' }).click();
  assert.equal(await page.getByLabel('Title of step 4', { exact: true }).inputValue(), 'Step 5');
  await page.getByRole('button', { name: 'Move step 4 down' }).click();
  assert.equal(await page.getByLabel('Title of step 5', { exact: true }).inputValue(), 'Step 5');
  await page.getByRole('button', { name: 'Save tour' }).click();
  await page.getByText('Tour saved.').waitFor();
  await page.getByText('Around the ring — version 1, 5 steps').waitFor();
  assert.deepEqual(problems, []);
  await page.close();

  const tours = await (await fetch(`${service.url}/api/models/torus/tours`)).json();
  assert.equal(tours.length, 1);
  recorded = tours[0];
  assert.deepEqual(
    recorded.steps.map((s) => s.title.en),
    ['Step 1', 'Step 2', 'Step 3', 'Step 4', 'Step 5'],
  );
  assert.equal(recorded.steps[0].title.pt, 'Etapa 1');
  const cameras = recorded.steps.map((s) => JSON.stringify(cameraOf(s.view)));
  assert.equal(new Set(cameras).size, 5, 'five different views');
  const manifest = await (await fetch(`${service.url}/iiif/torus/manifest`)).json();
  assert.equal(manifest.structures.length, 1);
  assert.equal(manifest.structures[0].type, 'Range');
  assert.deepEqual(manifest.structures[0].label, { en: ['Around the ring'] });
  assert.equal(manifest.structures[0].items.length, 5);
});

test('the tour plays end to end by keyboard alone', { timeout: 240_000 }, async () => {
  assert.ok(recorded, 'recorded by the test before');
  const { page, problems } = await newPage();
  await page.goto(`${service.url}/m/torus`);
  await untilComplete(page);
  const tourButton = page.locator('vitrine-viewer').getByRole('button', { name: 'Tour', exact: true });
  await tourButton.waitFor();
  // Tab through the page until the Tour button has the focus.
  for (let k = 0; k < 40; k++) {
    await page.keyboard.press('Tab');
    const focused = await page.evaluate(() => document.querySelector('vitrine-viewer')?.shadowRoot?.activeElement?.getAttribute('data-action') ?? null);
    if (focused === 'tour') break;
  }
  await page.keyboard.press('Enter');
  let state = await player(page);
  assert.ok(state.open);
  assert.equal(state.count, 'Step 1 of 5');
  assert.equal(state.heading, 'Step 1');
  await page.keyboard.press('p');
  assert.ok((await player(page)).playing);
  await page.waitForFunction(
    () => {
      const t = /** @type {any} */ (document.querySelector('vitrine-viewer')).viewer.tours;
      return t.index === 4 && !t.playing && !t.moving;
    },
    undefined,
    { timeout: 120_000, polling: 100 },
  );
  state = await player(page);
  assert.equal(state.count, 'Step 5 of 5');
  assert.ok(sameCamera(state.camera, cameraOf(recorded.steps[4].view)), JSON.stringify(state.camera));
  // Back one step, then to the first: the camera eases there.
  await page.keyboard.press('ArrowLeft');
  await page.waitForFunction(() => !(/** @type {any} */ (document.querySelector('vitrine-viewer')).viewer.tours.moving));
  state = await player(page);
  assert.equal(state.index, 3);
  assert.ok(sameCamera(state.camera, cameraOf(recorded.steps[3].view)));
  await page.keyboard.press('Home');
  assert.ok((await player(page)).moving, 'the camera moves, eased');
  await page.waitForFunction(() => !(/** @type {any} */ (document.querySelector('vitrine-viewer')).viewer.tours.moving));
  assert.ok(sameCamera((await player(page)).camera, cameraOf(recorded.steps[0].view)));
  await page.keyboard.press('Escape');
  assert.ok(!(await player(page)).open);
  assert.deepEqual(problems, []);
  await page.close();
});

test('under prefers-reduced-motion each step is put on screen at once', { timeout: 120_000 }, async () => {
  const { page, problems } = await newPage();
  await page.emulateMedia({ reducedMotion: 'reduce' });
  await page.goto(`${service.url}/m/torus`);
  await untilComplete(page);
  await page.locator('vitrine-viewer').getByRole('button', { name: 'Tour', exact: true }).click();
  await page.keyboard.press('ArrowRight');
  const state = await player(page);
  assert.equal(state.index, 1);
  assert.ok(!state.moving);
  assert.ok(sameCamera(state.camera, cameraOf(recorded.steps[1].view)));
  assert.deepEqual(problems, []);
  await page.close();
});

test('a link to step 3 opens the tour there', { timeout: 120_000 }, async () => {
  const { page, problems } = await newPage();
  await page.goto(`${service.url}/m/torus?tour=${recorded.id}&step=3&lang=pt`);
  await untilComplete(page);
  await page.waitForFunction(() => /** @type {any} */ (document.querySelector('vitrine-viewer')).viewer.tours.index === 2, undefined, {
    timeout: 30_000,
  });
  const state = await player(page);
  assert.ok(state.open);
  assert.equal(state.count, 'Etapa 3 de 5');
  assert.equal(state.heading, 'Step 3', 'a title without Portuguese falls back to English');
  assert.ok(sameCamera(state.camera, cameraOf(recorded.steps[2].view)));
  assert.deepEqual(problems, []);
  await page.close();
});
