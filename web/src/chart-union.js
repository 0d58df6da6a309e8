// @ts-check
/**
 * The charts a view-dependent refinement shows, sent to the renderer as one
 * level: shared by charted streams (part-refinement.js) and nested ones
 * (nested-refinement.js), in the decode worker.
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
 * positions: they are welded by position, and their normals summed over
 * every chart that holds them, so the shading is continuous across chart
 * borders, as the mesh is.
 */

import { accumulateNormals, edgeIndices, packNormals } from './geometry.js';

/**
 * The union is posted at most every PUBLISH_MS while parts arrive, and
 * less often as it grows (one more millisecond per {@link PUBLISH_VERTICES_PER_MS}
 * vertices: 460 ms at 4 M): each post uploads all its triangles again, and
 * the renderer drops an upload that a newer post overtakes.
 */
const PUBLISH_MS = 60;
const PUBLISH_VERTICES_PER_MS = 10_000;

/**
 * One chart as shown.
 * @typedef {object} UnionPiece
 * @property {Float32Array} positions
 * @property {Uint8Array | null} colours
 * @property {Uint32Array} indices in the chart's own ids
 * @property {number} base where its vertices start in the renderer's store (-1: not sent since it changed)
 */

/**
 * Vertices shared by several pieces: per piece, pairs of (its vertex id,
 * weld group); `groups` groups in all.
 * @typedef {{ pairs: Uint32Array[], groups: number }} Weld
 */

/**
 * Welds pieces by position: a position held by several of them is one
 * vertex of the surface (the cut is the same bit for bit in every chart).
 * @param {{ positions: Float32Array }[]} pieces
 * @param {(Uint32Array | null)[]} [candidates] per piece, the only vertices
 *   that may be shared (its border); null or absent: all of them
 * @returns {Weld}
 */
export function weldByPosition(pieces, candidates) {
  /** @type {Map<string, number[]>} */
  const byPosition = new Map();
  for (const [k, { positions: p }] of pieces.entries()) {
    const ids = candidates?.[k];
    const count = ids ? ids.length : p.length / 3;
    for (let j = 0; j < count; j++) {
      const i = ids ? ids[j] : j;
      const key = `${p[3 * i]} ${p[3 * i + 1]} ${p[3 * i + 2]}`;
      const holders = byPosition.get(key);
      if (holders) holders.push(k, i);
      else byPosition.set(key, [k, i]);
    }
  }
  /** @type {number[][]} */
  const pairs = pieces.map(() => []);
  let groups = 0;
  for (const holders of byPosition.values()) {
    if (holders.length < 4) continue;
    const group = groups++;
    for (let j = 0; j < holders.length; j += 2) pairs[holders[j]].push(holders[j + 1], group);
  }
  return { pairs: pairs.map((p) => Uint32Array.from(p)), groups };
}

/**
 * What the union is made of at the moment it is posted.
 * @typedef {object} UnionSource
 * @property {UnionPiece[]} pieces the charts shown, each once
 * @property {Weld} weld over `pieces`
 * @property {number} level what the page shows as the level on screen
 * @property {number} received payload bytes so far
 */

/**
 * @typedef {object} ChartUnionOptions
 * @property {number} sentVertices vertices the renderer holds already (the global level's)
 * @property {import('./geometry.js').Bounds} baseBounds
 * @property {boolean} wireframe
 * @property {import('./reconstruction.js').Post} post levels (to the renderer)
 * @property {() => UnionSource} source the union now
 * @property {() => void} posted after each post
 */

export class ChartUnion {
  #sent;
  /** The global level's vertices, never written over. */
  #kept;
  /** @type {ReturnType<typeof setTimeout> | null} */
  #timer = null;
  #changed = false;
  #stopped = false;

  /** @param {ChartUnionOptions} options */
  constructor(options) {
    this.options = options;
    this.#sent = options.sentVertices;
    this.#kept = options.sentVertices;
  }

  /** Whether a change waits to be posted. */
  get pending() {
    return this.#changed || this.#timer !== null;
  }

  /**
   * A piece changed (its `base` set to -1 by the caller): the union is
   * posted soon, later the more vertices are resident.
   * @param {number} resident
   */
  changed(resident) {
    this.#changed = true;
    this.#timer ??= setTimeout(
      () => {
        this.#timer = null;
        if (!this.#stopped) this.publish();
      },
      Math.max(PUBLISH_MS, resident / PUBLISH_VERTICES_PER_MS),
    );
  }

