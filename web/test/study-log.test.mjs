// @ts-check
// The study's view log (src/study/log.js): batches of at most 200 events and
// 60 kB of JSON, in order, a failed batch kept for the next flush; moves of
// one kind coalesce into one interaction and camera samples at most every
// 200 ms; state events carry the camera; times are relative to the session's start.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { MAX_BYTES, MAX_EVENTS, ViewLog, batches } from '../src/study/log.js';
import { OrbitCamera } from '../src/camera.js';

test('batches hold at most 200 events and 60 kB each, in order', () => {
  const events = Array.from({ length: 1001 }, (_, i) => ({ at_ms: i, step: 1, state: /** @type {const} */ ('pre'), kind: /** @type {const} */ ('state') }));
  const parts = batches(events);
  assert.deepEqual(parts.map((p) => p.length), [200, 200, 200, 200, 200, 1]);
  assert.deepEqual(parts.flat(), events);
  const big = events.map((e) => ({ ...e, camera: { eye: [1e6 / 3, 2e6 / 3, 1 / 3], target: [1 / 7, 2 / 7, 3 / 7], up: [0, 1, 0], fov: 40 }, zoom: 1 / 3 }));
  for (const part of batches(big)) {
    assert.ok(part.length <= MAX_EVENTS);
    assert.ok(JSON.stringify({ events: part }).length <= MAX_BYTES + 20);
  }
});

test('the log coalesces moves, samples the camera and keeps a failed batch', async () => {
  let now = 5000;
  /** @type {any[][]} */
  const sent = [];
  let fail = true;
  const camera = new OrbitCamera({ min: [-1, -1, -1], max: [1, 1, 1] });
  const log = new ViewLog({
    send: async (events) => {
      if (fail) throw new Error('offline');
      sent.push(events);
    },
    now: () => now,
    origin: 4000,
    camera: () => camera,
  });
  log.enter(2, 'pre');
  for (let i = 0; i < 10; i++) {
    now += 50;
    camera.rotate(5, 0, 100);
    log.interaction('orbit');
  }
  now += 1000;
  camera.zoom(0.5);
  log.interaction('zoom');
  await log.flush();
  assert.equal(sent.length, 0, 'the failed batch is kept');
  fail = false;
  await log.flush();
  const events = sent.flat();
  assert.deepEqual(events.map((e) => e.kind), ['state', 'interaction', 'camera', 'camera', 'interaction']);
  assert.equal(events[0].at_ms, 1000, 'ms since the session start');
  assert.equal(events[0].step, 2);
  assert.equal(events[0].state, 'pre');
  assert.equal(events[0].camera.fov, 40);
  assert.equal(events[0].zoom, 1);
  assert.equal(events[1].interaction, 'orbit');
  assert.equal(events.at(-1).interaction, 'zoom');
  assert.equal(events.at(-1).zoom, 2, 'half the distance is a zoom of 2');
  await log.flush();
  assert.equal(sent.length, 1, 'nothing left to send');
});
