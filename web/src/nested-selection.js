// @ts-check
/**
 * View-dependent refinement of a nested stream (format 6, issue 41), the
 * pure part: the part index as a tree, what to do next for the view on
 * screen (a chart's next part, or its split into its children), and which
 * subtrees to give back when the vertex budget is spent. No DOM, no worker,
 * no codec: nested-refinement.js runs it in the decode worker,
 * test/nested-selection.test.mjs in Node. Charts are placed, measured and
 * ranked as part-selection.js does for a charted stream's.
 *
 * A chart's error still to come is the largest refinement error
 * (part-selection.js, `refinementError`) of its phase's parts it has not
 * applied and of every part of its descendants: a chart near the camera
 * goes deepest (its parts, then its split, then its children's parts), one
 * far away stops where the rest is below a pixel on screen. Occlusion
 * keeps the largest errors, a bound.
 */

import { SCREEN_ERROR_PX, byLeastNeeded, byNeed, frustumPlanes, onScreen, refinementError, remainingMax, sight } from './part-selection.js';

/**
 * The part index of a nested stream as the service sends it (`GET …/parts`).
 * @typedef {object} NestedPartIndex
 * @property {number} charts phase 0's
 * @property {number} phases
 * @property {number} first_level the first parted batch's level
 * @property {string} head_url
 * @property {string} part_url with `{level}` and `{chart}`
 * @property {string} split_url with `{level}` and `{parent}`
 * @property {NestedPartEntry[]} parts
 * @property {SplitEntry[]} splits
 */

/**
 * @typedef {{ level: number, chart: number, phase: number, parent?: number, bytes: number, inserted: number, error: number, bulk_error?: number }} NestedPartEntry
 * @typedef {{ level: number, parent: number, first_child: number, children: number, bytes: number }} SplitEntry
 */

/**
 * The index as a tree. `parts[p][k][d]`: the part that takes chart k of
 * phase p from depth d to d + 1; `splits[p][k]`: its split into
 * `children[p][k]` of phase p + 1; `own[p][k][d]`: the largest refinement
 * error of its parts from depth d on; `below[p][k]`: of every part of its
 * descendants; `ownBound` and `belowBound`: the same of their largest
 * errors (for occlusion); `batches`: each phase's parted batches (the parts a chart
 * of it has in all); `phaseStart`: each phase's first level.
 * @typedef {object} NestedTable
 * @property {number} phases
 * @property {number} firstLevel
 * @property {number[]} phaseStart
 * @property {number[]} batches
 * @property {number[]} charts per phase
 * @property {NestedPartEntry[][][]} parts
 * @property {(SplitEntry | null)[][]} splits
 * @property {[number, number][][]} children
 * @property {number[][][]} own
 * @property {number[][]} below
 * @property {number[][][]} ownBound
 * @property {number[][]} belowBound
 * @property {import('./codec.js').NestedBatch[]} batchesInOrder every parted batch, as the view is declared from
 */

/**
 * @param {NestedPartIndex} index
 * @returns {NestedTable}
 */
