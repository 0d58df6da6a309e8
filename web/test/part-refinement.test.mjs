// @ts-check
// Node tests of view-dependent refinement in the decode worker
// (part-refinement.js) on the committed charted fixture, with parts served
// from memory: the unions it posts, laid into a vertex store as the
// renderer does, are every chart at its depth with no vertex lost; cut
// vertices have one normal whatever chart draws them; the chart in view
// reaches the final depth bit for bit the whole decoder's; the budget holds.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { partedLayout, splitStream } from '../src/codec.js';
import { PartRefinement } from '../src/part-refinement.js';
import { fixture } from './support/fixtures.mjs';
import { cameraOn, loadCodec as codec, refinementSink } from './support/refinement.mjs';

/** @typedef {import('../src/reconstruction.js').LevelMessage} LevelMessage */
/** @typedef {import('../src/part-refinement.js').PartsState} PartsState */

/**
 * The fixture's global batches decoded, its parted batches as a part index
 * (errors halving with each level) and the parts' bytes.
 * @param {import('../src/codec.js').VitrineCodec} c
 */
function opened(c) {
  const { base, batches } = splitStream(fixture('charted-torus').stream);
  const decoder = c.decoder(base);
  /** @type {{ batch: Uint8Array, layout: import('../src/codec.js').PartedLayout }[]} */
  const parted = [];
  for (const batch of batches) {
    const layout = partedLayout(c, batch);
    if (layout) parted.push({ batch, layout });
    else decoder.apply(batch);
  }
  const vertices = decoder.view().vertices;
  const firstLevel = batches.length - parted.length + 1;
  const view = decoder.intoView(parted[0].batch.subarray(...parted[0].layout.head));
  const charts = view.chartCount();
  /** @type {import('../src/part-selection.js').PartIndex} */
  const index = { charts, first_level: firstLevel, head_url: '', part_url: '', parts: [] };
  /** @type {Map<string, Uint8Array>} */
  const bytes = new Map();
  for (const [d, { batch, layout }] of parted.entries()) {
    for (let k = 0; k < charts; k++) {
      const part = batch.subarray(...layout.parts[k]);
      bytes.set(`${firstLevel + d} ${k}`, part);
      index.parts.push({ level: firstLevel + d, chart: k, bytes: part.length, inserted: 0, error: part.length ? 0.05 / 2 ** d : 0 });
    }
  }
  return { view, index, bytes, vertices, base, batches };
}

/**
 * Runs a refinement until it settles; returns its messages and a vertex store
 * as the renderer's (vertex-store.js: positions from `firstVertex` on).
 * @param {{ budget: number }} options
 */
async function refine({ budget }) {
  const c = await codec();
  const { view, index, bytes, vertices, base, batches } = opened(c);
  /** @type {ReturnType<typeof refinementSink<PartsState>>} */
  const sink = refinementSink();
  const fetched = { count: 0 };
  const refinement = new PartRefinement({
    view,
    index,
    budget,
    capLevel: index.first_level + 100,
    sentVertices: vertices,
    baseBounds: { min: [0, 0, 0], max: [0, 0, 0] },
    bytesFetched: 0,
    wireframe: false,
    fetchPart: async (part) => {
      fetched.count++;
      await new Promise((resolve) => setTimeout(resolve, 1));
      return { bytes: /** @type {Uint8Array} */ (bytes.get(`${part.level} ${part.chart}`)) };
    },
    post: sink.post,
    tell: sink.tell,
  });
  const target = 0;
  const state = await sink.settle(() => refinement.setCamera(cameraOn(view.chart(target).positions)));
  const { store, last } = sink.posted();
  const errors = sink.errors;
  return { c, refinement, view, store, last: /** @type {LevelMessage | null} */ (last), state: /** @type {PartsState | null} */ (state), errors, base, batches, target, fetched };
}

test('the posted union is every chart at its depth, with one normal per cut vertex', async () => {
  const { c, refinement, view, store, last: posted, state, errors, base, batches, target } = await refine({ budget: 1e9 });
  assert.deepEqual(errors, []);
  assert.ok(state?.settled && posted);
  /** @type {LevelMessage} */
  const last = posted;
  assert.equal(state.depths[target], state.finalDepth, 'the chart under the camera reaches the final depth');
  assert.equal(last.standIn, false);
  // Every chart's triangles, read through the store, are its own triangles.
  let t = 0;
  /** @type {Map<string, string>} */
  const normalAt = new Map();
  /** Positions drawn by several charts (the cut's). @type {Map<string, Set<number>>} */
  const holders = new Map();
  const normals = /** @type {Int16Array} */ (last.normals);
  for (let k = 0; k < state.charts; k++) {
    const chart = view.chart(k);
    for (let i = 0; i < chart.indices.length; i++, t++) {
      /** @type {number} */
      const s = last.indices[t];
      const own = chart.indices[i];
      for (let a = 0; a < 3; a++) assert.equal(store[3 * s + a], chart.positions[3 * own + a]);
      /** @type {string} */
      const key = `${store[3 * s]} ${store[3 * s + 1]} ${store[3 * s + 2]}`;
      /** @type {string} */
      const normal = `${normals[3 * s]} ${normals[3 * s + 1]} ${normals[3 * s + 2]}`;
      holders.set(key, (holders.get(key) ?? new Set()).add(k));
      const seen = normalAt.get(key);
      if (seen) assert.equal(normal, seen, `one normal at ${key}`);
      else normalAt.set(key, normal);
    }
  }
  assert.equal(t, last.indices.length);
  // The compact union for measurements is welded: each cut position has one id.
  const union = refinement.current();
  /** @type {Map<string, Set<number>>} */
  const ids = new Map();
  for (const id of union.indices) {
    const key = `${union.positions[3 * id]} ${union.positions[3 * id + 1]} ${union.positions[3 * id + 2]}`;
    ids.set(key, (ids.get(key) ?? new Set()).add(id));
  }
  assert.ok([...ids.values()].every((set) => set.size === 1), 'one id per position');
  assert.equal(union.indices.length, last.indices.length);
  assert.ok([...holders.values()].filter((h) => h.size > 1).length > 10, 'cut vertices are drawn by several charts');
  // Bit for bit the whole decoder's chart at the last level.
  const whole = c.decoder(base);
  for (const batch of batches) whole.apply(batch);
  assert.deepEqual(Buffer.from(view.chart(target).positions.buffer), Buffer.from(whole.chartView(target).positions.slice().buffer));
  whole.free();
  refinement.stop();
});

test('a budget the charts at the cut nearly fill: nothing past it, and no error', async () => {
  const atCut = (await refine({ budget: 0 })).state;
  assert.ok(atCut);
  const budget = atCut.resident + 40;
  const { refinement, state, errors, fetched } = await refine({ budget });
  assert.deepEqual(errors, []);
  // Settled for good: a part the view refused is not fetched again for the same camera.
  const count = fetched.count;
  await new Promise((resolve) => setTimeout(resolve, 200));
  assert.equal(fetched.count, count, 'no part fetched after settling');
  assert.ok(state && state.resident <= budget, `${state?.resident} resident, budget ${budget}`);
  assert.ok(state.depths.some((d) => d > 0), 'the budget left room for some parts');
  assert.ok(state.depths.every((d) => d < state.finalDepth), 'and not for every part');
  refinement.stop();
});
