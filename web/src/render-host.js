// @ts-check
/**
 * Where the viewer draws: in a render worker on an OffscreenCanvas when the
 * browser can (the main thread then only handles input and the interface),
 * else on the page's canvas on the main thread (the fallback: browsers whose
 * workers have no WebGL2, or `offscreen: false`).
 *
 * Both give the viewer one interface ({@link RenderHost}); on the worker side
 * it is a proxy that forwards the camera, size and colour textures, and
 * mirrors what the worker reports (levels swapped in, frames drawn, lost
 * context, pending uploads).
 */

import { occludedPoints, pickLevel } from './pick.js';
import { Renderer, frameStats } from './renderer.js';

/** @typedef {import('./reconstruction.js').LevelMessage} LevelMessage */
/** @typedef {import('./renderer.js').AtlasResolution} AtlasResolution */
/** @typedef {{ width: number, height: number, rgba: Uint8Array }} Capture */
/** @typedef {import('./pick.js').PickResult} PickResult */

/**
 * @typedef {object} RenderHooks
 * @property {(level: { level: number, vertices: number, normalsMs: number }) => void} onSwap a level is
 *   complete on the GPU (normalsMs: the renderer's time deriving normals so far)
 * @property {(level: number) => void} onHeld a level above the hold is complete on the GPU, off screen
 * @property {(frame: { level: number | null, colourResolution: AtlasResolution | null, reliefTop: number | null, at: number }) => void} onFrame
 *   a frame was drawn: the level and colour texture in it (the level may be a coarser one standing in
 *   for the one on screen while the view moves; motion.js), the top of its θ scale in degrees
 *   (null: not in the relief view), at (performance.now() of this page)
 * @property {(bounds: import('./geometry.js').Bounds) => import('./camera.js').OrbitCamera} camera
 *   the viewer's camera, made from the base mesh's bounds by whoever needs it first
 */

/**
 * @typedef {object} RenderHost
 * @property {'worker' | 'main'} thread where WebGL runs
 * @property {import('./camera.js').OrbitCamera | null} camera
 * @property {boolean} lost the WebGL context is lost
 * @property {boolean} settled the newest level is complete on the GPU
 * @property {boolean} edges the level on screen has its wire edges on the GPU
 * @property {AtlasResolution | null} colourResolution
 * @property {number} maxTextureSize
 * @property {boolean} antialias whether the context multisamples (rasteriser.js)
 * @property {(on: boolean) => void} setWireframe
 * @property {(on: boolean) => void} setRelief colour by θ (relief.js) where the level has it
 * @property {(level: number | null) => void} setHold show levels up to this one only (null: all);
 *   those above are uploaded and wait off screen (renderer.js `hold`)
 * @property {() => void} requestFrame
 * @property {(on: boolean) => void} setGrabbed the visitor holds the view (a pointer is down): it
 *   counts as moving until released (motion.js)
 * @property {(mapping: import('./renderer.js').ColourMapping | null) => void} setColourMapping
 * @property {(source: ImageBitmap, resolution: AtlasResolution) => void} setColourAtlas
 * @property {() => Promise<Capture>} capture draws and reads the pixels (rows bottom-up)
 * @property {(look: import('./program.js').Look) => void} setLook model rotation, light, clay, section
 * @property {(ray: import('./pick.js').Ray, snap: number) => Promise<PickResult>} pick the surface point of the level
 *   on screen along a ray (model coordinates), and the vertex nearest to it within `snap` × depth model units (pick.js pickLevel)
 * @property {(eye: number[], points: number[][], tolerance: number) => Promise<boolean[]>} occlusion which
 *   points the level on screen hides from the eye
 * @property {() => Promise<Blob>} snapshot the view as a PNG
 * @property {() => Promise<import('./renderer.js').FrameStats | null>} frameStats frames drawn, and the
 *   stand-in's (benchmarks and tests of motion.js)
 * @property {() => Promise<number>} finish resolves when the GPU has drawn every frame asked
 *   for so far, with performance.now() then (benchmarks: frames are drawn some time after they are issued)
 * @property {(port: MessagePort) => void} attach the port a decode worker posts its levels
 *   and edges to (a new one replaces the last: a retry's new worker)
 * @property {() => void} loseContext tests
 * @property {() => void} restoreContext tests
 */

/**
 * Whether this page can hand a canvas to a worker at all.
 * @param {HTMLCanvasElement} canvas
 */
