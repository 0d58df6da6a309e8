// @ts-check
// Node tests of view-dependent refinement's choices (part-selection.js):
// which chart's next part is fetched for a camera (error on screen, frustum,
// cap, final depth, charts that sit a batch out), and which charts give
// their vertices back for the budget, in what order; a chart hidden behind
// another (occlusion.js) wants no part and gives its vertices back first.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { OrbitCamera, multiply } from '../src/camera.js';
import {
  SCREEN_ERROR_PX,
  VERTEX_BUDGETS,
  assess,
  boundingSphere,
  defaultBudget,
  evictionOrder,
  facesAway,
  frustumPlanes,
  inFrustum,
  normalCone,
  occluderTolerance,
  occlusionSphere,
  partTable,
  wantedParts,
} from '../src/part-selection.js';
import { depthMap, occluded } from '../src/occlusion.js';

/**
 * A camera at `eye` looking at `target` (model coordinates = world: no up rotation).
 * @param {[number, number, number]} target
 * @param {number} distance
 * @param {number} yaw
 * @returns {import('../src/part-selection.js').PartCamera}
 */
function camera(target, distance, yaw = 0) {
  const c = new OrbitCamera({ min: [-20, -20, -20], max: [20, 20, 20] }, 1);
  c.state = { target, distance, yaw, pitch: 0 };
  const clip = Array.from(multiply(c.projection(1), c.view()));
  return { eye: c.basis().eye, clip, pixelsPerRadian: 600 / c.fovY };
}

/**
 * Charts in a row along −z, away from a camera on +z, each a unit-radius sphere; parts with the given errors per depth.
 * @param {number[][]} errors errors[chart][depth]
 * @param {number[]} [bytes] bytes of every part (default 100)
 */
function setup(errors, bytes) {
  const parts = errors.flatMap((row, chart) =>
    row.map((error, depth) => ({ level: 5 + depth, chart, bytes: bytes?.[depth] ?? 100, inserted: 10, error })),
  );
  const table = partTable({ charts: errors.length, first_level: 5, head_url: '', part_url: '', parts });
  /** @type {import('../src/part-selection.js').ChartState[]} */
  const charts = errors.map((_, k) => ({ depth: 0, sphere: { centre: [0, 0, -3 * k], radius: 1 } }));
  return { table, charts };
}

test('spheres, frustum planes and normal cones', () => {
  const s = boundingSphere(new Float32Array([0, 0, 0, 2, 0, 0, 1, 1, 0]));
  assert.deepEqual(s.centre, [1, 0.5, 0]);
  assert.ok(Math.abs(s.radius - Math.hypot(1, 0.5)) < 1e-12);
  const cam = camera([0, 0, 0], 5);
  const planes = frustumPlanes(cam.clip);
  assert.equal(planes.length, 6);
  assert.ok(inFrustum(planes, { centre: [0, 0, 0], radius: 0.1 }));
  assert.ok(!inFrustum(planes, { centre: [0, 0, 20], radius: 1 }), 'behind the eye');
  assert.ok(!inFrustum(planes, { centre: [50, 0, 0], radius: 1 }), 'far to the side');
  assert.ok(inFrustum(planes, { centre: [4, 0, 0], radius: 3 }), 'a sphere that reaches into the view');
  // A flat patch facing +z, seen from +z and from −z.
  const cone = normalCone(new Float32Array([0, 0, 0, 1, 0, 0, 0, 1, 0]), new Uint32Array([0, 1, 2]));
  assert.deepEqual(cone.axis, [0, 0, 1]);
  const patch = { centre: /** @type {[number, number, number]} */ ([0.3, 0.3, 0]), radius: 0.5 };
  assert.ok(!facesAway(cone, patch, [0, 0, 5]));
  assert.ok(facesAway(cone, patch, [0, 0, -5]));
  assert.ok(!facesAway(cone, patch, [0, 0, -0.2]), 'the eye inside the sphere');
});

