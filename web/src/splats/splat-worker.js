// @ts-check
/**
 * The splat worker: everything splats need before the GPU, off the page's
 * main thread. A point-cloud model is fetched and decoded level by level
 * (point-stream.js) with the splat preprocessing after each level; a mesh
 * level is turned into splats (mesh-splats.js). Splats leave as transferred
 * buffers.
 */

import { VitrineCodec } from '../codec.js';
import { meshSplats } from './mesh-splats.js';
import { fetchPayload } from '../payload.js';
import { PointStream, splitHeader } from './point-stream.js';

/** @typedef {import('./messages.js').SplatCommand} SplatCommand */
/** @typedef {import('./messages.js').SplatMessage} SplatMessage */

const scope = /** @type {DedicatedWorkerGlobalScope} */ (/** @type {unknown} */ (self));

/** @param {SplatMessage} message */
function post(message) {
  /** @type {Transferable[]} */
  const transfer = [];
  if (message.type === 'splats') {
    const s = message.set;
    for (const b of [s.positions, s.normals, s.colours, s.radii, s.surfaceIds, s.clip, s.planes]) if (b) transfer.push(b.buffer);
  }
  scope.postMessage(message, transfer);
}

/** The point model loading now: `extend` raises its `upTo`. @type {{ upTo: number, wake: (() => void) | null } | null} */
let loading = null;

/** @param {Extract<SplatCommand, { type: 'points' }>} command */
async function points(command) {
  const codec = await VitrineCodec.instantiate(command.module);
  const threshold = command.sharpThreshold ?? 0.9;
  const load = { upTo: command.upTo, wake: /** @type {(() => void) | null} */ (null) };
  loading = load;
  /** @type {PointStream | null} */
  let stream = null;
  let received = 0;
  // Level k + 1 downloads while level k decodes.
  /** @param {number} k */
  const fetchLevel = (k) =>
    fetchPayload(k === 0 ? command.baseUrl : command.batchUrls[k - 1], {
      what: k === 0 ? 'first level of the point stream' : `level ${k + 1} of the point stream`,
      headers: command.headers,
    });
  /** @type {Promise<import('../payload.js').Fetched> | null} */
  let next = null;
  let level = 0;
  for (;;) {
    if (level > load.upTo) {
      post({ type: 'done', level: load.upTo });
      // Until the page raises the cap (a capped load resumes).
      await new Promise((resolve) => (load.wake = () => resolve(undefined)));
      load.wake = null;
      continue;
    }
    next ??= fetchLevel(level);
    let fetched;
    try {
      fetched = await next;
    } catch (error) {
      post({ type: 'error', kind: 'network', level, message: error instanceof Error ? error.message : String(error) });
      return;
    }
    next = null;
    if ('capped' in fetched) {
      // The server refused this level (its cap fell since the manifest was
      // read): the levels before it stay on screen.
      if (level === 0) {
        post({ type: 'error', kind: 'network', level, message: 'the server refused the first level of the point stream' });
        return;
      }
      load.upTo = level - 1;
      post({ type: 'capped', level: level - 1, ...fetched.capped });
      continue;
    }
    const bytes = fetched.bytes;
    received += bytes.length;
    if (level < load.upTo) {
      next = fetchLevel(level + 1);
      next.catch(() => {});
    }
    const started = performance.now();
    try {
      if (level === 0) {
        const { header, chunk } = splitHeader(bytes);
        stream = new PointStream(codec, header);
        stream.apply(chunk);
      } else /** @type {PointStream} */ (stream).apply(bytes);
      const set = /** @type {PointStream} */ (stream).splats(threshold);
      post({ type: 'splats', id: null, level, set, received, ms: performance.now() - started });
    } catch (error) {
      post({ type: 'error', kind: 'decode', level, message: error instanceof Error ? error.message : String(error) });
      return;
    }
    level++;
  }
}

scope.onmessage = (/** @type {MessageEvent<SplatCommand>} */ event) => {
  const command = event.data;
  if (command.type === 'points') void points(command);
  else if (command.type === 'extend') {
    if (loading && command.upTo > loading.upTo) {
      loading.upTo = command.upTo;
      loading.wake?.();
    }
  }
  else if (command.type === 'mesh') {
    const started = performance.now();
    const set = meshSplats(command.positions, command.indices, command.colours, command.sharpThreshold);
    post({ type: 'splats', id: command.id, level: -1, set, received: 0, ms: performance.now() - started });
  }
};
