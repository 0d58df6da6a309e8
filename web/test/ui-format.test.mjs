// @ts-check
import assert from 'node:assert/strict';
import test from 'node:test';
import { formatBytes, formatCount } from '../src/ui.js';

test('counts are grouped as toLocaleString("en") groups them', () => {
  for (const n of [0, 7, 42, 999, 1000, 8405, 12345, 100000, 998560, 1000000, 2147483647, -1234]) {
    assert.equal(formatCount(n), n.toLocaleString('en'), String(n));
  }
});

test('bytes in bytes, kB, MB (Intl units, English by default)', () => {
  assert.equal(formatBytes(512), '512 bytes');
  assert.equal(formatBytes(89588), '87.5 kB');
  assert.equal(formatBytes(676204 * 4), '2.58 MB');
});
