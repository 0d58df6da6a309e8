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
import { NestedRefinement } from './nested-refinement.js';
import { nestedTable } from './nested-selection.js';
import { PartRefinement } from './part-refinement.js';
import { fetchPayload } from './payload.js';
import { Reconstruction } from './reconstruction.js';

/**
 * @typedef {{ type: 'load', module: WebAssembly.Module, request: import('./reconstruction.js').LoadRequest, port?: MessagePort | null, helpers?: MessagePort[] }
 *   | { type: 'extend', upTo: number }
 *   | { type: 'wireframe', on: boolean }
 *   | { type: 'relief', on: boolean }
 *   | { type: 'normals', which: 'always' | 'last' }
 *   | { type: 'geodesic', id: number, from: number[], to: number[] }
 *   | { type: 'level-data', id: number }
 *   | { type: 'part-camera', camera: import('./part-selection.js').PartCamera }
 *   | { type: 'part-chart', id: number, chart: number, phase?: number }} WorkerCommand
 * `part-camera`: where the camera is, for view-dependent refinement (part-refinement.js, nested-refinement.js);
 * `part-chart` (`phase`: a nested stream's, default 0) is answered with
 * `{ type: 'part-chart', id, depth, positions, colours, indices }` or `{ type: 'part-chart', id, error }`.
 * `geodesic` is answered with `{ type: 'geodesic', id, distance, level }` or `{ type: 'geodesic', id, error }`;
 * `level-data` with a copy of the last decoded level (splats/mesh-splat-view.js `LevelData`), or nothing before one.
 */

const scope = /** @type {DedicatedWorkerGlobalScope} */ (/** @type {unknown} */ (self));

/** @type {Promise<VitrineCodec> | null} */
let codec = null;
/** @type {Reconstruction | null} */
let job = null;
/** View-dependent refinement, once the global batches are in (a load with `parts`). @type {PartRefinement | NestedRefinement | null} */
let parts = null;
/** The camera sent before the refinement started. @type {import('./part-selection.js').PartCamera | null} */
let partCamera = null;
/**
 * The body bytes the network carried for the last fetch of `address`, by
 * its resource timing (compressed, where the service compressed it); null
 * where the browser keeps no such entry.
 * @param {string} address
 * @returns {number | null}
 */
function carriedBytes(address) {
  if (typeof location === 'undefined' || typeof performance?.getEntriesByName !== 'function') return null;
  const entries = /** @type {PerformanceResourceTiming[]} */ (performance.getEntriesByName(new URL(address, location.href).href, 'resource'));
  const last = entries.at(-1);
  return last && last.encodedBodySize > 0 ? last.encodedBodySize : null;
}

/** Bumped by every load, so a load still starting (or fetching its part index) gives up. */
let loads = 0;
/** The cap of a parted load (null: none), which 'extend' raises or lowers. @type {number | null} */
let partedUpTo = null;
/** The last global level of a parted load. */
let partedGlobal = 0;

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
    const load = ++loads;
    job?.cancel();
    parts?.stop();
    parts = null;
    partCamera = null;
    partedUpTo = null;
    renderPort = command.port ?? null;
    codec ??= VitrineCodec.instantiate(command.module);
    let instance;
    try {
      instance = await codec;
    } catch (error) {
      post({ type: 'error', kind: 'decode', level: -1, message: `the decoder did not start: ${error}` }, []);
      return;
    }
    if (load !== loads) return;
    if (command.request.parts) return void loadParted(instance, command.request, load);
    job = new Reconstruction(instance, command.request, post, undefined, command.helpers ?? []);
    if (normals !== null) job.setNormals(normals);
    if (relief !== null) job.setRelief(relief);
    void job.run();
  } else if (command.type === 'extend') {
    // A parted load keeps its decoder to the global batches; the parts follow the cap.
    if (partedUpTo !== null) {
      partedUpTo = command.upTo;
      // Global batches refused earlier (a cap that fell) may be fetched again.
      if (!parts) job?.extend(Math.min(command.upTo, partedGlobal));
    } else job?.extend(command.upTo);
    parts?.setCap(command.upTo);
  } else if (command.type === 'part-camera') {
    partCamera = command.camera;
    parts?.setCamera(command.camera);
  } else if (command.type === 'part-chart') {
    try {
      if (!parts) throw new Error('not refining by parts');
      const { depth, positions, colours, indices } = parts.chart(command.chart, command.phase ?? 0);
      scope.postMessage({ type: 'part-chart', id: command.id, depth, positions, colours, indices });
    } catch (error) {
      scope.postMessage({ type: 'part-chart', id: command.id, error: error instanceof Error ? error.message : String(error) });
    }
  } else if (command.type === 'wireframe') {
    job?.setWireframe(command.on);
    parts?.setWireframe(command.on);
  } else if (command.type === 'relief') {
    relief = command.on;
    job?.setRelief(command.on);
  } else if (command.type === 'geodesic') {
    try {
      if (!job && !parts) throw new Error('no model loaded');
      const { distance, level } = parts ? surfaceDistance(/** @type {VitrineCodec} */ (instanceNow), parts, command.from, command.to) : /** @type {Reconstruction} */ (job).surfaceDistance(command.from, command.to);
      scope.postMessage({ type: 'geodesic', id: command.id, distance, level });
    } catch (error) {
      scope.postMessage({ type: 'geodesic', id: command.id, error: error instanceof Error ? error.message : String(error) });
    }
  } else if (command.type === 'level-data') {
    const source = parts ?? (job && job.level >= 0 ? job : null);
    if (!source) return;
    const { level, positions, indices, colours } = source.current();
    const transfer = [positions.buffer, indices.buffer, ...(colours ? [colours.buffer] : [])];
    scope.postMessage({ type: 'level-data', id: command.id, level, positions, indices, colours }, transfer);
  } else if (command.type === 'normals') {
    normals = command.which;
    job?.setNormals(command.which);
  }
};

