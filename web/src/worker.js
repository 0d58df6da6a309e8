// @ts-check
/**
 * The decode worker: one WebAssembly instance of the codec (the module is
 * compiled once on the page and shared by every worker), one progressive
 * reconstruction at a time. Levels leave as transferred buffers, so the page
 * never copies or decodes anything.
 */

import { VitrineCodec } from './codec.js';
import { Reconstruction } from './reconstruction.js';

/**
 * @typedef {{ type: 'load', module: WebAssembly.Module, request: import('./reconstruction.js').LoadRequest }
 *   | { type: 'extend', upTo: number }
 *   | { type: 'wireframe', on: boolean }} WorkerCommand
 */

const scope = /** @type {DedicatedWorkerGlobalScope} */ (/** @type {unknown} */ (self));

/** @type {Promise<VitrineCodec> | null} */
let codec = null;
/** @type {Reconstruction | null} */
let job = null;

/** @type {import('./reconstruction.js').Post} */
function post(message, transfer) {
  scope.postMessage(message, transfer);
}

scope.onmessage = async (/** @type {MessageEvent<WorkerCommand>} */ event) => {
  const command = event.data;
  if (command.type === 'load') {
    job?.cancel();
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
