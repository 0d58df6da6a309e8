// @ts-check
/**
 * Raw WebGL2 rather than a scene library: the viewer draws one indexed mesh
 * with one shader, and three.js alone would be ~170 KB gzipped of script for
 * a tablet to fetch and parse before the base mesh could appear; this file,
 * the camera and the controls are a few KB.
 *
 * This file orchestrates; the parts live beside it: the shader program, its
 * uniforms and textures in program.js; the vertex store, each level's GPU
 * buffers and their sliced uploads in vertex-store.js; the normals of levels
 * that came without them in normals-task.js.
 *
 * Vertices are only ever appended from one level to the next, so positions
 * and colours live in one pair of buffers sized once for the last level
 * (the manifest's count): each level uploads only its new vertices there.
 * Normals and indices change everywhere; a new level gets fresh ones,
 * uploaded a slice per frame (at most `uploadBudgetMs` of bufferSubData)
 * while the previous level keeps being drawn; the two are swapped when the
 * upload is complete. So a 40 MB level never becomes one long task (on the
 * main thread, or in the render worker where it would delay the camera). A fence after each frame's
 * commands holds the next slice back until the GPU has caught up: otherwise
 * a slow GPU (a tablet's, or SwiftShader) fills the command buffer and the
 * next bufferSubData blocks the thread until it drains. The level's arrays
 * (and every vertex received) are kept so a lost WebGL context can be
 * rebuilt without asking the worker again.
 *
 * The same class draws on the page's canvas (the fallback) or, in the render
 * worker, on the OffscreenCanvas the page handed over (render-worker.js).
 */

import { multiply } from './camera.js';
import { MotionPolicy } from './motion.js';
import { NormalsTask, deriveNormals } from './normals-task.js';
import { DEFAULT_LOOK, bindCcc, bindLook, bindRelief, createAtlasTexture, createCellTexture, createProgram } from './program.js';
import { isSoftwareRasteriser, probeRenderer } from './rasteriser.js';
import { BACKGROUND, CLAY } from './shading.js';
import {
  VertexStore,
  addEdgeBuffer,
  addReliefBuffer,
  allocateMesh,
  emptyMesh,
  releaseMesh,
  reliefReady,
  uploadMesh,
} from './vertex-store.js';

const UPLOAD_BUDGET_MS = 6;
const UPLOAD_CHUNK_BYTES = 256 << 10;

/**
 * requestAnimationFrame where the thread has one (pages; Chromium's and
 * Firefox's workers), else a timer.
 * @type {(callback: () => void) => number}
 */
const nextFrame =
  typeof requestAnimationFrame === 'function' ? (f) => requestAnimationFrame(f) : (f) => Number(setTimeout(f, 16));
/** @type {(id: number) => void} */
const cancelFrame = typeof cancelAnimationFrame === 'function' ? (id) => cancelAnimationFrame(id) : (id) => clearTimeout(id);

/** @typedef {import('./reconstruction.js').LevelMessage} LevelMessage */
/** @typedef {import('./vertex-store.js').GpuMesh} GpuMesh */

/**
 * @typedef {object} RendererOptions
 * @property {number} [uploadBudgetMs] bufferSubData per frame (default 6 ms)
 * @property {number} [uploadChunkBytes] bytes per bufferSubData (default 256 KB)
 * @property {boolean} [antialias] multisample (default: on a GPU, not on a CPU rasteriser; rasteriser.js)
 * @property {[number, number, number]} [background] clear colour, 0–1 components (default shading.js BACKGROUND)
 * @property {import('./motion.js').MotionMode} [motion] what is drawn while the view moves (motion.js; default `auto`)
 */

/** @typedef {HTMLCanvasElement | OffscreenCanvas} AnyCanvas */

