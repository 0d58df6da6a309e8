// @ts-check
// Node tests of the part-by-part decoder (issue 41) in WebAssembly, on the
// committed charted fixture: each chart refined by its own parts is, bit for
// bit, the chart the whole-batch decoder makes at the same level; charts
// refine to different depths, a reset frees a chart, the vertex budget
// refuses a part and changes nothing, and a broken part touches only its
// chart.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { existsSync, readFileSync } from 'node:fs';
import { VitrineCodec, partedLayout, splitStream } from '../src/codec.js';
import { fixture, wasmPath } from './support/fixtures.mjs';

async function codec() {
  assert.ok(existsSync(wasmPath), `build the wasm first: ${wasmPath}`);
  return VitrineCodec.instantiate(readFileSync(wasmPath));
}

/**
 * The charted fixture's global batches applied, its parted batches laid out.
 * @param {VitrineCodec} c
 */
function opened(c) {
  const { base, batches } = splitStream(fixture('charted-torus').stream);
  const decoder = c.decoder(base);
  /** @type {{ batch: Uint8Array, layout: import('../src/codec.js').PartedLayout }[]} */
  const parted = [];
  for (const batch of batches) {
    const layout = partedLayout(c, batch);
    if (layout) parted.push({ batch, layout });
    else {
      assert.equal(parted.length, 0, 'global batches come before the parted ones');
      decoder.apply(batch);
    }
  }
  assert.ok(parted.length >= 2, 'the fixture has several parted batches');
  const [first] = parted;
  const view = decoder.intoView(first.batch.subarray(...first.layout.head));
  /** @param {number} chart @param {number} depth the part of the depth-th parted batch */
  const part = (chart, depth) => parted[depth].batch.subarray(...parted[depth].layout.parts[chart]);
  return { view, parted, batches, base, part };
}

/** @param {ReturnType<import('../src/codec.js').PartView['chart']>} a @param {ReturnType<import('../src/codec.js').PartView['chart']>} b */
function same(a, b) {
  assert.deepEqual(Buffer.from(a.positions.buffer), Buffer.from(b.positions.buffer), 'positions');
  assert.deepEqual(Buffer.from(a.indices.buffer), Buffer.from(b.indices.buffer), 'triangles');
  assert.deepEqual(a.colours && Buffer.from(a.colours), b.colours && Buffer.from(b.colours), 'colours');
}

test('a chart refined by its parts alone is the whole decoder chart at each depth', async () => {
  const c = await codec();
  const { view, parted, batches, base, part } = opened(c);
  const charts = view.chartCount();
  assert.equal(view.finalDepth(), parted.length);
  assert.equal(parted[0].layout.parts.length, charts);
  const whole = c.decoder(base);
  const globals = batches.length - parted.length;
  for (let k = 0; k < globals; k++) whole.apply(batches[k]);
  for (let depth = 0; depth < parted.length; depth++) {
    whole.apply(parted[depth].batch);
    view.applyPart(0, part(0, depth));
    assert.equal(view.depth(0), depth + 1);
    const w = whole.chartView(0);
    const mine = view.chart(0);
    assert.deepEqual(Buffer.from(mine.positions.buffer), Buffer.from(w.positions.slice().buffer), `chart 0 positions at depth ${depth + 1}`);
    assert.deepEqual(mine.colours && Buffer.from(mine.colours), w.colours && Buffer.from(w.colours.slice()), 'colours');
  }
  for (let k = 1; k < charts; k++) assert.equal(view.depth(k), 0, `chart ${k} stays at the cut`);
  whole.free();
  view.free();
});

test('resets free a chart, the budget refuses a part and changes nothing', async () => {
  const c = await codec();
  const { view, parted, part } = opened(c);
  const atCut = view.chart(1);
  const resident = view.residentVertices();
  view.applyPart(1, part(1, 0));
  assert.ok(view.residentVertices() > resident, 'a part adds vertices');
  view.reset(1);
  assert.equal(view.depth(1), 0);
  assert.equal(view.residentVertices(), resident);
  same(view.chart(1), atCut);
  // No room for one more vertex: the part is refused, nothing moves.
  view.setVertexBudget(resident);
  assert.throws(() => view.applyPart(1, part(1, 0)), /budget/);
  assert.equal(view.depth(1), 0);
  same(view.chart(1), atCut);
  view.setVertexBudget(0xffffffff);
  for (let depth = 0; depth < parted.length; depth++) view.applyPart(1, part(1, depth));
  assert.equal(view.depth(1), view.finalDepth());
  assert.throws(() => view.applyPart(1, part(1, 0)), /final level/);
  view.free();
});

test('a broken part leaves the other charts untouched', async () => {
  const c = await codec();
  const { view, part } = opened(c);
  view.applyPart(0, part(0, 0));
  const other = view.chart(0);
  const good = part(2, 0);
  for (const broken of [good.subarray(0, Math.max(1, good.length >> 1)), good.map((b, i) => (i === 3 ? b ^ 0xff : b))]) {
    try {
      view.applyPart(2, broken);
    } catch {
      // refused: the chart is as it was or back at the cut
    }
    view.reset(2);
    assert.equal(view.depth(0), 1);
    same(view.chart(0), other);
  }
  assert.throws(() => view.applyPart(99, good), /no chart 99/);
  assert.throws(() => partedLayout(c, new Uint8Array([0x50, 1, 2])));
  view.free();
});
