// @ts-check
// End-to-end: a curator publishes from the browser (issue 22). The /admin
// page in Chromium against the real service: the curator token is pasted,
// a small generated mesh (`vitrine sample torus`) is uploaded through the
// form, the jobs list follows the ingest to `done`, and the model is then in
// the gallery (the list from /api/models) with its thumbnail, and with the
// unit, up axis, credit and licence chosen in the form. A reload keeps the
// token (sessionStorage) and the finished job. A version's credit and
// licence are changed from its list; the server's refusal is shown.
import { after, before, test } from 'node:test';
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import { join } from 'node:path';
import { launch } from '../test/support/browser.mjs';
import { vitrine } from '../test/support/fixtures.mjs';
import { startService } from '../test/support/service.mjs';

/** @type {Awaited<ReturnType<typeof startService>>} */
let service;
/** @type {Awaited<ReturnType<typeof launch>>} */
let browser;
/** @type {string} */
let token;
/** @type {string} */
let mesh;

before(async () => {
  service = await startService({ models: [] });
  const printed = execFileSync(vitrine, ['token', 'create', '--db', service.db, '--scope', 'curator', '--label', 'e2e'], {
    encoding: 'utf8',
  });
  token = printed.trim().split('\n').at(-1) ?? '';
  assert.match(token, /^vtr_[0-9a-f]{64}$/, 'the token alone on the last line');
  mesh = join(service.dir, 'amphora.ply');
  execFileSync(vitrine, ['sample', 'torus', '-o', mesh, '--kilo-vertices', '2', '--colour'], { stdio: 'pipe' });
  browser = await launch({ width: 390, height: 844 });
});

after(async () => {
  await browser?.close();
  await service?.stop();
});

test('an upload through /admin ends with the model in the gallery', { timeout: 20_000 }, async () => {
  const page = await browser.context.newPage();
  const errors = /** @type {string[]} */ ([]);
  page.on('pageerror', (e) => errors.push(String(e)));
  await page.goto(`${service.url}/admin`);
  await page.getByLabel('Token (from vitrine token create --scope curator)').fill(token);
  await page.getByRole('button', { name: 'Use token' }).click();
  await page.getByText('No uploads yet.').waitFor();

  await page.getByLabel('Scan (PLY, OBJ, OFF, GLB, glTF, MD2)').setInputFiles(mesh);
  await page.getByLabel('Slug (a-z, 0-9, -)').fill('amphora');
  await page.getByLabel('Title').fill('Amphora');
  await page.getByLabel('Description').fill('Uploaded in the browser');
  await page.getByLabel('Audience policy').selectOption('open');
  await page.getByLabel('Unit of the coordinates').selectOption('mm');
  await page.getByLabel('Up axis').selectOption('z');
  await page.getByLabel('Credit line (shown under the model)').fill('Scan: Test Museum, 2026');
  // The licences come from GET /api/licences: the first option is "not stated".
  const licence = page.getByLabel('Licence', { exact: true });
  await licence.locator('option[value="CC-BY-4.0"]').waitFor({ state: 'attached' });
  assert.deepEqual((await licence.locator('option').allInnerTexts()).slice(0, 3), ['— not stated —', 'CC0 1.0 Universal', 'Public Domain Mark 1.0']);
  await licence.selectOption({ label: 'CC BY 4.0' });
  await page.getByRole('button', { name: 'Upload' }).click();
  await page.getByText(/ingest job \d+ started/).waitFor();
  const done = page.locator('li[data-state="done"]');
  await done.waitFor({ timeout: 15_000 });
  assert.match(await done.innerText(), /Amphora \(amphora, amphora\.ply\): done/);
  assert.equal(await done.locator('progress').getAttribute('value'), '1');

  // After a reload the token and the finished job are still there.
  await page.reload();
  await page.locator('li[data-state="done"]').waitFor();

  // The gallery's list has the model, with its thumbnail.
  const listed = await page.evaluate(async () => (await (await fetch('/api/models')).json()).models);
  const amphora = listed.find((/** @type {{ slug: string }} */ m) => m.slug === 'amphora');
  assert.ok(amphora, 'the model is in /api/models');
  assert.equal(amphora.title, 'Amphora');
  assert.equal(amphora.thumbnail, '/api/models/amphora/thumbnail?v=1');
  const manifest = await (await fetch(`${service.url}/api/models/amphora`)).json();
  assert.deepEqual(manifest.rights, {
    credit: 'Scan: Test Museum, 2026',
    licence: { id: 'CC-BY-4.0', name: 'CC BY 4.0', url: 'https://creativecommons.org/licenses/by/4.0/' },
  });
  assert.equal(manifest.unit, 'mm');
  assert.equal(manifest.up, 'z');
  await page.goto(`${service.url}/`);
  await page.getByRole('link', { name: /Amphora/ }).first().waitFor();
  assert.deepEqual(errors, []);
  await page.close();
});

