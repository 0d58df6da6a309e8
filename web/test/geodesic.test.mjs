// @ts-check
// Node tests of the geodesic distance in the WebAssembly module (what the
// viewer's measurement tool calls on a decoded level) against the native
// library's numbers in test/fixtures/geodesic-torus.json, which the Rust
// test codec/wasm/tests/geodesic_fixture.rs checks (and re-records with
// VITRINE_BLESS=1). Only the wasm module must be built.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { existsSync, readFileSync } from 'node:fs';
import { join } from 'node:path';
import { VitrineCodec, DecodeError, DIJKSTRA, FAST_MARCHING } from '../src/codec.js';
import { fixturesDir, wasmPath } from './support/fixtures.mjs';

async function surface() {
  assert.ok(existsSync(wasmPath), `build the wasm first: ${wasmPath}`);
  const codec = await VitrineCodec.instantiate(readFileSync(wasmPath));
  const f = JSON.parse(readFileSync(join(fixturesDir, 'geodesic-torus.json'), 'utf8'));
  return { codec, f, s: codec.surface(new Float32Array(f.positions), new Uint32Array(f.indices)) };
}

/** Same code, same IEEE arithmetic: equal but for the last bits at most. */
function close(/** @type {number} */ a, /** @type {number} */ b, /** @type {string} */ what) {
  assert.ok(Math.abs(a - b) <= 1e-12 * Math.max(1, Math.abs(b)), `${what}: wasm ${a}, native ${b}`);
}

test('point-to-point distances are the native ones, for both methods', async () => {
  const { f, s } = await surface();
  assert.equal(f.distances.length, 8);
  for (const { method, to, distance } of f.distances) {
    close(s.distance(f.from, to, method), distance, `method ${method} to ${to}`);
  }
  // Along the surface is never shorter than the straight line.
  for (const { to, distance } of f.distances) {
    const straight = Math.hypot(to[0] - f.from[0], to[1] - f.from[1], to[2] - f.from[2]);
    assert.ok(distance >= straight - 0.05, `${distance} vs straight ${straight}`);
  }
  s.free();
});

test('the distance field is the native one at every vertex', async () => {
  const { f, s } = await surface();
  const field = s.field(f.from, FAST_MARCHING);
  assert.equal(field.length, f.positions.length / 3);
  field.forEach((d, v) => close(d, f.field.values[v], `vertex ${v}`));
  const dijkstra = s.field(f.from, DIJKSTRA);
  field.forEach((d, v) => assert.ok(d <= dijkstra[v], `vertex ${v}: FMM ${d} > Dijkstra ${dijkstra[v]}`));
  s.free();
});

test('a bad mesh or a freed surface is an error, not a crash', async () => {
  const { codec, s } = await surface();
  assert.throws(() => codec.surface(new Float32Array([0, 0, 0, 1, 0, 0, NaN, 1, 0]), new Uint32Array([0, 1, 2])), DecodeError);
  assert.throws(() => codec.surface(new Float32Array(9), new Uint32Array([0, 1, 7])), /indexes past/);
  s.free();
  assert.throws(() => s.distance([0, 0, 0], [1, 0, 0]), /no surface/);
});
