// @ts-check
/**
 * Progressive reconstruction (thesis §6.4): the base mesh, then refinement
 * batches in order, m_i = decode(m_{i-1}, d_{i-1}), up to the visitor's level
 * cap. Batch k+1 is requested as soon as batch k has arrived, so the network
 * works while the decoder does. Runs inside the decode worker; it has no DOM
 * or worker dependency so Node tests drive it with a fake `fetch`.
 */

import { DecodeError } from './codec.js';
import { PooledDecoder } from './decode-pool.js';
import { bounds, edgeIndices, vertexNormals } from './geometry.js';
import { normalDeviation, reliefTop } from './relief.js';
import { NetworkError, fetchPayload } from './payload.js';

/**
 * @typedef {object} LoadRequest
 * @property {string} baseUrl absolute URL of header + base mesh
 * @property {string[]} batchUrls absolute URLs; batchUrls[k - 1] produces level k
 * @property {number} upTo the highest level to reach now (the visitor's cap)
 * @property {'each' | 'last'} show post every level, or only the last one reached
 * @property {number} [showFrom] with `each`, post levels from this one on (a retry
 *   does not step back through levels already on screen)
 * @property {boolean} wireframe also build the edge list of each posted level
 * @property {boolean} [relief] also compute θ (relief.js) of each posted level
 * @property {'always' | 'last'} [normals] which posted levels carry their normals:
 *   every one (the default: the renderer is on the page's main thread), or only
 *   the level this worker stops at (`upTo`), when it has nothing else to do;
 *   the levels before it go without, straight on to the next batch, and a
 *   render worker derives normals for those it draws (levels superseded while
 *   they wait for it never are)
 * @property {Record<string, string>} [headers] sent with every request
 * @property {number} [capacity] vertices of the last level (from the manifest): the
 *   renderer sizes its position and colour buffers once for it
 * @property {PartsRequest} [parts] refine a charted or nested stream by parts where the camera
 *   looks, after its global batches (worker.js, part-refinement.js, nested-refinement.js)
 */

/**
 * @typedef {object} PartsRequest
 * @property {string} indexUrl absolute URL of the part index (the manifest's `parts` or `nested_parts`)
 * @property {boolean} [nested] a nested stream's (format 6: nested-refinement.js)
 * @property {string} apiBase the URL the index's paths are relative to (the manifest's)
 * @property {[string, string][]} query forwarded on every request (`device`, `token`)
 * @property {number} budget resident vertices, at most
 */

/**
 * @typedef {object} LevelMessage
 * @property {'level'} type
 * @property {number} level
 * @property {number} vertices
 * @property {number} faces
 * @property {number} [firstVertex] `positions` and `colours` hold the vertices from
 *   this one on; the ones before it were posted with an earlier level and have
 *   not changed (0 or absent: the whole level)
 * @property {number} [capacity] vertices the renderer should make room for
 *   (the last level's), so later levels append without reallocating
 * @property {Float32Array} positions x, y, z of vertices firstVertex…vertices − 1
 * @property {Int16Array | null} normals normalised int16 x, y, z of every vertex
 *   (null: not computed, the renderer derives them; see LoadRequest.normals)
 * @property {Uint8Array | null} colours r, g, b of vertices firstVertex…vertices − 1
 * @property {Uint32Array} indices
 * @property {Uint32Array | null} edges
 * @property {Float32Array | null} [relief] θ of every vertex in radians (the relief
 *   view; null or absent when it was off)
 * @property {number | null} [reliefTop] the top of θ's colour scale in degrees
 *   (relief.js `reliefTop`), with `relief`
 * @property {import('./geometry.js').Bounds} baseBounds bounds of the base mesh: the
 *   camera frames these, so the view does not shift when a level or a direct
 *   load of the last level arrives
 * @property {number} received payload bytes received so far
 * @property {number} decodeMs time in the WASM decoder so far (apply + copy out)
 * @property {number} deriveMs time computing normals, edges and θ so far
 * @property {number} decoders members decoding the stream (1, or a pool's size: decode-pool.js)
 * @property {boolean} [standIn] false: never the stand-in while the view moves (motion.js), as
 *   the vertices it reads may be sent again (part-refinement.js)
 */

