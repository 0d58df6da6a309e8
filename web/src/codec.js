// @ts-check
/**
 * The Vitrine decoder compiled to WebAssembly (crate `vitrine-wasm`), behind a
 * small promise-free API. Works in browsers, Web Workers and Node.
 *
 * Buffers returned by a level are copies: they stay valid after later calls
 * and can be transferred to another thread.
 */

const POSITIONS = 0;
const COLOURS = 1;
const INDICES = 2;
const LEVEL_INDICES = 3;

/**
 * @typedef {object} Level
 * @property {number} level      batches applied (0 = base mesh)
 * @property {number} vertices
 * @property {Float32Array} positions  x, y, z per vertex
 * @property {Uint8Array | null} colours  r, g, b per vertex
 * @property {Uint32Array} indices   three per triangle
 */

/**
 * One chart of a charted level (format 5).
 * @typedef {object} ChartView
 * @property {Float32Array} positions x, y, z per chart vertex
 * @property {Uint8Array | null} colours r, g, b per chart vertex
 * @property {Uint32Array} levelIndices the chart's triangles in the level's vertex ids
 *   (empty for a chart the decoder leaves to others)
 * @property {number} newFrom the chart's vertices before the last batch: those after
 *   are its insertions, whose level ids follow each other
 */

export class DecodeError extends Error {}

export class VitrineCodec {
  /** @param {WebAssembly.Instance} instance */
  constructor(instance) {
    /** @type {any} */
    this.exports = instance.exports;
  }

  /**
   * @param {WebAssembly.Module | BufferSource} module compiled module or wasm bytes
   * @returns {Promise<VitrineCodec>}
   */
  static async instantiate(module) {
    const compiled = module instanceof WebAssembly.Module ? module : await WebAssembly.compile(module);
    const instance = await WebAssembly.instantiate(compiled, {});
    return new VitrineCodec(instance);
  }

  /** @returns {Uint8Array} */
  memory() {
    return new Uint8Array(this.exports.memory.buffer);
  }

  /** @param {Uint8Array} bytes */
  #write(bytes) {
    const ptr = this.exports.input_reserve(bytes.length);
    this.memory().set(bytes, ptr);
  }

  /** Copies bytes into the decoder's input buffer, for a call that reads them. @param {Uint8Array} bytes */
  input(bytes) {
    this.#write(bytes);
  }

  #error() {
    const ptr = this.exports.error_ptr();
    const len = this.exports.error_len();
    return new DecodeError(new TextDecoder().decode(this.memory().slice(ptr, ptr + len)));
  }

  /**
   * Starts decoding from the stream's header + base mesh.
   * @param {Uint8Array} base
   * @returns {StreamDecoder}
   */
  decoder(base) {
    this.#write(base);
    const handle = this.exports.decoder_new(base.length);
    if (handle === 0) throw this.#error();
    return new StreamDecoder(this, handle);
  }

  /**
   * @param {number} handle
   * @param {Uint8Array} batch
   */
  apply(handle, batch) {
    this.#write(batch);
    if (this.exports.decoder_apply(handle, batch.length) !== 0) throw this.#error();
  }

  /**
   * A decoded level's surface, for geodesic measurements between picked
   * points (crate vitrine-geodesic).
   * @param {Float32Array} positions x, y, z per vertex
   * @param {Uint32Array} indices three per triangle
   * @returns {SurfaceDistance}
   */
  surface(positions, indices) {
    const e = this.exports;
    const p = e.geodesic_positions(positions.length);
    new Float32Array(e.memory.buffer, p, positions.length).set(positions);
    const i = e.geodesic_indices(indices.length);
    new Uint32Array(e.memory.buffer, i, indices.length).set(indices);
    const handle = e.geodesic_new();
    if (handle === 0) throw this.#error();
    return new SurfaceDistance(this, handle);
  }

  /** The last error as a DecodeError. */
  lastError() {
    return this.#error();
  }

  /**
   * A view on a level buffer inside the WebAssembly memory (no copy): valid
   * only until the next call into the decoder, which may move or grow it.
   * @param {number} handle
   * @param {number} kind
   * @returns {{ ptr: number, len: number } | null}
   */
  span(handle, kind) {
    const ptr = this.exports.buffer_ptr(handle, kind);
    const len = this.exports.buffer_len(handle, kind);
    return ptr === 0 && len === 0 ? null : { ptr, len };
  }

  /**
   * @param {number} handle
   * @param {number} kind
   * @param {number} bytesPerElement
   */
  copyBuffer(handle, kind, bytesPerElement) {
    const ptr = this.exports.buffer_ptr(handle, kind);
    const len = this.exports.buffer_len(handle, kind);
    if (ptr === 0 && len === 0) return null;
    return this.exports.memory.buffer.slice(ptr, ptr + len * bytesPerElement);
  }
}

