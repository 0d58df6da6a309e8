// @ts-check
/**
 * The normals of a level that came without them (LoadRequest.normals),
 * derived where the renderer runs, a slice at a time: face normals summed
 * per corner, then packed (geometry.js, the decode worker's own algorithm,
 * so both give the same bytes). The slices run in tasks of their own
 * ({@link NormalsTask}), not in animation frames: they are CPU work, and
 * need not wait for the GPU (a frame can be late by seconds on SwiftShader)
 * nor for the frame rate; between two slices the thread takes its messages
 * (camera moves).
 */

import { accumulateNormals, packNormals } from './geometry.js';

/** Triangles, then vertices, per step of a level's normals between budget checks (well under a millisecond). */
const NORMAL_TRIANGLES_PER_STEP = 8192;
const NORMAL_VERTICES_PER_STEP = 16384;

/**
 * A level's normals being derived: face normals summed per corner up to
 * index `index`, then packed up to component `packed`.
 * @typedef {{ sum: Float32Array, normals: Int16Array, index: number, packed: number }} NormalJob
 */

/**
 * @param {number} vertices the level's vertex count
 * @returns {NormalJob}
 */
export function normalJob(vertices) {
  return { sum: new Float32Array(3 * vertices), normals: new Int16Array(3 * vertices), index: 0, packed: 0 };
}

/**
 * Goes on with a job while the budget lasts.
 * @param {NormalJob} job
 * @param {Float32Array} positions every vertex the level's indices name (and maybe more)
 * @param {Uint32Array} indices the level's triangles
 * @param {() => boolean} inBudget
 * @returns {boolean} whether `job.normals` is complete
 */
export function deriveNormals(job, positions, indices, inBudget) {
  while (job.index < indices.length && inBudget()) {
    const end = Math.min(indices.length, job.index + 3 * NORMAL_TRIANGLES_PER_STEP);
    accumulateNormals(positions, indices, job.sum, job.index, end);
    job.index = end;
  }
  while (job.index === indices.length && job.packed < job.sum.length && inBudget()) {
    const end = Math.min(job.sum.length, job.packed + 3 * NORMAL_VERTICES_PER_STEP);
    packNormals(job.sum, job.normals, job.packed, end);
    job.packed = end;
  }
  return job.index >= indices.length && job.packed >= job.sum.length;
}

/**
 * Runs `slice` in a task of its own each time it is queued (at most one
 * waiting at a time). A MessageChannel rather than setTimeout, which is
 * clamped to 4 ms after a few nested calls.
 */
export class NormalsTask {
  /** @type {MessagePort | null} */
  #port = null;
  #queued = false;

  /** @param {() => void} slice */
  constructor(slice) {
    this.slice = slice;
  }

  queue() {
    if (this.#queued) return;
    this.#queued = true;
    if (!this.#port) {
      const channel = new MessageChannel();
      channel.port1.onmessage = () => {
        this.#queued = false;
        this.slice();
      };
      this.#port = channel.port2;
    }
    this.#port.postMessage(null);
  }
}