export function nestedTable(index) {
  const phases = index.phases;
  const levels = [...new Set(index.parts.map((p) => p.level))].sort((a, b) => a - b);
  /** @type {Map<number, NestedPartEntry[]>} */
  const byLevel = new Map(levels.map((l) => [l, []]));
  for (const p of index.parts) byLevel.get(p.level)?.push(p);
  const phaseStart = new Array(phases).fill(0);
  const batches = new Array(phases).fill(0);
  const charts = new Array(phases).fill(0);
  /** @type {import('./codec.js').NestedBatch[]} */
  const batchesInOrder = [];
  for (const level of levels) {
    const parts = /** @type {NestedPartEntry[]} */ (byLevel.get(level));
    const phase = parts[0].phase;
    if (batches[phase]++ === 0) phaseStart[phase] = level;
    charts[phase] = parts.length;
    const children = index.splits
      .filter((s) => s.level === level)
      .sort((a, b) => a.parent - b.parent)
      .map((s) => s.children);
    batchesInOrder.push({ level, phase, charts: parts.length, children });
  }
  const parts = charts.map((n, p) => Array.from({ length: n }, () => new Array(batches[p])));
  for (const part of index.parts) parts[part.phase][part.chart][part.level - phaseStart[part.phase]] = part;
  for (const [p, phase] of parts.entries()) {
    for (const [k, chart] of phase.entries()) {
      for (let d = 0; d < batches[p]; d++) if (!chart[d]) throw new Error(`the part index has no part for chart ${k} of phase ${p} at depth ${d}`);
    }
  }
  /** @type {(SplitEntry | null)[][]} */
  const splits = charts.map((n) => new Array(n).fill(null));
  /** @type {[number, number][][]} */
  const children = charts.map((n) => Array.from({ length: n }, () => /** @type {[number, number]} */ ([0, 0])));
  for (const s of index.splits) {
    const phase = phaseStart.indexOf(s.level) - 1;
    if (phase < 0) throw new Error(`the split entry of chart ${s.parent} at level ${s.level} begins no phase`);
    splits[phase][s.parent] = s;
    children[phase][s.parent] = [s.first_child, s.first_child + s.children];
  }
  /** @param {(part: NestedPartEntry) => number} of */
  const suffixMax = (of) => parts.map((phase) => phase.map((chart) => remainingMax(chart, of)));
  /** @param {number[][][]} own */
  const descendants = (own) => {
    const below = charts.map((n) => new Array(n).fill(0));
    for (let p = phases - 2; p >= 0; p--) {
      for (let k = 0; k < charts[p]; k++) {
        for (let c = children[p][k][0]; c < children[p][k][1]; c++) below[p][k] = Math.max(below[p][k], own[p + 1][c][0], below[p + 1][c]);
      }
    }
    return below;
  };
  const own = suffixMax(refinementError);
  const ownBound = suffixMax((part) => part.error);
  const [below, belowBound] = [descendants(own), descendants(ownBound)];
  return { phases, firstLevel: index.first_level, phaseStart, batches, charts, parts, splits, children, own, below, ownBound, belowBound, batchesInOrder };
}

/**
 * One chart of the tree as the selection sees it.
 * @typedef {object} NodeState
 * @property {number} phase
 * @property {number} chart
 * @property {number} depth parts of its phase applied
 * @property {import('./part-selection.js').Sphere} sphere
 * @property {import('./part-selection.js').NormalCone} [cone]
 * @property {boolean} [busy] its part or split entry is on its way
 * @property {boolean} [yielded] given back (or its split undone) to make room: left as it is until the camera moves
 * @property {boolean} expanded split, its children shown in its place
 * @property {number} vertices
 */

/**
 * What to do next for a chart: its next part, or its split.
 * @typedef {{ node: NodeState, kind: 'part', part: NestedPartEntry, level: number, pixels: number, distance: number }
 *   | { node: NodeState, kind: 'split', split: SplitEntry, level: number, pixels: number, distance: number }} Action
 */

/**
 * The chart's next step down the tree (null at the bottom).
 * @param {NestedTable} table
 * @param {NodeState} node
 * @returns {{ kind: 'part', part: NestedPartEntry, level: number } | { kind: 'split', split: SplitEntry, level: number } | null}
 */
export function nextStep(table, node) {
  const { phase, chart, depth } = node;
  if (depth < table.batches[phase]) return { kind: 'part', part: table.parts[phase][chart][depth], level: table.phaseStart[phase] + depth };
  const split = table.splits[phase]?.[chart];
  return split ? { kind: 'split', split, level: split.level } : null;
}

/**
 * The error a chart shown at its depth leaves: its phase's parts still to
 * apply and its descendants'.
 * @param {NestedTable} table
 * @param {NodeState} node
 */
export function errorLeft(table, node) {
  return Math.max(table.own[node.phase][node.chart][node.depth], table.below[node.phase][node.chart]);
}