/**
 * A CCC colour mapping as the renderer holds it: the sources are kept so a
 * lost context can be rebuilt.
 * @typedef {object} ColourMapping
 * @property {import('./ccc.js').CccParameters} parameters
 * @property {import('./ccc.js').Pixels} cells the decoded cell texture
 */

/** @typedef {'low' | 'full'} AtlasResolution */

export class Renderer {
  /** @type {WebGL2RenderingContext} */
  gl;
  /** @type {GpuMesh | null} */
  current = null;
  /** @type {GpuMesh | null} */
  pending = null;
  /**
   * A coarser level shown before `current`, drawn in its place while the
   * view moves where `current` is slow to draw (motion.js).
   * @type {GpuMesh | null}
   */
  standIn = null;
  /** The level in the last frame drawn: `current`, or `standIn` while moving. @type {GpuMesh | null} */
  drawn = null;
  /** Frames that drew the stand-in. */
  standInFrames = 0;
  wireframe = false;
  /** The relief view: colour by θ where the level on screen has it. */
  relief = false;
  /**
   * The top (degrees) of the θ scale in the last frame drawn, null when
   * that frame was not in the relief view (off, or the level's θ not yet
   * on the GPU).
   * @type {number | null}
   */
  reliefTop = null;
  lost = false;
  frames = 0;
  /** Model rotation, key light, clay, section plane (program.js Look). */
  look = DEFAULT_LOOK;
  /** Milliseconds spent deriving normals of levels that came without them. */
  normalsMs = 0;
  /**
   * The highest level put on screen (null: every level, as it completes).
   * A level above it is still uploaded, then waits complete as `pending`
   * (reported by onHeld) until the hold rises to it: the quality study
   * decodes m_b while m_a stays on screen, and swaps when it chooses.
   * @type {number | null}
   */
  hold = null;
  /** The pending level is complete on the GPU and held back. */
  #parked = false;
  /** @type {number | null} */
  #raf = null;
  #dirty = false;
  /** @type {WebGLSync | null} */
  #fence = null;
  /** @type {WebGLProgram | null} */
  #program = null;
  /** @type {import('./program.js').Uniforms} */
  #uniforms = {};
  /** @type {ColourMapping | null} */
  #mapping = null;
  /** @type {{ source: TexImageSource, width: number, height: number, resolution: AtlasResolution } | null} */
  #atlas = null;
  /** @type {WebGLTexture | null} */
  #cellTexture = null;
  /** @type {WebGLTexture | null} */
  #atlasTexture = null;
  #store = new VertexStore();
  /** @type {LevelMessage | null} the newest level, waiting for the first one to be on screen */
  #next = null;
  /** @type {any} WEBGL_lose_context, for tests */
  #loseContext = null;
  /** @type {MotionPolicy} */
  #motion;
  /**
   * The finest level received that the stand-in may be (motion.js): it
   * becomes the stand-in once it is neither on screen nor on its way there,
   * drawn or not (levels that arrive while the first is drawn are skipped).
   * @type {LevelMessage | null}
   */
  #candidate = null;
  /** The view of the last frame drawn, to tell motion (view and projection, then the look). */
  /** @type {{ matrix: Float32Array<ArrayBufferLike>, look: import('./program.js').Look, width: number, height: number }} */
  #lastView = { matrix: new Float32Array(0), look: DEFAULT_LOOK, width: 0, height: 0 };
  /** A frame of `current` whose cost is being timed: its fence, when it was issued, its triangles. @type {{ fence: WebGLSync, at: number, triangles: number } | null} */
  #timing = null;
  /** Draws the level again once motion has stopped. @type {ReturnType<typeof setTimeout> | null} */
  #rest = null;

