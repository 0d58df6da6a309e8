// @ts-check
/**
 * Streams written by the Rust encoder, for Node tests and benchmarks: the
 * small committed fixtures in test/fixtures (scripts/bless-fixtures.sh
 * re-records them and what the native decoder says of them), or, for
 * benchmarks that need a size of their own, a sample encoded now by the CLI.
 */
import { execFileSync } from 'node:child_process';
import { createHash } from 'node:crypto';
import { existsSync, mkdtempSync, readFileSync, readdirSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { dirname, join } from 'node:path';
import { fileURLToPath } from 'node:url';

export const root = join(dirname(fileURLToPath(import.meta.url)), '..', '..', '..');
export const vitrine = process.env.VITRINE_BIN ?? join(root, 'target', 'release', 'vitrine');
export const wasmPath =
  process.env.VITRINE_WASM ?? join(root, 'target', 'wasm32-unknown-unknown', 'wasm', 'vitrine_wasm.wasm');
export const fixturesDir = join(root, 'web', 'test', 'fixtures');

/**
 * What the native decoder said of one level (`vitrine dump-levels`): counts,
 * and the SHA-256 (hex) of each buffer's little-endian bytes.
 * @typedef {object} FixtureLevel
 * @property {number} level
 * @property {number} vertices
 * @property {number} faces
 * @property {string} positions f32, x y z per vertex
 * @property {string} indices u32, three per face
 * @property {string | null} colours u8, r g b per vertex; null without colour
 */

/**
 * A committed stream and its sidecar NAME.json.
 * @typedef {object} Fixture
 * @property {string} name
 * @property {Uint8Array} stream
 * @property {string} madeBy the commands that wrote it
 * @property {{ bytes: number, sha256: string }} streamDigest as blessed
 * @property {FixtureLevel[]} levels level 0 (the base) to the last
 */

/** Names of the committed fixtures (NAME.vtr with NAME.json beside it), sorted. */
export function fixtureNames() {
  return readdirSync(fixturesDir)
    .filter((file) => file.endsWith('.vtr'))
    .map((file) => file.slice(0, -'.vtr'.length))
    .sort();
}

/**
 * @param {string} name e.g. `painted-torus`
 * @returns {Fixture}
 */
export function fixture(name) {
  const stream = new Uint8Array(readFileSync(join(fixturesDir, `${name}.vtr`)));
  const sidecar = JSON.parse(readFileSync(join(fixturesDir, `${name}.json`), 'utf8'));
  return { name, stream, madeBy: sidecar.made_by, streamDigest: sidecar.stream, levels: sidecar.levels };
}

/**
 * SHA-256 (hex) of a typed array's bytes, as the bless script hashes them.
 * @param {ArrayBufferView} view
 */
export function sha256(view) {
  return createHash('sha256').update(new Uint8Array(view.buffer, view.byteOffset, view.byteLength)).digest('hex');
}

/**
 * A sample encoded now by the CLI (benchmarks: any size). Tests use the
 * committed {@link fixture}s instead, and need no CLI.
 * @param {string} kind torus, sphere or plate
 * @param {string[]} [extra] more `vitrine sample` flags
 * @returns {{ dir: string, mesh: string, streamPath: string, stream: Uint8Array }}
 */
export function encodedSample(kind, extra = []) {
  if (!existsSync(vitrine)) throw new Error(`build the CLI first: cargo build --release -p vitrine (${vitrine})`);
  const dir = mkdtempSync(join(tmpdir(), `vitrine-${kind}-`));
  const mesh = join(dir, 'mesh.ply');
  const streamPath = join(dir, 'mesh.vtr');
  execFileSync(vitrine, ['sample', kind, '-o', mesh, ...extra], { stdio: 'pipe' });
  execFileSync(vitrine, ['encode', mesh, '-o', streamPath], { stdio: 'pipe' });
  return { dir, mesh, streamPath, stream: new Uint8Array(readFileSync(streamPath)) };
}