/**
 * @typedef {{ type: 'progress', received: number }
 *   | { type: 'edges', level: number, edges: Uint32Array }
 *   | { type: 'relief', level: number, relief: Float32Array, top: number }
 *   | { type: 'capped', level: number, status: number, reason: string | null, retryAfterS: number | null }
 *   | { type: 'error', kind: 'network' | 'decode', level: number, message: string }
 *   | { type: 'done', level: number }} StatusMessage
 * `relief`: θ of a level posted before the relief view was switched on.
 * `capped`: the server refused the next batch (the cap fell since the
 * manifest was read); `done`: `upTo` is reached and nothing is pending.
 */

/** @typedef {LevelMessage | StatusMessage} WorkerMessage */

/**
 * What the page's main thread gets for a level when the buffers went to a
 * render worker: a few numbers, nothing to copy.
 * @typedef {Pick<LevelMessage, 'type' | 'level' | 'vertices' | 'faces' | 'baseBounds' | 'received' | 'decodeMs' | 'deriveMs' | 'decoders'>} LevelNotice
 */

/** @typedef {LevelNotice | StatusMessage} PageMessage */

/** @typedef {(message: WorkerMessage, transfer: Transferable[]) => void} Post */

/** @typedef {import('./payload.js').Fetched} Fetched */

/**
 * What decodes the levels: the codec's decoder, or for a charted stream
 * with helpers a pool of them (decode-pool.js), whose `apply` is async.
 * @typedef {import('./codec.js').StreamDecoder | PooledDecoder} LevelDecoder
 */

/** The stream format whose charts a pool can refine in parallel (codec/core/FORMAT.md). */
const CHARTED_FORMAT = 5;

export { NetworkError };

const PROGRESS_EVERY_MS = 100;

export class Reconstruction {
  /** @type {LevelDecoder | null} */
  #decoder = null;
  /** @type {Map<number, Promise<Fetched>>} */
  #inFlight = new Map();
  /** @type {(() => void) | null} */
  #wake = null;
  #abort = new AbortController();
  #cancelled = false;
  #received = 0;
  #decodeMs = 0;
  #deriveMs = 0;
  #lastProgress = 0;
  /** Vertices whose positions and colours have been posted (they never change). */
  #sentVertices = 0;
  /** The newest level posted, and the newest whose θ went with it or after it (-1: none). */
  #postedLevel = -1;
  #reliefLevel = -1;
  /** @type {import('./geometry.js').Bounds} */
  #baseBounds = { min: [0, 0, 0], max: [0, 0, 0] };
  /** Levels applied so far; -1 before the base mesh. */
  level = -1;

  /**
   * @param {import('./codec.js').VitrineCodec} codec
   * @param {LoadRequest} request
   * @param {Post} post
   * @param {typeof fetch} [fetchImpl]
   * @param {import('./decode-pool.js').HelperPort[]} [helpers] decode helpers (chart-worker.js):
   *   a charted stream's charts are refined by them and this worker together
   */
  constructor(codec, request, post, fetchImpl = (input, init) => fetch(input, init), helpers = []) {
    this.codec = codec;
    this.request = { ...request };
    this.post = post;
    this.fetchImpl = fetchImpl;
    this.helpers = helpers;
  }

  /** Members decoding the stream: 1, or the pool's size once a charted stream started one. */
  get decoders() {
    return this.#decoder instanceof PooledDecoder ? this.#decoder.members : 1;
  }

  /**
   * Raises (or lowers) the level to reach; resumes a waiting run.
   * @param {number} upTo
   */
  extend(upTo) {
    this.request.upTo = Math.min(upTo, this.request.batchUrls.length);
    this.#wake?.();
  }

  /**
   * Which levels posted from now on carry their normals (the page says
   * 'always' once it knows its renderer is on the main thread).
   * @param {'always' | 'last'} which
   */
  setNormals(which) {
    this.request.normals = which;
  }

  /** @param {boolean} on */
  setWireframe(on) {
    this.request.wireframe = on;
    if (on && this.#decoder && this.level >= 0) {
      const t0 = performance.now();
      const { indices, vertices } = this.#decoder.view();
      const edges = edgeIndices(indices, vertices);
      this.#deriveMs += performance.now() - t0;
      this.post({ type: 'edges', level: this.level, edges }, [edges.buffer]);
    }
  }