  /**
   * @param {AnyCanvas} canvas
   * @param {import('./camera.js').OrbitCamera | null} camera
   * @param {{ onSwap?: (level: LevelMessage) => void, onHeld?: (level: LevelMessage) => void, onFrame?: () => void,
   *   onTick?: () => void }} hooks
   *   onSwap: a level is complete on the GPU and replaces the previous one;
   *   onHeld: a level above the hold is complete on the GPU and waits off screen;
   *   onFrame: a frame was drawn; onTick: after every animation frame's work
   * @param {RendererOptions} [options]
   */
  constructor(canvas, camera, hooks = {}, options = {}) {
    this.canvas = canvas;
    this.camera = camera;
    this.hooks = hooks;
    this.uploadBudgetMs = options.uploadBudgetMs ?? UPLOAD_BUDGET_MS;
    this.uploadChunkBytes = options.uploadChunkBytes ?? UPLOAD_CHUNK_BYTES;
    this.background = options.background ?? BACKGROUND;
    this.#motion = new MotionPolicy(options.motion ?? 'auto');
    const antialias = options.antialias ?? !isSoftwareRasteriser(probeRenderer() ?? '');
    const gl = /** @type {WebGL2RenderingContext | null} */ (
      canvas.getContext('webgl2', { antialias, powerPreference: 'high-performance' })
    );
    if (!gl) throw new Error('this browser has no WebGL2');
    this.gl = gl;
    canvas.addEventListener('webglcontextlost', (event) => {
      event.preventDefault();
      this.lost = true;
      if (this.#raf !== null) cancelFrame(this.#raf);
      this.#raf = null;
    });
    canvas.addEventListener('webglcontextrestored', () => this.#restore());
    this.#init();
  }

  /** Loses the WebGL context on purpose (tests of the recovery). */
  loseContext() {
    this.#loseContext = this.gl.getExtension('WEBGL_lose_context');
    this.#loseContext?.loseContext();
  }

  /** Waits until the GPU has drawn everything asked of it (benchmarks: when the last frame is really done). */
  finish() {
    if (!this.lost) this.gl.finish();
  }

  /** Restores a context lost by loseContext(). */
  restoreContext() {
    this.#loseContext?.restoreContext();
  }

  /** Nothing waiting to be uploaded: the newest level is complete on the GPU. */
  get settled() {
    return !this.lost && !this.pending && !this.#next && Boolean(this.current) && this.current?.uploads.length === 0;
  }

  #init() {
    const gl = this.gl;
    const { program, uniforms } = createProgram(gl);
    this.#program = program;
    this.#uniforms = uniforms;
    gl.enable(gl.DEPTH_TEST);
    gl.clearColor(this.background[0], this.background[1], this.background[2], 1);
  }

  #restore() {
    this.lost = false;
    this.#fence = null;
    this.#cellTexture = null;
    this.#atlasTexture = null;
    this.#store.lose();
    // The stand-in's buffers went with the context: it is uploaded again
    // after the levels (and drawn once it is complete).
    const standIn = this.standIn?.source ?? null;
    this.standIn = null;
    this.drawn = null;
    this.#timing = null;
    this.#init();
    this.#uploadColour();
    const shown = this.current?.source;
    const newest = this.#next ?? this.pending?.source ?? shown;
    this.#next = null;
    this.current = null;
    this.pending = null;
    this.#parked = false;
    // A held level goes back behind the one that was on screen.
    if (shown && newest && newest !== shown && this.#holds(newest.level)) this.show(shown);
    if (newest) this.show(newest);
    if (standIn) this.standIn = this.#allocate(standIn);
    this.requestFrame();
  }

  /**
   * Starts uploading a level; the newest level wins over one still uploading.
   * @param {LevelMessage} level
   */
  show(level) {
    this.#store.receive(level);
    const candidate = this.#candidate;
    const keeps = level.standIn !== false && this.#motion.keeps(level.indices.length / 3, candidate && candidate.indices.length / 3, this.#store.capacity);
    if (keeps) {
      this.#candidate = level;
    }
    if (this.lost) {
      this.#next = null;
      this.pending = { ...emptyMesh(), source: level };
      return;
    }
    // The first level to arrive is drawn first (the base mesh at once), even
    // when newer ones arrive with it; after that the newest wins.
    if (this.pending && !this.current) {
      this.#next = level;
      return;
    }
    // A level superseded before it was shown may be the stand-in.
    if (this.pending) this.#retire(this.pending);
    this.pending = this.#allocate(level);
    this.#parked = false;
    this.#schedule();
  }

  /**
   * Shows levels up to `level` only (null: all); raising it swaps in a held level.
   * @param {number | null} level
   */
  setHold(level) {
    this.hold = level;
    if (this.#parked && this.pending && !this.#holds(this.pending.source.level)) this.#schedule();
  }

  /** @param {number} level */
  #holds(level) {
    return this.hold !== null && level > this.hold;
  }

  /**
   * Wire edges computed after the level was sent (wireframe switched on).
   * @param {number} level
   * @param {Uint32Array} edges
   */
  addEdges(level, edges) {
    for (const mesh of [this.pending, this.current]) {
      if (mesh && mesh.source.level === level && !mesh.source.edges) {
        mesh.source.edges = edges;
        if (!this.lost) addEdgeBuffer(this.gl, mesh, edges);
      }
    }
    this.requestFrame();
  }

  /**
   * θ computed after the level was sent (relief view switched on).
   * @param {number} level
   * @param {Float32Array} relief
   * @param {number} top degrees
   */
  addRelief(level, relief, top) {
    for (const mesh of [this.pending, this.current]) {
      if (mesh && mesh.source.level === level && !mesh.source.relief) {
        mesh.source.relief = relief;
        mesh.source.reliefTop = top;
        if (!this.lost && mesh.vao) addReliefBuffer(this.gl, mesh, relief);
      }
    }
    // A level waiting for the first one to be on screen gets its buffer when it is allocated.
    if (this.#next?.level === level && !this.#next.relief) Object.assign(this.#next, { relief, reliefTop: top });
    this.requestFrame();
  }

  /** @param {boolean} on */
  setRelief(on) {
    this.relief = on;
    this.requestFrame();
  }

  /**
   * Sets (or clears) the CCC colour mapping. It is drawn once a colour
   * texture is set too (`setColourAtlas`); until then levels keep their
   * per-vertex colour, or clay.
   * @param {ColourMapping | null} mapping
   */
  setColourMapping(mapping) {
    this.#mapping = mapping;
    this.#atlas = null;
    this.#uploadColour();
    this.requestFrame();
  }

  /**
   * Sets the colour texture: the low-resolution one first, the full one
   * when it arrives. Uploaded at once (one texImage2D).
   * @param {TexImageSource & { width: number, height: number }} source a decoded JPEG (ImageBitmap)
   * @param {AtlasResolution} resolution
   */
  setColourAtlas(source, resolution) {
    this.#atlas = { source, width: source.width, height: source.height, resolution };
    this.#uploadColour();
    this.requestFrame();
  }

  /** Which colour texture is drawn: null without a CCC mapping. */
  get colourResolution() {
    return this.#mapping && this.#atlas ? this.#atlas.resolution : null;
  }

  /** Whether the context multisamples (rasteriser.js: not on a CPU rasteriser). */
  get antialias() {
    return Boolean(this.gl.getContextAttributes()?.antialias);
  }

  /** The largest texture side this GPU takes. */
  get maxTextureSize() {
    return /** @type {number} */ (this.gl.getParameter(this.gl.MAX_TEXTURE_SIZE));
  }

  /** (Re)creates the GPU textures from the kept sources. */
  #uploadColour() {
    if (this.lost) return;
    const gl = this.gl;
    if (!this.#mapping) {
      if (this.#cellTexture) gl.deleteTexture(this.#cellTexture);
      this.#cellTexture = null;
    } else if (!this.#cellTexture) {
      this.#cellTexture = createCellTexture(gl, this.#mapping.cells);
    }
    if (this.#atlasTexture) gl.deleteTexture(this.#atlasTexture);
    this.#atlasTexture = null;
    if (this.#atlas) this.#atlasTexture = createAtlasTexture(gl, this.#atlas.source);
    gl.activeTexture(gl.TEXTURE0);
  }

  /** @param {boolean} on */
  setWireframe(on) {
    this.wireframe = on;
    this.requestFrame();
  }

  /** @param {import('./program.js').Look} look */
  setLook(look) {
    this.look = look;
    this.requestFrame();
  }

  /**
   * The level on screen as the picking code reads it (pick.js pickLevel,
   * occludedPoints): every vertex received, its triangles; null before one is drawn.
   * @returns {import('./pick.js').Surface | null}
   */
  surface() {
    const mesh = this.current;
    if (!mesh) return null;
    return { positions: this.#store.positions, vertices: mesh.source.vertices, indices: mesh.source.indices, level: mesh.source.level };
  }

  /**
   * Draws and encodes the picture as a PNG in the same task (the drawing
   * buffer is not preserved between frames), with the browser's own encoder.
   * @returns {Promise<Blob>}
   */
  snapshot() {
    this.#draw();
    const canvas = this.canvas;
    if ('convertToBlob' in canvas) return canvas.convertToBlob({ type: 'image/png' });
    return new Promise((resolve, reject) =>
      canvas.toBlob((blob) => (blob ? resolve(blob) : reject(new Error('the picture could not be encoded'))), 'image/png'),
    );
  }

  /**
   * Draws now and reads the pixels back in the same task, before the
   * compositor clears the drawing buffer (tests and benchmarks).
   * @returns {{ width: number, height: number, rgba: Uint8Array }} rows bottom-up
   */
  capture() {
    const gl = this.gl;
    this.#draw();
    const { width, height } = this.canvas;
    const rgba = new Uint8Array(width * height * 4);
    gl.readPixels(0, 0, width, height, gl.RGBA, gl.UNSIGNED_BYTE, rgba);
    return { width, height, rgba };
  }

  /** Draws at the next animation frame (camera moved, resized, …). */
  requestFrame() {
    this.#dirty = true;
    this.#schedule();
  }

  #schedule() {
    if (this.#raf === null && !this.lost) this.#raf = nextFrame(() => this.#frame());
  }

  /**
   * Uploads a slice; draws only when something visible changed, so the GPU
   * (on tablets, or SwiftShader) is not redrawing an unchanged picture
   * while buffers stream in.
   */
  #frame() {
    this.#raf = null;
    if (this.lost) return;
    const gl = this.gl;
    const caughtUp = !this.#fence || gl.getSyncParameter(this.#fence, gl.SYNC_STATUS) === gl.SIGNALED;
    let issued = false;
    const pending = this.pending;
    const start = performance.now();
    this.#pollTiming(start);
    const inBudget = () => performance.now() - start < this.uploadBudgetMs;
    if (this.standIn?.uploads.length && caughtUp) {
      // A stand-in allocated from a level skipped on its way to the screen
      // (or after a lost context): small, and wanted before the next level
      // is complete, since that one is what moving would be slow to draw.
      issued = true;
      this.#upload(this.standIn, this.standIn.source.vertices, inBudget);
    } else if (pending && this.#parked) {
      if (!this.#holds(pending.source.level)) this.#swap(pending);
    } else if (pending && caughtUp) {
      issued = true;
      if (this.#upload(pending, pending.source.vertices, inBudget)) {
        if (!this.#holds(pending.source.level)) {
          this.#swap(pending);
        } else {
          this.#parked = true;
          this.hooks.onHeld?.(pending.source);
        }
      }
    } else if (this.current?.uploads.length && caughtUp) {
      issued = true;
      if (this.#upload(this.current, this.current.source.vertices, inBudget)) this.#dirty = true;
    }
    if (this.#dirty) {
      this.#dirty = false;
      issued = true;
      this.#drawFrame(start);
    }
    if (issued) {
      if (this.#fence) gl.deleteSync(this.#fence);
      this.#fence = gl.fenceSync(gl.SYNC_GPU_COMMANDS_COMPLETE, 0);
      gl.flush();
    }
    const uploading = (this.pending && !this.#parked) || this.current?.uploads.length || this.standIn?.uploads.length;
    if (uploading || this.#timing) this.#schedule();
    this.hooks.onTick?.();
  }

  /**
   * Draws the level on screen, or the stand-in while the view moves where
   * the level is slow (motion.js); times the level's frames.
   * @param {number} now
   */
  #drawFrame(now) {
    this.#noteMotion(now);
    const current = this.current;
    const standIn = this.standIn;
    const coarse =
      current !== null &&
      standIn !== null &&
      standIn.uploads.length === 0 &&
      standIn.normalJob === null &&
      !this.wireframe &&
      !this.relief &&
      this.#motion.drawsStandIn(now, triangles(current), triangles(standIn));
    this.#draw(coarse ? standIn : current);
    if (coarse) {
      this.standInFrames++;
      this.#awaitRest();
    } else if (current && !this.#timing) {
      const gl = this.gl;
      const fence = gl.fenceSync(gl.SYNC_GPU_COMMANDS_COMPLETE, 0);
      if (fence) this.#timing = { fence, at: now, triangles: triangles(current) };
    }
    this.frames++;
    this.hooks.onFrame?.();
  }

  /** Draws the level once the view has rested (not while it is held: the release does). */
  #awaitRest() {
    if (this.#rest !== null) clearTimeout(this.#rest);
    this.#rest = setTimeout(() => {
      this.#rest = null;
      if (!this.#motion.grabbed) this.requestFrame();
    }, this.#motion.restMs());
  }

  /**
   * The visitor holds the view (a pointer is down), or let it go: while
   * held it counts as moving (motion.js), and the level comes back after
   * the release.
   * @param {boolean} on
   */
  setGrabbed(on) {
    this.#motion.grab(on, performance.now());
    if (!on && this.drawn && this.drawn === this.standIn) this.#awaitRest();
  }

  /**
   * Whether the camera or the look (model rotation, light, section)
   * differs from the last frame's: if so, the view moved now. The first
   * frame with a camera, and a resized canvas, are not motion.
   * @param {number} now
   */
  #noteMotion(now) {
    const { width, height } = this.canvas;
    const camera = this.camera;
    const matrix = camera ? multiply(camera.projection(width / Math.max(1, height)), camera.view()) : new Float32Array(0);
    const last = this.#lastView;
    const resized = last.width !== width || last.height !== height;
    const turned = !resized && matrix.some((x, i) => x !== last.matrix[i]);
    if (last.matrix.length > 0 && (turned || last.look !== this.look)) this.#motion.moved(now);
    this.#lastView = { matrix, look: this.look, width, height };
  }

  /** Reads the timed frame's fence: once the GPU is done, the frame's cost is known. @param {number} now */
  #pollTiming(now) {
    const timing = this.#timing;
    if (!timing) return;
    const gl = this.gl;
    if (gl.getSyncParameter(timing.fence, gl.SYNC_STATUS) !== gl.SIGNALED) return;
    gl.deleteSync(timing.fence);
    this.#timing = null;
    this.#motion.time(timing.triangles, now - timing.at);
  }

  /** The last timed frame of a level: its triangles and its milliseconds to the GPU done (motion.js). */
  get timedFrame() {
    return this.#motion.timed;
  }

  /** @param {GpuMesh} pending complete on the GPU: it replaces the level on screen */
  #swap(pending) {
    if (this.current) this.#retire(this.current);
    this.current = pending;
    this.pending = null;
    this.#parked = false;
    this.#dirty = true;
    this.hooks.onSwap?.(pending.source);
    if (this.#next) {
      this.pending = this.#allocate(this.#next);
      this.#next = null;
    }
    this.#adoptCandidate();
  }

  /**
   * @param {LevelMessage} level
   * @returns {GpuMesh}
   */
  #allocate(level) {
    const store = this.#ensureStore();
    const mesh = allocateMesh(this.gl, store, level);
    if (mesh.normalJob) this.#normals.queue();
    return mesh;
  }

  /** Derives the stand-in's and the pending level's normals in tasks of their own, a budget's worth each (normals-task.js). */
  #normals = new NormalsTask(() => this.#normalsTask());

  #normalsTask() {
    // The stand-in first (small, and wanted before the next level is complete), then the pending level.
    const mesh = this.standIn?.normalJob ? this.standIn : this.pending?.normalJob ? this.pending : null;
    if (!mesh?.normalJob || this.lost) return;
    const start = performance.now();
    this.#deriveNormals(mesh, () => performance.now() - start < this.uploadBudgetMs);
    if (mesh.normalJob) {
      this.#normals.queue();
      return;
    }
    this.#schedule();
    if (this.pending?.normalJob || this.standIn?.normalJob) this.#normals.queue();
  }

  /**
   * Derives a level's normals while the budget lasts; when they are
   * complete, the level keeps them (a lost context does not derive them
   * again) and their upload is queued.
   * @param {GpuMesh} mesh
   * @param {() => boolean} inBudget
   */
  #deriveNormals(mesh, inBudget) {
    const job = /** @type {import('./normals-task.js').NormalJob} */ (mesh.normalJob);
    const t0 = performance.now();
    // Every vertex of the level was received with it or before (vertices are only appended).
    const done = deriveNormals(job, this.#store.positions, mesh.source.indices, inBudget);
    this.normalsMs += performance.now() - t0;
    if (!done) return;
    mesh.normalJob = null;
    mesh.source.normals = job.normals;
    if (this.lost || !mesh.normalBuffer) return;
    mesh.uploads.unshift({ target: this.gl.ARRAY_BUFFER, buffer: mesh.normalBuffer, data: job.normals, offset: 0 });
  }

  /** The vertex store's GPU buffers, (re)made when they are missing or too small. */
  #ensureStore() {
    return this.#store.ensureGpu(this.gl, [this.current, this.pending, this.standIn]);
  }

  /**
   * @param {GpuMesh} mesh
   * @param {number} vertices
   * @param {() => boolean} inBudget
   * @returns {boolean} whether the mesh is complete (normals derived and everything uploaded)
   */
  #upload(mesh, vertices, inBudget) {
    const store = this.#ensureStore();
    return uploadMesh(this.gl, store, mesh, vertices, this.uploadChunkBytes, inBudget);
  }

  /** @param {GpuMesh} mesh */
  #release(mesh) {
    releaseMesh(this.gl, mesh);
  }