export function canTransfer(canvas) {
  return typeof OffscreenCanvas === 'function' && typeof canvas.transferControlToOffscreen === 'function';
}

/**
 * Starts drawing on `canvas`: in a render worker when `offscreen` and the
 * worker reports WebGL2, else on the main thread.
 * @param {HTMLCanvasElement} canvas
 * @param {RenderHooks} hooks
 * @param {{ offscreen: boolean, createWorker: () => Promise<Worker>, background?: [number, number, number], antialias?: boolean | null,
 *   motion?: import('./motion.js').MotionMode }} options
 *   `antialias`: multisample (null or absent: on a GPU only; rasteriser.js); `motion`: what is drawn
 *   while the view moves (motion.js; default `auto`)
 * @returns {Promise<RenderHost>}
 */
export async function openRenderer(canvas, hooks, options) {
  if (options.offscreen && canTransfer(canvas)) {
    const worker = await options.createWorker().catch(() => null);
    if (worker) {
      const ready = await new Promise((resolve) => {
        worker.onmessage = (event) => resolve(event.data?.type === 'ready' && event.data.webgl2 === true);
        worker.onerror = () => resolve(false);
      });
      performance.mark(`vitrine:render-worker-${ready ? 'ready' : 'without-webgl2'}`);
      if (ready) return WorkerRenderer.start(canvas, worker, hooks, options);
      worker.terminate();
    }
  }
  return new MainRenderer(canvas, hooks, options);
}

/** The fallback: the renderer on the page's own canvas. */
class MainRenderer {
  thread = /** @type {const} */ ('main');

  /**
   * @param {HTMLCanvasElement} canvas
   * @param {RenderHooks} hooks
   * @param {{ background?: [number, number, number], antialias?: boolean | null, motion?: import('./motion.js').MotionMode }} options
   */
  constructor(canvas, hooks, { background, antialias, motion }) {
    this.hooks = hooks;
    this.renderer = new Renderer(canvas, null, {
      onSwap: (level) => hooks.onSwap({ level: level.level, vertices: level.vertices, normalsMs: this.renderer.normalsMs }),
      onHeld: (level) => hooks.onHeld(level.level),
      onFrame: () =>
        hooks.onFrame({
          level: this.renderer.drawn?.source.level ?? null,
          colourResolution: this.renderer.colourResolution,
          reliefTop: this.renderer.reliefTop,
          at: performance.now(),
        }),
    }, { background, antialias: antialias ?? undefined, motion });
  }

  get camera() {
    return this.renderer.camera;
  }

  set camera(camera) {
    this.renderer.camera = camera;
  }

  get lost() {
    return this.renderer.lost;
  }

  get settled() {
    return this.renderer.settled;
  }

  get edges() {
    const current = this.renderer.current;
    return Boolean(current?.edgeBuffer && current.uploads.length === 0);
  }

  get colourResolution() {
    return this.renderer.colourResolution;
  }

  get maxTextureSize() {
    return this.renderer.maxTextureSize;
  }

  get antialias() {
    return this.renderer.antialias;
  }

  /** @type {MessagePort | null} */
  #port = null;

  /** @param {MessagePort} port */
  attach(port) {
    this.#port?.close();
    this.#port = port;
    port.onmessage = (event) => {
      const message = /** @type {import('./reconstruction.js').WorkerMessage} */ (event.data);
      if (message.type === 'level') {
        this.renderer.camera ??= this.hooks.camera(message.baseBounds);
        this.renderer.show(message);
      } else if (message.type === 'edges') {
        this.renderer.addEdges(message.level, message.edges);
      } else if (message.type === 'relief') {
        this.renderer.addRelief(message.level, message.relief, message.top);
      }
    };
  }

  /** @param {boolean} on */
  setWireframe(on) {
    this.renderer.setWireframe(on);
  }

  /** @param {boolean} on */
  setRelief(on) {
    this.renderer.setRelief(on);
  }

  /** @param {number | null} level */
  setHold(level) {
    this.renderer.setHold(level);
  }

  requestFrame() {
    this.renderer.requestFrame();
  }

  /** @param {boolean} on */
  setGrabbed(on) {
    this.renderer.setGrabbed(on);
  }

  /** @param {import('./renderer.js').ColourMapping | null} mapping */
  setColourMapping(mapping) {
    this.renderer.setColourMapping(mapping);
  }

