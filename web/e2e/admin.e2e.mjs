// @ts-check
// End-to-end: a curator publishes from the browser (issue 22). The /admin
// page in Chromium against the real service: the curator token is pasted,
// a small generated mesh (`vitrine sample torus`) is uploaded through the
// form, the jobs list follows the ingest to `done`, and the model is then in
// the gallery (the list from /api/models) with its thumbnail. A reload
// keeps the token (sessionStorage) and the finished job.
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
  await page.goto(`${service.url}/`);
  await page.getByRole('link', { name: /Amphora/ }).first().waitFor();
  assert.deepEqual(errors, []);
  await page.close();
});
