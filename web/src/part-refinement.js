// @ts-check
/**
 * View-dependent refinement of a charted stream (issue 41), in the decode
 * worker: after the global batches the decoder becomes a PartView (codec.js),
 * each chart refines by its own parts as the camera asks (part-selection.js),
 * and the union of the charts goes to the renderer as a level.
 *
 * The renderer's vertex store is append-only (vertex-store.js): a chart that
 * changed is appended whole at the end, the others keep their place, and
 * the indices of every chart point at its newest copy. When the stale
 * copies outweigh the live ones, every chart is sent again from the end of
 * the global level's vertices, which stay: that level remains a valid
 * stand-in while the view moves (motion.js), and no union ever becomes one
 * (`standIn: false`), since its vertices may be written over. Until the
 * union sent again is uploaded, the one on screen may read some of its
 * vertices: a frame or two of wrong triangles after such a compaction.
 * Cut vertices are duplicated across charts, bit for bit the same
 * positions: their normals are summed over every chart that holds them, so
 * the shading is continuous across chart borders, as the mesh is.
 */

import { DecodeError } from './codec.js';
import { accumulateNormals, edgeIndices, packNormals } from './geometry.js';
import { PARTS_IN_FLIGHT, assess, boundingSphere, evictionOrder, normalCone, partTable, wantedParts } from './part-selection.js';

/**
 * The union is posted at most every PUBLISH_MS while parts arrive, and
 * less often as it grows (one more millisecond per {@link PUBLISH_VERTICES_PER_MS}
 * vertices: 460 ms at 4 M): each post uploads all its triangles again, and
 * the renderer drops an upload that a newer post overtakes.
 */
const PUBLISH_MS = 60;
const PUBLISH_VERTICES_PER_MS = 10_000;

