// @ts-check
// End-to-end: accessibility as a visitor meets it (issue 43). axe-core
// (WCAG 2.0, 2.1 and 2.2, levels A and AA) finds no violation on the
// gallery, a mesh model page, a point-cloud page, the embed, the quality
// study and /admin, at 1280 × 800 and 390 × 844, in English and Arabic; the
// model page works with the keyboard alone (turn, zoom, a note, a
// measurement, out again, through the embed's iframe too) and with buttons
// instead of drags; the accessibility tree names the view, every control
// and the live region; under reduced motion an idle page stays still. One
// service and one browser serve every check.
import { after, before, test } from 'node:test';
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import { readFileSync } from 'node:fs';
import { createRequire } from 'node:module';
import { launch } from '../test/support/browser.mjs';
import { vitrine } from '../test/support/fixtures.mjs';
import { createStudy, startService } from '../test/support/service.mjs';

/** @typedef {import('playwright-core').Page} Page */

const AXE_SOURCE = readFileSync(createRequire(import.meta.url).resolve('axe-core/axe.min.js'), 'utf8');
/** The rule sets of WCAG 2.0, 2.1 and 2.2 at levels A and AA (axe's tags). */
const WCAG_TAGS = ['wcag2a', 'wcag2aa', 'wcag21a', 'wcag21aa', 'wcag22a', 'wcag22aa'];
const VIEWPORTS = [
  { width: 1280, height: 800 },
  { width: 390, height: 844 },
];


/** @type {Awaited<ReturnType<typeof startService>>} */
let service;
/** @type {Awaited<ReturnType<typeof launch>>} */
let browser;
/** @type {string} */
let studyLink;
/** @type {string} */
let token;

before(async () => {
  service = await startService({
    models: [
      { slug: 'sphere', title: 'Sphere', description: 'A generated globe.', kind: 'sphere', kiloVertices: 3, colour: true, ingestArgs: ['--credit', 'Scan: Museu da Inconfidência', '--licence', 'CC-BY-4.0'] },
      { slug: 'cloud', title: 'Jittered cube', description: 'A generated point cloud.', kind: 'cloud', kiloVertices: 4, colour: true },
    ],
  });
  const printed = execFileSync(vitrine, ['token', 'create', '--db', service.db, '--scope', 'curator', '--label', 'a11y'], { encoding: 'utf8' });
  token = printed.trim().split('\n').at(-1)?.trim() ?? '';
  // Two notes on the sphere's surface, facing the home view (front, +Z) and its right (+X).
  const { bounds } = await (await fetch(`${service.url}/api/models/sphere`)).json();
  const centre = [0, 1, 2].map((k) => (bounds.min[k] + bounds.max[k]) / 2);
  const radius = (bounds.max[0] - bounds.min[0]) / 2;
  const notes = [
    { title: 'Front', text: 'The *front* of the globe.', position: [centre[0], centre[1], centre[2] + radius], normal: [0, 0, 1] },
    { title: 'Right side', text: 'Its right side.', position: [centre[0] + radius, centre[1], centre[2]], normal: [1, 0, 0] },
  ];
  for (const note of notes) {
    const response = await fetch(`${service.url}/api/models/sphere/annotations`, {
      method: 'POST',
      headers: { authorization: `Bearer ${token}`, 'content-type': 'application/json' },
      body: JSON.stringify(note),
    });
    assert.ok(response.ok, `POST annotation: ${response.status} ${await response.text()}`);
  }
  [studyLink] = createStudy(service, { slug: 'sphere', count: 1 });
  browser = await launch({ width: 1280, height: 800 });
});

after(async () => {
  await browser?.close();
  await service?.stop();
});

/**
 * The pages a visitor meets, each with what shows it is ready.
 * @type {Array<{ name: string, path: () => string, ready: (page: Page) => Promise<unknown> }>}
 */
const PAGES = [
  { name: 'gallery', path: () => '/', ready: (page) => page.locator('ul.models li a').first().waitFor() },
  { name: 'mesh page', path: () => '/m/sphere', ready: (page) => untilComplete(page) },
  { name: 'point-cloud page', path: () => '/m/cloud', ready: (page) => untilComplete(page) },
  { name: 'embed', path: () => '/embed/sphere', ready: (page) => untilComplete(page) },
  { name: 'study', path: () => new URL(studyLink).pathname + new URL(studyLink).search, ready: (page) => page.locator('#app button').first().waitFor() },
  { name: 'admin', path: () => '/admin', ready: (page) => page.locator('#app input').first().waitFor() },
];

