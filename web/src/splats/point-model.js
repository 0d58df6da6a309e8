// @ts-check
/**
 * A point-cloud model in the viewer (manifest `kind: "points"`): the splat
 * worker fetches level 0 (header + first chunk) and each later chunk from
 * the manifest's level URLs, decodes them and runs the splat preprocessing;
 * each level's splats replace the last in a SplatView over the viewer's
 * canvas, so the cloud refines as levels arrive. A chunk that does not
 * decode (a truncated stream) or a download that fails ends in the
 * viewer's error state; a level the server refuses (a load cap) holds the
 * cloud at the level before it until {@link PointModel#extend}.
 */

import { bounds } from '../geometry.js';
import { SplatView } from './splat-view.js';

/**
 * What the viewer lends the point model.
 * @typedef {object} PointHost
 * @property {(canvas: HTMLCanvasElement) => void} place puts the splat canvas over the viewer's
 * @property {[number, number, number]} background
 * @property {(bounds: import('../geometry.js').Bounds) => import('../camera.js').OrbitCamera} camera the
 *   viewer's camera, made from the first level's bounds if there is none yet
 * @property {() => import('../camera.js').OrbitCamera | null} current the viewer's camera as it is now
 * @property {() => ArrayLike<number>} model the upright rotation (the viewer's look)
 * @property {() => Promise<Worker>} createWorker the splat worker
 * @property {(level: { level: number, vertices: number, normalsMs: number }) => void} shown a level is on screen
 * @property {(frame: { level: number, colourResolution: null, reliefTop: null, at: number }) => void} framed a level was drawn
 * @property {(patch: Partial<import('../viewer.js').ViewerState>) => void} set
 * @property {(cap: { level: number, reason: string | null, retryAfterS: number | null }) => void} capped the
 *   server refused the level after `level` (the viewer's cap handling, as for a mesh)
 * @property {(message: string) => void} fail
 */

export class PointModel {
  /** @type {SplatView | null} */
  view = null;
  /** @type {Worker | null} */
  #worker = null;
  #host;
  #decodeMs = 0;

  /** @param {PointHost} host */
  constructor(host) {
    this.#host = host;
  }

  /**
   * @param {WebAssembly.Module} module
   * @param {{ baseUrl: string, batchUrls: string[], upTo: number }} request
   */
  async start(module, request) {
    const host = this.#host;
    this.view = new SplatView(host.place, { camera: host.current, background: host.background, model: host.model });
    host.set({ antialias: this.view.antialias });
    const worker = await host.createWorker();
    this.#worker = worker;
    worker.onerror = (event) => host.fail(`the splat worker failed: ${event.message}`);
    worker.onmessage = (/** @type {MessageEvent<import('./messages.js').SplatMessage>} */ event) => {
      const m = event.data;
      if (m.type === 'splats') {
        host.camera(bounds(m.set.positions));
        const view = /** @type {SplatView} */ (this.view);
        view.setSplats(m.set);
        view.draw();
        host.set({ decodedLevel: m.level, received: m.received, decodeMs: (this.#decodeMs += m.ms) });
        host.shown({ level: m.level, vertices: m.set.count, normalsMs: 0 });
        host.framed({ level: m.level, colourResolution: null, reliefTop: null, at: performance.now() });
      } else if (m.type === 'capped') {
        host.capped(m);
      } else if (m.type === 'error') {
        const what = m.kind === 'decode' ? `could not decode level ${m.level + 1} of the point stream` : 'a download failed';
        host.fail(`${what}: ${m.message}`);
      }
    };
    worker.postMessage({ type: 'points', module, ...request });
  }

  /** Loads up to `upTo` (the cap rose). @param {number} upTo */
  extend(upTo) {
    this.#worker?.postMessage({ type: 'extend', upTo });
  }

  /** Whether levels may still come (not stopped). */
  get running() {
    return this.#worker !== null;
  }

  /** Stops decoding; what is on screen stays until {@link destroy}. */
  stop() {
    this.#worker?.terminate();
    this.#worker = null;
  }

  destroy() {
    this.stop();
    this.view?.destroy();
    this.view = null;
  }
}