/**
 * How far the surface still to come may lie from a shown chart's, in model
 * units, for occlusion (occlusion.js): twice the largest error of its
 * parts still to come and its descendants', not their sum (which the
 * halving of errors from level to level keeps under twice it).
 * @param {NestedTable} table
 * @param {NodeState} node
 */
export function occluderTolerance(table, node) {
  return 2 * Math.max(table.ownBound[node.phase][node.chart][node.depth], table.belowBound[node.phase][node.chart]);
}

/**
 * A chart's bounding sphere for occlusion: the one made at its cut, grown
 * by every part error of its phase (their sum: how far its parts may have
 * moved its surface out of that sphere) and twice the largest below it (its
 * descendants', shown in its place when it is expanded), so its own
 * surface, or its descendants', is never nearer than the sphere's nearest
 * point: a chart never hides itself.
 * @param {NestedTable} table
 * @param {NodeState} node
 * @returns {import('./part-selection.js').Sphere}
 */
export function occlusionSphere(table, node) {
  const drift = table.parts[node.phase][node.chart].reduce((e, part) => e + part.error, 0) + 2 * table.belowBound[node.phase][node.chart];
  return { centre: node.sphere.centre, radius: node.sphere.radius + drift };
}

/**
 * Whether a chart is hidden behind the surface shown (occlusion.js), for
 * the camera the selection is asked about; absent: nothing is.
 * @typedef {(node: NodeState) => boolean} Hidden
 */

/**
 * The shown charts' next steps, most wanted first: in view (and not hidden
 * behind the surface shown), not busy, not past the cap, with the error
 * they leave above the threshold on screen.
 * @param {NestedTable} table
 * @param {NodeState[]} shown the charts on screen (no expanded one)
 * @param {import('./part-selection.js').PartCamera} camera
 * @param {{ capLevel: number, threshold?: number, hidden?: Hidden }} limits
 * @returns {Action[]}
 */
export function wantedSteps(table, shown, camera, { capLevel, threshold = SCREEN_ERROR_PX, hidden }) {
  const planes = frustumPlanes(camera.clip);
  /** @type {Action[]} */
  const wanted = [];
  for (const node of shown) {
    if (node.busy || node.yielded) continue;
    const step = nextStep(table, node);
    if (!step || step.level > capLevel) continue;
    const { distance, visible } = sight(planes, camera.eye, node);
    const pixels = onScreen(errorLeft(table, node), distance, camera);
    // The cheap tests first: the map is read only for a chart that would refine.
    if (visible && pixels > threshold && !hidden?.(node)) wanted.push({ node, ...step, pixels, distance });
  }
  return wanted.sort(byNeed);
}

/**
 * Which expanded charts to fold back (their subtrees dropped, the chart
 * shown again) to make room for `wanted`: those off its path to the root
 * with nothing on its way below them; out of view (or hidden behind the
 * surface shown) first (farthest first),
 * then those in view whose error on screen once folded (every part below
 * them) is smaller than `wanted`'s now (smallest first). A chart folded so
 * never wants its room back more than the one that took it, so two do not
 * take the room in turn.
 * @param {NestedTable} table
 * @param {NodeState[]} expanded with no busy descendant
 * @param {Action} wanted
 * @param {NodeState[]} path `wanted`'s chart and its ancestors
 * @param {import('./part-selection.js').PartCamera} camera
 * @param {Hidden} [hidden]
 * @returns {NodeState[]}
 */
export function foldOrder(table, expanded, wanted, path, camera, hidden) {
  const planes = frustumPlanes(camera.clip);
  return expanded
    .filter((n) => !path.includes(n))
    .map((node) => {
      const seen = sight(planes, camera.eye, node);
      const distance = seen.distance;
      const visible = seen.visible && !hidden?.(node);
      return { node, distance, visible, cutPixels: onScreen(table.below[node.phase][node.chart], distance, camera) };
    })
    .filter((a) => !a.visible || a.cutPixels < wanted.pixels)
    .sort(byLeastNeeded)
    .map((a) => a.node);
}