/** The codec once started (for measurements on the parts' union). @type {VitrineCodec | null} */
let instanceNow = null;

/**
 * @param {VitrineCodec} codec
 * @param {{ current(): import('./codec.js').Level }} refinement
 * @param {number[]} from
 * @param {number[]} to
 */
function surfaceDistance(codec, refinement, from, to) {
  const { positions, indices, level } = refinement.current();
  const surface = codec.surface(positions, indices);
  try {
    return { distance: surface.distance(from, to), level };
  } finally {
    surface.free();
  }
}

/**
 * A charted stream refined where the camera looks (issue 41): the part
 * index first, then the base and the global batches as any load (one
 * decoder, no pool), then the first parted batch's head turns the decoder
 * into a PartView and part-refinement.js takes over; for a nested stream
 * (format 6, the request's `nested`), into a NestedView declared from the
 * index, and nested-refinement.js takes over. A stream whose cap stops
 * before its parted batches loads as usual.
 * @param {VitrineCodec} codec
 * @param {import('./reconstruction.js').LoadRequest} request
 * @param {number} load
 */
async function loadParted(codec, request, load) {
  instanceNow = codec;
  parts?.stop();
  parts = null;
  const options = /** @type {import('./reconstruction.js').PartsRequest} */ (request.parts);
  const url = (/** @type {string} */ path) => {
    const u = new URL(path, options.apiBase);
    for (const [key, value] of options.query) u.searchParams.set(key, value);
    return u.href;
  };
  const headers = request.headers;
  let bytes = 0;
  /** @param {string} address @param {string} what */
  const payload = async (address, what) => {
    const fetched = await fetchPayload(address, { what, headers });
    if ('bytes' in fetched) bytes += fetched.bytes.length;
    return fetched;
  };
  /** @type {import('./part-selection.js').PartIndex & import('./nested-selection.js').NestedPartIndex} */
  let index;
  try {
    const fetched = await payload(options.indexUrl, 'part index');
    if (!('bytes' in fetched)) throw new Error('the server refused the part index');
    index = JSON.parse(new TextDecoder().decode(fetched.bytes));
    // JSON the service compresses: counted as the network carried it.
    const carried = carriedBytes(options.indexUrl);
    if (carried !== null) bytes += carried - fetched.bytes.length;
  } catch (error) {
    post({ type: 'error', kind: 'network', level: -1, message: error instanceof Error ? error.message : String(error) }, []);
    return;
  }
  if (load !== loads) return;
  const globalTo = index.first_level - 1;
  const parted = globalTo >= 0 && globalTo < request.upTo;
  if (parted) {
    partedUpTo = request.upTo;
    partedGlobal = globalTo;
  }
  let started = false;
  /** @type {import('./reconstruction.js').LevelMessage | null} */
  let lastLevel = null;
  /** @type {import('./reconstruction.js').Post} */
  const intercept = (message, transfer) => {
    if (parted && message.type === 'done' && message.level === globalTo && !started) {
      started = true;
      void begin();
      return;
    }
    if (message.type === 'level') lastLevel = message;
    post(message, transfer);
  };
  const begin = async () => {
    const reconstruction = /** @type {Reconstruction} */ (job);
    const decoder = reconstruction.release();
    const level = /** @type {import('./reconstruction.js').LevelMessage} */ (lastLevel);
    try {
      if (!decoder) throw new Error('no decoder to refine by parts');
      const head = await payload(url(index.head_url), 'parted batch head');
      if (!('bytes' in head)) throw new Error('the server refused the parted batch head');
      if (load !== loads) return decoder.free();
      /** @param {string} what @param {string} path */
      const piece = (what, path) => fetchPayload(url(path), { what, headers });
      const common = {
        index,
        budget: options.budget,
        capLevel: partedUpTo ?? request.upTo,
        sentVertices: level.vertices,
        baseBounds: level.baseBounds,
        bytesFetched: level.received + bytes,
        wireframe: request.wireframe,
        /** @param {{ level: number, chart: number }} part */
        fetchPart: (part) =>
          piece(`part ${part.chart} of batch ${part.level}`, index.part_url.replace('{level}', String(part.level)).replace('{chart}', String(part.chart))),
        post,
        tell: (/** @type {any} */ message) => scope.postMessage(message),
      };
      if (options.nested) {
        const view = decoder.intoNested(head.bytes, nestedTable(index).batchesInOrder);
        parts = new NestedRefinement({
          ...common,
          view,
          fetchSplit: (split) =>
            piece(`split entry ${split.parent} of batch ${split.level}`, index.split_url.replace('{level}', String(split.level)).replace('{parent}', String(split.parent))),
        });
      } else {
        parts = new PartRefinement({ ...common, view: decoder.intoView(head.bytes) });
      }
      if (partCamera) parts.setCamera(partCamera);
    } catch (error) {
      const kind = error instanceof Error && /refused|fetch|answered/.test(error.message) ? 'network' : 'decode';
      post({ type: 'error', kind, level: globalTo, message: error instanceof Error ? error.message : String(error) }, []);
    }
  };
  const upTo = parted ? globalTo : request.upTo;
  job = new Reconstruction(codec, { ...request, upTo, capacity: request.capacity }, intercept, undefined, []);
  if (normals !== null) job.setNormals(normals);
  void job.run();
}