/** Until the viewer has drawn its last level and the notes are in. @param {Page} page */
function untilComplete(page) {
  return page.waitForFunction(
    () => {
      const viewer = /** @type {any} */ (document.querySelector('vitrine-viewer'))?.viewer;
      return viewer?.state?.status === 'complete';
    },
    undefined,
    { timeout: 30_000, polling: 50 },
  );
}

/**
 * axe-core's violations of the WCAG A and AA rules on the page as it is now,
 * one line each: rule, impact, and where.
 * @param {Page} page
 */
async function violations(page) {
  if (!(await page.evaluate(() => 'axe' in window))) await page.addScriptTag({ content: AXE_SOURCE });
  /** @type {Array<{ id: string, impact: string, help: string, nodes: Array<{ target: unknown[], failureSummary: string }> }>} */
  const found = await page.evaluate(async (tags) => {
    const result = await /** @type {any} */ (window).axe.run(document, { runOnly: { type: 'tag', values: tags }, resultTypes: ['violations'] });
    return result.violations.map((/** @type {any} */ v) => ({
      id: v.id,
      impact: v.impact,
      help: v.help,
      nodes: v.nodes.map((/** @type {any} */ n) => ({ target: n.target, failureSummary: n.failureSummary })),
    }));
  }, WCAG_TAGS);
  return found.flatMap((v) => v.nodes.map((n) => `${v.id} (${v.impact}): ${v.help} at ${JSON.stringify(n.target)}: ${n.failureSummary}`));
}

for (const lang of ['en', 'ar']) {
  test(`axe-core: no WCAG 2.x A/AA violation on any page (${lang}, 1280 × 800 and 390 × 844)`, async () => {
    const page = await browser.context.newPage();
    /** @type {string[]} */
    const problems = [];
    page.on('pageerror', (e) => problems.push(`error: ${e.message}`));
    /** @type {string[]} */
    const found = [];
    for (const viewport of VIEWPORTS) {
      await page.setViewportSize(viewport);
      for (const p of PAGES) {
        const path = p.path();
        await page.goto(`${service.url}${path}${path.includes('?') ? '&' : '?'}lang=${lang}`);
        await p.ready(page);
        assert.equal(await page.evaluate(() => document.documentElement.lang), lang, `${p.name}: <html lang>`);
        for (const line of await violations(page)) found.push(`${p.name} ${viewport.width}×${viewport.height}: ${line}`);
      }
    }
    assert.deepEqual(found, [], `axe-core violations:\n${found.join('\n')}`);
    assert.deepEqual(problems, []);
    await page.close();
  });
}

/**
 * What has focus, through the viewer's shadow root: `outside`, or the
 * focused part of the viewer (its canvas, a button's action or class).
 * @param {Page} page
 */
function focused(page) {
  return page.evaluate(() => {
    const host = document.querySelector('vitrine-viewer');
    if (document.activeElement !== host) return { where: 'outside', tag: document.activeElement?.tagName ?? null };
    const e = /** @type {HTMLElement | null} */ (host?.shadowRoot?.activeElement ?? null);
    if (!e) return { where: 'host', tag: null };
    const name = e.tagName === 'CANVAS' ? 'canvas' : (e.dataset.action ?? e.dataset.nudge ?? e.className);
    return { where: name, tag: e.tagName, visible: e.matches(':focus-visible') };
  });
}

/**
 * Presses `key` until `want` holds of what has focus (at most `limit` times).
 * @param {Page} page @param {string} key @param {(f: Awaited<ReturnType<typeof focused>>) => boolean} want
 */
async function pressUntil(page, key, want, limit = 40) {
  for (let i = 0; i < limit; i++) {
    await page.keyboard.press(key);
    const f = await focused(page);
    if (want(f)) return f;
  }
  throw new Error(`${key} ×${limit} never reached the element wanted (last: ${JSON.stringify(await focused(page))})`);
}

/** The viewer's camera state. @param {Page} page */
function cameraOf(page) {
  return page.evaluate(() => structuredClone(/** @type {any} */ (document.querySelector('vitrine-viewer')).viewer.camera.state));
}