  /** @param {ImageBitmap} source @param {AtlasResolution} resolution */
  setColourAtlas(source, resolution) {
    this.renderer.setColourAtlas(source, resolution);
  }

  async capture() {
    return this.renderer.capture();
  }

  /** @param {import('./program.js').Look} look */
  setLook(look) {
    this.renderer.setLook(look);
  }

  /** @param {import('./pick.js').Ray} ray @param {number} snap */
  async pick(ray, snap) {
    return pickLevel(this.renderer.surface(), ray, snap);
  }

  /** @param {number[]} eye @param {number[][]} points @param {number} tolerance */
  async occlusion(eye, points, tolerance) {
    return occludedPoints(this.renderer.surface(), eye, points, tolerance);
  }

  snapshot() {
    return this.renderer.snapshot();
  }

  async frameStats() {
    return frameStats(this.renderer);
  }

  async finish() {
    this.renderer.finish();
    return performance.now();
  }

  loseContext() {
    this.renderer.loseContext();
  }

  restoreContext() {
    this.renderer.restoreContext();
  }
}

/**
 * The page's side of the render worker. The canvas element stays in the
 * page for input and layout; its drawing buffer belongs to the worker, and
 * the canvas's width and height are forwarded there (after the transfer the
 * element's own size may no longer be set).
 */
class WorkerRenderer {
  thread = /** @type {const} */ ('worker');
  /** @type {import('./camera.js').OrbitCamera | null} */
  camera = null;
  lost = false;
  settled = false;
  edges = false;
  frames = 0;
  /** @type {AtlasResolution | null} */
  colourResolution = null;
  maxTextureSize = 4096;
  antialias = false;
  /** @type {Map<number, (value: any) => void>} */
  #captures = new Map();
  #nextCapture = 1;

  /**
   * @param {HTMLCanvasElement} canvas
   * @param {Worker} worker
   * @param {RenderHooks} hooks
   */
  constructor(canvas, worker, hooks) {
    this.canvas = canvas;
    this.worker = worker;
    this.hooks = hooks;
  }

  /**
   * Hands the canvas over; resolves once the worker has a context, rejects
   * with its reason (no WebGL2) otherwise.
   * @param {HTMLCanvasElement} canvas
   * @param {Worker} worker
   * @param {RenderHooks} hooks
   * @param {{ background?: [number, number, number], antialias?: boolean | null, motion?: import('./motion.js').MotionMode }} options
   * @returns {Promise<RenderHost>}
   */
  static start(canvas, worker, hooks, { background, antialias, motion }) {
    const host = new WorkerRenderer(canvas, worker, hooks);
    const { width, height } = canvas;
    const offscreen = canvas.transferControlToOffscreen();
    host.#forwardSize(width, height);
    return new Promise((resolve, reject) => {
      worker.onmessage = (event) => {
        const message = /** @type {import('./render-worker.js').RenderReport} */ (event.data);
        if (message.type === 'started') {
          performance.mark('vitrine:render-worker-started');
          host.maxTextureSize = message.maxTextureSize;
          host.antialias = message.antialias;
          resolve(host);
        } else if (message.type === 'failed') {
          worker.terminate();
          reject(new Error(message.message));
        } else {
          host.#report(message);
        }
      };
      worker.onerror = (event) => reject(new Error(`the render worker failed: ${event.message}`));
      worker.postMessage({ type: 'canvas', canvas: offscreen, width, height, background, antialias, motion }, [offscreen]);
    });
  }

