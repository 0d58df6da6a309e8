// @ts-check
// Node tests of the WebAssembly decoder on the committed streams in
// test/fixtures, written by the Rust encoder from generated samples: every
// level's buffers must be what the native decoder made of the same bytes
// when they were blessed (SHA-256 of each buffer, in NAME.json), so any
// change to the decoder's output fails here. If the change is meant,
// re-record them with `bash scripts/bless-fixtures.sh`. No CLI is run: only
// the wasm module must be built.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { existsSync, readFileSync } from 'node:fs';
import { VitrineCodec, splitStream, DecodeError } from '../src/codec.js';
import { fixture, fixtureNames, sha256, wasmPath } from './support/fixtures.mjs';

async function codec() {
  assert.ok(existsSync(wasmPath), `build the wasm first: ${wasmPath}`);
  return VitrineCodec.instantiate(readFileSync(wasmPath));
}

const BLESS = 'if the change is meant: bash scripts/bless-fixtures.sh';

/**
 * A level as the fixture's sidecar records it.
 * @param {import('../src/codec.js').Level} level
 */
function digest(level) {
  return {
    level: level.level,
    vertices: level.vertices,
    faces: level.indices.length / 3,
    positions: sha256(level.positions),
    indices: sha256(level.indices),
    colours: level.colours && sha256(level.colours),
  };
}

test('the committed fixtures: small, each the stream its sidecar was blessed from', () => {
  const names = fixtureNames();
  assert.deepEqual(names, ['painted-torus', 'plate', 'sphere', 'torus']);
  for (const name of names) {
    const f = fixture(name);
    assert.ok(f.stream.length < 16 << 10, `${name}.vtr is ${f.stream.length} bytes`);
    assert.equal(f.stream.length, f.streamDigest.bytes, `${name}.vtr size`);
    assert.equal(sha256(f.stream), f.streamDigest.sha256, `${name}.vtr is not the stream ${name}.json describes: ${BLESS}`);
    assert.ok(f.levels.length >= 3, `${name}: a base and several batches`);
    f.levels.forEach((level, k) => assert.equal(level.level, k));
  }
});

for (const name of fixtureNames()) {
  test(`wasm decodes ${name}.vtr exactly as the native decoder did`, async () => {
    const f = fixture(name);
    const { base, batches } = splitStream(f.stream);
    assert.equal(batches.length + 1, f.levels.length, 'levels');
    const decoder = (await codec()).decoder(base);
    for (let k = 0; k <= batches.length; k++) {
      if (k > 0) decoder.apply(batches[k - 1]);
      assert.deepEqual(digest(decoder.level()), f.levels[k], `${name} level ${k}: the decoder's output changed; ${BLESS}`);
      // The zero-copy views the decode worker reads are the same bytes.
      assert.deepEqual(digest(decoder.view()), f.levels[k], `${name} level ${k} through view()`);
    }
    if (name === 'painted-torus') assert.ok(f.levels.every((l) => l.colours !== null), 'colour at every level');
    else assert.ok(f.levels.every((l) => l.colours === null), 'no colour');
    decoder.free();
  });
}

test('wasm reports truncated and corrupt batches as errors', async () => {
  const { base, batches } = splitStream(fixture('torus').stream);
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
