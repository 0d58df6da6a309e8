// @ts-check
// Node tests of view-dependent refinement of a nested stream in the decode
// worker (nested-refinement.js) on the committed nested fixture (format 6),
// with the part index made from the stream's own layouts and its pieces
// served from memory: the view declared from the index alone refines the
// chart under the camera to the last phase's final depth, bit for bit the
// whole decoder's; the unions it posts, laid into a vertex store as the
// renderer does, are every chart shown at its depth, closed (the torus has
// no border: every edge of the welded union has two triangles, so charts at
// different phases meet without a crack) with one normal per position; the
// budget holds, folding subtrees back; a chart hidden behind the torus
// (occlusion.js) refines once the camera turns to it.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { NestedView, splitStream } from '../src/codec.js';
import { NestedRefinement } from '../src/nested-refinement.js';
import { nestedTable } from '../src/nested-selection.js';
import { fixture } from './support/fixtures.mjs';
import { cameraOn, loadCodec, refinementSink } from './support/refinement.mjs';

/** @typedef {import('../src/reconstruction.js').LevelMessage} LevelMessage */
/** @typedef {import('../src/nested-refinement.js').NestedState} NestedState */

/**
 * A parted batch's layout as `nested_layout` gives it (codec/wasm/src/nested.rs).
 * @param {import('../src/codec.js').VitrineCodec} c
 * @param {Uint8Array} batch
 */
function layout(c, batch) {
  const e = c.exports;
  c.input(batch);
  const charts = e.nested_layout(batch.length);
  if (charts <= 0) return null;
  const head = new Uint32Array(e.memory.buffer, e.sizes_ptr(), 6).slice();
  const s = head[5];
  const words = new Uint32Array(e.memory.buffer, e.sizes_ptr(), 6 + 3 * s + 2 * charts).slice();
  const splits = Array.from({ length: s }, (_, k) => ({ children: words[6 + 3 * k], range: [words[7 + 3 * k], words[8 + 3 * k]] }));
  const parts = Array.from({ length: charts }, (_, k) => [words[6 + 3 * s + 2 * k], words[7 + 3 * s + 2 * k]]);
  return { level: words[0], phase: words[1], begins: words[2] === 1, head: [words[3], words[4]], splits, parts };
}

/**
 * The fixture as the service would serve it: its global batches decoded,
 * a part index (errors halving with each level of a phase, `inserted`
 * measured by walking the whole tree once) and every piece's bytes.
 * @param {import('../src/codec.js').VitrineCodec} c
 */
function opened(c) {
  const { base, batches } = splitStream(fixture('nested-torus').stream);
  const decoder = c.decoder(base);
  const walker = c.decoder(base);
  /** @type {{ batch: Uint8Array, layout: NonNullable<ReturnType<typeof layout>> }[]} */
  const parted = [];
  c.exports.nested_layouts_clear();
  for (const batch of batches) {
    const l = layout(c, batch);
    if (l) parted.push({ batch, layout: l });
    else {
      decoder.apply(batch);
      walker.apply(batch);
    }
  }
  const vertices = decoder.view().vertices;
  const head = parted[0].batch.slice(...parted[0].layout.head);
  // The walker's view: from the whole batches' layouts (kept by nested_layout).
  c.input(head);
  const whole = new NestedView(c, c.exports.nested_new(walker.handle, head.length));
  /** @type {import('../src/nested-selection.js').NestedPartIndex} */
  const index = { charts: parted[0].layout.parts.length, phases: 0, first_level: parted[0].layout.level, head_url: '', part_url: '', split_url: '', parts: [], splits: [] };
  /** @type {Map<string, Uint8Array>} */
  const bytes = new Map();
  let depth = 0;
  for (const { batch, layout: l } of parted) {
    index.phases = l.phase + 1;
    if (l.begins) depth = 0;
    let first = 0;
    for (const [parent, s] of l.splits.entries()) {
      const entry = batch.slice(...s.range);
      bytes.set(`s ${l.level} ${parent}`, entry);
      whole.split(l.phase - 1, parent, entry);
      index.splits.push({ level: l.level, parent, first_child: first, children: s.children, bytes: entry.length });
      first += s.children;
    }
    for (const [chart, range] of l.parts.entries()) {
      const part = batch.slice(...range);
      bytes.set(`p ${l.level} ${chart}`, part);
      const before = whole.chart(l.phase, chart).positions.length / 3;
      whole.applyPart(l.phase, chart, part);
      const inserted = whole.chart(l.phase, chart).positions.length / 3 - before;
      index.parts.push({ level: l.level, chart, phase: l.phase, bytes: part.length, inserted, error: part.length ? 0.05 / 2 ** (l.phase + depth) : 0 });
    }
    depth++;
  }
  const view = decoder.intoNested(head, nestedTable(index).batchesInOrder);
  return { view, whole, index, bytes, vertices };
}

