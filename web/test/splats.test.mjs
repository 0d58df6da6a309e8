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
import { boxMesh } from './support/solids.mjs';

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

test("a mesh level's sharp edges: vertices split per side, flat normals, the other side's plane clips", () => {
  const { positions, indices } = boxMesh({ min: [-1, -1, -1], max: [1, 1, 1] }, 4);
  const s = meshSplats(new Float32Array(positions), new Uint32Array(indices), null);
  const n = positions.length / 3;
  // 8 corners on 3 faces, 12 edges × 3 inner vertices on 2: 8·2 + 36 more splats.
  assert.equal(s.count, n + 8 * 2 + 36);
  assert.equal(new Set(s.surfaceIds).size, 6, 'one surface per face');
  let clipped = 0;
  let beyond = 0;
  for (let i = 0; i < s.count; i++) {
    const nrm = [...s.normals.subarray(3 * i, 3 * i + 3)];
    // Every splat's normal is its face's: one axis, exactly.
    assert.equal(nrm.filter((c) => Math.abs(c) > 1e-6).length, 1, `splat ${i}: ${nrm}`);
    const count = s.clip[i] & 15;
    if (count === 0) continue;
    clipped++;
    assert.equal((s.clip[i] >> 4) & 3, 1, 'union');
    const first = s.clip[i] >>> 6;
    const p = [...s.positions.subarray(3 * i, 3 * i + 3)];
    const r = s.radii[i];
    // Inside the box, just under the splat: kept; pushed out in its own
    // plane past an edge it is near: cut.
    const inside = p.map((c) => c * (1 - 1e-3));
    const cuts = (/** @type {number[]} */ q) => {
      for (let k = first; k < first + count; k++) {
        const [a, b, c, d] = s.planes.subarray(4 * k, 4 * k + 4);
        if (a * q[0] + b * q[1] + c * q[2] + d > 0) return true;
      }
      return false;
    };
    assert.equal(cuts(inside), false, `splat ${i} cuts the inside`);
    const out = p.map((c, a) => (Math.abs(nrm[a]) > 0.5 || Math.abs(c) < 1 - 1.01 * r ? c : c + Math.sign(c) * r));
    if (out.some((c, a) => Math.abs(c) > 1 && Math.abs(nrm[a]) < 0.5)) {
      beyond++;
      assert.equal(cuts(out), true, `splat ${i} keeps ${out}`);
    }
  }
  assert.ok(clipped > 100 && beyond > 50, `${clipped} splats clipped, ${beyond} checked past an edge`);
  // No sharp edge below −1: the splats of before (one per vertex, nothing clipped).
  const plain = meshSplats(new Float32Array(positions), new Uint32Array(indices), null, -2);
  assert.equal(plain.count, n);
  assert.equal(new Set(plain.surfaceIds).size, 1);
  assert.ok(plain.clip.every((w) => w === 0));
});
