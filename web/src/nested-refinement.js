// @ts-check
/**
 * View-dependent refinement of a nested stream (format 6, issue 41), in the
 * decode worker: after the global batches the decoder becomes a NestedView
 * (codec.js), declared from the part index and the first parted batch's
 * head, never a whole batch. As the camera asks (nested-selection.js), a
 * chart in view and near applies its next part, or, once it has all its
 * phase's parts, fetches its split entry and splits into its children,
 * which refine on; the charts on screen go to the renderer as one level
 * (chart-union.js), as part-refinement.js does for a charted stream.
 *
 * Each branch of the tree shows either a chart or its children, never
 * both: a parent stays resident when it splits (the view keeps it), so
 * folding its children back (to free their vertices) shows it again at
 * once, without a fetch.
 *
 * Why the union stays watertight: a phase's cut is frozen in its charts
 * and in all their descendants (no later part inserts on it, moves it or
 * joins two of its vertices), so a chart and its neighbour share every
 * vertex and edge of their common border bit for bit whatever phase and
 * depth each is shown at (codec/core/src/decoder/nested_view.rs;
 * test/nested-refinement.test.mjs checks that the union of charts of
 * several phases is closed). The border vertices of each
 * chart, found once from its triangles when it is made, are welded by
 * position across the charts shown: one normal each, summed over the
 * charts that hold them, so the shading is continuous too.
 *
 * The vertex budget counts every chart held, parents included (the view's
 * resident vertices). When the next step would pass it, expanded charts
 * fold back, out of view first, then those whose folded error on screen
 * is smallest (nested-selection.js `foldOrder`); a split whose children
 * turn out larger than foreseen is undone at once.
 *
 * Charts hidden behind the surface shown (occlusion.js: a small depth map
 * of the union, for the camera) want nothing and fold first, as those out
 * of view: a close-up does not refine the far side of the object. The map
 * is made again for each camera, and when the charts shown changed since
 * it was made, at most once per {@link OCCLUSION_GAP} times its cost
 * (occlusion.js OcclusionMap).
 */

import { ChartUnion, weldByPosition } from './chart-union.js';
import { DecodeError } from './codec.js';
import { foldOrder, nestedTable, occluderTolerance, occlusionSphere, wantedSteps } from './nested-selection.js';
import { OcclusionMap } from './occlusion.js';
import { PARTS_IN_FLIGHT, boundingSphere, normalCone } from './part-selection.js';

/**
 * Vertices a split is taken to add before it is made: the parent's, and
 * this share more for the cut vertices its children duplicate. A split
 * that adds more than foreseen and passes the budget is undone.
 */
const SPLIT_MARGIN = 0.1;

/**
 * The depth map of the same camera is made again once the charts shown
 * changed, but no sooner than this many times its last cost after it: at
 * most a fifth of the worker's time goes to occlusion while parts arrive.
 */
const OCCLUSION_GAP = 4;

/**
 * Triangles drawn into the depth map, at most: past it every k-th is drawn
 * (occlusion.js; pixels left empty hide nothing, so less is culled, never
 * what shows). 4 M: about the desktop budget's union.
 */
const OCCLUSION_TRIANGLES = 4_000_000;

/**
 * @typedef {object} NestedState what the page reads (viewer.partsState())
 * @property {'nested'} kind
 * @property {number} phases
 * @property {number[]} charts per phase, in the stream
 * @property {number[]} residentCharts per phase, held
 * @property {number[]} shownCharts per phase, on screen
 * @property {[number, number][]} shown the charts on screen, each as its phase and chart
 * @property {number} shownTriangles the triangles on screen, all charts shown together
 * @property {number[][]} depths per phase and chart: parts applied, -1 while not held
 * @property {number[]} phaseBatches per phase: the parts each chart of it has in all
 * @property {number} finalDepth the last phase's
 * @property {number} deepestPhase the deepest phase shown
 * @property {number} firstLevel the first parted batch's level
 * @property {number} level the finest level shown (a chart at depth d of phase p: the level of that part)
 * @property {number} resident vertices held, all charts together, parents included
 * @property {number} budget
 * @property {number} bytesFetched bytes of this load as the network carried them: base, global batches, part index (compressed), head, parts and split entries
 * @property {number} inFlight parts and split entries on their way
 * @property {boolean} settled nothing on its way and nothing more wanted for the last camera
 * @property {number} evictions subtrees folded back to make room so far
 * @property {number} hiddenCharts charts shown that the last depth map hides
 * @property {number} occlusionMs the last depth map's cost
 * @property {number} occlusionMaps depth maps made so far
 */

