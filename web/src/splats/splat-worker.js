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

/**
 * @param {string} url
 * @param {Record<string, string> | undefined} headers
 */
async function download(url, headers) {
  const response = await fetch(url, { headers });
  if (!response.ok) throw Object.assign(new Error(`the server answered ${response.status}`), { network: true });
  return new Uint8Array(await response.arrayBuffer());
}

/** @param {Extract<SplatCommand, { type: 'points' }>} command */
async function points(command) {
  const codec = await VitrineCodec.instantiate(command.module);
  const threshold = command.sharpThreshold ?? 0.9;
  /** @type {PointStream | null} */
  let stream = null;
  let received = 0;
  // Level k + 1 downloads while level k decodes.
  /** @param {number} k */
  const fetchLevel = (k) => download(k === 0 ? command.baseUrl : command.batchUrls[k - 1], command.headers);
  let next = fetchLevel(0);
  for (let level = 0; level <= command.upTo; level++) {
    let bytes;
    try {
      bytes = await next;
    } catch (error) {
      post({ type: 'error', kind: 'network', level, message: error instanceof Error ? error.message : String(error) });
      return;
    }
    received += bytes.length;
    if (level < command.upTo) next = fetchLevel(level + 1);
    next.catch(() => {});
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
  }
  post({ type: 'done', level: command.upTo });
}

scope.onmessage = (/** @type {MessageEvent<SplatCommand>} */ event) => {
  const command = event.data;
  if (command.type === 'points') void points(command);
  else if (command.type === 'mesh') {
    const started = performance.now();
    const set = meshSplats(command.positions, command.indices, command.colours);
    post({ type: 'splats', id: command.id, level: -1, set, received: 0, ms: performance.now() - started });
  }
};
