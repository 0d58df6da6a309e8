// @ts-check
// End-to-end: the quality study page (issue 17) against the real service, in
// Chromium. A study with a short T (0.4 s) and one invitation: information,
// consent, practice, the original's turntable, then every step answered
// through the page's buttons. Checked: every step's answer is stored (the
// API's plan and `vitrine study export`); each period lasted at least T (the
// view log's state events and the answers' shown_ms); a drag, the wheel and
// the keys during the questions do not move the camera; the next step's
// level is requested while the questions are up, before the answer is sent;
// the session POST carries device, viewport and pixel ratio; the model
// page's chart gains the study's bars; without an invitation the page says
// the study is closed; the layout holds from 320 px to 4K.
import { after, before, test } from 'node:test';
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import { readFileSync } from 'node:fs';
import { join } from 'node:path';
import { launch } from '../test/support/browser.mjs';
import { vitrine } from '../test/support/fixtures.mjs';
import { createStudy, inviteToStudy, startService } from '../test/support/service.mjs';

/** @typedef {import('playwright-core').Page} Page */

const SLUG = 'study-torus';
const T = 0.4;

/** @type {Awaited<ReturnType<typeof startService>>} */
let service;
/** @type {Awaited<ReturnType<typeof launch>>} */
let browser;
/** @type {string[]} */
let links;

before(async () => {
  service = await startService({
    models: [{ slug: SLUG, title: 'Study torus', kind: 'torus', kiloVertices: 8, colour: true, quality: true }],
  });
  links = createStudy(service, { slug: SLUG, seconds: T, count: 1 });
  assert.equal(links.length, 1, 'one link printed');
  browser = await launch({ width: 800, height: 600 });
});

after(async () => {
  await browser?.close();
  await service?.stop();
});

/** @param {string} link */
function invitationOf(link) {
  return /** @type {string} */ (new URL(link).searchParams.get('invitation'));
}

/** @param {Page} page */
function cameraState(page) {
  return page.evaluate(() => JSON.stringify(/** @type {any} */ (document.querySelector('vitrine-viewer'))?.viewer?.camera?.state ?? null));
}

/** @param {Page} page @param {string} condition on `s`, the viewer's state */
function untilViewer(page, condition) {
  return page.waitForFunction(
    `(() => { const s = document.querySelector('vitrine-viewer')?.viewer?.state; return Boolean(s) && (${condition}); })()`,
    undefined,
    { timeout: 60_000 },
  );
}

/** Drags across the upper half of the window, turns the wheel, presses keys on the canvas. @param {Page} page */
async function tryToMove(page) {
  const { width, height } = /** @type {{ width: number, height: number }} */ (page.viewportSize());
  await page.mouse.move(width * 0.3, height * 0.25);
  await page.mouse.down();
  await page.mouse.move(width * 0.7, height * 0.3, { steps: 6 });
  await page.mouse.up();
  await page.mouse.wheel(0, 400);
  await page.evaluate(() => {
    const canvas = /** @type {any} */ (document.querySelector('vitrine-viewer'))?.shadowRoot.querySelector('canvas');
    for (const key of ['ArrowLeft', '+']) canvas.dispatchEvent(new KeyboardEvent('keydown', { key, bubbles: true }));
  });
}

/**
 * Walks from the invitation link to the steps.
 * @param {Page} page
 * @param {string} link
 */
async function throughIntroduction(page, link) {
  await page.goto(link);
  await page.getByRole('heading', { name: /Quality study/ }).waitFor();
  await page.getByRole('button', { name: 'Continue' }).click();
  await page.getByRole('heading', { name: 'Consent' }).waitFor();
  await page.getByLabel(/I agree/).check();
  await page.getByRole('button', { name: 'Start' }).click();
  await page.getByRole('heading', { name: 'Practice' }).waitFor();
  await untilViewer(page, 's.shownLevel >= 0');
}

test('a page without an invitation, or with an unknown one, says the study is closed', async () => {
  const page = await browser.context.newPage();
  for (const path of [`/study/${SLUG}`, `/study/${SLUG}?invitation=not-a-real-invitation`]) {
    await page.goto(service.url + path);
    const alert = page.getByRole('alert');
    await alert.waitFor();
    assert.match(await alert.innerText(), /study is closed/i, path);
    assert.equal(await page.locator('vitrine-viewer').count(), 0, `no viewer on ${path}`);
  }
  await page.close();
});