export class StreamDecoder {
  /**
   * @param {VitrineCodec} codec
   * @param {number} handle
   */
  constructor(codec, handle) {
    this.codec = codec;
    this.handle = handle;
  }

  /** Applies the next refinement batch. @param {Uint8Array} batch */
  apply(batch) {
    this.codec.apply(this.handle, batch);
  }

  /** @returns {Level} */
  level() {
    const e = this.codec.exports;
    const positions = this.codec.copyBuffer(this.handle, POSITIONS, 4);
    const colours = this.codec.copyBuffer(this.handle, COLOURS, 1);
    const indices = this.codec.copyBuffer(this.handle, INDICES, 4);
    return {
      level: e.decoder_level(this.handle),
      vertices: e.decoder_vertices(this.handle),
      positions: new Float32Array(/** @type {ArrayBuffer} */ (positions)),
      colours: colours ? new Uint8Array(colours) : null,
      indices: new Uint32Array(/** @type {ArrayBuffer} */ (indices)),
    };
  }

  /**
   * The current level as views into the decoder's memory, not copies: read
   * them (or copy parts out) before the next call into the decoder. Lets the
   * worker compute normals and send only what changed without copying whole
   * levels first.
   * @returns {Level}
   */
  view() {
    const e = this.codec.exports;
    const buffer = e.memory.buffer;
    const positions = this.codec.span(this.handle, POSITIONS);
    const colours = this.codec.span(this.handle, COLOURS);
    const indices = this.codec.span(this.handle, INDICES);
    return {
      level: e.decoder_level(this.handle),
      vertices: e.decoder_vertices(this.handle),
      positions: positions ? new Float32Array(buffer, positions.ptr, positions.len) : new Float32Array(0),
      colours: colours ? new Uint8Array(buffer, colours.ptr, colours.len) : null,
      indices: indices ? new Uint32Array(buffer, indices.ptr, indices.len) : new Uint32Array(0),
    };
  }

  /**
   * Refine only these charts of a charted stream from the next parted
   * batch on, leaving the others to the pool's other members
   * (decode-pool.js); final once made.
   * @param {number[]} charts
   */
  refineOnly(charts) {
    let lo = 0;
    let hi = 0;
    for (const c of charts) {
      if (c < 32) lo |= 1 << c;
      else hi |= 1 << (c - 32);
    }
    if (this.codec.exports.decoder_refine_only(this.handle, lo, hi) !== 0) throw this.codec.lastError();
  }

  /** Charts of the stream once its first parted batch is in (0 before, and for a plain stream). */
  chartCount() {
    return this.codec.exports.decoder_charts(this.handle);
  }

  /**
   * Chart `chart` as views into the decoder's memory (read or copy them
   * before the next call into the decoder).
   * @param {number} chart
   * @returns {ChartView}
   */
  chartView(chart) {
    const e = this.codec.exports;
    const buffer = e.memory.buffer;
    /** @param {number} kind */
    const span = (kind) => ({ ptr: e.chart_buffer_ptr(this.handle, chart, kind), len: e.chart_buffer_len(this.handle, chart, kind) });
    const p = span(POSITIONS);
    const c = span(COLOURS);
    const i = span(LEVEL_INDICES);
    return {
      positions: new Float32Array(buffer, p.ptr, p.len),
      colours: c.ptr === 0 ? null : new Uint8Array(buffer, c.ptr, c.len),
      levelIndices: new Uint32Array(buffer, i.ptr, i.len),
      newFrom: e.chart_new_from(this.handle, chart),
    };
  }

  /**
   * The faces of each chart that a charted stream's first parted batch, not
   * applied yet, will cut the level into: how a pool shares the charts out.
   * @param {Uint8Array} batch
   * @returns {number[]}
   */
  chartSizes(batch) {
    const e = this.codec.exports;
    this.codec.input(batch);
    const charts = e.decoder_chart_sizes(this.handle, batch.length);
    if (charts < 0) throw this.codec.lastError();
    return Array.from(new Uint32Array(e.memory.buffer, e.sizes_ptr(), charts));
  }

