// @ts-check
/**
 * A member of the decode pool (decode-pool.js) on a thread of its own: it
 * decodes the base mesh and the global batches like every member, then
 * refines only the charts it was given and sends back what each of them
 * gained. No DOM or worker dependency: chart-worker.js runs it in a Web
 * Worker, the Node bench in a worker thread, the tests in-process.
 *
 * Every message gets exactly one reply, in order, so the pool matches them
 * first in, first out:
 * - `{ type: 'base', bytes }` → `{ type: 'ok' }` (a fresh decoder);
 * - `{ type: 'batch', bytes }` → `{ type: 'ok' }`, or once it has charts
 *   and the batch is parted, a ChartsReply;
 * - `{ type: 'charts', charts }` → `{ type: 'ok' }`: the charts it refines
 *   from the next parted batch on (after the first, which every member
 *   applies whole);
 * any failure → `{ type: 'error', message }`.
 */

import { DecodeError } from './codec.js';

/**
 * What one chart gained in a parted batch.
 * @typedef {object} ChartUpdate
 * @property {number} chart
 * @property {Uint32Array | null} levelIds the level's id of each chart vertex when the
 *   members stopped merging (the chart's first update only)
 * @property {Float32Array} positions x, y, z of the chart vertices after those sent before
 * @property {Uint8Array | null} colours r, g, b of the same vertices
 * @property {Uint32Array} indices every triangle of the chart, in chart vertex ids
 */

/** @typedef {{ type: 'charts', charts: ChartUpdate[] }} ChartsReply */
/** @typedef {{ type: 'ok' } | ChartsReply | { type: 'error', message: string }} HelperReply */
/** @typedef {{ type: 'base', bytes: Uint8Array } | { type: 'charts', charts: number[] } | { type: 'batch', bytes: Uint8Array }} HelperCommand */

/**
 * Copies out what `charts` gained since `sent` (vertices already sent, per
 * chart; updated), with the buffers to transfer.
 * @param {import('./codec.js').StreamDecoder} decoder
 * @param {number[]} charts
 * @param {Map<number, number>} sent
 * @returns {{ updates: ChartUpdate[], transfer: ArrayBuffer[] }}
 */
export function chartUpdates(decoder, charts, sent) {
  /** @type {ChartUpdate[]} */
  const updates = [];
  /** @type {ArrayBuffer[]} */
  const transfer = [];
  for (const chart of charts) {
    const view = decoder.chartView(chart);
    const before = sent.get(chart);
    const from = before ?? view.levelIds.length;
    const update = {
      chart,
      levelIds: before === undefined ? view.levelIds.slice() : null,
      positions: view.positions.slice(3 * from),
      colours: view.colours ? view.colours.slice(3 * from) : null,
      indices: view.indices.slice(),
    };
    sent.set(chart, view.positions.length / 3);
    updates.push(update);
    transfer.push(update.positions.buffer, update.indices.buffer);
    if (update.levelIds) transfer.push(update.levelIds.buffer);
    if (update.colours) transfer.push(update.colours.buffer);
  }
  return { updates, transfer };
}

export class ChartHelper {
  /** @type {import('./codec.js').StreamDecoder | null} */
  #decoder = null;
  /** @type {number[]} */
  #charts = [];
  /** @type {Map<number, number>} */
  #sent = new Map();

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
      this.#sent = new Map();
      this.#decoder = this.codec.decoder(command.bytes);
      return ok;
    }
    const decoder = this.#decoder;
    if (!decoder) throw new DecodeError('no base mesh yet');
    if (command.type === 'charts') {
      decoder.refineOnly(command.charts);
      this.#charts = command.charts;
      return ok;
    }
    decoder.apply(command.bytes);
    if (decoder.chartCount() === 0 || this.#charts.length === 0) return ok;
    const { updates, transfer } = chartUpdates(decoder, this.#charts, this.#sent);
    return { reply: { type: 'charts', charts: updates }, transfer };
  }
}