test('a participant answers every step through the page; answers, durations, lock and prefetch hold', async (t) => {
  const link = links[0];
  const invitation = invitationOf(link);
  const page = await browser.context.newPage();
  /** @type {string[]} */
  const problems = [];
  page.on('pageerror', (e) => problems.push(e.message));
  /** @type {Array<{ i: number, method: string, url: string, body: any }>} */
  const requests = [];
  page.on('request', (r) => {
    let body = null;
    try {
      body = r.postDataJSON();
    } catch {}
    requests.push({ i: requests.length, method: r.method(), url: r.url(), body });
  });

  await throughIntroduction(page, link);
  const session = requests.find((r) => r.method === 'POST' && r.url.endsWith(`/api/study/${SLUG}/session`));
  assert.ok(session, 'the session is created after consent');
  assert.equal(session.body.consent, true);
  assert.equal(session.body.device, 'desktop');
  assert.deepEqual(session.body.viewport, [800, 600]);
  assert.equal(session.body.pixel_ratio, 1);
  const auth = await (await fetch(`${service.url}/api/study/${SLUG}/session`, { headers: { authorization: `Bearer ${invitation}` } })).json();
  /** @type {Array<{ step: number, from: number, to: number, control: boolean }>} */
  const steps = auth.steps;
  assert.ok(steps.length >= 3, `${steps.length} steps`);
  assert.equal(steps.filter((s) => s.control).length, 1, 'one control step');

  // Practice: the controls move the camera (so the lock below means something).
  const before = await cameraState(page);
  await tryToMove(page);
  assert.notEqual(await cameraState(page), before, 'the practice view responds to the mouse');
  await page.getByRole('button', { name: 'Continue' }).click();

  // The original at its last level, turning by itself.
  await page.getByRole('heading', { name: 'The original' }).waitFor();
  const manifest = await (await fetch(`${service.url}/api/models/${SLUG}?token=${invitation}`)).json();
  assert.equal(manifest.cap.level, manifest.last_level, 'the invitation lifts the cap to m_n');
  await untilViewer(page, `s.shownLevel === ${manifest.last_level}`);
  const yaw0 = JSON.parse(await cameraState(page)).yaw;
  await page.waitForTimeout(400);
  assert.notEqual(JSON.parse(await cameraState(page)).yaw, yaw0, 'the turntable turns');
  // Every frame, turning or not, is of the level being judged: no coarser stand-in (src/motion.js).
  const frames = await page.evaluate(() => /** @type {any} */ (document.querySelector('vitrine-viewer')).viewer.renderer.frameStats());
  assert.ok(frames.frames > 1 && frames.standInLevel === null && frames.standInFrames === 0, JSON.stringify(frames));
  const begun = requests.length;
  await page.getByRole('button', { name: 'Begin the steps' }).click();

  /** @type {Record<number, number>} request index of each answer's PUT */
  const putAt = {};
  for (const step of steps) {
    const form = page.locator('form.study-questions');
    await form.waitFor({ timeout: 60_000 });
    await page.getByRole('heading', { name: `Step ${step.step} of ${steps.length}: your answers` }).waitFor();
    assert.equal(await page.evaluate(() => document.body.dataset.studyState), 'answer');
    const locked = await cameraState(page);
    await tryToMove(page);
    assert.equal(await cameraState(page), locked, `step ${step.step}: the camera does not move during the questions`);
    assert.match(await page.getByRole('status').filter({ hasText: /^Step / }).innerText(), new RegExp(`Step ${step.step} of ${steps.length}`));
    await form.getByRole('radio', { name: step.control ? 'None' : 'A little', exact: true }).check();
    await form.getByRole('radio', { name: step.to >= manifest.last_level - 1 ? 'Yes' : 'No', exact: true }).check();
    const stored = page.waitForResponse((r) => r.url().includes(`/session/answers/${step.step}`) && r.request().method() === 'PUT');
    await form.getByRole('button', { name: 'Submit answers' }).click();
    const response = await stored;
    assert.equal(response.status(), 201, `step ${step.step} stored`);
    putAt[step.step] = requests.findIndex((r) => r.method === 'PUT' && r.url.includes(`/session/answers/${step.step}`));
  }
  await page.getByRole('heading', { name: 'Thank you' }).waitFor({ timeout: 30_000 });
  assert.ok(requests.some((r) => r.method === 'POST' && r.url.endsWith('/session/finish')), 'the session is finished');

  // Every step's answer is stored.
  const plan = await (await fetch(`${service.url}/api/study/${SLUG}/session`, { headers: { authorization: `Bearer ${invitation}` } })).json();
  assert.deepEqual(plan.answered, steps.map((s) => s.step));
  assert.equal(plan.finished, true);
  const csv = join(service.dir, 'answers.csv');
  const views = join(service.dir, 'views.csv');
  execFileSync(vitrine, ['study', 'export', '--db', service.db, '--slug', SLUG, '-o', csv, '--views', views], { stdio: 'pipe' });
  const rows = readFileSync(csv, 'utf8').trim().split('\n');
  assert.equal(rows[0], 'participant,step,from_level,to_level,control,improvement,sufficient');
  assert.equal(rows.length - 1, steps.length, 'one exported row per step');
  for (const step of steps) {
    const row = rows.find((r) => r.split(',')[1] === String(step.step));
    assert.ok(row, `step ${step.step} exported`);
    const [, , from, to, control, improvement] = row.split(',');
    assert.deepEqual([Number(from), Number(to), control], [step.from, step.to, String(step.control)]);
    assert.equal(improvement, step.control ? 'none' : 'a-little');
  }

  // shown_ms: both periods of every answer at least T.
  const answers = requests.filter((r) => r.method === 'PUT' && r.url.includes('/session/answers/'));
  /** @type {number[]} */
  const shown = answers.flatMap((a) => a.body.shown_ms);
  for (const ms of shown) assert.ok(ms >= T * 1000, `shown_ms ${ms} ≥ ${T * 1000}`);

  // The view log: state events of every step, each period at least T from its own start.
  const events = requests.filter((r) => r.method === 'POST' && r.url.endsWith('/session/views')).flatMap((r) => r.body.events);
  assert.ok(events.length > 0, 'the view log was sent');
  // …and stored: `vitrine study export --views` has every event sent.
  const stored = readFileSync(views, 'utf8').trim().split('\n');
  assert.equal(stored[0], 'participant,at_ms,step,state,kind,data');
  const storedStates = stored.slice(1).filter((line) => /^[^,]+,[\d.]+,\d+,\w+,state,/.test(line));
  assert.equal(stored.length - 1, events.length, 'every view event stored');
  assert.equal(storedStates.length, events.filter((e) => e.kind === 'state').length);
  for (const r of requests.filter((r) => r.url.endsWith('/session/views'))) assert.ok(r.body.events.length <= 200);
  /** @type {Record<string, number[]>} */
  const periods = { pre: [], post: [] };
  for (const step of steps) {
    const states = events.filter((e) => e.kind === 'state' && e.step === step.step);
    const names = states.map((e) => e.state);
    assert.deepEqual(names, step.control ? ['pre', 'post', 'answer'] : ['pre', 'transition', 'post', 'answer'], `step ${step.step}`);
    const at = (/** @type {string} */ name) => states.find((e) => e.state === name).at_ms;
    const pre = at(step.control ? 'post' : 'transition') - at('pre');
    const post = at('answer') - at('post');
    periods.pre.push(pre);
    periods.post.push(post);
    // at_ms is rounded to 0.1 ms.
    assert.ok(pre >= T * 1000 - 0.1, `step ${step.step}: pre lasted ${pre} ms`);
    assert.ok(post >= T * 1000 - 0.1, `step ${step.step}: post lasted ${post} ms`);
    for (const e of states) assert.ok(e.camera && typeof e.zoom === 'number', 'state events carry the camera');
  }
  assert.ok(events.some((e) => e.kind === 'interaction' && e.state === 'practice' && e.interaction === 'orbit'), 'practice interactions logged');
  assert.ok(!events.some((e) => e.kind !== 'state' && e.state === 'answer'), 'no interaction logged during the questions');
  const fmt = (/** @type {number[]} */ v) => `min ${Math.min(...v).toFixed(1)} ms, max ${Math.max(...v).toFixed(1)} ms`;
  t.diagnostic(`T = ${T * 1000} ms; pre (+ transition) ${fmt(periods.pre)}; post ${fmt(periods.post)}; shown_ms ${fmt(shown)}`);

  // Prefetch: the next step's level is requested during this step's questions, before its answer goes.
  let prefetched = 0;
  for (let k = 0; k + 1 < steps.length; k++) {
    const step = steps[k];
    const next = steps[k + 1];
    if (next.to <= step.to) continue;
    const since = k === 0 ? begun : putAt[steps[k - 1].step];
    const batch = requests.find((r) => r.i > since && new RegExp(`/batches/${next.to}(\\?|$)`).test(r.url));
    assert.ok(batch, `batch ${next.to} requested during step ${step.step}`);
    assert.ok(batch.i < putAt[step.step], `batch ${next.to} requested before step ${step.step}'s answer`);
    const asked = requests.findIndex((r) => r.i > since && new RegExp(`/batches/${step.to}(\\?|$)`).test(r.url));
    assert.ok(asked === -1 || asked <= batch.i, 'in order');
    prefetched++;
  }
  assert.ok(prefetched >= steps.length - 2, `${prefetched} prefetches checked`);
  t.diagnostic(`${steps.length} steps (control: step ${steps.find((s) => s.control)?.step}), ${prefetched} prefetches checked, ${events.length} view events`);
  assert.deepEqual(problems, []);
  await page.close();

  // The model page's chart: a bar per level with the share of "sufficient".
  const model = await browser.context.newPage();
  await model.goto(`${service.url}/m/${SLUG}`);
  await model.waitForFunction(
    () => /** @type {any} */ (document.querySelector('vitrine-viewer'))?.shadowRoot?.querySelectorAll('.quality [data-study-level]').length > 0,
    undefined,
    { timeout: 30_000 },
  );
  const results = await (await fetch(`${service.url}/api/study/${SLUG}/results`)).json();
  const bars = await model.evaluate(() =>
    [.../** @type {any} */ (document.querySelector('vitrine-viewer')).shadowRoot.querySelectorAll('.quality [data-study-level]')].map((r) => ({
      level: Number(r.dataset.studyLevel),
      share: Number(r.dataset.share),
    })),
  );
  for (const bar of bars) {
    const l = results.levels.find((/** @type {any} */ x) => x.level === bar.level);
    assert.ok(l, `level ${bar.level} in the results`);
    assert.ok(Math.abs(bar.share - l.sufficient / l.answers) < 0.001);
  }
  await model.close();
});

