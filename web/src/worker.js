// @ts-check
/**
 * The decode worker: one WebAssembly instance of the codec (the module is
 * compiled once on the page and shared by every worker), one progressive
 * reconstruction at a time. Levels leave as transferred buffers, so the page
 * never copies or decodes anything. With a render worker (render-worker.js)
 * the 'load' command brings a MessagePort to it: levels and edges go there,
 * and the page gets each level as a notice without its buffers.
 */

import { VitrineCodec } from './codec.js';
import { Reconstruction } from './reconstruction.js';

/**
 * @typedef {{ type: 'load', module: WebAssembly.Module, request: import('./reconstruction.js').LoadRequest, port?: MessagePort | null }
 *   | { type: 'extend', upTo: number }
 *   | { type: 'wireframe', on: boolean }} WorkerCommand
 */

const scope = /** @type {DedicatedWorkerGlobalScope} */ (/** @type {unknown} */ (self));

/** @type {Promise<VitrineCodec> | null} */
let codec = null;
/** @type {Reconstruction | null} */
let job = null;

/** @type {MessagePort | null} */
let renderPort = null;
const NO_FLOATS = new Float32Array(0);
const NO_SHORTS = new Int16Array(0);
const NO_INDICES = new Uint32Array(0);

/** @type {import('./reconstruction.js').Post} */
function post(message, transfer) {
  if (!renderPort || (message.type !== 'level' && message.type !== 'edges')) {
    scope.postMessage(message, transfer);
    return;
  }
  renderPort.postMessage(message, transfer);
  if (message.type === 'level') {
    scope.postMessage({ ...message, positions: NO_FLOATS, normals: NO_SHORTS, colours: null, indices: NO_INDICES, edges: null });
  }
}

scope.onmessage = async (/** @type {MessageEvent<WorkerCommand>} */ event) => {
  const command = event.data;
  if (command.type === 'load') {
    job?.cancel();
    renderPort = command.port ?? null;
    codec ??= VitrineCodec.instantiate(command.module);
    let instance;
    try {
      instance = await codec;
    } catch (error) {
      post({ type: 'error', kind: 'decode', level: -1, message: `the decoder did not start: ${error}` }, []);
      return;
    }
    job = new Reconstruction(instance, command.request, post);
    void job.run();
  } else if (command.type === 'extend') {
    job?.extend(command.upTo);
  } else if (command.type === 'wireframe') {
    job?.setWireframe(command.on);
  }
};
