// @ts-check
/**
 * The splat view on the page: a canvas of its own over the viewer's (the
 * viewer's may belong to a render worker), a SplatRenderer on it, drawn
 * whenever the camera or the splats change. Input still goes to the canvas
 * below (this one lets pointer events through).
 */

import { DEFAULT_SPLAT_OPTIONS, SplatRenderer } from './splat-renderer.js';

/** @typedef {import('./splat-renderer.js').SplatSet} SplatSet */

const IDENTITY = [1, 0, 0, 0, 1, 0, 0, 0, 1];

export class SplatView {
  /** @type {SplatRenderer} */
  renderer;
  /** @type {import('./splat-renderer.js').SplatOptions} */
  options = { ...DEFAULT_SPLAT_OPTIONS };
  /** Splats on the GPU. */
  count = 0;
  /** Frames drawn. */
  frames = 0;
  #camera;
  #model;
  #dirty = true;
  #lastView = '';
  /** @type {number | null} */
  #raf = null;

  /**
   * @param {(canvas: HTMLCanvasElement) => void} place puts the canvas on the page (over the viewer's)
   * @param {{ camera: () => import('../camera.js').OrbitCamera | null, background: [number, number, number],
   *   model?: () => ArrayLike<number> }} options model: the upright rotation (frame.js upRotation)
   */
  constructor(place, options) {
    this.#camera = options.camera;
    this.#model = options.model ?? (() => IDENTITY);
    this.canvas = document.createElement('canvas');
    this.canvas.className = 'splats';
    Object.assign(this.canvas.style, { position: 'absolute', inset: '0', width: '100%', height: '100%', pointerEvents: 'none' });
    // Never multisampled: each splat fades out by its own Gaussian, so its
    // edges are smooth without it, and blending thousands of overlapping
    // splats is where a CPU rasteriser spends its time.
    const gl = this.canvas.getContext('webgl2', { antialias: false, preserveDrawingBuffer: false });
    if (!gl) throw new Error('The splat view needs WebGL2.');
    /** Whether the picture is multisampled (the context's own answer). */
    this.antialias = gl.getContextAttributes()?.antialias ?? false;
    place(this.canvas);
    try {
      this.renderer = new SplatRenderer(gl, options.background);
    } catch (error) {
      this.canvas.remove();
      throw error;
    }
    const loop = () => {
      this.#raf = requestAnimationFrame(loop);
      this.#drawIfChanged();
    };
    this.#raf = requestAnimationFrame(loop);
  }

  /** @param {SplatSet} set */
  setSplats(set) {
    this.renderer.setSplats(set);
    this.count = set.count;
    this.#dirty = true;
  }

  /** @param {Partial<import('./splat-renderer.js').SplatOptions>} patch */
  setOptions(patch) {
    this.options = { ...this.options, ...patch };
    this.#dirty = true;
  }

  #size() {
    const dpr = devicePixelRatio || 1;
    const width = Math.max(1, Math.round(this.canvas.clientWidth * dpr));
    const height = Math.max(1, Math.round(this.canvas.clientHeight * dpr));
    if (this.canvas.width !== width || this.canvas.height !== height) {
      this.canvas.width = width;
      this.canvas.height = height;
    }
    return { width, height };
  }

  #drawIfChanged() {
    const camera = this.#camera();
    if (!camera) return;
    const { width, height } = this.#size();
    const key = `${camera.view().join()}|${Array.from(this.#model()).join()}|${width}x${height}`;
    if (!this.#dirty && key === this.#lastView) return;
    this.#lastView = key;
    this.#dirty = false;
    this.draw();
  }

  /** Draws now; false when there is no camera yet. */
  draw() {
    const camera = this.#camera();
    if (!camera) return false;
    const { width, height } = this.#size();
    this.renderer.draw({ view: camera.view(), projection: camera.projection(width / height), width, height, model: this.#model() }, this.options);
    this.frames++;
    return true;
  }

  /** Draws and reads the pixels (RGBA, rows bottom-up), in one task. */
  capture() {
    this.draw();
    const gl = this.renderer.gl;
    const { width, height } = this.canvas;
    const rgba = new Uint8Array(width * height * 4);
    gl.readPixels(0, 0, width, height, gl.RGBA, gl.UNSIGNED_BYTE, rgba);
    return { width, height, rgba };
  }

  /**
   * Mean milliseconds of `frames` frames, each drawn and waited for
   * (a 1-pixel read makes the GPU finish).
   * @param {number} frames
   */
  frameTime(frames) {
    const gl = this.renderer.gl;
    const pixel = new Uint8Array(4);
    /** @type {number[]} */
    const times = [];
    for (let f = 0; f < frames; f++) {
      const t = performance.now();
      this.draw();
      gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, pixel);
      times.push(performance.now() - t);
    }
    return times.reduce((a, b) => a + b, 0) / Math.max(1, times.length);
  }

  destroy() {
    if (this.#raf !== null) cancelAnimationFrame(this.#raf);
    this.#raf = null;
    this.renderer.gl.getExtension('WEBGL_lose_context')?.loseContext();
    this.canvas.remove();
  }
}
