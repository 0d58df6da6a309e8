import assert from 'node:assert/strict';
import { test } from 'node:test';
import { MAX_REST_MS, MotionPolicy, REST_MS, SLOW_FRAME_MS, STAND_IN_TRIANGLES, motionMode } from '../src/motion.js';

/**
 * The levels a stand-in is chosen from as they leave the screen one after
 * another (triangles), for levels heading for `capacity` vertices.
 * @param {MotionPolicy} policy @param {number[]} levels @param {number} capacity
 */
function keptOf(policy, levels, capacity) {
  /** @type {number | null} */
  let kept = null;
  for (const triangles of levels) if (policy.keeps(triangles, kept, capacity)) kept = triangles;
  return kept;
}

test('the stand-in is the finest level left behind within a quarter of the target and the budget', () => {
  const policy = new MotionPolicy();
  // A scan's levels grow about 1.6× a batch: 2 M vertices at the end.
  const levels = [500, 800, 1_300, 2_100, 3_400, 5_400, 8_700, 14_000, 22_000, 36_000, 57_000, 92_000, 147_000, 235_000, 376_000, 600_000, 962_000, 1_540_000, 2_460_000, 3_940_000];
  assert.equal(keptOf(policy, levels, 2_000_000), 235_000);
  assert.ok(235_000 <= STAND_IN_TRIANGLES);
  // A small scan (30 k vertices): at most a quarter of its ~60 k triangles.
  assert.equal(keptOf(policy, [500, 1_000, 2_000, 4_000, 8_000, 14_000, 16_000, 30_000], 30_000), 14_000);
  // A coarser level arriving again (a retry from the base) does not replace a finer stand-in.
  assert.equal(policy.keeps(800, 235_000, 2_000_000), false);
  // `full` keeps nothing.
  assert.equal(keptOf(new MotionPolicy('full'), levels, 2_000_000), null);
});

test('auto draws the stand-in only while moving, after a slow frame of a level no heavier', () => {
  const policy = new MotionPolicy('auto');
  const current = 4_000_000;
  const standIn = 235_000;
  policy.moved(1_000);
  // Not timed yet: the level is drawn (and timed) once.
  assert.equal(policy.drawsStandIn(1_010, current, standIn), false);
  policy.time(current, 16.7);
  assert.equal(policy.drawsStandIn(1_020, current, standIn), false, 'a fast frame keeps the level');
  policy.time(current, SLOW_FRAME_MS + 1);
  assert.equal(policy.drawsStandIn(1_020, current, standIn), true, 'a slow frame calls for the stand-in');
  // Motion over: the level again.
  assert.equal(policy.drawsStandIn(1_000 + REST_MS, current, standIn), false);
  policy.moved(2_000);
  assert.equal(policy.drawsStandIn(2_001, current, standIn), true);
  // A slow frame of a heavier level says nothing of a lighter one (a retry's levels).
  assert.equal(policy.drawsStandIn(2_001, 3_000_000, standIn), false);
  // A slow lighter level makes a heavier one slow too.
  assert.equal(policy.drawsStandIn(2_001, 5_000_000, standIn), true);
  // No stand-in, or one not at most half as heavy: the level.
  assert.equal(policy.drawsStandIn(2_001, current, null), false);
  assert.equal(policy.drawsStandIn(2_001, 400_000, 235_000), false);
});

test('coarse and full ignore the timing', () => {
  const coarse = new MotionPolicy('coarse');
  coarse.moved(0);
  assert.equal(coarse.drawsStandIn(1, 60_000, 14_000), true);
  assert.equal(coarse.drawsStandIn(REST_MS, 60_000, 14_000), false, 'at rest, the level');
  const full = new MotionPolicy('full');
  full.moved(0);
  full.time(4_000_000, 1_000);
  assert.equal(full.drawsStandIn(1, 4_000_000, 235_000), false);
});

test('motion modes parse from attributes and URLs', () => {
  assert.equal(motionMode('auto'), 'auto');
  assert.equal(motionMode('coarse'), 'coarse');
  assert.equal(motionMode('full'), 'full');
  assert.equal(motionMode('fast'), null);
  assert.equal(motionMode(null), null);
});

test('a held view counts as moving until the release, then rests', () => {
  const policy = new MotionPolicy('coarse');
  policy.moved(0);
  policy.grab(true, 10);
  // The drag pauses: long past the rest, the pointer is still down.
  assert.equal(policy.drawsStandIn(10 * REST_MS, 4_000_000, 235_000), true);
  policy.grab(false, 5_000);
  assert.equal(policy.drawsStandIn(5_000 + REST_MS - 1, 4_000_000, 235_000), true, 'the rest counts from the release');
  assert.equal(policy.drawsStandIn(5_000 + REST_MS, 4_000_000, 235_000), false);
  // A release without a grab (a lost pointer) moves nothing.
  policy.grab(false, 9_000);
  assert.equal(policy.drawsStandIn(9_001, 4_000_000, 235_000), false);
});

test('where the level takes seconds a frame, the view must stay still longer before one starts', () => {
  const policy = new MotionPolicy('auto');
  policy.time(4_000_000, 30);
  assert.equal(policy.restMs(), REST_MS, 'a fast level: the usual rest');
  policy.time(4_000_000, 1_200);
  assert.equal(policy.restMs(), 600, 'half a frame');
  policy.moved(0);
  assert.equal(policy.drawsStandIn(599, 4_000_000, 235_000), true, 'a pause between wheel turns keeps the stand-in');
  assert.equal(policy.drawsStandIn(600, 4_000_000, 235_000), false);
  policy.time(4_000_000, 3_100);
  assert.equal(policy.restMs(), MAX_REST_MS);
});