  /**
   * The canvas's width and height setters throw once its control is
   * transferred; ui.js keeps setting them to follow the element's size in
   * device pixels. Own properties on this element take those values and send
   * them to the worker, where the OffscreenCanvas is resized.
   * @param {number} width
   * @param {number} height
   */
  #forwardSize(width, height) {
    const size = { width, height };
    for (const key of /** @type {const} */ (['width', 'height'])) {
      Object.defineProperty(this.canvas, key, {
        configurable: true,
        get: () => size[key],
        set: (value) => {
          const v = Math.max(1, Math.round(Number(value)) || 1);
          if (v === size[key]) return;
          size[key] = v;
          // Both setters run in one task (ui.js): send the pair once, after it.
          this.#sizePosted ??= Promise.resolve().then(() => {
            this.#sizePosted = null;
            this.worker.postMessage({ type: 'size', ...size });
          });
        },
      });
    }
  }

  /** @type {Promise<void> | null} */
  #sizePosted = null;

  /** @param {import('./render-worker.js').RenderReport} message */
  #report(message) {
    switch (message.type) {
      case 'swap':
        this.hooks.onSwap(message);
        break;
      case 'held':
        this.hooks.onHeld(message.level);
        break;
      case 'frame':
        this.colourResolution = message.colourResolution;
        this.hooks.onFrame({
          level: message.level,
          colourResolution: message.colourResolution,
          reliefTop: message.reliefTop,
          at: message.at - performance.timeOrigin,
        });
        break;
      case 'status':
        this.lost = message.lost;
        this.settled = message.settled;
        this.edges = message.edges;
        this.frames = message.frames;
        break;
      case 'captured':
      case 'finished':
      case 'answer': {
        const done = this.#captures.get(message.id);
        this.#captures.delete(message.id);
        if (message.type === 'captured') done?.({ width: message.width, height: message.height, rgba: message.rgba });
        else if (message.type === 'finished') done?.(message.at - performance.timeOrigin);
        else done?.(message.value);
        break;
      }
    }
  }

  /** @param {boolean} on */
  setWireframe(on) {
    this.worker.postMessage({ type: 'wireframe', on });
  }

  /** @param {boolean} on */
  setRelief(on) {
    this.worker.postMessage({ type: 'relief', on });
  }

  /** @param {number | null} level */
  setHold(level) {
    this.worker.postMessage({ type: 'hold', level });
  }

  /** The camera may have moved: the worker draws with the page's camera state. */
  requestFrame() {
    const camera = this.camera;
    this.worker.postMessage({ type: 'camera', state: camera ? camera.state : null, radius: camera?.radius ?? null });
  }

  /** @param {boolean} on */
  setGrabbed(on) {
    this.worker.postMessage({ type: 'grab', on });
  }

  /** @param {import('./renderer.js').ColourMapping | null} mapping */
  setColourMapping(mapping) {
    this.colourResolution = null;
    this.worker.postMessage({ type: 'colourMapping', mapping });
  }

  /**
   * The bitmap moves to the worker (it is not usable here afterwards).
   * @param {ImageBitmap} source
   * @param {AtlasResolution} resolution
   */
  setColourAtlas(source, resolution) {
    this.worker.postMessage({ type: 'colourAtlas', source, resolution }, [source]);
  }

  /** @returns {Promise<number>} */
  finish() {
    const id = this.#nextCapture++;
    return new Promise((resolve) => {
      this.#captures.set(id, resolve);
      this.worker.postMessage({ type: 'finish', id });
    });
  }

  /**
   * A question for the worker, answered by id ('answer').
   * @param {Record<string, unknown> & { type: string }} command
   * @returns {Promise<any>}
   */
  #ask(command) {
    const id = this.#nextCapture++;
    return new Promise((resolve) => {
      this.#captures.set(id, resolve);
      this.worker.postMessage({ ...command, id });
    });
  }

  /** @param {import('./program.js').Look} look */
  setLook(look) {
    this.worker.postMessage({ type: 'look', look });
  }

  /** @param {import('./pick.js').Ray} ray @param {number} snap @returns {Promise<PickResult>} */
  pick(ray, snap) {
    return this.#ask({ type: 'pick', ray, snap });
  }

  /** @param {number[]} eye @param {number[][]} points @param {number} tolerance @returns {Promise<boolean[]>} */
  occlusion(eye, points, tolerance) {
    return this.#ask({ type: 'occlusion', eye, points, tolerance });
  }

  /** @returns {Promise<Blob>} */
  async snapshot() {
    const answer = await this.#ask({ type: 'snapshot' });
    if (answer instanceof Blob) return answer;
    throw new Error(String(answer?.error ?? 'the picture could not be encoded'));
  }

  /** @returns {Promise<import('./renderer.js').FrameStats | null>} */
  frameStats() {
    return this.#ask({ type: 'frameStats' });
  }

  /** @returns {Promise<Capture>} */
  capture() {
    const id = this.#nextCapture++;
    return new Promise((resolve) => {
      this.#captures.set(id, resolve);
      this.worker.postMessage({ type: 'capture', id });
    });
  }

  /** Levels go from the decode worker to the render worker directly. @param {MessagePort} port */
  attach(port) {
    this.worker.postMessage({ type: 'source', port }, [port]);
  }

  loseContext() {
    this.worker.postMessage({ type: 'loseContext' });
  }

  restoreContext() {
    this.worker.postMessage({ type: 'restoreContext' });
  }
}
