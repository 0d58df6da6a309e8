// @ts-check
/**
 * The real service for browser tests and benchmarks: generated models are
 * ingested into a temporary SQLite database with the `vitrine` CLI, then
 * `vitrine serve` listens on a free loopback port and serves web/dist.
 */
import { execFileSync, spawn } from 'node:child_process';
import { existsSync, mkdtempSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { root, vitrine } from './fixtures.mjs';

export const webDist = join(root, 'web', 'dist');

/**
 * @typedef {object} ModelSpec
 * @property {string} slug
 * @property {string} title
 * @property {string} [description]
 * @property {'torus' | 'sphere' | 'plate' | 'cloud' | 'file'} kind a generated sample (`cloud`: a point
 *   cloud, a PLY without faces), or `file` (a mesh the test wrote)
 * @property {string} [file] with `kind: 'file'`, the mesh to ingest
 * @property {number} [kiloVertices] the sample's detail
 * @property {boolean} [colour] paint a procedural pattern on the vertices
 * @property {'vertex' | 'ccc' | 'none'} [colourMode] how `vitrine ingest` stores the colour (default vertex)
 * @property {string} [policy] exhibition, open or researchers
 * @property {boolean} [quality] measure every level at ingest (`vitrine ingest --quality`)
 * @property {string[]} [ingestArgs] more `vitrine ingest` arguments
 * @property {string[][]} [texts] translations set after the ingest, each a language tag and
 *   `vitrine texts` arguments: `[['pt', '--title', 'Toro', '--credit', '…']]`
 */

/**
 * `existingDb` serves a database ingested before (a benchmark's scan of
 * millions of vertices, ingested once): no model is ingested, and the
 * database is left as it was.
 * @param {{ models: ModelSpec[], serveArgs?: string[], existingDb?: string }} options
 * @returns {Promise<{ url: string, dir: string, db: string, stop: () => Promise<void> }>}
 */
export async function startService({ models, serveArgs = [], existingDb }) {
  if (!existsSync(vitrine)) throw new Error(`build the CLI first: cargo build --release -p vitrine (${vitrine})`);
  if (!existsSync(join(webDist, 'index.html'))) throw new Error('build the viewer first: npm run build');
  if (existingDb && models.length > 0) throw new Error('models are ingested into a new database, not an existing one');
  const dir = mkdtempSync(join(tmpdir(), 'vitrine-service-'));
  const db = existingDb ?? `sqlite:${join(dir, 'vitrine.db')}`;
  const env = { ...process.env, NO_COLOR: '1', RUST_LOG: process.env.RUST_LOG ?? 'warn,vitrine=info' };
  for (const m of models) {
    const mesh = m.kind === 'file' ? String(m.file) : join(dir, `${m.slug}.ply`);
    if (m.kind !== 'file') {
      const sample = ['sample', m.kind, '-o', mesh, '--kilo-vertices', String(m.kiloVertices ?? 10)];
      execFileSync(vitrine, m.colour ? [...sample, '--colour'] : sample, { stdio: 'pipe' });
    }
    const ingest = ['ingest', mesh, '--db', db, '--slug', m.slug, '--title', m.title];
    ingest.push('--description', m.description ?? '', '--policy', m.policy ?? 'open');
    if (m.colourMode) ingest.push('--colour', m.colourMode);
    if (m.quality) ingest.push('--quality');
    if (m.ingestArgs) ingest.push(...m.ingestArgs);
    execFileSync(vitrine, ingest, { stdio: 'pipe', env });
    for (const [language, ...args] of m.texts ?? []) {
      execFileSync(vitrine, ['texts', '--db', db, '--slug', m.slug, '--language', language, ...args], { stdio: 'pipe', env });
    }
  }
  // Chromium on SwiftShader keeps both cores of a small machine busy, which
  // the service would read as load and answer with load caps: tests that
  // are not about load switch the load signals off.
  const noLoadCaps = ['--load-high-inflight', '1000000', '--load-high-latency-ms', '1000000', '--load-high-queue-ms', '1000000'];
  const args = ['serve', '--db', db, '--listen', '127.0.0.1:0', '--web-dir', webDist, ...noLoadCaps, ...serveArgs];
  const child = spawn(vitrine, args, { stdio: ['ignore', 'ignore', 'pipe'], env });
  let log = '';
  const url = await new Promise((resolve, reject) => {
    const timer = setTimeout(() => reject(new Error(`vitrine serve did not start:\n${log}`)), 30_000);
    child.stderr.setEncoding('utf8');
    child.stderr.on('data', (chunk) => {
      log += chunk;
      const match = log.match(/serving.*?addr=(\d+\.\d+\.\d+\.\d+:\d+)/);
      if (match) {
        clearTimeout(timer);
        resolve(`http://${match[1]}`);
      }
    });
    child.on('exit', (code) => reject(new Error(`vitrine serve exited with ${code}:\n${log}`)));
  });
  const stop = async () => {
    if (child.exitCode === null) {
      const exited = new Promise((resolve) => child.once('exit', resolve));
      child.kill('SIGTERM');
      await exited;
    }
    rmSync(dir, { recursive: true, force: true });
  };
  return { url, dir, db, stop };
}

/**
 * A quality study of an ingested model (`vitrine study create`) and its
 * invitation links (`vitrine study invite`, one per line).
 * @param {{ url: string, db: string }} service
 * @param {{ slug: string, seconds?: number, from?: number, to?: number, count?: number }} study
 * @returns {string[]} the links
 */
export function createStudy(service, { slug, seconds = 0.4, from, to, count = 1 }) {
  const create = ['study', 'create', '--db', service.db, '--slug', slug, '--seconds', String(seconds)];
  if (from !== undefined) create.push('--from', String(from));
  if (to !== undefined) create.push('--to', String(to));
  execFileSync(vitrine, create, { stdio: 'pipe' });
  return inviteToStudy(service, { slug, count });
}

/**
 * More invitation links to an open study.
 * @param {{ url: string, db: string }} service
 * @param {{ slug: string, count?: number }} study
 * @returns {string[]}
 */
export function inviteToStudy(service, { slug, count = 1 }) {
  const invite = ['study', 'invite', '--db', service.db, '--slug', slug, '--count', String(count), '--base-url', service.url];
  const out = execFileSync(vitrine, invite, { stdio: ['ignore', 'pipe', 'pipe'], encoding: 'utf8' });
  return out
    .split('\n')
    .map((line) => line.trim())
    .filter((line) => /^https?:\/\//.test(line));
}
