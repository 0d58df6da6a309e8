// @ts-check
// The tour player's pure parts: easing, the path between two orbits, the
// language a step is shown in.
import assert from 'node:assert/strict';
import test from 'node:test';
import { between, ease, inLanguage } from '../src/tour.js';

test('easing starts and ends at rest', () => {
  assert.equal(ease(0), 0);
  assert.equal(ease(1), 1);
  assert.equal(ease(0.5), 0.5);
  assert.ok(ease(0.1) < 0.1 && ease(0.9) > 0.9);
});

test('the path between two orbits: ends exact, yaw the short way, zoom on a log scale', () => {
  const a = { target: /** @type {[number, number, number]} */ ([0, 0, 0]), distance: 1, yaw: 3, pitch: 0 };
  const b = { target: /** @type {[number, number, number]} */ ([2, 4, 6]), distance: 4, yaw: -3, pitch: 0.5 };
  assert.deepEqual(between(a, b, 0), a);
  assert.deepEqual(between(a, b, 1), b);
  const half = between(a, b, 0.5);
  assert.deepEqual(half.target, [1, 2, 3]);
  assert.ok(Math.abs(half.distance - 2) < 1e-12, 'geometric mean');
  // From 3 to -3 radians the short way passes through π, not 0.
  assert.ok(Math.abs(Math.cos(half.yaw) + 1) < 1e-3, String(half.yaw));
});

test('a step in the page language, else its base, else English, else the first', () => {
  const map = { en: 'Front', pt: 'Frente', 'pt-BR': 'Frente (BR)' };
  assert.equal(inLanguage(map, 'pt-BR'), 'Frente (BR)');
  assert.equal(inLanguage(map, 'pt-PT'), 'Frente');
  assert.equal(inLanguage(map, 'de'), 'Front');
  assert.equal(inLanguage({ fr: 'Face' }, 'de'), 'Face');
  assert.equal(inLanguage(undefined, 'de'), '');
});