test('a participant who leaves after two steps resumes at the third; a slow batch delays the swap; every step is stored once', async (t) => {
  const [link] = inviteToStudy(service, { slug: SLUG, count: 1 });
  const invitation = invitationOf(link);
  const page = await browser.context.newPage();
  /** @type {string[]} */
  const problems = [];
  page.on('pageerror', (e) => problems.push(e.message));
  await throughIntroduction(page, link);
  await page.getByRole('button', { name: 'Continue' }).click();
  await page.getByRole('button', { name: 'Begin the steps' }).click();
  /** @param {number} step @param {number} total */
  const answer = async (step, total) => {
    const form = page.locator('form.study-questions');
    await page.getByRole('heading', { name: `Step ${step} of ${total}: your answers` }).waitFor({ timeout: 60_000 });
    await form.getByRole('radio', { name: 'Improved', exact: true }).check();
    await form.getByRole('radio', { name: 'No', exact: true }).check();
    const stored = page.waitForResponse((r) => r.url().includes(`/session/answers/${step}`) && r.request().method() === 'PUT');
    await form.getByRole('button', { name: 'Submit answers' }).click();
    assert.equal((await stored).status(), 201, `step ${step} stored`);
  };
  const headers = { authorization: `Bearer ${invitation}` };
  const { steps } = await (await fetch(`${service.url}/api/study/${SLUG}/session`, { headers })).json();
  await answer(1, steps.length);
  await answer(2, steps.length);
  // After the reload, one step's m_b arrives 2.5 s late: m_a stays on screen until it is ready.
  const slow = steps.find((/** @type {{ step: number, from: number, to: number }} */ s) => s.step >= 3 && s.to > s.from);
  await page.route(new RegExp(`/batches/${slow.to}(\\?|$)`), async (route) => {
    await new Promise((resolve) => setTimeout(resolve, 2500));
    await route.continue();
  });
  await page.reload();
  // Listened to from the new page on: the old page's last views batch,
  // flushed as it unloads, may carry the slow step's first 'pre' if that
  // step had begun before the reload.
  /** @type {any[]} */
  const events = [];
  page.on('request', (r) => {
    if (r.method() === 'POST' && r.url().endsWith('/session/views')) events.push(...r.postDataJSON().events);
  });
  await page.getByText('continues where you left off').waitFor();
  await page.getByRole('button', { name: 'Continue' }).click();
  await page.getByLabel(/I agree/).check();
  const resumed = page.waitForResponse((r) => r.url().endsWith('/session') && r.request().method() === 'POST');
  await page.getByRole('button', { name: 'Start' }).click();
  assert.equal((await resumed).status(), 200, 'the session is resumed, not created');
  for (let step = 3; step <= steps.length; step++) await answer(step, steps.length);
  await page.getByRole('heading', { name: 'Thank you' }).waitFor({ timeout: 30_000 });
  const plan = await (await fetch(`${service.url}/api/study/${SLUG}/session`, { headers })).json();
  assert.deepEqual(plan.answered, steps.map((/** @type {{ step: number }} */ s) => s.step));
  assert.equal(plan.finished, true);
  const states = events.filter((e) => e.kind === 'state' && e.step === slow.step);
  const at = (/** @type {string} */ name) => states.find((e) => e.state === name)?.at_ms;
  assert.deepEqual(states.map((e) => e.state), ['pre', 'transition', 'post', 'answer']);
  assert.ok(at('transition') - at('pre') >= T * 1000 - 0.1);
  assert.ok(at('post') - at('transition') >= 1000, `the swap waited for the slow batch (${at('post') - at('transition')} ms)`);
  assert.ok(at('answer') - at('post') >= T * 1000 - 0.1, 'the post period counts from the swap');
  t.diagnostic(`slow batch on step ${slow.step}: pre ${(at('transition') - at('pre')).toFixed(1)} ms, transition ${(at('post') - at('transition')).toFixed(1)} ms, post ${(at('answer') - at('post')).toFixed(1)} ms`);
  assert.deepEqual(problems, []);
  await page.close();
});

