// @ts-check
/**
 * The "Splats" view of a mesh model: the level on screen (its vertices,
 * normals and colours, split and clipped at its sharp edges) drawn as
 * splats over the viewer's canvas. The decode worker copies the level out
 * ('level-data'), the splat worker derives the splats (mesh-splats.js); the
 * main thread only hands buffers on. Off, the canvas is removed and the
 * mesh path is as it was.
 */

import { SplatView } from './splat-view.js';

/**
 * @typedef {object} MeshSplatHost
 * @property {(canvas: HTMLCanvasElement) => void} place
 * @property {[number, number, number]} background
 * @property {() => import('../camera.js').OrbitCamera | null} current
 * @property {() => ArrayLike<number>} model
 * @property {() => Promise<Worker>} createWorker the splat worker
 * @property {(id: number) => boolean} requestLevel asks the decode worker for the level on screen
 *   (answered with {@link MeshSplats.receive}); false when there is none
 * @property {(message: string) => void} warn the view could not start (the mesh stays)
 */

/** @typedef {{ type: 'level-data', id: number, level: number, positions: Float32Array, indices: Uint32Array, colours: Uint8Array | null }} LevelData */

export class MeshSplats {
  /** @type {SplatView | null} */
  view = null;
  /** Level whose splats are on screen (-1: none). */
  level = -1;
  /** @type {Promise<Worker> | null} */
  #worker = null;
  #host;
  #asked = 0;

  /** @param {MeshSplatHost} host */
  constructor(host) {
    this.#host = host;
  }

  get on() {
    return this.view !== null;
  }

  show() {
    if (this.view) return;
    try {
      this.view = new SplatView(this.#host.place, { camera: this.#host.current, background: this.#host.background, model: this.#host.model });
    } catch (error) {
      this.#host.warn(error instanceof Error ? error.message : String(error));
      return;
    }
    this.level = -1;
    this.levelShown();
  }

  hide() {
    this.view?.destroy();
    this.view = null;
    this.level = -1;
  }

  /** A new level is on screen: its splats replace the last ones. */
  levelShown() {
    if (this.view) this.#host.requestLevel(++this.#asked);
  }

  /** @param {LevelData} data */
  async receive(data) {
    if (data.id !== this.#asked || !this.view) return;
    this.#worker ??= this.#host.createWorker();
    const worker = await this.#worker;
    worker.onmessage = (/** @type {MessageEvent<import('./messages.js').SplatMessage>} */ event) => {
      const m = event.data;
      if (m.type !== 'splats' || m.id !== this.#asked || !this.view) return;
      this.view.setSplats(m.set);
      this.level = data.level;
    };
    const { positions, indices, colours } = data;
    /** @type {Transferable[]} */
    const transfer = [positions.buffer, indices.buffer];
    if (colours) transfer.push(colours.buffer);
    worker.postMessage({ type: 'mesh', id: data.id, positions, indices, colours }, transfer);
  }

  destroy() {
    this.hide();
    void this.#worker?.then((w) => w.terminate());
    this.#worker = null;
  }
}
