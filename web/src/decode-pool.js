// @ts-check
/**
 * A charted stream (format 5, codec/core/FORMAT.md) decoded by a pool of
 * workers. The decode worker is the pool's first member; every helper
 * (chart-helper.js) is another, on a thread of its own. Every member
 * decodes the base mesh, the global batches and the first parted batch
 * whole (the coarsest of the charts' batches: together about a tenth of
 * the work), so no chart mesh ever travels between threads; then the
 * charts are shared out by their size, and from the next parted batch on
 * each member refines only its own charts and sends what they gained. This
 * member merges the charts as the native decoder does (each chart's new
 * vertices appended in chart order, then every chart's triangles in level
 * ids: `Charted::merge` in codec/core/src/decoder/charted.rs), so the levels
 * are the same bytes as one decoder's, and hands them on as one level.
 *
 * It behaves like a StreamDecoder, except that `apply` returns a promise.
 */

import { DecodeError, PARTED_TAG } from './codec.js';
import { chartUpdates } from './chart-helper.js';

/**
 * A helper's end of a channel: a MessagePort (browser), or the Node bench's
 * adapter of a worker thread, or an in-process one in the tests.
 * @typedef {object} HelperPort
 * @property {(message: import('./chart-helper.js').HelperCommand, transfer: Transferable[]) => void} postMessage
 * @property {((event: MessageEvent<import('./chart-helper.js').HelperReply>) => void) | null} onmessage
 */

/**
 * Shares charts out among `members` by the longest-processing-time rule:
 * largest first, each to the member with the least so far (the lowest on a
 * tie), so every member's share is within one chart of the fairest.
 * @param {number[]} sizes work per chart (its faces)
 * @param {number} members
 * @returns {number[][]} the charts of each member, ascending
 */
export function shareCharts(sizes, members) {
  const load = new Array(members).fill(0);
  /** @type {number[][]} */
  const shares = Array.from({ length: members }, () => []);
  const order = sizes.map((_, c) => c).sort((a, b) => sizes[b] - sizes[a] || a - b);
  for (const chart of order) {
    let best = 0;
    for (let m = 1; m < members; m++) if (load[m] < load[best]) best = m;
    load[best] += Math.max(sizes[chart], 1);
    shares[best].push(chart);
  }
  for (const share of shares) share.sort((a, b) => a - b);
  return shares;
}

/** The final level's vertex count from a stream's header (FORMAT.md). @param {Uint8Array} base */
function finalVertices(base) {
  const view = new DataView(base.buffer, base.byteOffset, base.byteLength);
  if (base.byteLength < 40) return 0;
  const batches = view.getUint32(24, true);
  const at = 28 + 12 * batches;
  return at + 4 <= base.byteLength ? view.getUint32(at, true) : 0;
}

/**
 * A Uint32Array with room for at least `n`, keeping the first `used` entries.
 * @param {Uint32Array} array
 * @param {number} used
 * @param {number} n
 * @returns {Uint32Array}
 */
function grown(array, used, n) {
  if (array.length >= n) return array;
  const bigger = new Uint32Array(Math.max(n, 2 * array.length, 64));
  bigger.set(array.subarray(0, used));
  return bigger;
}

/** The merged level of a charted stream, grown by every member's chart updates. */
class ChartMerge {
  /**
   * @param {import('./codec.js').Level} cut the level when the members stopped merging
   * @param {number} capacity vertices to make room for (the final level's)
   * @param {number} charts
   */
  constructor(cut, capacity, charts) {
    const room = 3 * Math.max(capacity, cut.vertices);
    this.vertices = cut.vertices;
    this.positions = new Float32Array(room);
    this.positions.set(cut.positions.subarray(0, 3 * cut.vertices));
    this.colours = cut.colours ? new Uint8Array(room) : null;
    if (this.colours && cut.colours) this.colours.set(cut.colours.subarray(0, 3 * cut.vertices));
    /** Level id of each chart vertex known so far. @type {Uint32Array[]} */
    this.ids = Array.from({ length: charts }, () => new Uint32Array(0));
    this.known = new Array(charts).fill(0);
    this.indices = new Uint32Array(0);
  }

  /** @param {number} vertices */
  #room(vertices) {
    if (3 * vertices <= this.positions.length) return;
    const positions = new Float32Array(6 * vertices);
    positions.set(this.positions);
    this.positions = positions;
    if (this.colours) {
      const colours = new Uint8Array(6 * vertices);
      colours.set(this.colours);
      this.colours = colours;
    }
  }

  /** @param {import('./chart-helper.js').ChartUpdate[]} updates every chart's, in chart order */
  add(updates) {
    for (const u of updates) {
      const c = u.chart;
      if (u.levelIds) {
        this.ids[c] = u.levelIds.slice();
        this.known[c] = u.levelIds.length;
      }
      const n = u.positions.length / 3;
      this.#room(this.vertices + n);
      this.positions.set(u.positions, 3 * this.vertices);
      if (this.colours && u.colours) this.colours.set(u.colours, 3 * this.vertices);
      const ids = (this.ids[c] = grown(this.ids[c], this.known[c], this.known[c] + n));
      for (let j = 0; j < n; j++) ids[this.known[c] + j] = this.vertices + j;
      this.known[c] += n;
      this.vertices += n;
    }
    let total = 0;
    for (const u of updates) total += u.indices.length;
    const indices = new Uint32Array(total);
    let at = 0;
    for (const u of updates) {
      const ids = this.ids[u.chart];
      const known = this.known[u.chart];
      const chart = u.indices;
      for (let k = 0; k < chart.length; k++) {
        const v = chart[k];
        if (v >= known) throw new DecodeError(`chart ${u.chart} names vertex ${v} of ${known}`);
        indices[at++] = ids[v];
      }
    }
    this.indices = indices;
  }
}

