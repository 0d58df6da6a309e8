// @ts-check
// Node tests of measure.js (distance with the level's error, its text),
// light.js (presets, the disc) and annotations.js's parser.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { diagonal, formatReading, levelHausdorff, measurement } from '../src/measure.js';
import { RAKING_ELEVATION_DEG, discLight, discPosition, rakingLight } from '../src/light.js';
import { parseAnnotations } from '../src/annotations.js';

test('a measurement carries twice the level error (both ends), in the model unit', () => {
  const m = measurement([0, 0, 0], [3, 4, 0], { hausdorff: 0.01, diagonal: 20 });
  assert.equal(m.value, 5);
  assert.ok(Math.abs(/** @type {number} */ (m.error) - 0.4) < 1e-12);
  assert.equal(formatReading(12.4, 0.3, 'mm'), '12.4 mm ± 0.3 mm at this level');
  assert.equal(formatReading(5, 0.4, 'cm'), '5.0 cm ± 0.4 cm at this level');
  assert.equal(formatReading(1.23456, 0.0012, null), '1.235 units ± 0.001 units at this level');
  assert.match(formatReading(7, null, 'in'), /^7\.000 in \(the error of this level was not measured\)$/);
  assert.equal(measurement([0, 0, 0], [1, 0, 0], { hausdorff: null, diagonal: 1 }).error, null);
  assert.equal(diagonal({ min: [0, 0, 0], max: [2, 3, 6] }), 7);
});

test('the level error comes from the level entry, else the quality curve', () => {
  assert.equal(levelHausdorff({ levels: [{ hausdorff: 0.02 }] }, 0), 0.02);
  assert.equal(levelHausdorff({ levels: [{ hausdorff: null }], quality: [{ level: 0, hausdorff: 0.03 }] }, 0), 0.03);
  assert.equal(levelHausdorff({ levels: [{}] }, 0), null);
});

test('raking light grazes from the named side; the disc maps to the front hemisphere', () => {
  const left = rakingLight('left');
  assert.ok(left.key[0] < -0.9 && Math.abs(left.key[1]) < 1e-12);
  assert.ok(Math.abs(Math.asin(left.key[2]) - (RAKING_ELEVATION_DEG * Math.PI) / 180) < 1e-12);
  assert.ok(rakingLight('top').key[1] > 0.9 && rakingLight('bottom').key[1] < -0.9);
  assert.ok(left.fill < 1);
  const centre = discLight(0, 0);
  assert.deepEqual(centre.key, [0, 0, 1]);
  const outside = discLight(3, 4);
  assert.ok(Math.abs(Math.hypot(...outside.key) - 1) < 1e-12 && outside.key[2] > 0, 'outside the disc: its rim, still in front');
  const [u, v] = discPosition(discLight(0.3, -0.4));
  assert.ok(Math.abs(u - 0.3) < 1e-12 && Math.abs(v + 0.4) < 1e-12);
});

test('annotations: entries without a valid point are dropped, a malformed view ignored', () => {
  const list = parseAnnotations([
    { id: 1, title: 'Seal', text: 'a *seal*', html: '<p>a <em>seal</em></p>', position: [1, 2, 3], normal: [0, 0, 1], view: { target: [0, 0, 0], distance: 2, yaw: 0.1, pitch: 0.2 } },
    { id: 2, title: 'No point', text: '', position: [1, 2], normal: [0, 0, 1] },
    { id: 3, title: 'Bad view', text: 'plain', position: [0, 0, 0], normal: [1, 0, 0], view: { distance: -1 } },
  ]);
  assert.deepEqual(list.map((a) => a.id), [1, 3]);
  assert.deepEqual(list[0].view, { target: [0, 0, 0], distance: 2, yaw: 0.1, pitch: 0.2 });
  assert.equal(list[1].view, null);
  assert.equal(list[1].html, null);
  assert.deepEqual(parseAnnotations({ not: 'a list' }), []);
});