  /**
   * Turns this decoder (its global batches applied) into a view whose charts
   * each refine by their own parts (issue 41); this decoder is spent.
   * @param {Uint8Array} head the first parted batch's head ({@link VitrineCodec#partedLayout})
   * @returns {PartView}
   */
  intoView(head) {
    this.codec.input(head);
    const view = this.codec.exports.view_new(this.handle, head.length);
    if (view === 0) throw this.codec.lastError();
    return new PartView(this.codec, view);
  }

  /**
   * Turns this decoder (its global batches applied) into a view of a nested
   * stream's tree of charts (format 6), from what the part index says of
   * each parted batch and the first one's head: no whole batch is needed.
   * This decoder is spent.
   * @param {Uint8Array} head the first parted batch's head (the index's `head_url`)
   * @param {NestedBatch[]} batches every parted batch, in stream order
   * @returns {NestedView}
   */
  intoNested(head, batches) {
    const e = this.codec.exports;
    e.nested_layouts_clear();
    for (const b of batches) {
      this.codec.input(new Uint8Array(Uint32Array.from(b.children).buffer));
      if (e.nested_layout_declare(b.level, b.phase, b.charts, b.children.length) < 0) {
        const error = this.codec.lastError();
        e.nested_layouts_clear();
        throw error;
      }
    }
    this.codec.input(head);
    const view = e.nested_new(this.handle, head.length);
    if (view === 0) throw this.codec.lastError();
    return new NestedView(this.codec, view);
  }

  free() {
    this.codec.exports.decoder_free(this.handle);
  }
}

/**
 * One parted batch of a nested stream as a part index tells it: its level,
 * phase and chart count, and, when it begins a phase after the first, each
 * chart of the phase before's number of children (in order; else empty).
 * @typedef {object} NestedBatch
 * @property {number} level
 * @property {number} phase
 * @property {number} charts
 * @property {number[]} children
 */

/**
 * A parted batch's layout: its level, the head a view starts from and each
 * chart's part, as byte ranges within the batch (an empty range: the chart
 * sits the batch out).
 * @typedef {object} PartedLayout
 * @property {number} level
 * @property {[number, number]} head
 * @property {[number, number][]} parts
 */

/**
 * The layout of a batch: null for a global batch (not cut into parts).
 * @param {VitrineCodec} codec
 * @param {Uint8Array} batch
 * @returns {PartedLayout | null}
 */
export function partedLayout(codec, batch) {
  const e = codec.exports;
  codec.input(batch);
  const charts = e.parted_layout(batch.length);
  if (charts < 0) throw codec.lastError();
  if (charts === 0) return null;
  const words = new Uint32Array(e.memory.buffer, e.sizes_ptr(), 3 + 2 * charts).slice();
  /** @type {[number, number][]} */
  const parts = [];
  for (let k = 0; k < charts; k++) parts.push([words[3 + 2 * k], words[4 + 2 * k]]);
  return { level: words[0], head: [words[1], words[2]], parts };
}

/**
 * A charted stream's charts, each at its own depth: the decoder of a viewer
 * that fetches parts, not batches (codec/core's ChartView). Every chart
 * shares the cut bit for bit whatever the depths, so the union of the
 * charts is watertight.
 */
export class PartView {
  /**
   * @param {VitrineCodec} codec
   * @param {number} handle
   */
  constructor(codec, handle) {
    this.codec = codec;
    this.handle = handle;
  }

  chartCount() {
    return this.codec.exports.view_charts(this.handle);
  }

  /** Parts applied to a chart (0: as the cut left it). @param {number} chart */
  depth(chart) {
    return this.codec.exports.view_depth(this.handle, chart);
  }

  /** The depth of every chart at the stream's final level. */
  finalDepth() {
    return this.codec.exports.view_final_depth(this.handle);
  }

  /** Vertices held, all charts together. */
  residentVertices() {
    return this.codec.exports.view_resident(this.handle);
  }

  /**
   * The most vertices the view may hold: a part past it is refused and
   * changes nothing (reset charts out of view, then try again).
   * @param {number} vertices
   */
  setVertexBudget(vertices) {
    this.codec.exports.view_set_budget(this.handle, Math.min(vertices, 0xffffffff));
  }

  /**
   * Applies a chart's next part; on error the chart is as it was, or back
   * at the cut, and the others are untouched.
   * @param {number} chart
   * @param {Uint8Array} part
   */
  applyPart(chart, part) {
    this.codec.input(part);
    if (this.codec.exports.view_apply_part(this.handle, chart, part.length) !== 0) throw this.codec.lastError();
  }