  /** @param {boolean} on */
  setWireframe(on) {
    this.options.wireframe = on;
    if (on && !this.#stopped) this.publish();
  }

  stop() {
    this.#stopped = true;
    if (this.#timer) clearTimeout(this.#timer);
    this.#timer = null;
  }

  /**
   * The union as one compact level (measurements along the surface, the
   * splat view), its triangles welded at the cut: every piece's triangles
   * use the first copy of a cut vertex, so paths cross chart borders.
   * @returns {import('./codec.js').Level}
   */
  current() {
    const { pieces, weld, level } = this.options.source();
    const vertices = pieces.reduce((n, c) => n + c.positions.length / 3, 0);
    const positions = new Float32Array(3 * vertices);
    const colours = pieces[0]?.colours ? new Uint8Array(3 * vertices) : null;
    const indices = new Uint32Array(pieces.reduce((n, c) => n + c.indices.length, 0));
    const canonical = new Int32Array(weld.groups).fill(-1);
    let v = 0;
    let t = 0;
    for (const [k, c] of pieces.entries()) {
      positions.set(c.positions, 3 * v);
      if (colours && c.colours) colours.set(c.colours, 3 * v);
      const ids = new Uint32Array(c.positions.length / 3).map((_, i) => v + i);
      const pairs = weld.pairs[k];
      for (let j = 0; j < pairs.length; j += 2) {
        const group = pairs[j + 1];
        if (canonical[group] < 0) canonical[group] = ids[pairs[j]];
        else ids[pairs[j]] = canonical[group];
      }
      for (let i = 0; i < c.indices.length; i++) indices[t + i] = ids[c.indices[i]];
      v += c.positions.length / 3;
      t += c.indices.length;
    }
    return { level, vertices, positions, colours, indices };
  }

  /**
   * Posts the union: the pieces that changed appended to the renderer's
   * store, every piece's triangles, normals welded across the cut.
   */
  publish() {
    const { pieces, weld, level, received } = this.options.source();
    const live = pieces.reduce((n, c) => n + c.positions.length / 3, 0);
    let fresh = pieces.filter((c) => c.base < 0);
    let first = this.#sent;
    const adding = fresh.reduce((n, c) => n + c.positions.length / 3, 0);
    if (first + adding > 2 * live + 65_536) {
      // Stale copies outweigh the live ones: send everything again.
      for (const c of pieces) c.base = -1;
      fresh = pieces;
      first = this.#kept;
    }
    let end = first;
    for (const c of fresh) {
      c.base = end;
      end += c.positions.length / 3;
    }
    const positions = new Float32Array(3 * (end - first));
    const colours = pieces[0]?.colours ? new Uint8Array(3 * (end - first)) : null;
    for (const c of fresh) {
      positions.set(c.positions, 3 * (c.base - first));
      if (colours && c.colours) colours.set(c.colours, 3 * (c.base - first));
    }
    const indices = new Uint32Array(pieces.reduce((n, c) => n + c.indices.length, 0));
    let t = 0;
    for (const c of pieces) {
      for (let i = 0; i < c.indices.length; i++) indices[t + i] = c.indices[i] + c.base;
      t += c.indices.length;
    }
    this.#sent = end;
    const normals = weldedNormals(pieces, weld, end);
    const edges = this.options.wireframe ? edgeIndices(indices, end) : null;
    /** @type {Transferable[]} */
    const transfer = [positions.buffer, indices.buffer, normals.buffer];
    if (colours) transfer.push(colours.buffer);
    if (edges) transfer.push(edges.buffer);
    this.#changed = false;
    this.options.post(
      {
        type: 'level',
        level,
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
        received,
        decodeMs: 0,
        deriveMs: 0,
        decoders: 1,
        standIn: false,
      },
      transfer,
    );
    this.options.posted();
  }
}

/**
 * Smooth normals of every piece, summed over the pieces for the welded
 * vertices, packed at each piece's place in the store.
 * @param {UnionPiece[]} pieces
 * @param {Weld} weld
 * @param {number} vertices the store's
 */
function weldedNormals(pieces, weld, vertices) {
  const sums = pieces.map((c) => {
    const sum = new Float32Array(c.positions.length);
    accumulateNormals(c.positions, c.indices, sum, 0, c.indices.length);
    return sum;
  });
  const group = new Float64Array(3 * weld.groups);
  for (const [k, pairs] of weld.pairs.entries()) {
    for (let j = 0; j < pairs.length; j += 2) {
      for (let a = 0; a < 3; a++) group[3 * pairs[j + 1] + a] += sums[k][3 * pairs[j] + a];
    }
  }
  const packed = new Int16Array(3 * vertices);
  for (const [k, c] of pieces.entries()) {
    const sum = sums[k];
    const pairs = weld.pairs[k];
    for (let j = 0; j < pairs.length; j += 2) {
      for (let a = 0; a < 3; a++) sum[3 * pairs[j] + a] = group[3 * pairs[j + 1] + a];
    }
    packNormals(sum, packed.subarray(3 * c.base, 3 * c.base + sum.length), 0, sum.length);
  }
  return packed;
}