  /**
   * A level leaves the screen, or its way there: it becomes the stand-in if
   * it is the candidate (motion.js), else it is freed.
   * @param {GpuMesh} mesh
   */
  #retire(mesh) {
    if (mesh.source === this.#candidate && this.standIn?.source !== mesh.source) this.#standIn(mesh);
    else this.#release(mesh);
  }

  /** @param {GpuMesh} mesh the new stand-in (its normals and uploads are finished in later tasks and frames) */
  #standIn(mesh) {
    if (this.standIn) this.#release(this.standIn);
    this.standIn = mesh;
    if (mesh.normalJob) this.#normals.queue();
  }

  /**
   * Makes the candidate the stand-in once it is no level's way to the
   * screen: a level skipped while the first was drawn was never allocated.
   */
  #adoptCandidate() {
    const candidate = this.#candidate;
    if (!candidate || this.standIn?.source === candidate) return;
    if ([this.current, this.pending].some((m) => m?.source === candidate) || this.#next === candidate) return;
    this.#standIn(this.#allocate(candidate));
  }

  /** Switches the shader to the CCC lookup when a mapping and a colour texture are on the GPU. */
  #bindColour() {
    const mapping = this.#mapping;
    const atlas = this.#atlas;
    const cellTexture = this.#cellTexture;
    const atlasTexture = this.#atlasTexture;
    const on = mapping && atlas && cellTexture && atlasTexture;
    bindCcc(this.gl, this.#uniforms, on ? { parameters: mapping.parameters, atlas, cellTexture, atlasTexture } : null);
  }

  /** @param {GpuMesh | null} mesh the level to draw (the stand-in while moving) */
  #draw(mesh = this.current) {
    const gl = this.gl;
    gl.viewport(0, 0, this.canvas.width, this.canvas.height);
    gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT);
    this.drawn = mesh;
    this.reliefTop = null;
    if (!mesh || !this.camera || !this.#program) return;
    const view = this.camera.view();
    const projection = this.camera.projection(this.canvas.width / Math.max(1, this.canvas.height));
    gl.useProgram(this.#program);
    gl.uniformMatrix4fv(this.#uniforms.u_view, false, view);
    gl.uniformMatrix4fv(this.#uniforms.u_viewProjection, false, multiply(projection, view));
    bindLook(gl, this.#uniforms, this.look);
    gl.bindVertexArray(mesh.vao);
    if (!mesh.source.colours) gl.vertexAttrib4f(2, CLAY[0], CLAY[1], CLAY[2], 1);
    const wire = this.wireframe && mesh.edgeBuffer && mesh.uploads.length === 0;
    if (wire) {
      // Push the surface back a little so the lines on it win the depth test.
      gl.enable(gl.POLYGON_OFFSET_FILL);
      gl.polygonOffset(1, 1);
    }
    gl.uniform1i(this.#uniforms.u_wire, 0);
    this.#bindColour();
    const top = mesh.source.reliefTop;
    const relief = this.relief && typeof top === 'number' && reliefReady(mesh) ? top : null;
    bindRelief(gl, this.#uniforms, relief);
    this.reliefTop = relief;
    gl.drawElements(gl.TRIANGLES, mesh.source.indices.length, gl.UNSIGNED_INT, 0);
    gl.disable(gl.POLYGON_OFFSET_FILL);
    if (wire && mesh.source.edges) {
      // Translucent lines: dense levels stay readable instead of turning black.
      gl.enable(gl.BLEND);
      gl.blendFunc(gl.SRC_ALPHA, gl.ONE_MINUS_SRC_ALPHA);
      gl.depthMask(false);
      gl.uniform1i(this.#uniforms.u_wire, 1);
      gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, mesh.edgeBuffer);
      gl.drawElements(gl.LINES, mesh.source.edges.length, gl.UNSIGNED_INT, 0);
      gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, mesh.indexBuffer);
      gl.depthMask(true);
      gl.disable(gl.BLEND);
    }
    gl.bindVertexArray(null);
  }
}

/** @param {GpuMesh} mesh */
function triangles(mesh) {
  return mesh.source.indices.length / 3;
}

/**
 * How the renderer has drawn so far (benchmarks and tests of motion.js).
 * @typedef {object} FrameStats
 * @property {number} frames frames drawn
 * @property {number} standInFrames of them, frames of the stand-in
 * @property {number | null} standInLevel the level kept as the stand-in
 * @property {{ triangles: number, ms: number } | null} timedFrame the last timed frame of a level
 */

/** @param {Renderer} renderer @returns {FrameStats} */
export function frameStats(renderer) {
  return {
    frames: renderer.frames,
    standInFrames: renderer.standInFrames,
    standInLevel: renderer.standIn?.source.level ?? null,
    timedFrame: renderer.timedFrame,
  };
}
