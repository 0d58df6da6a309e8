// @ts-check
// The splat worker's inputs: a point stream decoded level by level through
// the WebAssembly module (two intersecting spheres, codec/points/examples/
// splat_fixture.rs), and a mesh level turned into splats.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';
import { join } from 'node:path';
import { VitrineCodec } from '../src/codec.js';
import { PointStream, splitHeader, splitLevels } from '../src/splats/point-stream.js';
import { meshSplats } from '../src/splats/mesh-splats.js';
import { fixturesDir, wasmPath } from './support/fixtures.mjs';

const spheres = new Uint8Array(readFileSync(join(fixturesDir, 'two-spheres.vpts')));

test('a point stream decodes level by level into splats with two surfaces', async () => {
  const codec = await VitrineCodec.instantiate(readFileSync(wasmPath));
  const levels = splitLevels(spheres);
  assert.equal(levels.length, 4);
  const { header, chunk } = splitHeader(levels[0]);
  const stream = new PointStream(codec, header);
  assert.equal(stream.levels, 4);
  stream.apply(chunk);
  let last = 0;
  for (let k = 1; k <= 4; k++) {
    const s = stream.splats(0.9);
    assert.ok(s.count > last, `level ${k - 1} adds points`);
    last = s.count;
    assert.equal(s.positions.length, 3 * s.count);
    assert.equal(s.radii.length, s.count);
    assert.ok(s.colours);
    if (k === 4) {
      // Red splats and blue splats never share a surface id.
      const red = new Set();
      const blue = new Set();
      for (let i = 0; i < s.count; i++) (s.colours[3 * i] > 100 ? red : blue).add(s.surfaceIds[i]);
      for (const id of red) assert.ok(!blue.has(id), `surface ${id} is red and blue`);
      const clipped = s.clip.filter((w) => (w & 15) > 0).length;
      assert.ok(clipped > 0, 'splats along the intersection have clip partners');
      assert.ok(s.planes.length >= 4 * clipped);
    } else stream.apply(levels[k]);
  }
  assert.equal(stream.count, 24000);
  stream.free();
});

test('a truncated chunk is a decode error', async () => {
  const codec = await VitrineCodec.instantiate(readFileSync(wasmPath));
  const levels = splitLevels(spheres);
  const { header, chunk } = splitHeader(levels[0]);
  const stream = new PointStream(codec, header);
  stream.apply(chunk);
  assert.throws(() => stream.apply(levels[1].subarray(0, levels[1].length >> 1)), /truncated|corrupt/i);
});

test('a mesh level: normals, edge-length radii, one surface per component', () => {
  // Two separate triangles sharing no vertex, and a quad.
  const positions = new Float32Array([0, 0, 0, 1, 0, 0, 0, 1, 0, 5, 0, 0, 7, 0, 0, 5, 2, 0]);
  const indices = new Uint32Array([0, 1, 2, 3, 4, 5]);
  const s = meshSplats(positions, indices, null);
  assert.equal(s.count, 6);
  assert.deepEqual([...s.normals.subarray(0, 3)], [0, 0, 1]);
  assert.ok(Math.abs(s.radii[0] - 1) < 1e-6, 'vertex 0: edges of 1 and 1');
  assert.ok(Math.abs(s.radii[3] - 2) < 1e-6, 'vertex 3: edges of 2 and 2');
  assert.equal(s.surfaceIds[0], s.surfaceIds[2]);
  assert.notEqual(s.surfaceIds[0], s.surfaceIds[3]);
  assert.equal(s.clip.every((w) => w === 0), true);
});
