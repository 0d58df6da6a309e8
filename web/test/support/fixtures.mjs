// @ts-check
/** Streams written by the Rust encoder (`vitrine sample` + `vitrine encode`), for Node tests. */
import { execFileSync } from 'node:child_process';
import { existsSync, mkdtempSync, readFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { dirname, join } from 'node:path';
import { fileURLToPath } from 'node:url';

export const root = join(dirname(fileURLToPath(import.meta.url)), '..', '..', '..');
export const vitrine = process.env.VITRINE_BIN ?? join(root, 'target', 'release', 'vitrine');
export const wasmPath =
  process.env.VITRINE_WASM ?? join(root, 'target', 'wasm32-unknown-unknown', 'wasm', 'vitrine_wasm.wasm');

/**
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