  /** Puts a chart back where the cut left it, freeing what it had grown. @param {number} chart */
  reset(chart) {
    this.codec.exports.view_reset(this.handle, chart);
  }

  /**
   * One chart as copies: positions, colours and triangles in its own ids.
   * @param {number} chart
   * @returns {{ positions: Float32Array, colours: Uint8Array | null, indices: Uint32Array }}
   */
  chart(chart) {
    const e = this.codec.exports;
    /** @param {number} kind @param {number} size */
    const copy = (kind, size) => {
      const ptr = e.view_buffer_ptr(this.handle, chart, kind);
      const len = e.view_buffer_len(this.handle, chart, kind);
      return ptr === 0 && len === 0 ? null : e.memory.buffer.slice(ptr, ptr + len * size);
    };
    const positions = copy(POSITIONS, 4);
    const colours = copy(COLOURS, 1);
    const indices = copy(INDICES, 4);
    return {
      positions: new Float32Array(positions ?? 0),
      colours: colours ? new Uint8Array(colours) : null,
      indices: new Uint32Array(indices ?? 0),
    };
  }

  free() {
    this.codec.exports.view_free(this.handle);
  }
}

/** Kind of {@link NestedView} buffer: the ids of a chart's first vertices where it was cut from. */
const FIRST_IDS = 4;

/**
 * A nested stream's tree of charts (format 6, codec/core's NestedView):
 * charts are named by their phase and their position in it; each refines
 * by its own parts, and one that has had all its phase's parts splits into
 * its children of the next phase. A parent stays as it was when it splits;
 * dropping a chart drops its descendants. Charts shown at different depths
 * share their borders bit for bit.
 */
export class NestedView {
  /**
   * @param {VitrineCodec} codec
   * @param {number} handle
   */
  constructor(codec, handle) {
    this.codec = codec;
    this.handle = handle;
  }

  phaseCount() {
    return this.codec.exports.nested_phases(this.handle);
  }

  /** @param {number} phase */
  chartCount(phase) {
    return this.codec.exports.nested_charts(this.handle, phase);
  }

  /** Parts each chart of a phase has in all. @param {number} phase */
  phaseBatches(phase) {
    return this.codec.exports.nested_phase_batches(this.handle, phase);
  }

  /** A chart's parent in the phase before (-1 in phase 0). @param {number} phase @param {number} chart */
  parent(phase, chart) {
    return this.codec.exports.nested_parent(this.handle, phase, chart);
  }

  /**
   * A chart's children in the phase after, as [first, end) (empty in the last phase).
   * @param {number} phase
   * @param {number} chart
   * @returns {[number, number]}
   */
  children(phase, chart) {
    const e = this.codec.exports;
    const first = e.nested_first_child(this.handle, phase, chart);
    return [first, first + e.nested_children(this.handle, phase, chart)];
  }

  /** Parts applied to a chart in its phase; -1 while it is not in the view. @param {number} phase @param {number} chart */
  depth(phase, chart) {
    return this.codec.exports.nested_depth(this.handle, phase, chart);
  }

  /** Vertices held, all charts together, each counting its own copy. */
  residentVertices() {
    return this.codec.exports.nested_resident(this.handle);
  }

  /**
   * Applies a chart's next part of its phase (empty: it sits the batch
   * out); a part that fails part-way removes the chart.
   * @param {number} phase
   * @param {number} chart
   * @param {Uint8Array} part
   */
  applyPart(phase, chart, part) {
    this.codec.input(part);
    if (this.codec.exports.nested_apply_part(this.handle, phase, chart, part.length) !== 0) throw this.codec.lastError();
  }

  /**
   * Splits a chart that has had all its phase's parts into its children, by its split entry.
   * @param {number} phase
   * @param {number} chart
   * @param {Uint8Array} entry
   */
  split(phase, chart, entry) {
    this.codec.input(entry);
    if (this.codec.exports.nested_split(this.handle, phase, chart, entry.length) !== 0) throw this.codec.lastError();
  }

  /** Drops a chart of phase >= 1 and its descendants. @param {number} phase @param {number} chart */
  drop(phase, chart) {
    this.codec.exports.nested_drop(this.handle, phase, chart);
  }

