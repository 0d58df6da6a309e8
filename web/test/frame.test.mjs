// @ts-check
// Node tests of frame.js (up axis → rotation, bounds, the framing fit) and
// the camera's home view built on it.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { UP_AXES, corners, fitDistance, frameBox, rotate, rotateBounds, unrotate, upRotation, validBounds } from '../src/frame.js';
import { OrbitCamera } from '../src/camera.js';
import { projectPoint } from '../src/pick.js';

/**
 * @param {number[]} min
 * @param {number[]} max
 * @returns {import('../src/geometry.js').Bounds}
 */
function box(min, max) {
  return { min: [min[0], min[1], min[2]], max: [max[0], max[1], max[2]] };
}

/** @param {number[]} m column-major 3×3 */
function det(m) {
  return m[0] * (m[4] * m[8] - m[7] * m[5]) - m[3] * (m[1] * m[8] - m[7] * m[2]) + m[6] * (m[1] * m[5] - m[4] * m[2]);
}

test('each up axis is turned onto +Y by a proper rotation', () => {
  const axes = { x: [1, 0, 0], y: [0, 1, 0], z: [0, 0, 1], '-x': [-1, 0, 0], '-y': [0, -1, 0], '-z': [0, 0, -1] };
  for (const up of UP_AXES) {
    const m = upRotation(up);
    assert.deepEqual(rotate(m, axes[up]).map((v) => v + 0), [0, 1, 0], `${up} goes up`);
    assert.equal(det(m), 1, `${up}: a rotation, not a mirror`);
    const p = [0.3, -1.7, 2.5];
    assert.deepEqual(unrotate(m, rotate(m, p)), p, `${up}: the transpose undoes it`);
  }
  // Absent or unknown: the default y (identity).
  assert.deepEqual(upRotation(undefined), [1, 0, 0, 0, 1, 0, 0, 0, 1]);
  assert.deepEqual(upRotation('sideways'), [1, 0, 0, 0, 1, 0, 0, 0, 1]);
});

test('a Z-up box stands on its end after the rotation', () => {
  const b = box([0, 0, 0], [1, 2, 10]);
  const upright = rotateBounds(b, upRotation('z'));
  assert.deepEqual(upright.max.map((v, k) => v - upright.min[k]), [1, 10, 2], 'the tall axis is Y');
});

test('manifest bounds are used only when they are valid', () => {
  const fallback = box([0, 0, 0], [1, 1, 1]);
  assert.deepEqual(validBounds(box([-1, -2, -3], [1, 2, 3]), fallback), box([-1, -2, -3], [1, 2, 3]));
  for (const bad of [null, {}, { min: [0, 0], max: [1, 1, 1] }, { min: [2, 0, 0], max: [1, 1, 1] }, { min: [0, 0, NaN], max: [1, 1, 1] }]) {
    assert.equal(validBounds(bad, fallback), fallback, JSON.stringify(bad));
  }
  const look = { model: upRotation('z'), bounds: box([0, 0, 0], [1, 2, 3]) };
  assert.deepEqual(frameBox(look, fallback).max.map((v, k) => v - frameBox(look, fallback).min[k]), [1, 3, 2]);
});

test('the home view fills most of the view, in landscape and in portrait', () => {
  const b = box([-1, -0.5, -0.25], [1, 0.5, 0.25]);
  for (const [width, height] of [[1920, 1080], [390, 844], [320, 568], [800, 800]]) {
    const camera = new OrbitCamera(b, width / height);
    const ps = corners(b).map((c) => projectPoint(camera, [1, 0, 0, 0, 1, 0, 0, 0, 1], c, width, height));
    const xs = ps.map((p) => p.x);
    const ys = ps.map((p) => p.y);
    for (const p of ps) {
      assert.ok(p.inFront && p.x >= 0 && p.x <= width && p.y >= 0 && p.y <= height, `${width}×${height}: corner inside ${JSON.stringify(p)}`);
    }
    const fillX = (Math.max(...xs) - Math.min(...xs)) / width;
    const fillY = (Math.max(...ys) - Math.min(...ys)) / height;
    // One of the two directions is filled to the margin (90 % of the half-extent, from the centre).
    assert.ok(Math.max(fillX, fillY) > 0.75, `${width}×${height}: fills ${fillX.toFixed(2)} × ${fillY.toFixed(2)}`);
  }
});

test('fitDistance grows for a narrower view and never puts the eye inside the box', () => {
  const b = box([-1, -1, -1], [1, 1, 1]);
  const view = { yaw: 0.5, pitch: 0.4, fovY: (40 * Math.PI) / 180 };
  const wide = fitDistance(b, [0, 0, 0], { ...view, aspect: 2 });
  const narrow = fitDistance(b, [0, 0, 0], { ...view, aspect: 0.4 });
  assert.ok(narrow > wide * 1.5, `${narrow} vs ${wide}`);
  assert.ok(fitDistance(b, [0, 0, 0], { ...view, aspect: 1, fill: 50 }) >= 1.05 * Math.sqrt(3));
});
