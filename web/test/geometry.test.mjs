// @ts-check
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { accumulateNormals, bounds, edgeIndices, packNormals, vertexNormals } from '../src/geometry.js';

// A unit square in the z = 0 plane, two triangles, counter-clockwise from +z.
const square = {
  positions: new Float32Array([0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0]),
  indices: new Uint32Array([0, 1, 2, 0, 2, 3]),
};

test('normals of a flat square face +z', () => {
  const n = vertexNormals(square.positions, square.indices);
  assert.deepEqual([...n], [0, 0, 32767, 0, 0, 32767, 0, 0, 32767, 0, 0, 32767]);
});

test('a vertex on no face gets a zero normal', () => {
  const positions = new Float32Array([...square.positions, 5, 5, 5]);
  const n = vertexNormals(positions, square.indices);
  assert.deepEqual([...n.subarray(12)], [0, 0, 0]);
});

test('edges: shared diagonal once, every border edge whatever its direction', () => {
  const edges = edgeIndices(square.indices, 4);
  const set = new Set();
  for (let i = 0; i < edges.length; i += 2) set.add([edges[i], edges[i + 1]].sort().join('-'));
  assert.equal(edges.length, 10);
  assert.deepEqual([...set].sort(), ['0-1', '0-2', '0-3', '1-2', '2-3']);
});

test('edges of a closed tetrahedron: six', () => {
  const indices = new Uint32Array([0, 2, 1, 0, 1, 3, 1, 2, 3, 2, 0, 3]);
  assert.equal(edgeIndices(indices, 4).length, 12);
});

test('bounds', () => {
  assert.deepEqual(bounds(square.positions), { min: [0, 0, 0], max: [1, 1, 0] });
  assert.deepEqual(bounds(new Float32Array()), { min: [0, 0, 0], max: [0, 0, 0] });
});

test('normals derived a slice at a time equal vertexNormals', () => {
  // A bumpy 20×20 grid: many vertices shared by six triangles.
  const side = 20;
  const positions = new Float32Array(3 * side * side);
  for (let y = 0; y < side; y++) {
    for (let x = 0; x < side; x++) positions.set([x, y, Math.sin(x * 0.7) * Math.cos(y * 0.4)], 3 * (y * side + x));
  }
  const list = [];
  for (let y = 0; y + 1 < side; y++) {
    for (let x = 0; x + 1 < side; x++) {
      const v = y * side + x;
      list.push(v, v + 1, v + side + 1, v, v + side + 1, v + side);
    }
  }
  const indices = new Uint32Array(list);
  const whole = vertexNormals(positions, indices);
  const sum = new Float32Array(positions.length);
  for (let t = 0; t < indices.length; t += 3 * 37) accumulateNormals(positions, indices, sum, t, Math.min(indices.length, t + 3 * 37));
  const sliced = new Int16Array(positions.length);
  for (let i = 0; i < sum.length; i += 3 * 11) packNormals(sum, sliced, i, Math.min(sum.length, i + 3 * 11));
  assert.deepEqual(sliced, whole);
});