/**
 * @typedef {object} NestedRefinementOptions
 * @property {import('./codec.js').NestedView} view
 * @property {import('./nested-selection.js').NestedPartIndex} index
 * @property {number} budget resident vertices, at most
 * @property {number} capLevel the visitor's cap: no part or split entry past it
 * @property {number} sentVertices vertices the renderer holds already (the global level's)
 * @property {import('./geometry.js').Bounds} baseBounds
 * @property {number} bytesFetched before the first part
 * @property {boolean} wireframe
 * @property {(part: import('./nested-selection.js').NestedPartEntry) => Promise<import('./payload.js').Fetched>} fetchPart
 * @property {(split: import('./nested-selection.js').SplitEntry) => Promise<import('./payload.js').Fetched>} fetchSplit
 * @property {import('./reconstruction.js').Post} post levels (to the renderer)
 * @property {(message: NestedMessage) => void} tell the page
 */

/**
 * @typedef {{ type: 'parts', state: NestedState }
 *   | { type: 'capped', level: number, status: number, reason: string | null, retryAfterS: number | null }
 *   | { type: 'error', kind: 'network' | 'decode', level: number, message: string }} NestedMessage
 */

/**
 * A chart held in the view.
 * @typedef {import('./nested-selection.js').NodeState & import('./chart-union.js').UnionPiece & { border: Uint32Array }} Node
 */

/**
 * The ids of a chart's vertices on its border: on an edge of one triangle only.
 * @param {Uint32Array} indices
 * @param {number} vertices
 */
function borderVertices(indices, vertices) {
  /** @type {Map<number, number>} */
  const edges = new Map();
  for (let t = 0; t < indices.length; t += 3) {
    for (let e = 0; e < 3; e++) {
      const a = indices[t + e];
      const b = indices[t + ((e + 1) % 3)];
      const key = Math.min(a, b) * vertices + Math.max(a, b);
      edges.set(key, (edges.get(key) ?? 0) + 1);
    }
  }
  const on = new Uint8Array(vertices);
  for (const [key, count] of edges) {
    if (count !== 1) continue;
    on[Math.floor(key / vertices)] = 1;
    on[key % vertices] = 1;
  }
  const ids = [];
  for (let v = 0; v < vertices; v++) if (on[v]) ids.push(v);
  return Uint32Array.from(ids);
}

export class NestedRefinement {
  /** Charts held, by phase and position. @type {(Node | null)[][]} */
  #nodes;
  /** The charts shown and their weld, until a split or a fold changes them. @type {{ pieces: Node[], weld: import('./chart-union.js').Weld } | null} */
  #shown = null;
  /** @type {import('./part-selection.js').PartCamera | null} */
  #camera = null;
  #inFlight = 0;
  /** Vertices the steps on their way will add. */
  #reserved = 0;
  #bytes;
  #evictions = 0;
  #stopped = false;
  /** Split entries fetched: a subtree folded back splits again without a fetch. @type {Map<string, Uint8Array>} */
  #entries = new Map();
  /** @type {ChartUnion} */
  #union;
  /** The charts shown changed this many times (the depth map's is older when less). */
  #generation = 0;
  /** The depth map of the charts shown, for the camera. */
  #occlusion = new OcclusionMap({ gap: OCCLUSION_GAP, maxTriangles: OCCLUSION_TRIANGLES });

  /** @param {NestedRefinementOptions} options */
  constructor(options) {
    this.options = options;
    this.view = options.view;
    this.table = nestedTable(options.index);
    this.capLevel = options.capLevel;
    this.#bytes = options.bytesFetched;
    const phases = this.view.phaseCount();
    if (phases !== this.table.phases) throw new DecodeError(`the part index has ${this.table.phases} phases, the stream ${phases}`);
    this.#nodes = this.table.charts.map((n) => new Array(n).fill(null));
    for (let k = 0; k < this.table.charts[0]; k++) this.#nodes[0][k] = this.#made(0, k);
    this.#union = new ChartUnion({
      sentVertices: options.sentVertices,
      baseBounds: options.baseBounds,
      wireframe: options.wireframe,
      post: options.post,
      source: () => ({ ...this.#showing(), level: this.#level(), received: this.#bytes }),
      posted: () => this.#tellState(),
    });
    this.#union.publish();
  }