/**
 * Runs a refinement until it settles; returns its messages and a vertex
 * store as the renderer's (vertex-store.js: positions from `firstVertex` on).
 * @param {{ budget: number }} options
 */
async function refine({ budget }) {
  const { view, whole, index, bytes, vertices } = opened(await loadCodec());
  /** @type {ReturnType<typeof refinementSink<NestedState>>} */
  const sink = refinementSink();
  /** @param {string} key */
  const serve = async (key) => {
    await new Promise((resolve) => setTimeout(resolve, 1));
    return { bytes: /** @type {Uint8Array} */ (bytes.get(key)) };
  };
  const refinement = new NestedRefinement({
    view,
    index,
    budget,
    capLevel: 1000,
    sentVertices: vertices,
    baseBounds: { min: [0, 0, 0], max: [0, 0, 0] },
    bytesFetched: 0,
    wireframe: false,
    fetchPart: (part) => serve(`p ${part.level} ${part.chart}`),
    fetchSplit: (split) => serve(`s ${split.level} ${split.parent}`),
    post: sink.post,
    tell: sink.tell,
  });
  /** @param {import('../src/part-selection.js').PartCamera} camera */
  const settle = (camera) => sink.settle(() => refinement.setCamera(camera));
  // Close to a point of the surface: the first vertex of a top chart.
  const state = await settle(cameraOn(view.chart(0, 0).positions.subarray(0, 3)));
  const posted = () => {
    const { store, last } = sink.posted();
    return { store, last: /** @type {LevelMessage} */ (last) };
  };
  return { refinement, view, whole, state, errors: sink.errors, settle, posted };
}

/**
 * The posted triangles, read through the store: one normal per position.
 * @param {{ store: Float32Array, last: LevelMessage }} posted
 */
function assertOneNormal({ store, last }) {
  /** @type {Map<string, string>} */
  const normalAt = new Map();
  const normals = /** @type {Int16Array} */ (last.normals);
  for (const s of last.indices) {
    const key = `${store[3 * s]} ${store[3 * s + 1]} ${store[3 * s + 2]}`;
    const normal = `${normals[3 * s]} ${normals[3 * s + 1]} ${normals[3 * s + 2]}`;
    const seen = normalAt.get(key);
    if (seen) assert.equal(normal, seen, `one normal at ${key}`);
    else normalAt.set(key, normal);
  }
}

/**
 * The compact union, welded by position, is closed as the torus is: every
 * edge has two triangles, so charts shown at different phases and depths
 * meet without a crack.
 * @param {NestedRefinement} refinement
 * @param {LevelMessage} last
 */
function assertClosed(refinement, last) {
  const union = refinement.current();
  assert.equal(union.indices.length, last.indices.length);
  /** @type {Map<string, number>} */
  const edges = new Map();
  for (let t = 0; t < union.indices.length; t += 3) {
    for (let e = 0; e < 3; e++) {
      const a = union.indices[t + e];
      const b = union.indices[t + ((e + 1) % 3)];
      const key = a < b ? `${a} ${b}` : `${b} ${a}`;
      edges.set(key, (edges.get(key) ?? 0) + 1);
    }
  }
  const open = [...edges.values()].filter((n) => n !== 2).length;
  assert.equal(open, 0, `${open} edges without exactly two triangles`);
}

