// @ts-check
/**
 * The decode worker: one WebAssembly instance of the codec (the module is
 * compiled once on the page and shared by every worker), one progressive
 * reconstruction at a time. Levels leave as transferred buffers, so the page
 * never copies or decodes anything. With a render worker (render-worker.js)
 * the 'load' command brings a MessagePort to it: levels, edges and θ go there,
 * and the page gets each level as a notice without its buffers. `helpers`
 * are channels to decode helpers (chart-worker.js) that the page started:
 * a charted stream's charts are refined by them and this worker together.
 */

import { VitrineCodec } from './codec.js';
import { Reconstruction } from './reconstruction.js';

/**
 * @typedef {{ type: 'load', module: WebAssembly.Module, request: import('./reconstruction.js').LoadRequest, port?: MessagePort | null, helpers?: MessagePort[] }
 *   | { type: 'extend', upTo: number }
 *   | { type: 'wireframe', on: boolean }
 *   | { type: 'relief', on: boolean }
 *   | { type: 'normals', which: 'always' | 'last' }
 *   | { type: 'geodesic', id: number, from: number[], to: number[] }
 *   | { type: 'level-data', id: number }} WorkerCommand
 * `geodesic` is answered with `{ type: 'geodesic', id, distance, level }` or `{ type: 'geodesic', id, error }`;
 * `level-data` with a copy of the last decoded level (splats/mesh-splat-view.js `LevelData`), or nothing before one.
 */

const scope = /** @type {DedicatedWorkerGlobalScope} */ (/** @type {unknown} */ (self));

/** @type {Promise<VitrineCodec> | null} */
let codec = null;
/** @type {Reconstruction | null} */
let job = null;

/** @type {MessagePort | null} */
let renderPort = null;
/** A 'normals' command that came while the decoder was starting. @type {'always' | 'last' | null} */
let normals = null;
/** A 'relief' command that came while the decoder was starting. @type {boolean | null} */
let relief = null;
/** @type {import('./reconstruction.js').Post} */
function post(message, transfer) {
  if (!renderPort || (message.type !== 'level' && message.type !== 'edges' && message.type !== 'relief')) {
    scope.postMessage(message, transfer);
    return;
  }
  renderPort.postMessage(message, transfer);
  if (message.type === 'level') {
    const { type, level, vertices, faces, baseBounds, received, decodeMs, deriveMs, decoders } = message;
    /** @type {import('./reconstruction.js').LevelNotice} */
    const notice = { type, level, vertices, faces, baseBounds, received, decodeMs, deriveMs, decoders };
    scope.postMessage(notice);
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
    job = new Reconstruction(instance, command.request, post, undefined, command.helpers ?? []);
    if (normals !== null) job.setNormals(normals);
    if (relief !== null) job.setRelief(relief);
    void job.run();
  } else if (command.type === 'extend') {
    job?.extend(command.upTo);
  } else if (command.type === 'wireframe') {
    job?.setWireframe(command.on);
  } else if (command.type === 'relief') {
    relief = command.on;
    job?.setRelief(command.on);
  } else if (command.type === 'geodesic') {
    try {
      if (!job) throw new Error('no model loaded');
      const { distance, level } = job.surfaceDistance(command.from, command.to);
      scope.postMessage({ type: 'geodesic', id: command.id, distance, level });
    } catch (error) {
      scope.postMessage({ type: 'geodesic', id: command.id, error: error instanceof Error ? error.message : String(error) });
    }
  } else if (command.type === 'level-data') {
    if (!job || job.level < 0) return;
    const { level, positions, indices, colours } = job.current();
    const transfer = [positions.buffer, indices.buffer, ...(colours ? [colours.buffer] : [])];
    scope.postMessage({ type: 'level-data', id: command.id, level, positions, indices, colours }, transfer);
  } else if (command.type === 'normals') {
    normals = command.which;
    job?.setNormals(command.which);
  }
};