/** The view's pixels, once the frame after the last change is drawn. @param {Page} page */
async function viewPixels(page) {
  await page.evaluate(() => new Promise((resolve) => requestAnimationFrame(() => requestAnimationFrame(resolve))));
  return page.locator('vitrine-viewer canvas').screenshot();
}

test('the keyboard alone: Tab to the view, keys turn and zoom it, a note, a measurement, Tab out (no trap)', async () => {
  const page = await browser.context.newPage();
  await page.setViewportSize({ width: 1280, height: 800 });
  /** @type {string[]} */
  const problems = [];
  page.on('pageerror', (e) => problems.push(`error: ${e.message}`));
  await page.goto(`${service.url}/m/sphere`);
  await untilComplete(page);
  // Tab reaches the view; its focus is visible.
  const view = await pressUntil(page, 'Tab', (f) => f.where === 'canvas', 5);
  assert.equal(view.visible, true, 'the view shows its focus');
  // Keys turn and zoom it: the image changes each time.
  const home = await cameraOf(page);
  const still = await viewPixels(page);
  for (let i = 0; i < 3; i++) await page.keyboard.press('ArrowLeft');
  const turned = await viewPixels(page);
  assert.notDeepEqual(turned, still, 'the arrows turn the view');
  assert.notEqual((await cameraOf(page)).yaw, home.yaw);
  await page.keyboard.press('+');
  await page.keyboard.press('+');
  const zoomed = await viewPixels(page);
  assert.notDeepEqual(zoomed, turned, '+ zooms the view');
  assert.ok((await cameraOf(page)).distance < home.distance, 'closer after +');
  // A single-key shortcut acts only while the view has focus (2.1.4): W on a button does nothing.
  await page.keyboard.press('r');
  assert.deepEqual(await cameraOf(page), home, 'R resets the view');
  // A note: Tab to the notes button, open the list, choose the first note.
  await pressUntil(page, 'Tab', (f) => f.where === 'notes');
  await page.keyboard.press('w');
  assert.equal(await page.locator('vitrine-viewer [data-action="wireframe"]').getAttribute('aria-pressed'), 'false', 'W away from the view does nothing');
  await page.keyboard.press('Enter');
  await pressUntil(page, 'Tab', (f) => f.where === 'note-item');
  await page.keyboard.press('Enter');
  const detail = page.locator('vitrine-viewer .note-detail');
  await detail.waitFor();
  assert.equal(await detail.locator('h3').innerText(), 'Front');
  assert.match(await page.locator('vitrine-viewer .live').first().innerText(), /^Front\. The front of the globe\.$/, 'the note is announced');
  // A measurement: the measure button, back to the view, Enter at the crosshair, turn, Enter again.
  await pressUntil(page, 'Shift+Tab', (f) => f.where === 'measure');
  await page.keyboard.press('Enter');
  assert.equal(await page.locator('vitrine-viewer [data-action="measure"]').getAttribute('aria-pressed'), 'true');
  await pressUntil(page, 'Shift+Tab', (f) => f.where === 'canvas');
  await page.keyboard.press('Enter');
  await page.waitForFunction(() => /** @type {any} */ (document.querySelector('vitrine-viewer')).viewer.inspection.points.length === 1);
  for (let i = 0; i < 4; i++) await page.keyboard.press('ArrowRight');
  await page.keyboard.press('Enter');
  await page.waitForFunction(() => /** @type {any} */ (document.querySelector('vitrine-viewer')).viewer.inspection.reading !== null);
  const reading = await page.locator('vitrine-viewer .measure-reading').innerText();
  assert.match(reading, /\d/, `a distance is read out (${reading})`);
  const value = await page.evaluate(() => /** @type {any} */ (document.querySelector('vitrine-viewer')).viewer.inspection.reading.value);
  assert.ok(value > 0, 'two different points');
  // Tab leaves the view and the viewer: focus reaches the page after it.
  const out = await pressUntil(page, 'Tab', (f) => f.where === 'outside', 60);
  assert.equal(out.tag, 'BUTTON', 'the embed section’s Copy button after the viewer');
  assert.deepEqual(problems, []);
  await page.close();
});