test('the chart under the camera reaches the last phase bit for bit; the union is closed, one normal per position', async () => {
  const { refinement, view, whole, state, errors, posted } = await refine({ budget: 1e9 });
  assert.deepEqual(errors, []);
  assert.ok(state?.settled && posted().last);
  const final = state.phases - 1;
  assert.ok(state.phases >= 3, `${state.phases} phases`);
  const leaves = state.depths[final].flatMap((d, k) => (d === state.finalDepth ? [k] : []));
  assert.ok(leaves.length > 0, 'a leaf reaches the final depth');
  assert.ok(state.depths[final].some((d) => d < state.finalDepth), 'and not every leaf');
  for (const k of leaves) {
    const ours = view.chart(final, k);
    const theirs = whole.chart(final, k);
    assert.deepEqual(Buffer.from(ours.positions.buffer), Buffer.from(theirs.positions.buffer), `leaf ${k}'s positions`);
    assert.deepEqual(Buffer.from(ours.indices.buffer), Buffer.from(theirs.indices.buffer), `leaf ${k}'s triangles`);
  }
  assertOneNormal(posted());
  assertClosed(refinement, posted().last);
  refinement.stop();
});

test('a small budget: subtrees fold back, never more resident than the budget, no error', async () => {
  const atCut = (await refine({ budget: 0 })).state;
  assert.ok(atCut);
  const budget = 4 * atCut.resident;
  const { refinement, view, state, errors, settle, posted } = await refine({ budget });
  assert.deepEqual(errors, []);
  assert.ok(state && state.settled);
  assert.ok(state.resident <= budget, `${state.resident} resident, budget ${budget}`);
  assert.ok(state.deepestPhase > 0, 'the budget left room for a split');
  // Over to the other top chart: what the first camera split folds back.
  const moved = await settle(cameraOn(view.chart(0, 1).positions.subarray(0, 3)));
  console.log(`nested, budget ${budget}: shown per phase ${state.shownCharts.join(' ')}, then ${moved?.shownCharts.join(' ')}; ${moved?.evictions} subtrees folded back`);
  assert.deepEqual(errors, []);
  assert.ok(moved && moved.settled);
  assert.ok(moved.evictions > 0, 'subtrees folded back');
  assert.ok(moved.resident <= budget, `${moved.resident} resident, budget ${budget}`);
  assert.ok(moved.shownCharts.filter((n) => n > 0).length >= 2, `charts of several phases shown (${moved.shownCharts.join(' ')})`);
  assertOneNormal(posted());
  assertClosed(refinement, posted().last);
  refinement.stop();
});

test('a chart hidden behind the torus refines once the camera turns to it; the union stays closed', async () => {
  const { refinement, view, whole, state, errors, settle, posted } = await refine({ budget: 1e9 });
  assert.ok(state && state.settled);
  const final = state.phases - 1;
  const before = state.depths[final].slice();
  // The far side of the torus: the point opposite the first camera's, behind the near tube.
  const p = view.chart(0, 0).positions;
  const opposite = new Float32Array([-p[0], -p[1], -p[2]]);
  const moved = await settle(cameraOn(opposite));
  assert.deepEqual(errors, []);
  assert.ok(moved && moved.settled);
  const newly = moved.depths[final].flatMap((d, k) => (d === moved.finalDepth && before[k] !== moved.finalDepth ? [k] : []));
  console.log(`nested, turned round: leaves ${before.join(' ')}, then ${moved.depths[final].join(' ')}; ${moved.hiddenCharts} shown hidden`);
  assert.ok(newly.length > 0, 'a leaf the first camera did not refine reaches the final depth');
  assert.ok(moved.hiddenCharts > 0, 'charts shown are hidden behind the tube (occlusion.js)');
  for (const k of newly) {
    assert.deepEqual(Buffer.from(view.chart(final, k).positions.buffer), Buffer.from(whole.chart(final, k).positions.buffer), `leaf ${k}'s positions`);
  }
  assertOneNormal(posted());
  assertClosed(refinement, posted().last);
  refinement.stop();
});
