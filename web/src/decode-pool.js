// @ts-check
/**
 * A charted stream (format 5, codec/core/FORMAT.md) decoded by a pool of
 * workers. The decode worker is the pool's first member; every helper
 * (chart-helper.js) is another, on a thread of its own. Every member
 * decodes the base mesh and the global batches (about a tenth of the work)
 * so that no chart mesh ever travels between threads. Before the first
 * parted batch, this member reads from it how big each chart will be and
 * shares the charts out; from then on each member refines only its own and
 * sends what they gained: the new vertices, and the chart's triangles
 * already in the level's vertex ids (each member numbers its charts' new
 * vertices as one decoder would, counting the other charts' insertions
 * from the batch). This member lays them end to end in chart order, as the
 * native decoder merges (`Charted::merge` in codec/core/src/decoder/
 * charted.rs), so the levels are the same bytes as one decoder's.
 *
 * It behaves like a StreamDecoder, except that `apply` returns a promise.
 */

import { DecodeError, PARTED_TAG, levelTable } from './codec.js';
import { chartUpdates, shareCharts } from './chart-helper.js';

export { shareCharts };

/**
 * A helper's end of a channel: a MessagePort (browser), or the Node bench's
 * adapter of a worker thread, or an in-process one in the tests.
 * @typedef {object} HelperPort
 * @property {(message: import('./chart-helper.js').HelperCommand, transfer: Transferable[]) => void} postMessage
 * @property {((event: MessageEvent<import('./chart-helper.js').HelperReply>) => void) | null} onmessage
 */

/**
 * How far past the vertices a batch verifies the merged level may reserve
 * toward the header's final count (as the codec's decoder does,
 * codec/core/src/room.rs): a hostile header claiming millions of
 * vertices costs at most this factor in memory.
 */
export const RESERVE_AHEAD = 4;

/** The merged level of a charted stream, grown by every member's chart updates. */
class ChartMerge {
  /**
   * @param {import('./codec.js').Level} start the level when the members stopped merging
   * @param {number} expected vertices the header says the last level has
   */
  constructor(start, expected) {
    this.expected = expected;
    this.vertices = start.vertices;
    this.positions = start.positions.slice(0, 3 * start.vertices);
    this.colours = start.colours ? start.colours.slice(0, 3 * start.vertices) : null;
    this.indices = new Uint32Array(0);
  }

  /**
   * Room for `needed` vertices, reserved toward the expected final count
   * when the arrays must move, but no further than RESERVE_AHEAD × needed.
   * @param {number} needed
   */
  #makeRoom(needed) {
    if (3 * needed <= this.positions.length) return;
    const room = 3 * Math.min(Math.max(this.expected, needed), RESERVE_AHEAD * needed);
    const positions = new Float32Array(room);
    positions.set(this.positions.subarray(0, 3 * this.vertices));
    this.positions = positions;
    if (this.colours) {
      const colours = new Uint8Array(room);
      colours.set(this.colours.subarray(0, 3 * this.vertices));
      this.colours = colours;
    }
  }

  /**
   * @param {import('./chart-helper.js').ChartUpdate[]} updates every chart's, in chart order
   * @param {number} vertices the level's vertex count after them (the level table's)
   */
  add(updates, vertices) {
    let total = 0;
    for (const u of updates) total += u.positions.length / 3;
    if (this.vertices + total !== vertices) {
      throw new DecodeError(`the charts bring ${this.vertices + total} vertices, the level has ${vertices}`);
    }
    this.#makeRoom(vertices);
    let faces = 0;
    for (const u of updates) {
      this.positions.set(u.positions, 3 * this.vertices);
      if (this.colours && u.colours) this.colours.set(u.colours, 3 * this.vertices);
      this.vertices += u.positions.length / 3;
      faces += u.indices.length;
    }
    const indices = new Uint32Array(faces);
    let at = 0;
    for (const u of updates) {
      indices.set(u.indices, at);
      at += u.indices.length;
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
  /** Helpers left without charts, to leave out after this batch. @type {number[]} */
  #leaveOut = [];
  /** @type {ChartMerge | null} */
  #merge = null;
  /** @type {number[]} */
  #levels;
  #level = 0;
  /** The charts each member refines (index 0: this one), once shared. @type {number[][] | null} */
  shares = null;
  /** The faces of each chart they were shared by. @type {number[] | null} */
  sizes = null;

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
    this.#levels = levelTable(base).map((level) => level.vertices);
    ports.forEach((port, i) => {
      port.onmessage = (event) => this.#reply(i, event.data);
    });
    for (const i of this.#active) this.#hold(this.#send(i, { type: 'base', bytes: new Uint8Array(base) }));
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
   * Applies the next batch: a global one here and in every helper; a
   * parted one (its charts shared out first, if it is the first) by every
   * member at once, each refining its own charts.
   * @param {Uint8Array} batch
   */
  async apply(batch) {
    if (batch[0] !== PARTED_TAG) {
      for (const i of this.#active) {
        const copy = new Uint8Array(batch); // a copy (a Node Buffer's slice() is a view)
        this.#hold(this.#send(i, { type: 'batch', bytes: copy }, [copy.buffer]));
      }
      this.#inner.apply(batch);
      this.#level++;
      return;
    }
    // The first parted batch: every member shares the charts out by the
    // same rule from the same sizes, at once, and keeps its own share.
    const first = !this.#mine;
    const replies = this.#active.map((i) => {
      const copy = new Uint8Array(batch); // a copy (a Node Buffer's slice() is a view)
      /** @type {import('./chart-helper.js').HelperCommand} */
      const command = first ? { type: 'batch', bytes: copy, share: { members: this.members, member: i + 1 } } : { type: 'batch', bytes: copy };
      return this.#send(i, command, [copy.buffer]);
    });
    // Awaited below unless this member fails first.
    for (const reply of replies) reply.catch(() => {});
    if (first) this.#share(batch);
    // This member's charts while the helpers do theirs.
    this.#inner.apply(batch);
    const mine = chartUpdates(this.#inner, /** @type {number[]} */ (this.#mine)).updates;
    await Promise.all(this.#pending.splice(0));
    const theirs = await Promise.all(replies);
    if (this.#leaveOut.length > 0) {
      this.#active = this.#active.filter((i) => !this.#leaveOut.includes(i));
      this.#leaveOut = [];
    }
    const updates = mine.concat(...theirs.map((r) => (r.type === 'charts' ? r.charts : [])));
    updates.sort((a, b) => a.chart - b.chart);
    const charts = this.#inner.chartCount();
    if (updates.length !== charts || updates.some((u, c) => u.chart !== c)) {
      throw new DecodeError(`charts ${updates.map((u) => u.chart)} came back, of ${charts}`);
    }
    this.#merge ??= new ChartMerge(this.#inner.view(), this.#levels[this.#levels.length - 1]);
    this.#merge.add(updates, this.#levels[this.#level + 1]);
    this.#level++;
  }

  /** Shares the charts out by their faces, read from the first parted batch. @param {Uint8Array} batch */
  #share(batch) {
    this.sizes = this.#inner.chartSizes(batch);
    const shares = shareCharts(this.sizes, this.members);
    this.shares = shares;
    this.#mine = shares[0];
    this.#inner.refineOnly(shares[0]);
    // A helper without charts sends empty updates from now on: leave it out.
    this.#leaveOut = this.#active.filter((i) => shares[i + 1].length === 0);
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