test('the embed in an iframe: Tab goes in, through the view and out again', async () => {
  const page = await browser.context.newPage();
  await page.setContent(
    `<!doctype html><html lang="en"><title>Host</title><button id="before">Before</button>` +
      `<iframe src="${service.url}/embed/sphere" title="3D model" width="640" height="480"></iframe><button id="after">After</button>`,
  );
  const frame = page.frameLocator('iframe');
  await frame.locator('vitrine-viewer canvas').waitFor();
  await page.focus('#before');
  let inside = false;
  for (let i = 0; i < 40; i++) {
    await page.keyboard.press('Tab');
    const active = await page.evaluate(() => document.activeElement?.id || document.activeElement?.tagName);
    if (active === 'IFRAME') inside = true;
    if (active === 'after') break;
  }
  assert.ok(inside, 'focus went into the iframe');
  assert.equal(await page.evaluate(() => document.activeElement?.id), 'after', 'and out of it after the viewer');
  await page.close();
});

test('buttons turn, zoom and reset the view without a drag; every target is at least 24 × 24 px and the pad covers nothing', async () => {
  const page = await browser.context.newPage();
  for (const viewport of VIEWPORTS) {
    await page.setViewportSize(viewport);
    await page.goto(`${service.url}/m/sphere`);
    await untilComplete(page);
    const home = await cameraOf(page);
    await page.locator('vitrine-viewer [data-nudge="left"]').click();
    const left = await cameraOf(page);
    // The model turns left: the camera goes round towards its right (+X, growing yaw).
    assert.ok(left.yaw > home.yaw, `${viewport.width}: ◀ turns the model left`);
    await page.locator('vitrine-viewer [data-nudge="up"]').click();
    assert.notEqual((await cameraOf(page)).pitch, left.pitch, `${viewport.width}: ▲ tilts it`);
    await page.locator('vitrine-viewer [data-nudge="in"]').click();
    assert.ok((await cameraOf(page)).distance < home.distance, `${viewport.width}: + zooms in`);
    await page.locator('vitrine-viewer [data-nudge="out"]').click();
    await page.locator('vitrine-viewer [data-nudge="out"]').click();
    assert.ok((await cameraOf(page)).distance > home.distance, `${viewport.width}: − zooms out`);
    await page.locator('vitrine-viewer [data-action="reset"]').click();
    assert.deepEqual(await cameraOf(page), home, `${viewport.width}: Reset goes home`);
    const small = await page.evaluate(() => {
      const root = /** @type {ShadowRoot} */ (document.querySelector('vitrine-viewer')?.shadowRoot);
      const targets = [...root.querySelectorAll('button, select, a, input, [tabindex]'), ...document.querySelectorAll('#app > :not(vitrine-viewer) :is(button, a)')];
      return targets
        .map((e) => ({ e, r: e.getBoundingClientRect() }))
        .filter(({ e, r }) => r.width > 0 && r.height > 0 && !e.closest('p, li:not(.models li), pre, .credit-line'))
        .filter(({ r }) => r.width < 24 || r.height < 24)
        .map(({ e, r }) => `${e.tagName}.${e.className} ${Math.round(r.width)}×${Math.round(r.height)}`);
    });
    assert.deepEqual(small, [], `${viewport.width}: targets under 24 × 24 px`);
    // The pad covers none of the chrome (the panel, the toolbar, the panes, the status, the credit).
    const covered = await page.evaluate(() => {
      const root = /** @type {ShadowRoot} */ (document.querySelector('vitrine-viewer')?.shadowRoot);
      const pad = /** @type {Element} */ (root.querySelector('.nav')).getBoundingClientRect();
      return [...root.querySelectorAll('.panel, .tools, .panes > *, .status > *, .credit')]
        .filter((e) => /** @type {HTMLElement} */ (e).offsetParent !== null)
        .filter((e) => {
          const r = e.getBoundingClientRect();
          return pad.left < r.right && r.left < pad.right && pad.top < r.bottom && r.top < pad.bottom;
        })
        .map((e) => e.className);
    });
    assert.deepEqual(covered, [], `${viewport.width}: the turn and zoom pad covers part of the chrome`);
  }
  await page.close();
});

