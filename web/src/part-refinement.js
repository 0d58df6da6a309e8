// @ts-check
/**
 * View-dependent refinement of a charted stream (issue 41), in the decode
 * worker: after the global batches the decoder becomes a PartView (codec.js),
 * each chart refines by its own parts as the camera asks (part-selection.js),
 * and the union of the charts goes to the renderer as a level.
 *
 * The union goes to the renderer as chart-union.js does it for every
 * view-dependent refinement: charts that changed appended to the store,
 * cut vertices welded by position so the shading is continuous across
 * chart borders. A charted stream's cut is fixed, so it is welded once.
 *
 * Charts hidden behind the charts shown (occlusion.js) want no part and
 * give their vertices back first, as those out of view, as for a nested
 * stream (nested-refinement.js).
 */

import { ChartUnion, weldByPosition } from './chart-union.js';
import { DecodeError } from './codec.js';
import { OcclusionMap } from './occlusion.js';
import { PARTS_IN_FLIGHT, assess, boundingSphere, evictionOrder, normalCone, occluderTolerance, occlusionSphere, partTable, wantedParts } from './part-selection.js';

/** The depth map's throttle and size bound, as nested-refinement.js's. */
const OCCLUSION = { gap: 4, maxTriangles: 4_000_000 };

/**
 * @typedef {object} PartsState what the page reads (viewer.partsState())
 * @property {number} charts
 * @property {number[]} depths parts applied per chart
 * @property {number} finalDepth
 * @property {number} firstLevel the first parted batch's level: a chart at depth d is at level firstLevel − 1 + d
 * @property {number} level the finest level a chart reached (the union's, as posted)
 * @property {number} resident vertices held, all charts together
 * @property {number} budget
 * @property {number} bytesFetched bytes of this load as the network carried them: base, global batches, part index (compressed), head and parts
 * @property {boolean[]} visible per chart, in view: in the frustum, not facing away, not hidden behind the charts shown
 * @property {number} inFlight parts on their way
 * @property {boolean} settled nothing on its way and nothing more wanted for the last camera
 * @property {number} evictions charts reset to make room so far
 */

/**
 * @typedef {object} PartRefinementOptions
 * @property {import('./codec.js').PartView} view
 * @property {import('./part-selection.js').PartIndex} index
 * @property {number} budget resident vertices, at most
 * @property {number} capLevel the visitor's cap: no part past it
 * @property {number} sentVertices vertices the renderer holds already (the global level's)
 * @property {import('./geometry.js').Bounds} baseBounds
 * @property {number} bytesFetched before the first part
 * @property {boolean} wireframe
 * @property {(part: import('./part-selection.js').PartIndex['parts'][number]) => Promise<import('./payload.js').Fetched>} fetchPart
 * @property {import('./reconstruction.js').Post} post levels and edges (to the renderer)
 * @property {(message: PartsMessage) => void} tell the page
 */

/**
 * @typedef {{ type: 'parts', state: PartsState }
 *   | { type: 'capped', level: number, status: number, reason: string | null, retryAfterS: number | null }
 *   | { type: 'error', kind: 'network' | 'decode', level: number, message: string }} PartsMessage
 */

/**
 * @typedef {object} Chart
 * @property {number} depth
 * @property {number} cutVertices its vertices at the cut (what a reset leaves)
 * @property {import('./part-selection.js').Sphere} sphere from its vertices at the cut
 * @property {import('./part-selection.js').NormalCone} cone its face normals at the cut
 * @property {boolean} busy
 * @property {boolean} yielded reset to make room: left at the cut until the camera moves
 * @property {Float32Array} positions
 * @property {Uint8Array | null} colours
 * @property {Uint32Array} indices in the chart's own ids
 * @property {number} base where its vertices start in the renderer's store (-1: not sent since it changed)
 */