  /**
   * Computes θ for every level posted from now on; switched on, also for
   * the level last posted if its θ was never sent (the renderer keeps the θ
   * it got, so switching off and on again costs nothing).
   * @param {boolean} on
   */
  setRelief(on) {
    this.request.relief = on;
    if (!on || !this.#decoder || this.#postedLevel < 0 || this.#postedLevel !== this.level) return;
    if (this.#reliefLevel === this.level) return;
    const t0 = performance.now();
    const { positions, indices, vertices } = this.#decoder.view();
    const relief = normalDeviation(positions, indices, vertices);
    const top = reliefTop(relief);
    this.#deriveMs += performance.now() - t0;
    this.#reliefLevel = this.level;
    this.post({ type: 'relief', level: this.level, relief, top }, [relief.buffer]);
  }

  /**
   * Distance along the surface of the newest decoded level between two
   * points (model coordinates; each taken to its nearest surface point):
   * the geodesic library in the codec (fast marching), on a copy of the
   * level, which the library keeps while it measures.
   * @param {ArrayLike<number>} from
   * @param {ArrayLike<number>} to
   * @returns {{ distance: number, level: number }}
   */
  surfaceDistance(from, to) {
    if (!this.#decoder || this.level < 0) throw new Error('no level decoded yet');
    const { positions, indices } = this.#decoder.view();
    // Copies: the library's allocations may move the decoder's memory.
    const surface = this.codec.surface(positions.slice(), indices.slice());
    try {
      return { distance: surface.distance(from, to), level: this.level };
    } finally {
      surface.free();
    }
  }

  /**
   * A copy of the level decoded last (the splat view of a mesh).
   * @returns {import('./codec.js').Level}
   */
  current() {
    if (!this.#decoder || this.level < 0) throw new Error('no level decoded yet');
    return this.#decoder.level();
  }

  /**
   * Hands the decoder over, its batches applied (view-dependent refinement:
   * part-refinement.js), and stops; null with a pool (decode-pool.js).
   * @returns {import('./codec.js').StreamDecoder | null}
   */
  release() {
    const decoder = this.#decoder instanceof PooledDecoder ? null : this.#decoder;
    if (decoder) this.#decoder = null;
    this.cancel();
    return decoder;
  }

  cancel() {
    this.#cancelled = true;
    this.#abort.abort();
    this.#wake?.();
    this.#decoder?.free();
    this.#decoder = null;
  }

  /** Runs until cancelled or failed; errors are posted, never thrown. */
  async run() {
    try {
      await this.#run();
    } catch (error) {
      if (this.#cancelled) return;
      const kind = error instanceof NetworkError ? 'network' : 'decode';
      this.post({ type: 'error', kind, level: this.level, message: describe(error) }, []);
    }
  }

  async #run() {
    const base = await this.#fetch(0, this.request.baseUrl);
    if (this.#cancelled) return;
    if (!('bytes' in base)) throw new NetworkError('the server refused the base mesh');
    const t0 = performance.now();
    this.#decoder =
      this.helpers.length > 0 && base.bytes[4] === CHARTED_FORMAT
        ? new PooledDecoder(this.codec, base.bytes, this.helpers)
        : this.codec.decoder(base.bytes);
    this.#decodeMs += performance.now() - t0;
    this.#baseBounds = bounds(this.#decoder.view().positions);
    this.level = 0;
    if (this.#shows(0)) this.#postLevel();
    while (!this.#cancelled) {
      if (this.level >= this.request.upTo) {
        this.post({ type: 'done', level: this.level }, []);
        await new Promise((resolve) => (this.#wake = () => resolve(undefined)));
        this.#wake = null;
        continue;
      }
      await this.#step(this.level + 1);
    }
  }

  /**
   * Fetches (or takes the prefetched) batch k, prefetches k + 1, decodes k.
   * @param {number} k
   */
  async #step(k) {
    const fetched = await this.#batch(k);
    if (this.#cancelled) return;
    if (!('bytes' in fetched)) {
      this.#inFlight.delete(k);
      const posted = this.#shows(this.level);
      this.request.upTo = this.level;
      if (!posted) this.#postLevel();
      this.post({ type: 'capped', level: this.level, ...fetched.capped }, []);
      return;
    }
    if (k + 1 <= this.request.upTo) void this.#batch(k + 1);
    const decoder = /** @type {LevelDecoder} */ (this.#decoder);
    const t0 = performance.now();
    await decoder.apply(fetched.bytes);
    if (this.#cancelled) return;
    this.#decodeMs += performance.now() - t0;
    this.#inFlight.delete(k);
    this.level = k;
    if (this.#shows(k)) this.#postLevel();
  }

  /** @param {number} level */
  #shows(level) {
    const { show, showFrom = 0, upTo } = this.request;
    return level === upTo || (show === 'each' && level >= showFrom);
  }

  /** @param {number} k */
  #batch(k) {
    let pending = this.#inFlight.get(k);
    if (!pending) {
      pending = this.#fetch(k, this.request.batchUrls[k - 1]);
      // A prefetch that fails is reported when it is awaited, not before.
      pending.catch(() => {});
      this.#inFlight.set(k, pending);
    }
    return pending;
  }

  /**
   * Posts the current level. Vertices are only ever appended (codec/core/FORMAT.md:
   * each pass appends the vertices it inserts), so positions and colours
   * carry only the vertices not posted before (from `firstVertex`); normals
   * and indices change everywhere and go whole. Normals (unless the
   * renderer derives them), edges (wireframe) and θ (relief view) are
   * computed on views into the decoder's memory, so nothing is copied out
   * except what is sent.
   */
  #postLevel() {
    const decoder = /** @type {LevelDecoder} */ (this.#decoder);
    const t0 = performance.now();
    const view = decoder.view();
    const t1 = performance.now();
    const derive = this.request.normals !== 'last' || view.level >= this.request.upTo;
    const normals = derive ? vertexNormals(view.positions, view.indices) : null;
    const edges = this.request.wireframe ? edgeIndices(view.indices, view.vertices) : null;
    const relief = this.request.relief ? normalDeviation(view.positions, view.indices, view.vertices) : null;
    const top = relief ? reliefTop(relief) : null;
    const t2 = performance.now();
    const first = Math.min(this.#sentVertices, view.vertices);
    const positions = view.positions.slice(3 * first);
    const colours = view.colours ? view.colours.slice(3 * first) : null;
    const indices = view.indices.slice();
    this.#sentVertices = view.vertices;
    this.#decodeMs += t1 - t0 + (performance.now() - t2);
    if (normals || edges || relief) this.#deriveMs += t2 - t1;
    this.#postedLevel = view.level;
    if (relief) this.#reliefLevel = view.level;
    /** @type {Transferable[]} */
    const transfer = [positions.buffer, indices.buffer];
    if (normals) transfer.push(normals.buffer);
    if (colours) transfer.push(colours.buffer);
    if (edges) transfer.push(edges.buffer);
    if (relief) transfer.push(relief.buffer);
    this.post(
      {
        type: 'level',
        level: view.level,
        vertices: view.vertices,
        faces: indices.length / 3,
        firstVertex: first,
        capacity: Math.max(view.vertices, this.request.capacity ?? 0),
        positions,
        normals,
        colours,
        indices,
        edges,
        relief,
        reliefTop: top,
        baseBounds: this.#baseBounds,
        received: this.#received,
        decodeMs: this.#decodeMs,
        deriveMs: this.#deriveMs,
        decoders: this.decoders,
      },
      transfer,
    );
  }

  /**
   * The whole body of one payload, reporting bytes as they arrive. A level
   * cap answer (403/429 with `"error": "level_capped"`) is a result, not an
   * error.
   * @param {number} level
   * @param {string} url
   * @returns {Promise<Fetched>}
   */
  async #fetch(level, url) {
    const what = level === 0 ? 'base mesh' : `batch ${level}`;
    const { headers } = this.request;
    return fetchPayload(url, { what, headers, signal: this.#abort.signal, fetchImpl: this.fetchImpl, read: (r) => this.#readBody(r) });
  }

  /** @param {Response} response */
  async #readBody(response) {
    if (!response.body) {
      const bytes = new Uint8Array(await response.arrayBuffer());
      this.#count(bytes.length);
      return bytes;
    }
    const reader = response.body.getReader();
    /** @type {Uint8Array[]} */
    const chunks = [];
    let length = 0;
    for (;;) {
      const { done, value } = await reader.read();
      if (done) break;
      chunks.push(value);
      length += value.length;
      this.#count(value.length);
    }
    if (chunks.length === 1) return chunks[0];
    const bytes = new Uint8Array(length);
    let at = 0;
    for (const chunk of chunks) {
      bytes.set(chunk, at);
      at += chunk.length;
    }
    return bytes;
  }

  /** @param {number} bytes */
  #count(bytes) {
    this.#received += bytes;
    const now = performance.now();
    if (now - this.#lastProgress >= PROGRESS_EVERY_MS) {
      this.#lastProgress = now;
      this.post({ type: 'progress', received: this.#received }, []);
    }
  }
}

/** @param {unknown} error */
function describe(error) {
  if (error instanceof DecodeError) return `the stream is damaged (${error.message})`;
  if (error instanceof WebAssembly.RuntimeError) return `the decoder stopped (${error.message})`;
  return error instanceof Error ? error.message : String(error);
}
