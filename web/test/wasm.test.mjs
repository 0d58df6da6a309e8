// @ts-check
// Node tests of the WebAssembly decoder against streams written by the Rust
// encoder: every level's buffers must equal the native decoder's, byte for byte.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import { mkdtempSync, readFileSync, existsSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join, dirname } from 'node:path';
import { fileURLToPath } from 'node:url';
import { VitrineCodec, splitStream, DecodeError } from '../src/codec.js';

const root = join(dirname(fileURLToPath(import.meta.url)), '..', '..');
const vitrine = process.env.VITRINE_BIN ?? join(root, 'target', 'release', 'vitrine');
const wasmPath = process.env.VITRINE_WASM ?? join(root, 'target', 'wasm32-unknown-unknown', 'wasm', 'vitrine_wasm.wasm');

async function codec() {
  return VitrineCodec.instantiate(readFileSync(wasmPath));
}

/**
 * Encodes a generated sample with the Rust CLI and dumps native levels.
 * @param {string} kind
 * @param {string[]} [extra]
 */
function fixture(kind, extra = []) {
  const dir = mkdtempSync(join(tmpdir(), `vitrine-${kind}-`));
  const mesh = join(dir, 'mesh.ply');
  const stream = join(dir, 'mesh.vtr');
  execFileSync(vitrine, ['sample', kind, '-o', mesh, '--kilo-vertices', '20', ...extra], { stdio: 'pipe' });
  execFileSync(vitrine, ['encode', mesh, '-o', stream], { stdio: 'pipe' });
  execFileSync(vitrine, ['dump-levels', stream, join(dir, 'native')], { stdio: 'pipe' });
  return { dir, stream: new Uint8Array(readFileSync(stream)) };
}

/** @param {ArrayBufferView} view */
function bytesOf(view) {
  return Buffer.from(view.buffer, view.byteOffset, view.byteLength);
}

for (const [kind, extra] of /** @type {Array<[string, string[]]>} */ ([['torus', ['--colour', '--noise', '0.003']], ['plate', []], ['sphere', ['--noise', '0.002']]])) {
  test(`wasm decodes ${kind} exactly like the native decoder`, async () => {
    assert.ok(existsSync(wasmPath), `build the wasm first: ${wasmPath}`);
    const { dir, stream } = fixture(kind, extra);
    const { base, batches } = splitStream(stream);
    assert.ok(batches.length >= 2, 'several levels');
    const c = await codec();
    const decoder = c.decoder(base);
    for (let k = 0; k <= batches.length; k++) {
      if (k > 0) decoder.apply(batches[k - 1]);
      const level = decoder.level();
      assert.equal(level.level, k);
      const native = (/** @type {string} */ what) => readFileSync(join(dir, 'native', `level-${k}.${what}`));
      assert.ok(bytesOf(level.positions).equals(native('positions')), `positions at level ${k}`);
      assert.ok(bytesOf(level.indices).equals(native('indices')), `indices at level ${k}`);
      if (extra.includes('--colour')) {
        assert.ok(level.colours && bytesOf(level.colours).equals(native('colours')), `colours at level ${k}`);
      } else {
        assert.equal(level.colours, null);
      }
    }
    decoder.free();
  });
}

test('wasm reports truncated and corrupt batches as errors', async () => {
  const { stream } = fixture('torus');
  const { base, batches } = splitStream(stream);
  const c = await codec();
  assert.throws(() => c.decoder(base.subarray(0, base.length - 7)), DecodeError);
  const d1 = c.decoder(base);
  assert.throws(() => d1.apply(batches[0].subarray(0, batches[0].length - 3)), /truncated/);
  const d2 = c.decoder(base);
  assert.throws(() => d2.apply(batches[1]), /level/);
  // Flipping bytes inside the payload must give an error or a different mesh, never a crash.
  const corrupt = Uint8Array.from(batches[0]);
  for (let i = 40; i < corrupt.length; i += 7) corrupt[i] ^= 0x5a;
  const d3 = c.decoder(base);
  try {
    d3.apply(corrupt);
  } catch (e) {
    assert.ok(e instanceof DecodeError, String(e));
  }
});
