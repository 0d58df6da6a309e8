// @ts-check
// Node tests of pick.js: rays through pixels, ray–triangle hits,
// occlusion, snapping to vertices and projection, on meshes whose answers are known,
// and its speed on a million triangles.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { OrbitCamera } from '../src/camera.js';
import { upRotation } from '../src/frame.js';
import { intersect, nearestVertex, occluded, projectPoint, viewRay } from '../src/pick.js';

const IDENTITY = [1, 0, 0, 0, 1, 0, 0, 0, 1];

/** A unit cube's 12 triangles (outward winding not needed). */
function cube() {
  const positions = new Float32Array([0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 0, 0, 1, 1, 0, 1, 1, 1, 1, 0, 1, 1]);
  // prettier-ignore
  const indices = new Uint32Array([0, 2, 1, 0, 3, 2, 4, 5, 6, 4, 6, 7, 0, 1, 5, 0, 5, 4, 3, 7, 6, 3, 6, 2, 0, 4, 7, 0, 7, 3, 1, 2, 6, 1, 6, 5]);
  return { positions, indices };
}

test('a ray hits the nearest face of a cube at the right point', () => {
  const { positions, indices } = cube();
  const hit = intersect(positions, indices, { origin: [0.25, 0.5, 5], direction: [0, 0, -1] });
  assert.ok(hit);
  assert.deepEqual(hit.point.map((v) => Math.round(v * 1e6) / 1e6), [0.25, 0.5, 1]);
  assert.equal(hit.t, 4);
  assert.equal(intersect(positions, indices, { origin: [2, 2, 5], direction: [0, 0, -1] }), null, 'a miss');
  assert.equal(intersect(positions, indices, { origin: [0.5, 0.5, 5], direction: [0, 0, 1] }), null, 'behind the origin');
  assert.equal(intersect(positions, indices, { origin: [0.5, 0.5, 5], direction: [0, 0, -1] }, 3.9), null, 'beyond tMax');
});

test('the back of the cube is occluded from the front, the front is not', () => {
  const { positions, indices } = cube();
  const eye = [0.5, 0.5, 5];
  assert.equal(occluded(positions, indices, eye, [0.5, 0.5, 1], 0.01), false);
  assert.equal(occluded(positions, indices, eye, [0.5, 0.5, 0], 0.01), true);
  // A point slightly inside the surface (a coarse level) is still seen within the tolerance.
  assert.equal(occluded(positions, indices, eye, [0.5, 0.5, 0.995], 0.01), false);
});

test('the ray through a projected point hits that point (any up axis)', () => {
  const { positions, indices } = cube();
  for (const up of ['y', 'z', '-x']) {
    const model = upRotation(up);
    const camera = new OrbitCamera({ min: [-1, -1, -1], max: [2, 2, 2] }, 640 / 480);
    const target = [0.5, 0.5, 1];
    const screen = projectPoint(camera, model, target, 640, 480);
    const ray = viewRay(camera, model, screen.x, screen.y, 640, 480);
    const hit = intersect(positions, indices, ray);
    assert.ok(hit, `${up}: hit`);
    // Either this face point or a nearer face along the same ray: check it projects back to the same pixel.
    const back = projectPoint(camera, model, hit.point, 640, 480);
    assert.ok(Math.hypot(back.x - screen.x, back.y - screen.y) < 1e-6 * 640, `${up}: ${JSON.stringify([screen, back])}`);
  }
});

test('nearestVertex snaps within the radius only', () => {
  const { positions } = cube();
  assert.deepEqual(nearestVertex(positions, 8, [0.05, 0.98, 1.02], 0.1), [0, 1, 1]);
  assert.equal(nearestVertex(positions, 8, [0.5, 0.5, 1], 0.1), null);
  assert.equal(nearestVertex(positions, 1, [0.05, 0.98, 1.02], 0.1), null, 'only the first `count` vertices');
});

test('a million triangles are picked in well under a second', () => {
  // A 708 × 708 grid: 1,002,528 triangles.
  const n = 708;
  const positions = new Float32Array(3 * (n + 1) * (n + 1));
  for (let j = 0; j <= n; j++) {
    for (let i = 0; i <= n; i++) positions.set([i / n, j / n, 0.1 * Math.sin(i / 20) * Math.cos(j / 30)], 3 * (j * (n + 1) + i));
  }
  const indices = new Uint32Array(6 * n * n);
  let k = 0;
  for (let j = 0; j < n; j++) {
    for (let i = 0; i < n; i++) {
      const a = j * (n + 1) + i;
      indices.set([a, a + 1, a + n + 2, a, a + n + 2, a + n + 1], k);
      k += 6;
    }
  }
  const times = [];
  for (let r = 0; r < 5; r++) {
    const t0 = performance.now();
    const hit = intersect(positions, indices, { origin: [0.3 + 0.05 * r, 0.6, 2], direction: [0, 0, -1] });
    times.push(performance.now() - t0);
    assert.ok(hit && Math.abs(hit.point[0] - (0.3 + 0.05 * r)) < 1e-6);
  }
  times.sort((a, b) => a - b);
  console.log(`# pick on ${indices.length / 3} triangles: median ${times[2].toFixed(1)} ms`);
  assert.ok(times[2] < 1000, `median ${times[2]} ms`);
});
