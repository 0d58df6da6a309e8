// @ts-check
/**
 * A member of the decode pool (decode-pool.js) on a thread of its own: it
 * decodes the base mesh and the global batches like every member, then
 * refines only the charts it was given and sends back what each of them
 * gained: its new vertices, and its triangles already in the level's ids. No DOM or worker dependency: chart-worker.js runs it in a Web
 * Worker, the Node bench in a worker thread, the tests in-process.
 *
 * Every message gets exactly one reply, in order, so the pool matches them
 * first in, first out:
 * - `{ type: 'base', bytes }` → `{ type: 'ok' }` (a fresh decoder);
 * - `{ type: 'batch', bytes, share? }` → `{ type: 'ok' }` for a global
 *   batch, a ChartsReply for a parted one; `share` comes with the first
 *   parted batch: the helper reads the charts' sizes from it and takes its
 *   share by {@link shareCharts}, as every member does;
 * any failure → `{ type: 'error', message }`.
 */

import { DecodeError } from './codec.js';

/**
 * What one chart gained in a parted batch.
 * @typedef {object} ChartUpdate
 * @property {number} chart
 * @property {Float32Array} positions x, y, z of the chart's vertices the batch inserted
 * @property {Uint8Array | null} colours r, g, b of the same vertices
 * @property {Uint32Array} indices every triangle of the chart, in the level's vertex ids
 */

/** @typedef {{ type: 'charts', charts: ChartUpdate[] }} ChartsReply */
/** @typedef {{ type: 'ok' } | ChartsReply | { type: 'error', message: string }} HelperReply */
/**
 * `share`, with a charted stream's first parted batch: the pool's size and
 * this helper's place in it (1…), to share the charts out as every member does.
 * @typedef {{ type: 'base', bytes: Uint8Array } | { type: 'batch', bytes: Uint8Array, share?: { members: number, member: number } }} HelperCommand
 */

/**
 * Copies out what `charts` gained in the last batch, with the buffers to
 * transfer.
 * @param {import('./codec.js').StreamDecoder} decoder
 * @param {number[]} charts
 * @returns {{ updates: ChartUpdate[], transfer: ArrayBuffer[] }}
 */
export function chartUpdates(decoder, charts) {
  /** @type {ChartUpdate[]} */
  const updates = [];
  /** @type {ArrayBuffer[]} */
  const transfer = [];
  for (const chart of charts) {
    const view = decoder.chartView(chart);
    const update = {
      chart,
      positions: view.positions.slice(3 * view.newFrom),
      colours: view.colours ? view.colours.slice(3 * view.newFrom) : null,
      indices: view.levelIndices.slice(),
    };
    updates.push(update);
    transfer.push(update.positions.buffer, update.indices.buffer);
    if (update.colours) transfer.push(update.colours.buffer);
  }
  return { updates, transfer };
}

/**
 * Shares charts out among `members` by the longest-processing-time rule:
 * largest first, each to the member with the least so far, so every
 * member's share is within one chart of the fairest. On a tie the helpers
 * come first and member 0 (the decode worker, which also merges and posts
 * the levels) last.
 * @param {number[]} sizes work per chart (its faces)
 * @param {number} members
 * @returns {number[][]} the charts of each member, ascending
 */
export function shareCharts(sizes, members) {
  const load = new Array(members).fill(0);
  /** @type {number[][]} */
  const shares = Array.from({ length: members }, () => []);
  const order = sizes.map((_, c) => c).sort((a, b) => sizes[b] - sizes[a] || a - b);
  const preference = [...Array(members).keys()].slice(1).concat(0);
  for (const chart of order) {
    let best = preference[0];
    for (const m of preference) if (load[m] < load[best]) best = m;
    load[best] += Math.max(sizes[chart], 1);
    shares[best].push(chart);
  }
  for (const share of shares) share.sort((a, b) => a - b);
  return shares;
}

export class ChartHelper {
  /** @type {import('./codec.js').StreamDecoder | null} */
  #decoder = null;
  /** @type {number[]} */
  #charts = [];

  /** @param {import('./codec.js').VitrineCodec} codec */
  constructor(codec) {
    this.codec = codec;
  }

  /**
   * @param {HelperCommand} command
   * @returns {{ reply: HelperReply, transfer: ArrayBuffer[] }}
   */
  handle(command) {
    try {
      return this.#handle(command);
    } catch (error) {
      const message = error instanceof Error ? error.message : String(error);
      return { reply: { type: 'error', message }, transfer: [] };
    }
  }

  /** @param {HelperCommand} command @returns {{ reply: HelperReply, transfer: ArrayBuffer[] }} */
  #handle(command) {
    /** @type {{ reply: HelperReply, transfer: ArrayBuffer[] }} */
    const ok = { reply: { type: 'ok' }, transfer: [] };
    if (command.type === 'base') {
      this.#decoder?.free();
      this.#decoder = null;
      this.#charts = [];
      this.#decoder = this.codec.decoder(command.bytes);
      return ok;
    }
    const decoder = this.#decoder;
    if (!decoder) throw new DecodeError('no base mesh yet');
    if (command.share) {
      const { members, member } = command.share;
      this.#charts = shareCharts(decoder.chartSizes(command.bytes), members)[member] ?? [];
      decoder.refineOnly(this.#charts);
    }
    decoder.apply(command.bytes);
    if (decoder.chartCount() === 0) return ok;
    const { updates, transfer } = chartUpdates(decoder, this.#charts);
    return { reply: { type: 'charts', charts: updates }, transfer };
  }
}