test('the accessibility tree names the view, every control and the live region', async () => {
  const page = await browser.context.newPage();
  await page.setViewportSize({ width: 1280, height: 800 });
  await page.goto(`${service.url}/m/sphere`);
  await untilComplete(page);
  const last = await page.evaluate(() => /** @type {any} */ (document.querySelector('vitrine-viewer')).viewer.state.lastLevel);
  // Twice to the right: from the home view's front right to the front; twice closer (1.15²).
  for (const step of ['right', 'right', 'in', 'in']) await page.locator(`vitrine-viewer [data-nudge="${step}"]`).click();
  await page.locator('vitrine-viewer [data-action="notes"]').click();
  // The view as Chromium gives it to a screen reader: role, name and description.
  await page.waitForFunction(() => /seen from the front, from above, 1\.3× zoom/.test(document.querySelector('vitrine-viewer')?.shadowRoot?.querySelector('.view-description')?.textContent ?? ''));
  const cdp = await browser.context.newCDPSession(page);
  const { nodes } = /** @type {{ nodes: Array<{ role?: { value: string }, name?: { value: string }, description?: { value: string } }> }} */ (
    await cdp.send('Accessibility.getFullAXTree')
  );
  const view = nodes.find((n) => n.role?.value === 'application');
  assert.equal(view?.name?.value, '3D view of Sphere');
  assert.equal(
    view?.description?.value,
    `A generated globe. · level ${last} of ${last} shown · seen from the front, from above, 1.3× zoom · ` +
      'Arrow keys turn it, Shift + arrows pan, + and − zoom, R resets; or drag to turn, pinch or scroll to zoom, ' +
      'two fingers or right-drag to pan. While measuring, Enter picks the point under the crosshair.',
  );
  await cdp.detach();
  // Every control by role and name, the notes as a list, the live region.
  const tree = await page.locator('vitrine-viewer').ariaSnapshot();
  const expected = [
    '- application "3D view of Sphere"',
    '- button "Note 1: Front"',
    '- toolbar "View tools"',
    ...['Reset', 'Wireframe', 'Relief', 'Splats'].map((name) => `- button "${name}"`),
    '- button "Notes" [pressed]',
    ...['Measure', 'Light', 'Section', 'Clay', 'Snapshot', 'Fullscreen'].map((name) => `- button "${name}"`),
    '- combobox "Language"',
    '- region "Notes"',
    '- list',
    '- button "Front"',
    '- button "Right side"',
    '- group "Turn and zoom"',
    ...['Turn left', 'Turn right', 'Turn up', 'Turn down', 'Zoom in', 'Zoom out'].map((name) => `- button "${name}"`),
    '- group "Credit and licence"',
    '- link "CC BY 4.0"',
    `- status: "Level ${last} of ${last} shown: full detail"`,
  ];
  // A line is `- role "name"`, followed by `:` and its text or children; YAML quotes a name with a colon.
  const lines = tree.split('\n').map((l) => l.trim().replace(/^- '(.*)'(:.*)?$/, '- $1$2'));
  for (const line of expected) assert.ok(lines.some((l) => l === line || l.startsWith(`${line}:`) || l.startsWith(`${line} `)), `${line} in\n${tree}`);
  assert.ok(!tree.includes('seen from'), 'the description is not read twice as page text');
  await page.close();
});

test('reduced motion: an idle page stays still, and the turntable holds the home view', async () => {
  const page = await browser.context.newPage();
  await page.emulateMedia({ reducedMotion: 'reduce' });
  await page.setViewportSize({ width: 1280, height: 800 });
  await page.goto(`${service.url}/m/sphere`);
  await untilComplete(page);
  await page.waitForTimeout(300);
  const first = await page.screenshot();
  await page.waitForTimeout(2000);
  const second = await page.screenshot();
  assert.ok(first.equals(second), 'two screenshots 2 s apart are the same');
  const yaws = await page.evaluate(async () => {
    const viewer = /** @type {any} */ (document.querySelector('vitrine-viewer')).viewer;
    /** @type {number[]} */
    const seen = [];
    const sampling = setInterval(() => seen.push(viewer.camera.state.yaw), 50);
    await viewer.turntable(600);
    clearInterval(sampling);
    return seen;
  });
  assert.ok(yaws.length >= 5, 'sampled during the turn');
  assert.equal(new Set(yaws).size, 1, `the camera stays still: ${yaws.join(', ')}`);
  await page.close();
});