test('the study page fits from 320 px wide to 4K: information, questions, no overlap', async () => {
  const [link] = inviteToStudy(service, { slug: SLUG, count: 1 });
  const page = await browser.context.newPage();
  await page.setViewportSize({ width: 320, height: 568 });
  await page.goto(link);
  await page.getByRole('heading', { name: /Quality study/ }).waitFor();
  /** Horizontal overflow of the document, and the panel's boxes that overlap or leave the window. */
  const layout = () =>
    page.evaluate(() => {
      const boxes = [...document.querySelectorAll('.study-panel h1, .study-panel h2, .study-panel p, .study-panel fieldset, .study-panel li, .study-panel button')]
        .map((e) => e.getBoundingClientRect())
        .filter((r) => r.width > 0);
      const out = boxes.filter((r) => r.left < -0.5 || r.right > innerWidth + 0.5);
      return { overflow: document.documentElement.scrollWidth - innerWidth, outside: out.length };
    });
  for (const width of [320, 3840]) {
    await page.setViewportSize({ width, height: width === 320 ? 568 : 2160 });
    assert.deepEqual(await layout(), { overflow: 0, outside: 0 }, `information page at ${width} px`);
  }
  await page.setViewportSize({ width: 320, height: 568 });
  await page.getByRole('button', { name: 'Continue' }).click();
  await page.getByLabel(/I agree/).check();
  await page.getByRole('button', { name: 'Start' }).click();
  await page.getByRole('heading', { name: 'Practice' }).waitFor();
  await page.getByRole('button', { name: 'Continue' }).click();
  await page.getByRole('button', { name: 'Begin the steps' }).click();
  await page.locator('form.study-questions').waitFor({ timeout: 60_000 });
  for (const [width, height] of [[320, 568], [390, 844], [1280, 720], [3840, 2160]]) {
    await page.setViewportSize({ width, height });
    await page.waitForTimeout(50);
    assert.deepEqual(await layout(), { overflow: 0, outside: 0 }, `questions at ${width} px`);
    const overlaps = await page.evaluate(() => {
      const parts = [...document.querySelectorAll('form.study-questions > *')].map((e) => e.getBoundingClientRect());
      let n = 0;
      for (let i = 0; i < parts.length; i++)
        for (let j = i + 1; j < parts.length; j++) {
          const a = parts[i];
          const b = parts[j];
          if (a.left < b.right && b.left < a.right && a.top < b.bottom && b.top < a.bottom) n++;
        }
      const form = /** @type {HTMLElement} */ (document.querySelector('.study-panel')).getBoundingClientRect();
      return { n, inside: form.top >= 0 && form.bottom <= innerHeight + 0.5 };
    });
    assert.deepEqual(overlaps, { n: 0, inside: true }, `no overlap at ${width} px`);
  }
  // Keyboard: the radios and the submit button are reachable with Tab.
  await page.locator('form.study-questions input').first().focus();
  /** @type {string[]} */
  const reached = [];
  for (let i = 0; i < 4; i++) {
    reached.push(await page.evaluate(() => `${document.activeElement?.tagName}:${/** @type {any} */ (document.activeElement)?.type}`));
    await page.keyboard.press('Tab');
  }
  assert.ok(reached.includes('BUTTON:submit'), `Tab reaches the submit button (${reached})`);
  await page.close();
});