test('an upload without credit or licence sends neither; a version\'s licence and credit are changed from its list', { timeout: 30_000 }, async () => {
  const page = await browser.context.newPage();
  const errors = /** @type {string[]} */ ([]);
  page.on('pageerror', (e) => errors.push(String(e)));
  /** @type {string[]} */
  const sent = [];
  page.on('request', (r) => {
    if (r.method() === 'POST' && new URL(r.url()).pathname === '/api/models') sent.push(r.postData() ?? '');
  });
  await page.goto(`${service.url}/admin`);
  await page.getByLabel('Token (from vitrine token create --scope curator)').fill(token);
  await page.getByRole('button', { name: 'Use token' }).click();
  await page.getByLabel('Scan (PLY, OBJ, OFF, GLB, glTF, MD2)').setInputFiles(mesh);
  await page.getByLabel('Slug (a-z, 0-9, -)').fill('krater');
  await page.getByLabel('Title').fill('Krater');
  await page.getByRole('button', { name: 'Upload' }).click();
  await page.locator('li[data-state="done"]', { hasText: 'Krater' }).waitFor({ timeout: 15_000 });
  assert.equal(sent.length, 1);
  for (const name of ['unit', 'up', 'credit', 'licence', 'colour']) assert.ok(!sent[0].includes(`name="${name}"`), `${name} not sent`);
  const manifest = async () => (await (await fetch(`${service.url}/api/models/krater`)).json());
  assert.deepEqual((await manifest()).rights, { credit: null, licence: null });

  // The versions list shows the rights and changes them through PUT.
  await page.reload();
  await page.getByRole('button', { name: 'Versions of krater' }).click();
  const version = page.locator('li[data-slug="krater"] li[data-version="1"]');
  await version.getByText('Credit: not stated · Licence: not stated').waitFor();
  await version.getByLabel('Licence of version 1', { exact: true }).selectOption('CC-BY-SA-4.0');
  await version.getByLabel('Credit line of version 1', { exact: true }).fill('Scan: Krater Project');
  await version.getByRole('button', { name: 'Save credit and licence of version 1' }).click();
  await version.getByText('Credit: Scan: Krater Project · Licence: CC BY-SA 4.0').waitFor();
  assert.deepEqual((await manifest()).rights, {
    credit: 'Scan: Krater Project',
    licence: { id: 'CC-BY-SA-4.0', name: 'CC BY-SA 4.0', url: 'https://creativecommons.org/licenses/by-sa/4.0/' },
  });
  assert.equal(await version.getByLabel('Licence of version 1', { exact: true }).inputValue(), 'CC-BY-SA-4.0', 'the form shows what is recorded');

  // Only the licence changes; then a credit over 300 bytes (200 two-byte letters) is refused with the server's reason.
  await version.getByLabel('Licence of version 1', { exact: true }).selectOption('CC0-1.0');
  await version.getByRole('button', { name: 'Save credit and licence of version 1' }).click();
  await version.getByText('Licence: CC0 1.0 Universal').waitFor();
  assert.equal((await manifest()).rights.licence.id, 'CC0-1.0');
  assert.equal((await manifest()).rights.credit, 'Scan: Krater Project');
  await version.getByLabel('Credit line of version 1', { exact: true }).fill('Μ'.repeat(200));
  await version.getByRole('button', { name: 'Save credit and licence of version 1' }).click();
  await version.locator('[role="status"]', { hasText: '400 bytes, more than 300' }).waitFor();
  assert.equal((await manifest()).rights.credit, 'Scan: Krater Project', 'the refused change left the version alone');

  // Clearing both: the manifest says neither.
  await version.getByLabel('Credit line of version 1', { exact: true }).fill('');
  await version.getByLabel('Licence of version 1', { exact: true }).selectOption('');
  await version.getByRole('button', { name: 'Save credit and licence of version 1' }).click();
  await version.getByText('Credit: not stated · Licence: not stated').waitFor();
  assert.deepEqual((await manifest()).rights, { credit: null, licence: null });
  assert.deepEqual(errors, []);
  await page.close();
});