export class PooledDecoder {
  #inner;
  /** @type {HelperPort[]} */
  #ports;
  /** Replies awaited from each helper, first in, first out. @type {Array<Array<{ resolve: (reply: any) => void, reject: (error: Error) => void }>>} */
  #waiting;
  /** Replies to global batches, checked at the next parted batch. @type {Promise<unknown>[]} */
  #pending = [];
  /** Helpers that take part: all until the charts are shared, then those with charts. @type {number[]} */
  #active;
  /** This member's charts, once shared. @type {number[] | null} */
  #mine = null;
  /** @type {Map<number, number>} */
  #sent = new Map();
  /** @type {ChartMerge | null} */
  #merge = null;
  #capacity;
  #level = 0;
  /** The charts each member refines (index 0: this one), once shared. @type {number[][] | null} */
  shares = null;

  /**
   * @param {import('./codec.js').VitrineCodec} codec
   * @param {Uint8Array} base the stream's header and base mesh
   * @param {HelperPort[]} ports one per helper
   */
  constructor(codec, base, ports) {
    this.#inner = codec.decoder(base);
    this.#ports = ports;
    this.#waiting = ports.map(() => []);
    this.#active = ports.map((_, i) => i);
    this.#capacity = finalVertices(base);
    ports.forEach((port, i) => {
      port.onmessage = (event) => this.#reply(i, event.data);
    });
    for (const i of this.#active) this.#hold(this.#send(i, { type: 'base', bytes: base.slice() }));
  }

  /** @param {number} helper @param {import('./chart-helper.js').HelperReply} reply */
  #reply(helper, reply) {
    const waiter = this.#waiting[helper].shift();
    if (!waiter) return;
    if (reply.type === 'error') waiter.reject(new DecodeError(reply.message));
    else waiter.resolve(reply);
  }

  /**
   * @param {number} helper
   * @param {import('./chart-helper.js').HelperCommand} command
   * @param {Transferable[]} [transfer]
   * @returns {Promise<import('./chart-helper.js').HelperReply>}
   */
  #send(helper, command, transfer = []) {
    return new Promise((resolve, reject) => {
      this.#waiting[helper].push({ resolve, reject });
      this.#ports[helper].postMessage(command, transfer);
    });
  }

  /** Keeps a reply to check later, marked handled so that waiting for it is not an error. @param {Promise<unknown>} reply */
  #hold(reply) {
    reply.catch(() => {});
    this.#pending.push(reply);
  }

  /** Members of the pool: this one and its helpers. */
  get members() {
    return this.#ports.length + 1;
  }

  /**
   * Applies the next batch: a global one and the first parted one here and
   * in every helper, then the charts are shared out; a later parted one
   * each member refines its own charts of, at once.
   * @param {Uint8Array} batch
   */
  async apply(batch) {
    if (batch[0] !== PARTED_TAG || !this.#mine) {
      for (const i of this.#active) {
        const copy = batch.slice();
        this.#hold(this.#send(i, { type: 'batch', bytes: copy }, [copy.buffer]));
      }
      this.#inner.apply(batch);
      this.#level++;
      if (batch[0] === PARTED_TAG) this.#share();
      return;
    }
    const replies = this.#active.map((i) => {
      const copy = batch.slice();
      return this.#send(i, { type: 'batch', bytes: copy }, [copy.buffer]);
    });
    // Awaited below unless this member fails first.
    for (const reply of replies) reply.catch(() => {});
    // This member's charts while the helpers do theirs.
    this.#inner.apply(batch);
    const mine = chartUpdates(this.#inner, /** @type {number[]} */ (this.#mine), this.#sent).updates;
    await Promise.all(this.#pending.splice(0));
    const theirs = await Promise.all(replies);
    const updates = mine.concat(...theirs.map((r) => (r.type === 'charts' ? r.charts : [])));
    updates.sort((a, b) => a.chart - b.chart);
    const charts = this.#inner.chartCount();
    if (updates.length !== charts) throw new DecodeError(`${updates.length} of ${charts} charts came back`);
    this.#merge ??= new ChartMerge(this.#inner.view(), this.#capacity, charts);
    this.#merge.add(updates);
    this.#level++;
  }

  /** Shares the charts out by their faces now, the first parted batch applied. */
  #share() {
    const sizes = [];
    for (let c = 0; c < this.#inner.chartCount(); c++) sizes.push(this.#inner.chartView(c).indices.length);
    const shares = shareCharts(sizes, this.members);
    this.shares = shares;
    this.#mine = shares[0];
    this.#inner.refineOnly(shares[0]);
    const active = [];
    for (const i of this.#active) {
      if (shares[i + 1].length === 0) continue;
      active.push(i);
      this.#hold(this.#send(i, { type: 'charts', charts: shares[i + 1] }));
    }
    this.#active = active;
  }

  /** @returns {import('./codec.js').Level} views, valid until the next apply */
  view() {
    const merge = this.#merge;
    if (!merge) return this.#inner.view();
    return {
      level: this.#level,
      vertices: merge.vertices,
      positions: merge.positions.subarray(0, 3 * merge.vertices),
      colours: merge.colours ? merge.colours.subarray(0, 3 * merge.vertices) : null,
      indices: merge.indices,
    };
  }

  /** @returns {import('./codec.js').Level} copies */
  level() {
    const v = this.view();
    return { ...v, positions: v.positions.slice(), colours: v.colours ? v.colours.slice() : null, indices: v.indices.slice() };
  }

  free() {
    this.#inner.free();
    for (const port of this.#ports) port.onmessage = null;
    for (const waiting of this.#waiting) for (const w of waiting.splice(0)) w.reject(new DecodeError('the decoder was freed'));
  }
}
