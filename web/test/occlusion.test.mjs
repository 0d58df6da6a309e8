// @ts-check
// Node tests of occlusion culling (occlusion.js): the depth map of the
// surface shown and whether a bounding sphere lies wholly behind it, with
// the tolerance, the near plane, the eye inside, the screen's edges, and
// an empty or degenerate surface hiding nothing.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { OcclusionMap, depthMap, occluded } from '../src/occlusion.js';
import { boundingSphere } from '../src/part-selection.js';

/**
 * The clip matrix of an eye at (0, 0, `eye`) looking down −z, 90° field of
 * view, near 0.1, far 100 (column-major, as the viewer sends it).
 * @param {number} eye
 * @param {number} [aspect]
 */
function clipFrom(eye, aspect = 1) {
  const f = 1;
  const [near, far] = [0.1, 100];
  const a = (far + near) / (near - far);
  const b = (2 * far * near) / (near - far);
  // prettier-ignore
  return [f / aspect, 0, 0, 0, 0, f, 0, 0, 0, 0, a, -1, 0, 0, -a * eye + b, eye];
}

/**
 * A square in the plane z, half-side `half`, centred on (cx, 0), as two triangles.
 * @param {number} z
 * @param {number} half
 * @param {number} [cx]
 */
function square(z, half, cx = 0) {
  // prettier-ignore
  const positions = new Float32Array([cx - half, -half, z, cx + half, -half, z, cx + half, half, z, cx - half, half, z]);
  return { positions, indices: new Uint32Array([0, 1, 2, 0, 2, 3]) };
}

/** @param {number} x @param {number} y @param {number} z @param {number} radius */
const sphere = (x, y, z, radius) => ({ centre: /** @type {[number, number, number]} */ ([x, y, z]), radius });

test('a square in front hides a sphere behind it, not one beside it or in front', () => {
  // The eye at z = 3, the square at z = 0 fills the view's middle (±1 at 3: a third of the half-width).
  const map = depthMap([{ ...square(0, 1), tolerance: 0 }], clipFrom(3), 1);
  assert.equal(map.width, 64);
  assert.equal(map.height, 64);
  assert.equal(map.triangles, 2);
  assert.ok(occluded(map, sphere(0, 0, -1, 0.2)), 'right behind');
  assert.ok(occluded(map, sphere(0.3, -0.2, -5, 0.5)), 'far behind, smaller on screen');
  assert.ok(!occluded(map, sphere(0, 0, 1, 0.2)), 'in front of the square');
  assert.ok(!occluded(map, sphere(1.3, 0, -1, 0.3)), 'partly beside the square: seen past its edge');
  assert.ok(!occluded(map, sphere(0, 0, -1, 2)), 'larger than the square on screen');
  assert.ok(!occluded(map, sphere(0, 0, -0.1, 0.2)), 'through the square: its nearest point is in front');
});

test('the tolerance: a sphere just behind the surface is hidden only past it', () => {
  // Nearest point of the sphere 0.1 behind the square.
  const behind = sphere(0, 0, -0.3, 0.2);
  assert.ok(occluded(depthMap([{ ...square(0, 1), tolerance: 0.05 }], clipFrom(3), 1), behind));
  assert.ok(!occluded(depthMap([{ ...square(0, 1), tolerance: 0.15 }], clipFrom(3), 1), behind), 'the surface to come may lie behind it');
  // Two pieces over each other: the nearer pushed back by its tolerance, the farther not.
  const two = depthMap([{ ...square(0.5, 1), tolerance: 10 }, { ...square(0, 1), tolerance: 0 }], clipFrom(3), 1);
  assert.ok(occluded(two, behind), 'the least of depth plus tolerance over the pieces covering a pixel');
});

test('a chart does not hide itself: its own surface lies in its sphere', () => {
  const { positions, indices } = square(0, 1);
  const map = depthMap([{ positions, indices, tolerance: 0 }], clipFrom(3), 1);
  assert.ok(!occluded(map, boundingSphere(positions)));
  // Seen at a slant, too: the square tilted towards the eye.
  const tilted = new Float32Array([-1, -1, -1, 1, -1, -1, 1, 1, 1, -1, 1, 1]);
  assert.ok(!occluded(depthMap([{ positions: tilted, indices, tolerance: 0 }], clipFrom(3), 1), boundingSphere(tilted)));
});

test('a sphere that holds the eye or crosses the near plane is never hidden; triangles behind the eye are not drawn', () => {
  const map = depthMap([{ ...square(0, 1), tolerance: 0 }], clipFrom(3), 1);
  assert.ok(!occluded(map, sphere(0, 0, 3, 0.5)), 'the eye inside');
  assert.ok(!occluded(map, sphere(0, 0, 2.85, 0.1)), 'across the near plane (2.9)');
  // A square behind the eye draws nothing: nothing is hidden.
  const back = depthMap([{ ...square(4, 1), tolerance: 0 }], clipFrom(3), 1);
  assert.equal(back.triangles, 0);
  assert.ok(!occluded(back, sphere(0, 0, -1, 0.2)));
  // A square straddling the eye's plane is not drawn either (a vertex behind it).
  const straddling = { positions: new Float32Array([-1, -1, 0, 1, -1, 0, 0, 1, 5]), indices: new Uint32Array([0, 1, 2]) };
  assert.equal(depthMap([{ ...straddling, tolerance: 0 }], clipFrom(3), 1).triangles, 0);
});