  /**
   * One chart as copies: positions, colours, triangles in its own ids, and
   * the ids of its first vertices where it was cut from (its parent's, or
   * in phase 0 the level where the charts begin).
   * @param {number} phase
   * @param {number} chart
   * @returns {{ positions: Float32Array, colours: Uint8Array | null, indices: Uint32Array, firstIds: Uint32Array }}
   */
  chart(phase, chart) {
    const e = this.codec.exports;
    /** @param {number} kind @param {number} size */
    const copy = (kind, size) => {
      const ptr = e.nested_buffer_ptr(this.handle, phase, chart, kind);
      const len = e.nested_buffer_len(this.handle, phase, chart, kind);
      return ptr === 0 && len === 0 ? null : e.memory.buffer.slice(ptr, ptr + len * size);
    };
    const positions = copy(POSITIONS, 4);
    const colours = copy(COLOURS, 1);
    const indices = copy(INDICES, 4);
    const firstIds = copy(FIRST_IDS, 4);
    return {
      positions: new Float32Array(positions ?? 0),
      colours: colours ? new Uint8Array(colours) : null,
      indices: new Uint32Array(indices ?? 0),
      firstIds: new Uint32Array(firstIds ?? 0),
    };
  }

  free() {
    this.codec.exports.nested_free(this.handle);
  }
}

/** Geodesic distance by Dijkstra on edges (0) or fast marching on faces (1). */
export const DIJKSTRA = 0;
export const FAST_MARCHING = 1;

/**
 * Distance along a level's surface (see VitrineCodec.surface). Points are
 * positions; each is taken to the nearest point of the surface.
 */
export class SurfaceDistance {
  /**
   * @param {VitrineCodec} codec
   * @param {number} handle
   */
  constructor(codec, handle) {
    this.codec = codec;
    this.handle = handle;
  }

  /**
   * Distance along the surface between two points (Infinity across parts).
   * @param {ArrayLike<number>} from x, y, z
   * @param {ArrayLike<number>} to x, y, z
   * @param {number} [method] DIJKSTRA or FAST_MARCHING (default)
   */
  distance(from, to, method = FAST_MARCHING) {
    const d = this.codec.exports.geodesic_distance(this.handle, method, from[0], from[1], from[2], to[0], to[1], to[2]);
    if (Number.isNaN(d)) throw this.codec.lastError();
    return d;
  }

  /**
   * Distance from a point to every vertex (a copy).
   * @param {ArrayLike<number>} from x, y, z
   * @param {number} [method] DIJKSTRA or FAST_MARCHING (default)
   * @returns {Float64Array}
   */
  field(from, method = FAST_MARCHING) {
    const e = this.codec.exports;
    const ptr = e.geodesic_field(this.handle, method, from[0], from[1], from[2]);
    if (ptr === 0) throw this.codec.lastError();
    return new Float64Array(e.memory.buffer.slice(ptr, ptr + 8 * e.geodesic_field_len()));
  }

  free() {
    this.codec.exports.geodesic_free(this.handle);
  }
}

/**
 * Splits a whole stream file into its base part and batches, reading only
 * the level table (see codec/core/FORMAT.md).
 * @param {Uint8Array} stream
 */
export function splitStream(stream) {
  const view = new DataView(stream.buffer, stream.byteOffset, stream.byteLength);
  const magic = String.fromCharCode(...stream.subarray(0, 4));
  if (magic !== 'VTRN') throw new DecodeError('not a Vitrine stream');
  const levels = levelTable(stream);
  let at = 40 + 12 * (levels.length - 1);
  const parts = [];
  for (const [k, { bytes }] of levels.entries()) {
    parts.push(stream.subarray(k === 0 ? 0 : at, at + bytes));
    at += bytes;
  }
  return { base: parts[0], batches: parts.slice(1) };
}

/**
 * A stream's level table (FORMAT.md), from its header: each level's vertex
 * and face counts and its chunk's bytes (the base's includes the header).
 * @param {Uint8Array} stream the stream, or any prefix holding its header
 * @returns {{ vertices: number, faces: number, bytes: number }[]}
 */
export function levelTable(stream) {
  const view = new DataView(stream.buffer, stream.byteOffset, stream.byteLength);
  const batches = view.getUint32(24, true);
  return Array.from({ length: batches + 1 }, (_, k) => ({
    vertices: view.getUint32(28 + 12 * k, true),
    faces: view.getUint32(28 + 12 * k + 4, true),
    bytes: view.getUint32(28 + 12 * k + 8, true),
  }));
}

/** The chunk tag of a parted batch (a charted stream's fine levels). */
export const PARTED_TAG = 0x50;
