// @ts-check
// Node tests of view-dependent refinement's choices for a nested stream
// (nested-selection.js): the part index as a tree (phases, batches,
// children, the errors left below each chart, the batches a view is
// declared from), the next step of a chart (part, then split), which shown
// charts step for a camera, and which expanded charts fold back first;
// a chart hidden behind another (occlusion.js) wants nothing and folds first.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { OrbitCamera, multiply } from '../src/camera.js';
import { errorLeft, foldOrder, nestedTable, nextStep, occluderTolerance, occlusionSphere, wantedSteps } from '../src/nested-selection.js';
import { depthMap, occluded } from '../src/occlusion.js';

/**
 * @param {[number, number, number]} target
 * @param {number} distance
 * @returns {import('../src/part-selection.js').PartCamera}
 */
function camera(target, distance) {
  const c = new OrbitCamera({ min: [-20, -20, -20], max: [20, 20, 20] }, 1);
  c.state = { target, distance, yaw: 0, pitch: 0 };
  return { eye: c.basis().eye, clip: Array.from(multiply(c.projection(1), c.view())), pixelsPerRadian: 600 / c.fovY };
}

/**
 * 2 top charts (levels 3–4), each split in 2 (levels 5–6): errors halve
 * with each level; chart 1 of phase 0 sits level 4 out.
 * @returns {import('../src/nested-selection.js').NestedPartIndex}
 */
function index() {
  const parts = [];
  for (const level of [3, 4]) for (const chart of [0, 1]) parts.push({ level, chart, phase: 0, bytes: level === 4 && chart === 1 ? 0 : 50, inserted: 10, error: level === 4 && chart === 1 ? 0 : 0.4 / 2 ** (level - 3) });
  for (const level of [5, 6]) for (const chart of [0, 1, 2, 3]) parts.push({ level, chart, phase: 1, parent: chart >> 1, bytes: 40, inserted: 10, error: 0.1 / 2 ** (level - 5) });
  const splits = [0, 1].map((parent) => ({ level: 5, parent, first_child: 2 * parent, children: 2, bytes: 9 }));
  return { charts: 2, phases: 2, first_level: 3, head_url: '', part_url: '', split_url: '', parts, splits };
}

test('the index as a tree', () => {
  const t = nestedTable(index());
  assert.deepEqual(t.phaseStart, [3, 5]);
  assert.deepEqual(t.batches, [2, 2]);
  assert.deepEqual(t.charts, [2, 4]);
  assert.deepEqual(t.children[0], [[0, 2], [2, 4]]);
  assert.deepEqual(
    t.batchesInOrder.map((b) => [b.level, b.phase, b.charts, b.children]),
    [[3, 0, 2, []], [4, 0, 2, []], [5, 1, 4, [2, 2]], [6, 1, 4, []]],
  );
  assert.deepEqual(t.own[0][0], [0.4, 0.2, 0]);
  assert.deepEqual(t.below[0], [0.1, 0.1]);
  assert.deepEqual(t.below[1], [0, 0, 0, 0]);
  const node = { phase: 0, chart: 1, depth: 2, sphere: { centre: /** @type {[number, number, number]} */ ([0, 0, 0]), radius: 1 }, expanded: false, vertices: 100 };
  assert.equal(errorLeft(t, node), 0.1, 'all its own parts applied: what its children would add');
  assert.deepEqual(nextStep(t, node), { kind: 'split', split: t.splits[0][1], level: 5 });
  assert.equal(nextStep(t, { ...node, depth: 1 })?.kind, 'part');
  assert.equal(nextStep(t, { ...node, phase: 1, chart: 3 }), null, 'a leaf at its final depth');
});

test('charts refine by their parts\' bulk error; their largest bounds occlusion and still refines a feature', () => {
  // Noise: each part's largest error twice its bulk. A feature: phase 1's
  // chart 3 has one vertex far out at level 6, its bulk tiny.
  const noisy = index();
  for (const p of noisy.parts) {
    p.bulk_error = p.error / 2;
    if (p.phase === 1 && p.chart === 3 && p.level === 6) [p.error, p.bulk_error] = [0.8, 0.01];
  }
  const t = nestedTable(noisy);
  assert.deepEqual(t.own[0][0], [0.2, 0.1, 0], 'the bulk, where the largest is within 4 times it');
  assert.deepEqual(t.ownBound[0][0], [0.4, 0.2, 0]);
  assert.deepEqual(t.below[0], [0.05, 0.2], 'the feature refines by a quarter of its largest');
  assert.deepEqual(t.belowBound[0], [0.1, 0.8]);
  const node = { phase: 0, chart: 0, depth: 2, sphere: { centre: /** @type {[number, number, number]} */ ([0, 0, 0]), radius: 1 }, expanded: false, vertices: 100 };
  assert.equal(errorLeft(t, node), 0.05);
  assert.equal(occluderTolerance(t, node), 0.2, 'twice the largest left, not the bulk');
  // An index measured before bulk errors refines by the largest, as then.
  assert.deepEqual(nestedTable(index()).own, nestedTable(index()).ownBound);
});