test('an empty or degenerate surface hides nothing; off the screen is not hidden', () => {
  const empty = depthMap([], clipFrom(3), 1);
  assert.ok(!occluded(empty, sphere(0, 0, -1, 0.2)));
  const none = depthMap([{ positions: new Float32Array(0), indices: new Uint32Array(0), tolerance: 0 }], clipFrom(3), 1);
  assert.ok(!occluded(none, sphere(0, 0, -1, 0.2)));
  // Every triangle with no area (a point, a line).
  const flat = { positions: new Float32Array([0, 0, 0, 0, 0, 0, 1, 1, 0]), indices: new Uint32Array([0, 1, 2, 0, 0, 0]) };
  assert.ok(!occluded(depthMap([{ ...flat, tolerance: 0 }], clipFrom(3), 1), sphere(0, 0, -1, 0.2)));
  // A wall filling the view hides what is behind it, but not what lies off screen.
  const wall = depthMap([{ ...square(0, 100), tolerance: 0 }], clipFrom(3), 1);
  assert.ok(occluded(wall, sphere(0, 0, -1, 0.5)));
  assert.ok(!occluded(wall, sphere(50, 0, -1, 0.5)), 'outside the frustum: the frustum test says so, not this');
  // Partly off screen: only its part on screen counts.
  assert.ok(occluded(wall, sphere(3.9, 0, -1, 0.5)));
});

test('the map follows the aspect; a subsample draws fewer triangles and hides no more', () => {
  const wide = depthMap([{ ...square(0, 1), tolerance: 0 }], clipFrom(3, 2), 2);
  assert.deepEqual([wide.width, wide.height], [64, 32]);
  const tall = depthMap([{ ...square(0, 1), tolerance: 0 }], clipFrom(3, 0.5), 0.5);
  assert.deepEqual([tall.width, tall.height], [32, 64]);
  assert.ok(occluded(wide, sphere(0, 0, -1, 0.2)));
  // Of the square's two triangles, one drawn: the sphere behind the other half is seen.
  const half = depthMap([{ ...square(0, 1), tolerance: 0 }], clipFrom(3), 1, { maxTriangles: 1 });
  assert.equal(half.triangles, 1);
  assert.ok(!occluded(half, sphere(0, 0, -1, 0.2)));
});

test('a chart drawn in the map is tested by its own extent: tighter than its sphere, never hidden by itself', () => {
  const camera = { eye: /** @type {[number, number, number]} */ ([0, 0, 3]), clip: clipFrom(3), pixelsPerRadian: 300 };
  const wall = { key: {}, ...square(0, 1), tolerance: 0 };
  // A square 0.5 behind the wall, its sphere reaching in front of the wall.
  const flat = { key: {}, ...square(-0.5, 0.6), tolerance: 0.1 };
  const occlusion = new OcclusionMap({ gap: 4, maxTriangles: Infinity });
  occlusion.refresh(camera, 0, () => [wall, flat]);
  assert.equal(occlusion.made, 1);
  const sphere = boundingSphere(flat.positions);
  assert.ok(sphere.radius > 0.5, 'its sphere crosses the wall');
  assert.ok(!occlusion.hides(camera, {}, () => sphere), 'by its sphere: not hidden');
  assert.ok(occlusion.hides(camera, flat.key, () => sphere), 'by its extent: hidden');
  assert.ok(!occlusion.hides(camera, wall.key, () => boundingSphere(wall.positions)), 'the wall does not hide itself');
  assert.ok(!occlusion.hides({ ...camera }, flat.key, () => sphere), 'another camera: the map does not answer');
  // Its tolerance past the gap: the surface to come may reach in front of the wall.
  const loose = { key: {}, ...square(-0.5, 0.6), tolerance: 0.6 };
  const c2 = { ...camera };
  occlusion.refresh(c2, 0, () => [wall, loose]);
  assert.equal(occlusion.made, 2, 'a new camera: a new map');
  assert.ok(!occlusion.hides(c2, loose.key, () => sphere));
  // A piece with a vertex behind the eye has no extent: never hidden.
  const straddling = { key: {}, positions: new Float32Array([-0.1, -0.1, -1, 0.1, -0.1, -1, 0, 0.1, 5]), indices: new Uint32Array([0, 1, 2]), tolerance: 0 };
  const c3 = { ...camera };
  occlusion.refresh(c3, 0, () => [wall, straddling]);
  assert.ok(!occlusion.hides(c3, straddling.key, () => ({ centre: [0, 0, -1], radius: 0.01 })));
  assert.ok(occlusion.hides(c3, {}, () => ({ centre: [0, 0, -1], radius: 0.01 })), 'a chart not drawn: by its sphere');
  // Off the map by its vertices (its sphere would reach into the view): out of view.
  const aside = { key: {}, ...square(-0.5, 0.2, 6), tolerance: 0 };
  const c4 = { ...camera };
  occlusion.refresh(c4, 0, () => [aside]);
  assert.ok(occlusion.hides(c4, aside.key, () => ({ centre: [6, 0, -0.5], radius: 5 })));
  assert.ok(!occlusion.hides(c4, {}, () => ({ centre: [6, 0, -0.5], radius: 5 })));
  // The same camera, the surface unchanged: the map is kept.
  occlusion.refresh(c4, 0, () => [wall]);
  assert.equal(occlusion.made, 4);
});