test('the next part goes to the chart with the largest error on screen, within the cap and the threshold', () => {
  const { table, charts } = setup([
    [0.1, 0.05, 0.02],
    [0.1, 0.05, 0.02],
    [0.1, 0.05, 0.02],
  ]);
  const near = camera([0, 0, 0], 4);
  const wanted = wantedParts(charts, table, near, { firstLevel: 5, capLevel: 7 });
  assert.deepEqual(
    wanted.map((w) => w.chart),
    [0, 1, 2],
    'nearest first for parts of one level',
  );
  assert.ok(wanted.every((w) => w.pixels > SCREEN_ERROR_PX));
  // At the cap: a chart one level below it may take one more part, not two.
  charts[0].depth = 2;
  assert.ok(!wantedParts(charts, table, near, { firstLevel: 5, capLevel: 6 }).some((w) => w.chart === 0));
  assert.ok(wantedParts(charts, table, near, { firstLevel: 5, capLevel: 7 }).some((w) => w.chart === 0));
  // At the final depth, nothing more; busy charts wait for their part.
  charts[0].depth = 3;
  charts[1].busy = true;
  assert.deepEqual(
    wantedParts(charts, table, near, { firstLevel: 5, capLevel: 7 }).map((w) => w.chart),
    [2],
  );
  // Far away the errors fall under a pixel: nothing is wanted.
  charts[1].busy = false;
  assert.deepEqual(wantedParts(charts, table, camera([0, 0, 0], 1e6), { firstLevel: 5, capLevel: 7 }), []);
  // Out of the frustum: not wanted however large its error.
  const aside = camera([300, 0, 0], 4);
  assert.deepEqual(wantedParts(charts, table, aside, { firstLevel: 5, capLevel: 7 }), []);
});

test('a chart that sits a batch out is still refined for the parts after it', () => {
  const { table, charts } = setup([[0, 0.05, 0.02]], [0, 100, 100]);
  assert.deepEqual(table.remaining[0], [0.05, 0.05, 0.02, 0]);
  const wanted = wantedParts(charts, table, camera([0, 0, 0], 4), { firstLevel: 5, capLevel: 7 });
  assert.equal(wanted.length, 1, 'its empty part is wanted: the error after it counts');
});

test('room is made out of view first, then from the charts that miss their detail least', () => {
  const { table, charts } = setup([
    [0.1, 0.01, 0.001],
    [0.1, 0.01, 0.001],
    [0.1, 0.01, 0.001],
    [0.1, 0.01, 0.001],
  ]);
  for (const c of charts) c.depth = 2;
  // Chart 0 at the cut, nearest: it wants room. Chart 3 far away to the
  // side and out of view; 2, the farthest, misses least at the cut.
  charts[0].depth = 0;
  charts[3].sphere = { centre: [0, 0, 500], radius: 1 };
  const cam = camera([0, 0, 0], 3);
  assert.ok(assess(charts, table, cam)[2].cutPixels < assess(charts, table, cam)[1].cutPixels);
  const assessed = assess(charts, table, cam);
  assert.equal(assessed[3].visible, false);
  assert.deepEqual(evictionOrder(charts, assessed, 0), [3, 2, 1]);
  // A chart needing less than the others would miss at the cut takes nothing from them.
  charts[0].depth = 3;
  charts[1].depth = 2;
  const calm = assess(charts, table, cam);
  assert.deepEqual(evictionOrder(charts, calm, 1), [3], 'only the chart out of view');
  // Never a busy chart, never one at the cut, never the chart itself.
  charts[3].busy = true;
  charts[2].depth = 0;
  assert.deepEqual(evictionOrder(charts, assess(charts, table, cam), 1), []);
});

test('budgets by device class', () => {
  assert.equal(defaultBudget('phone'), VERTEX_BUDGETS.phone);
  assert.equal(defaultBudget('tablet'), 1_500_000);
  assert.equal(defaultBudget('desktop'), 4_000_000);
  assert.equal(defaultBudget(undefined), 4_000_000);
  assert.throws(
    () => partTable({ charts: 2, first_level: 3, head_url: '', part_url: '', parts: [{ level: 3, chart: 0, bytes: 1, inserted: 1, error: 0 }] }),
    /no part for chart 1/,
  );
});

test('a chart hidden behind another wants no part and is reset first', () => {
  // Chart 0 at z = 0 is a wall across the view; chart 1 at z = −3 lies behind it.
  const { table, charts } = setup([[0.1, 0.05], [0.1, 0.05]]);
  const cam = camera([0, 0, 0], 5);
  // prettier-ignore
  const wall = { positions: new Float32Array([-50, -50, 0, 50, -50, 0, 50, 50, 0, -50, 50, 0]), indices: new Uint32Array([0, 1, 2, 0, 2, 3]) };
  const map = depthMap([{ ...wall, tolerance: occluderTolerance(table, 0, 0) }], cam.clip, 1);
  const hidden = (/** @type {number} */ k) => occluded(map, occlusionSphere(table, k, charts[k].sphere));
  const limits = { firstLevel: 5, capLevel: 99 };
  assert.deepEqual(wantedParts(charts, table, cam, limits).map((w) => w.chart), [0, 1]);
  assert.deepEqual(wantedParts(charts, table, cam, { ...limits, hidden }).map((w) => w.chart), [0], 'the chart behind wants nothing');
  charts[1].depth = 2;
  const assessed = assess(charts, table, cam, hidden);
  assert.deepEqual(assessed.map((a) => a.visible), [true, false]);
  assert.deepEqual(evictionOrder(charts, assessed, 0), [1], 'reset first, as one out of view');
});