/**
 * @typedef {object} PartsState what the page reads (viewer.partsState())
 * @property {number} charts
 * @property {number[]} depths parts applied per chart
 * @property {number} finalDepth
 * @property {number} firstLevel the first parted batch's level: a chart at depth d is at level firstLevel − 1 + d
 * @property {number} resident vertices held, all charts together
 * @property {number} budget
 * @property {number} bytesFetched payload bytes of this load: base, global batches, part index, head and parts
 * @property {boolean[]} visible per chart, in the view's frustum
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
  /** Cut vertices: per chart, pairs of (chart id, weld group). @type {Uint32Array[]} */
  #shared;
  #groups = 0;
  /** @type {import('./part-selection.js').PartCamera | null} */
  #camera = null;
  #inFlight = 0;
  /** Vertices the parts on their way will add. */
  #reserved = 0;
  #sent;
  /** The global level's vertices, never written over. */
  #kept;
  #bytes;
  #evictions = 0;
  /** @type {ReturnType<typeof setTimeout> | null} */
  #timer = null;
  #changed = false;
  #stopped = false;
  /** @type {boolean[]} */
  #visible;

  /** @param {PartRefinementOptions} options */
  constructor(options) {
    this.options = options;
    this.view = options.view;
    this.parts = partTable(options.index);
    this.firstLevel = options.index.first_level;
    this.capLevel = options.capLevel;
    this.#sent = options.sentVertices;
    this.#kept = options.sentVertices;
    this.#bytes = options.bytesFetched;
    this.view.setVertexBudget(options.budget);
    const count = this.view.chartCount();
    if (count !== options.index.charts) throw new DecodeError(`the part index has ${options.index.charts} charts, the stream ${count}`);
    this.#charts = Array.from({ length: count }, (_, k) => {
      const { positions, colours, indices } = this.view.chart(k);
      return { depth: 0, cutVertices: positions.length / 3, sphere: boundingSphere(positions), cone: normalCone(positions, indices), busy: false, yielded: false, positions, colours, indices, base: -1 };
    });
    this.#visible = new Array(count).fill(true);
    this.#shared = this.#weld();
    this.#publish();
  }

  /**
   * Cut vertices, found by position at the cut: a position held by several
   * charts is one vertex of the surface. Their ids within each chart never
   * change (a part appends the vertices it inserts; a reset goes back to
   * the cut).
   */
  #weld() {
    /** @type {Map<string, number[]>} */
    const byPosition = new Map();
    for (const [k, c] of this.#charts.entries()) {
      const p = c.positions;
      for (let i = 0; i < p.length / 3; i++) {
        const key = `${p[3 * i]} ${p[3 * i + 1]} ${p[3 * i + 2]}`;
        const holders = byPosition.get(key);
        if (holders) holders.push(k, i);
        else byPosition.set(key, [k, i]);
      }
    }
    /** @type {number[][]} */
    const pairs = this.#charts.map(() => []);
    for (const holders of byPosition.values()) {
      if (holders.length < 4) continue;
      const group = this.#groups++;
      for (let j = 0; j < holders.length; j += 2) pairs[holders[j]].push(holders[j + 1], group);
    }
    return pairs.map((p) => Uint32Array.from(p));
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
    this.options.wireframe = on;
    if (on) this.#publish();
  }

  stop() {
    this.#stopped = true;
    if (this.#timer) clearTimeout(this.#timer);
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
   * The union as one compact level (measurements along the surface, the
   * splat view), its triangles welded at the cut: every chart's triangles
   * use the first copy of a cut vertex, so paths cross chart borders.
   * @returns {import('./codec.js').Level}
   */
  current() {
    const vertices = this.#charts.reduce((n, c) => n + c.positions.length / 3, 0);
    const positions = new Float32Array(3 * vertices);
    const colours = this.#charts[0]?.colours ? new Uint8Array(3 * vertices) : null;
    const indices = new Uint32Array(this.#charts.reduce((n, c) => n + c.indices.length, 0));
    const canonical = new Int32Array(this.#groups).fill(-1);
    let v = 0;
    let t = 0;
    for (const [k, c] of this.#charts.entries()) {
      positions.set(c.positions, 3 * v);
      if (colours && c.colours) colours.set(c.colours, 3 * v);
      const ids = new Uint32Array(c.positions.length / 3).map((_, i) => v + i);
      const pairs = this.#shared[k];
      for (let j = 0; j < pairs.length; j += 2) {
        const group = pairs[j + 1];
        if (canonical[group] < 0) canonical[group] = ids[pairs[j]];
        else ids[pairs[j]] = canonical[group];
      }
      for (let i = 0; i < c.indices.length; i++) indices[t + i] = ids[c.indices[i]];
      v += c.positions.length / 3;
      t += c.indices.length;
    }
    return { level: this.#level(), vertices, positions, colours, indices };
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
      const limits = { firstLevel: this.firstLevel, capLevel: this.capLevel };
      const wanted = wantedParts(this.#charts, this.parts, camera, limits);
      const assessed = assess(this.#charts, this.parts, camera);
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
    this.#changed = true;
    this.#timer ??= setTimeout(
      () => {
        this.#timer = null;
        if (!this.#stopped) this.#publish();
      },
      Math.max(PUBLISH_MS, this.view.residentVertices() / PUBLISH_VERTICES_PER_MS),
    );
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
        resident,
        budget: this.options.budget,
        bytesFetched: this.#bytes,
        visible: this.#visible,
        inFlight: this.#inFlight,
        settled: this.#camera !== null && this.#inFlight === 0 && this.#timer === null && !this.#changed,
        evictions: this.#evictions,
      },
    });
  }

  /**
   * Posts the union: the charts that changed appended to the renderer's
   * store, every chart's triangles, normals welded across the cut.
   */
  #publish() {
    const charts = this.#charts;
    const live = charts.reduce((n, c) => n + c.positions.length / 3, 0);
    let fresh = charts.filter((c) => c.base < 0);
    let first = this.#sent;
    const adding = fresh.reduce((n, c) => n + c.positions.length / 3, 0);
    if (first + adding > 2 * live + 65_536) {
      // Stale copies outweigh the live ones: send everything again.
      for (const c of charts) c.base = -1;
      fresh = charts;
      first = this.#kept;
    }
    let end = first;
    for (const c of fresh) {
      c.base = end;
      end += c.positions.length / 3;
    }
    const positions = new Float32Array(3 * (end - first));
    const colours = charts[0]?.colours ? new Uint8Array(3 * (end - first)) : null;
    for (const c of fresh) {
      positions.set(c.positions, 3 * (c.base - first));
      if (colours && c.colours) colours.set(c.colours, 3 * (c.base - first));
    }
    const indices = new Uint32Array(charts.reduce((n, c) => n + c.indices.length, 0));
    let t = 0;
    for (const c of charts) {
      for (let i = 0; i < c.indices.length; i++) indices[t + i] = c.indices[i] + c.base;
      t += c.indices.length;
    }
    this.#sent = end;
    const normals = this.#normals(end);
    const edges = this.options.wireframe ? edgeIndices(indices, end) : null;
    /** @type {Transferable[]} */
    const transfer = [positions.buffer, indices.buffer, normals.buffer];
    if (colours) transfer.push(colours.buffer);
    if (edges) transfer.push(edges.buffer);
    this.#changed = false;
    this.options.post(
      {
        type: 'level',
        level: this.#level(),
        vertices: end,
        faces: indices.length / 3,
        firstVertex: first,
        capacity: end,
        positions,
        normals,
        colours,
        indices,
        edges,
        baseBounds: this.options.baseBounds,
        received: this.#bytes,
        decodeMs: 0,
        deriveMs: 0,
        decoders: 1,
        standIn: false,
      },
      transfer,
    );
    this.#tellState();
  }

  /**
   * Smooth normals of every chart, summed over the charts for the cut
   * vertices, packed at each chart's place in the store.
   * @param {number} vertices the store's
   */
  #normals(vertices) {
    const sums = this.#charts.map((c) => {
      const sum = new Float32Array(c.positions.length);
      accumulateNormals(c.positions, c.indices, sum, 0, c.indices.length);
      return sum;
    });
    const group = new Float64Array(3 * this.#groups);
    for (const [k, pairs] of this.#shared.entries()) {
      for (let j = 0; j < pairs.length; j += 2) {
        for (let a = 0; a < 3; a++) group[3 * pairs[j + 1] + a] += sums[k][3 * pairs[j] + a];
      }
    }
    const packed = new Int16Array(3 * vertices);
    for (const [k, c] of this.#charts.entries()) {
      const sum = sums[k];
      const pairs = this.#shared[k];
      for (let j = 0; j < pairs.length; j += 2) {
        for (let a = 0; a < 3; a++) sum[3 * pairs[j] + a] = group[3 * pairs[j + 1] + a];
      }
      packNormals(sum, packed.subarray(3 * c.base, 3 * c.base + sum.length), 0, sum.length);
    }
    return packed;
  }
}