  /**
   * A chart just made (the cut, or a split): its place and normal cone from
   * its vertices now, its border once (frozen from here down).
   * @param {number} phase
   * @param {number} chart
   * @returns {Node}
   */
  #made(phase, chart) {
    const { positions, colours, indices } = this.view.chart(phase, chart);
    const vertices = positions.length / 3;
    return {
      phase,
      chart,
      depth: this.view.depth(phase, chart),
      sphere: boundingSphere(positions),
      cone: normalCone(positions, indices),
      expanded: false,
      vertices,
      positions,
      colours,
      indices,
      base: -1,
      border: borderVertices(indices, vertices),
    };
  }

  /** The charts on screen, each branch's shallowest unexpanded one, and their weld. */
  #showing() {
    if (this.#shown) return this.#shown;
    /** @type {Node[]} */
    const pieces = [];
    /** @param {Node} node */
    const walk = (node) => {
      if (!node.expanded) return void pieces.push(node);
      const [from, to] = this.table.children[node.phase][node.chart];
      for (let c = from; c < to; c++) {
        const child = this.#nodes[node.phase + 1][c];
        if (child) walk(child);
      }
    };
    for (const top of this.#nodes[0]) if (top) walk(top);
    this.#shown = { pieces, weld: weldByPosition(pieces, pieces.map((p) => p.border)) };
    return this.#shown;
  }

  /** @param {import('./part-selection.js').PartCamera} camera */
  setCamera(camera) {
    this.#camera = camera;
    for (const phase of this.#nodes) for (const n of phase) if (n) n.yielded = false;
    this.#pump();
    this.#tellState();
  }

  /** @param {number} level */
  setCap(level) {
    this.capLevel = level;
    this.#pump();
  }

  /** @param {boolean} on */
  setWireframe(on) {
    this.#union.setWireframe(on);
  }

  stop() {
    this.#stopped = true;
    this.#union.stop();
    this.view.free();
  }

  /**
   * One chart's buffers as copies (tests compare them with the whole decoder's chart).
   * @param {number} chart
   * @param {number} [phase]
   */
  chart(chart, phase = 0) {
    const depth = this.view.depth(phase, chart);
    if (depth < 0) throw new Error(`chart ${chart} of phase ${phase} is not held`);
    return { depth, phase, ...this.view.chart(phase, chart) };
  }

  /**
   * The union as one compact level, welded at the cuts (chart-union.js).
   * @returns {import('./codec.js').Level}
   */
  current() {
    return this.#union.current();
  }

  /** The level of a chart's last part (a chart just split: its parent's). @param {Node} node */
  #nodeLevel(node) {
    return this.table.phaseStart[node.phase] - 1 + node.depth;
  }

  /** The finest level shown: what the page shows as the level on screen. */
  #level() {
    return Math.max(this.table.firstLevel - 1, ...this.#showing().pieces.map((n) => this.#nodeLevel(n)));
  }

  /** Starts the steps the camera wants, as many as may be on their way. */
  #pump() {
    const camera = this.#camera;
    if (!camera || this.#stopped) return;
    const steps = this.table.charts.reduce((n, k, p) => n + k * (this.table.batches[p] + 1), 0);
    for (let round = 0; round < steps && this.#inFlight < PARTS_IN_FLIGHT; round++) {
      this.#refreshOcclusion(camera);
      const wanted = wantedSteps(this.table, this.#showing().pieces, camera, { capLevel: this.capLevel, hidden: this.#hidden });
      let started = false;
      let again = false;
      for (const w of wanted) {
        if (this.#inFlight >= PARTS_IN_FLIGHT) break;
        const node = /** @type {Node} */ (w.node);
        // Room made for a step before this one may have folded this chart away.
        if (this.#nodes[node.phase][node.chart] !== node) continue;
        const adds = w.kind === 'part' ? w.part.inserted : Math.ceil(node.vertices * (1 + SPLIT_MARGIN));
        if (!this.#makeRoom(w, adds, camera)) continue;
        started = true;
        const cached = w.kind === 'split' ? this.#entries.get(`${node.phase} ${node.chart}`) : undefined;
        if (w.kind === 'part' && w.part.bytes === 0) {
          // The chart sits this batch out: its empty part advances its depth.
          this.#applyPart(node, new Uint8Array(0));
          again = true;
          break; // what it leaves changed: choose again
        }
        if (cached) {
          this.#split(node, cached);
          again = true;
          break; // the charts shown changed: choose again
        }
        this.#start(w, adds);
      }
      if (!started || !again) break;
    }
  }

  /**
   * Folds expanded charts back, least needed first, until `adds` more
   * vertices fit the budget (with what the steps on their way will add).
   * @param {import('./nested-selection.js').Action} wanted
   * @param {number} adds
   * @param {import('./part-selection.js').PartCamera} camera
   */
  #makeRoom(wanted, adds, camera) {
    const fits = () => this.view.residentVertices() + this.#reserved + adds <= this.options.budget;
    if (fits()) return true;
    const path = this.#path(/** @type {Node} */ (wanted.node));
    const expanded = this.#all().filter((n) => n.expanded && !this.#busyBelow(n));
    const order = /** @type {Node[]} */ (foldOrder(this.table, expanded, wanted, path, camera, this.#hidden));
    // Nothing is folded unless folding them all would make the room
    // (a subtree inside another folded counts once).
    const outer = order.filter((n) => !this.#path(n).some((a) => a !== n && order.includes(a)));
    const freed = outer.reduce((v, n) => v + this.#heldBelow(n), 0);
    if (this.view.residentVertices() - freed + this.#reserved + adds > this.options.budget) return false;
    for (const node of order) {
      if (!node.expanded || this.#nodes[node.phase][node.chart] !== node) continue; // folded with an ancestor
      this.#fold(node);
      node.yielded = true;
      this.#evictions++;
      if (fits()) return true;
    }
    return false;
  }

  /**
   * Makes the depth map again for a new camera, or when the charts shown
   * changed and its last cost allows.
   * @param {import('./part-selection.js').PartCamera} camera
   */
  #refreshOcclusion(camera) {
    this.#occlusion.refresh(camera, this.#generation, () =>
      this.#showing().pieces.map((n) => ({ key: n, positions: n.positions, indices: n.indices, tolerance: occluderTolerance(this.table, n) })),
    );
  }

  /**
   * Whether a chart is hidden behind the charts shown, for the camera.
   * @param {import('./nested-selection.js').NodeState} node
   */
  #hidden = (node) => this.#occlusion.hides(this.#camera, node, () => occlusionSphere(this.table, node));

  /** Every chart held. */
  #all() {
    return /** @type {Node[]} */ (this.#nodes.flat().filter(Boolean));
  }

  /** A chart and its ancestors, itself first. @param {Node} node */
  #path(node) {
    const path = [node];
    for (let n = node; n.phase > 0; ) {
      const parent = this.#nodes[n.phase - 1][this.view.parent(n.phase, n.chart)];
      if (!parent) break;
      path.push(parent);
      n = parent;
    }
    return path;
  }

  /** A chart's children held. @param {Node} node @returns {Node[]} */
  #children(node) {
    const [from, to] = this.table.children[node.phase][node.chart];
    const held = [];
    for (let c = from; c < to; c++) {
      const child = this.#nodes[node.phase + 1]?.[c];
      if (child) held.push(child);
    }
    return held;
  }

  /** Vertices held below a chart. @param {Node} node @returns {number} */
  #heldBelow(node) {
    return this.#children(node).reduce((v, c) => v + c.vertices + this.#heldBelow(c), 0);
  }

  /** Whether a step of a chart below this one is on its way. @param {Node} node @returns {boolean} */
  #busyBelow(node) {
    return this.#children(node).some((c) => c.busy || this.#busyBelow(c));
  }

  /**
   * Drops a chart's children and their descendants: it is shown again.
   * @param {Node} node
   */
  #fold(node) {
    /** @param {Node} n */
    const forget = (n) => {
      for (const c of this.#children(n)) {
        forget(c);
        this.#nodes[c.phase][c.chart] = null;
      }
    };
    for (const c of this.#children(node)) this.view.drop(c.phase, c.chart);
    forget(node);
    node.expanded = false;
    node.base = -1;
    this.#changed();
  }

  /**
   * @param {import('./nested-selection.js').Action} step
   * @param {number} adds
   */
  #start(step, adds) {
    const node = /** @type {Node} */ (step.node);
    node.busy = true;
    this.#inFlight++;
    this.#reserved += adds;
    const fetched = step.kind === 'part' ? this.options.fetchPart(step.part) : this.options.fetchSplit(step.split);
    const done = () => {
      node.busy = false;
      this.#inFlight--;
      this.#reserved -= adds;
    };
    fetched.then(
      (answer) => {
        done();
        if (this.#stopped) return;
        const held = this.#nodes[node.phase][node.chart] === node;
        if ('capped' in answer) {
          this.capLevel = Math.min(this.capLevel, step.level - 1);
          this.options.tell({ type: 'capped', level: this.capLevel, ...answer.capped });
        } else if (held && step.kind === 'part' && node.depth === step.part.level - this.table.phaseStart[node.phase]) {
          this.#bytes += answer.bytes.length;
          this.#applyPart(node, answer.bytes);
        } else if (held && step.kind === 'split' && !node.expanded) {
          this.#bytes += answer.bytes.length;
          this.#entries.set(`${node.phase} ${node.chart}`, answer.bytes);
          this.#split(node, answer.bytes);
        }
        this.#pump();
        this.#tellState();
      },
      (error) => {
        done();
        if (this.#stopped) return;
        this.options.tell({ type: 'error', kind: 'network', level: step.level - 1, message: error instanceof Error ? error.message : String(error) });
      },
    );
  }

  /**
   * @param {Node} node
   * @param {Uint8Array} bytes
   */
  #applyPart(node, bytes) {
    try {
      this.view.applyPart(node.phase, node.chart, bytes);
    } catch (error) {
      return this.#damaged(this.table.phaseStart[node.phase] + node.depth, error);
    }
    const { positions, colours, indices } = this.view.chart(node.phase, node.chart);
    Object.assign(node, { depth: this.view.depth(node.phase, node.chart), vertices: positions.length / 3, positions, colours, indices, base: -1 });
    this.#generation++;
    // The border is frozen: the weld holds, only the union is posted again.
    this.#union.changed(this.view.residentVertices());
  }

  /**
   * Splits a chart into its children; undone when they pass the budget.
   * @param {Node} node
   * @param {Uint8Array} entry
   */
  #split(node, entry) {
    try {
      this.view.split(node.phase, node.chart, entry);
    } catch (error) {
      return this.#damaged(this.table.phaseStart[node.phase + 1], error);
    }
    const [from, to] = this.table.children[node.phase][node.chart];
    if (this.view.residentVertices() + this.#reserved > this.options.budget) {
      for (let c = from; c < to; c++) this.view.drop(node.phase + 1, c);
      node.yielded = true;
      return;
    }
    for (let c = from; c < to; c++) this.#nodes[node.phase + 1][c] = this.#made(node.phase + 1, c);
    node.expanded = true;
    this.#changed();
  }

  /** The charts shown changed: weld again, post soon. */
  #changed() {
    this.#shown = null;
    this.#generation++;
    this.#union.changed(this.view.residentVertices());
  }

  /**
   * @param {number} level the batch whose piece failed
   * @param {unknown} error
   */
  #damaged(level, error) {
    this.#stopped = true;
    this.#union.stop();
    this.options.tell({ type: 'error', kind: 'decode', level: level - 1, message: `the stream is damaged (${error instanceof Error ? error.message : String(error)})` });
  }

  #tellState() {
    const { pieces } = this.#showing();
    const t = this.table;
    /** @param {(n: Node) => boolean} where */
    const perPhase = (where) => t.charts.map((_, p) => this.#nodes[p].filter((n) => n && where(n)).length);
    this.options.tell({
      type: 'parts',
      state: {
        kind: 'nested',
        phases: t.phases,
        charts: t.charts,
        residentCharts: perPhase(() => true),
        shownCharts: t.charts.map((_, p) => pieces.filter((n) => n.phase === p).length),
        shown: pieces.map((n) => [n.phase, n.chart]),
        shownTriangles: pieces.reduce((sum, n) => sum + n.indices.length / 3, 0),
        depths: this.#nodes.map((phase) => phase.map((n) => (n ? n.depth : -1))),
        phaseBatches: t.batches,
        finalDepth: t.batches[t.phases - 1],
        deepestPhase: Math.max(...pieces.map((n) => n.phase)),
        firstLevel: t.firstLevel,
        level: this.#level(),
        resident: this.view.residentVertices(),
        budget: this.options.budget,
        bytesFetched: this.#bytes,
        inFlight: this.#inFlight,
        settled: this.#camera !== null && this.#inFlight === 0 && !this.#union.pending,
        evictions: this.#evictions,
        hiddenCharts: pieces.filter(this.#hidden).length,
        occlusionMs: this.#occlusion.ms,
        occlusionMaps: this.#occlusion.made,
      },
    });
  }
}