test('the shown charts in view step, nearest and largest error first, not past the cap', () => {
  const t = nestedTable(index());
  /** @param {number} chart @param {number} z @param {number} depth */
  const node = (chart, z, depth) => ({ phase: 0, chart, depth, sphere: { centre: /** @type {[number, number, number]} */ ([0, 0, z]), radius: 1 }, expanded: false, vertices: 100 });
  const near = node(0, 0, 2);
  const far = node(1, -10, 0);
  const cam = camera([0, 0, 0], 3);
  const wanted = wantedSteps(t, [far, near], cam, { capLevel: 99 });
  // Near: 0.1 left below it at 2 from the eye; far: 0.4 at 12.
  assert.deepEqual(wanted.map((w) => [w.node.chart, w.kind]), [[0, 'split'], [1, 'part']]);
  assert.deepEqual(
    wantedSteps(t, [far, near], cam, { capLevel: 4 }).map((w) => w.kind),
    ['part'],
    'the split entry lies in level 5, past the cap',
  );
  assert.deepEqual(wantedSteps(t, [{ ...near, busy: true }], cam, { capLevel: 99 }), []);
  assert.deepEqual(wantedSteps(t, [near], camera([0, 0, 0], 3000), { capLevel: 99 }), [], 'far away: below a pixel');
});

test('what folds back first: out of view, then the smallest error folded; never the path of the chart that needs room', () => {
  const t = nestedTable(index());
  /** @param {number} chart @param {number} z */
  const node = (chart, z) => ({ phase: 0, chart, depth: 2, sphere: { centre: /** @type {[number, number, number]} */ ([0, 0, z]), radius: 1 }, expanded: true, vertices: 100 });
  const ahead = node(0, 0);
  const behind = node(1, 20);
  const cam = camera([0, 0, 0], 3);
  const child = { phase: 1, chart: 0, depth: 0, sphere: ahead.sphere, expanded: false, vertices: 60 };
  const wanted = wantedSteps(t, [child], cam, { capLevel: 99 })[0];
  assert.ok(wanted);
  assert.deepEqual(foldOrder(t, [ahead, behind], wanted, [child, ahead], cam), [behind]);
  const order = foldOrder(t, [ahead, behind], { ...wanted, pixels: 1e9 }, [child], cam);
  assert.deepEqual(order, [behind, ahead], 'out of view first');
});

test('a chart hidden behind another wants nothing and folds first; seen again, it steps', () => {
  const t = nestedTable(index());
  // Chart 0 is a wall at z = 0 across the view (its own vertices), chart 1 a sphere of radius 1 at z = −10 behind it.
  // prettier-ignore
  const positions = new Float32Array([-50, -50, 0, 50, -50, 0, 50, 50, 0, -50, 50, 0]);
  const wall = { phase: 0, chart: 0, depth: 2, sphere: { centre: /** @type {[number, number, number]} */ ([0, 0, 0]), radius: 71 }, expanded: false, vertices: 4, positions, indices: new Uint32Array([0, 1, 2, 0, 2, 3]) };
  const behind = { phase: 0, chart: 1, depth: 0, sphere: { centre: /** @type {[number, number, number]} */ ([0, 0, -10]), radius: 1 }, expanded: false, vertices: 100 };
  const cam = camera([0, 0, 0], 3);
  /** @param {typeof cam} c */
  const hiddenFor = (c) => {
    const map = depthMap([{ positions: wall.positions, indices: wall.indices, tolerance: occluderTolerance(t, wall) }], c.clip, 1);
    return (/** @type {import('../src/nested-selection.js').NodeState} */ node) => occluded(map, occlusionSphere(t, node));
  };
  assert.deepEqual(wantedSteps(t, [wall, behind], cam, { capLevel: 99 }).map((w) => w.node.chart), [0, 1], 'without the map: both');
  const hidden = hiddenFor(cam);
  assert.ok(!hidden(wall), 'the wall does not hide itself');
  assert.deepEqual(wantedSteps(t, [wall, behind], cam, { capLevel: 99, hidden }).map((w) => w.node.chart), [0], 'the chart behind the wall wants nothing');
  // Expanded, the chart behind folds first, as one out of view would.
  const child = { phase: 1, chart: 0, depth: 0, sphere: wall.sphere, expanded: false, vertices: 60 };
  const wanted = { ...wantedSteps(t, [child], cam, { capLevel: 99 })[0], pixels: 0 };
  const expandedBehind = { ...behind, depth: 2, expanded: true };
  assert.deepEqual(foldOrder(t, [expandedBehind], wanted, [child], cam), [], 'in view, its error folded too large to give way');
  assert.deepEqual(foldOrder(t, [expandedBehind], wanted, [child], cam, hidden), [expandedBehind], 'hidden: folds');
  // The camera goes behind the wall: the chart is seen again and steps.
  const back = camera([0, 0, -10], 3);
  assert.deepEqual(wantedSteps(t, [behind], back, { capLevel: 99, hidden: hiddenFor(back) }).map((w) => w.node.chart), [1]);
});