export class PartRefinement {
  /** @type {Chart[]} */
  #charts;
  /** Cut vertices, welded once: the cut never changes. @type {import('./chart-union.js').Weld} */
  #weld;
  /** @type {import('./part-selection.js').PartCamera | null} */
  #camera = null;
  #inFlight = 0;
  /** Vertices the parts on their way will add. */
  #reserved = 0;
  #bytes;
  #evictions = 0;
  #stopped = false;
  /** @type {boolean[]} */
  #visible;
  /** @type {ChartUnion} */
  #union;
  /** Counts the changes of the charts shown (the depth map's is older when less). */
  #generation = 0;
  #occlusion = new OcclusionMap(OCCLUSION);
  /** @param {number} k */
  #hidden = (k) => this.#occlusion.hides(this.#camera, this.#charts[k], () => occlusionSphere(this.parts, k, this.#charts[k].sphere));

  /** @param {PartRefinementOptions} options */
  constructor(options) {
    this.options = options;
    this.view = options.view;
    this.parts = partTable(options.index);
    this.firstLevel = options.index.first_level;
    this.capLevel = options.capLevel;
    this.#bytes = options.bytesFetched;
    this.view.setVertexBudget(options.budget);
    const count = this.view.chartCount();
    if (count !== options.index.charts) throw new DecodeError(`the part index has ${options.index.charts} charts, the stream ${count}`);
    this.#charts = Array.from({ length: count }, (_, k) => {
      const { positions, colours, indices } = this.view.chart(k);
      return { depth: 0, cutVertices: positions.length / 3, sphere: boundingSphere(positions), cone: normalCone(positions, indices), busy: false, yielded: false, positions, colours, indices, base: -1 };
    });
    this.#visible = new Array(count).fill(true);
    // Cut vertices, found by position at the cut. Their ids within each
    // chart never change (a part appends the vertices it inserts; a reset
    // goes back to the cut).
    this.#weld = weldByPosition(this.#charts);
    this.#union = new ChartUnion({
      sentVertices: options.sentVertices,
      baseBounds: options.baseBounds,
      wireframe: options.wireframe,
      post: options.post,
      source: () => ({ pieces: this.#charts, weld: this.#weld, level: this.#level(), received: this.#bytes }),
      posted: () => this.#tellState(),
    });
    this.#union.publish();
  }

  /** @param {import('./part-selection.js').PartCamera} camera */
  setCamera(camera) {
    this.#camera = camera;
    for (const c of this.#charts) c.yielded = false;
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
   */
  chart(chart) {
    return { depth: this.view.depth(chart), ...this.view.chart(chart) };
  }

  /**
   * The union as one compact level, welded at the cut (chart-union.js).
   * @returns {import('./codec.js').Level}
   */
  current() {
    return this.#union.current();
  }

  /** The finest level a chart reached: what the page shows as the level on screen. */
  #level() {
    return this.firstLevel - 1 + Math.max(0, ...this.#charts.map((c) => c.depth));
  }

  /** Starts the parts the camera wants, as many as may be on their way. */
  #pump() {
    const camera = this.#camera;
    if (!camera || this.#stopped) return;
    for (let round = 0; round < this.#charts.length * (this.parts.finalDepth + 1) && this.#inFlight < PARTS_IN_FLIGHT; round++) {
      this.#occlusion.refresh(camera, this.#generation, () =>
        this.#charts.map((c, k) => ({ key: c, positions: c.positions, indices: c.indices, tolerance: occluderTolerance(this.parts, k, c.depth) })),
      );
      const limits = { firstLevel: this.firstLevel, capLevel: this.capLevel, hidden: this.#hidden };
      const wanted = wantedParts(this.#charts, this.parts, camera, limits);
      const assessed = assess(this.#charts, this.parts, camera, this.#hidden);
      this.#visible = assessed.map((a) => a.visible);
      let started = false;
      for (const w of wanted) {
        if (this.#inFlight >= PARTS_IN_FLIGHT) break;
        const chart = this.#charts[w.chart];
        const part = this.parts.table[w.chart][chart.depth];
        if (!this.#makeRoom(w.chart, part.inserted, assessed)) continue;
        started = true;
        if (part.bytes === 0) {
          // The chart sits this batch out: its empty part advances its depth.
          this.#apply(w.chart, new Uint8Array(0));
          break; // its remaining error changed: choose again
        }
        this.#start(w.chart, part);
      }
      if (!started) break;
    }
  }

  /**
   * Resets charts, least wanted first, until `inserted` more vertices fit
   * the budget (with what the parts on their way will add).
   * @param {number} chart the chart that needs the room
   * @param {number} inserted
   * @param {ReturnType<typeof assess>} assessed
   */
  #makeRoom(chart, inserted, assessed) {
    const fits = () => this.view.residentVertices() + this.#reserved + inserted <= this.options.budget;
    if (fits()) return true;
    const order = evictionOrder(this.#charts, assessed, chart);
    // Nothing is reset unless resetting them all would make the room.
    const freed = order.reduce((n, k) => n + this.#charts[k].positions.length / 3 - this.#charts[k].cutVertices, 0);
    if (this.view.residentVertices() - freed + this.#reserved + inserted > this.options.budget) return false;
    for (const other of order) {
      this.view.reset(other);
      this.#charts[other].yielded = true;
      this.#evictions++;
      this.#reload(other);
      if (fits()) return true;
    }
    return false;
  }

  /**
   * @param {number} k
   * @param {import('./part-selection.js').PartIndex['parts'][number]} part
   */
  #start(k, part) {
    const chart = this.#charts[k];
    chart.busy = true;
    this.#inFlight++;
    this.#reserved += part.inserted;
    this.options.fetchPart(part).then(
      (fetched) => {
        chart.busy = false;
        this.#inFlight--;
        this.#reserved -= part.inserted;
        if (this.#stopped) return;
        if ('capped' in fetched) {
          this.capLevel = Math.min(this.capLevel, part.level - 1);
          this.options.tell({ type: 'capped', level: this.capLevel, ...fetched.capped });
        } else if (chart.depth === part.level - this.firstLevel) {
          this.#bytes += fetched.bytes.length;
          this.#apply(k, fetched.bytes);
        }
        this.#pump();
        this.#tellState();
      },
      (error) => {
        chart.busy = false;
        this.#inFlight--;
        this.#reserved -= part.inserted;
        if (this.#stopped) return;
        this.options.tell({ type: 'error', kind: 'network', level: part.level - 1, message: error instanceof Error ? error.message : String(error) });
      },
    );
  }

  /**
   * Applies a chart's next part; one the view refuses for the budget (a
   * prediction that fell short) waits for the camera to move.
   * @param {number} k
   * @param {Uint8Array} bytes
   */
  #apply(k, bytes) {
    try {
      this.view.applyPart(k, bytes);
    } catch (error) {
      if (error instanceof DecodeError && /budget/.test(error.message)) {
        // Left as it is until the camera moves (else fetched again at once).
        this.#charts[k].yielded = true;
        return;
      }
      this.#stopped = true;
      this.#union.stop();
      const level = this.firstLevel + this.#charts[k].depth;
      this.options.tell({ type: 'error', kind: 'decode', level: level - 1, message: `the stream is damaged (${error instanceof Error ? error.message : String(error)})` });
      return;
    }
    this.#reload(k);
  }

  /** @param {number} k a chart whose depth changed */
  #reload(k) {
    const chart = this.#charts[k];
    const { positions, colours, indices } = this.view.chart(k);
    Object.assign(chart, { depth: this.view.depth(k), positions, colours, indices, base: -1 });
    this.#generation++;
    this.#union.changed(this.view.residentVertices());
  }

  #tellState() {
    const resident = this.view.residentVertices();
    this.options.tell({
      type: 'parts',
      state: {
        charts: this.#charts.length,
        depths: this.#charts.map((c) => c.depth),
        finalDepth: this.parts.finalDepth,
        firstLevel: this.firstLevel,
        level: this.#level(),
        resident,
        budget: this.options.budget,
        bytesFetched: this.#bytes,
        visible: this.#visible,
        inFlight: this.#inFlight,
        settled: this.#camera !== null && this.#inFlight === 0 && !this.#union.pending,
        evictions: this.#evictions,
      },
    });
  }
}
