// @ts-check
/**
 * One model on screen: reads the manifest, starts a decode worker, shows each
 * level the worker sends, follows the visitor's level cap, and turns every
 * failure into a message with a retry button. A model in `ccc` mode gets its
 * colour textures from colour-loader.js once the base mesh is on screen.
 */

import { t } from './i18n/index.js';
import { OrbitCamera, multiply } from './camera.js';
import { ColourLoader } from './colour-loader.js';
import { OrbitControls } from './controls.js';
import { frameBox, unrotate, upRotation, validBounds } from './frame.js';
import { defaultBudget } from './part-selection.js';
import { DEFAULT_LOOK } from './program.js';
import { Annotations } from './annotations.js';
import { Inspection } from './inspection.js';
import { ViewText } from './view-text.js';
import { canTransfer, openRenderer } from './render-host.js';
import { retryAfterSeconds, waitToRetry } from './retry.js';
import { BACKGROUND } from './shading.js';
import { MeshSplats } from './splats/mesh-splat-view.js';
import { ShareView } from './share.js';
import { TourPlayer } from './tour.js';
import { PointModel } from './splats/point-model.js';

/**
 * @typedef {object} ViewerOptions
 * @property {string} manifestUrl absolute URL of `/api/models/{slug}`
 * @property {URLSearchParams} query forwarded to every API request (`device`, `token`)
 * @property {number | null} level load up to this level and show only it (tests, comparisons)
 * @property {string} workerUrl absolute URL of the bundled decode worker
 * @property {string} wasmUrl absolute URL of the decoder's WebAssembly
 * @property {string} renderWorkerUrl absolute URL of the bundled render worker
 * @property {boolean} offscreen draw in the render worker when the browser can
 *   (false: always on the main thread)
 * @property {number | null} [hold] show and decode up to this level only, until
 *   {@link Viewer#prefetch} and {@link Viewer#display} say otherwise (the quality study)
 * @property {[number, number, number]} [background] the canvas's clear colour (0–1 components)
 * @property {boolean | null} [antialias] multisample the picture (null or absent: on a GPU,
 *   not on a CPU rasteriser, where it costs seconds a frame of a large scan; rasteriser.js)
 * @property {number | null} [decoders] workers that decode a charted stream together
 *   (decode-pool.js): the decode worker and helpers; null or absent: as many as the
 *   device has cores, at most {@link MAX_DECODERS}; 1: no helpers
 * @property {import('./motion.js').MotionMode | null} [motion] what is drawn while the view
 *   moves (motion.js): `auto` (null or absent) a coarser level where the level on screen is
 *   slow to draw, `full` always that level, `coarse` always the coarser one
 * @property {import('./view-state.js').ViewState} [view] a shared view to open at (view-state.js)
 * @property {string | null} [contentState] a IIIF Content State to open at (`iiif-content`; content-state.js)
 * @property {{ tour: number, step: number } | null} [tour] a tour link: open this tour at this step (from 1; tour.js)
 * @property {'uniform' | 'view' | null} [refine] how a charted or nested stream with a part index
 *   refines: `uniform` batch by batch to the cap, `view` chart by chart where the camera looks
 *   (part-refinement.js, nested-refinement.js; README, "View-dependent refinement"); null or
 *   absent: `view` for a nested stream (format 6 is made for scans larger than a device's
 *   memory, which a uniform refinement would fill), `uniform` for any other
 * @property {number | null} [vertexBudget] with `refine: 'view'`, the most vertices held
 *   (null or absent: by the visitor's device, part-selection.js VERTEX_BUDGETS)
 */

/**
 * The parts of the service's manifest the viewer reads (server/src/service/api.rs).
 * @typedef {object} Manifest
 * @property {string} slug
 * @property {string} title
 * @property {string} description
 * @property {string | null} [language] the BCP 47 tag of `title`, `description` and `rights.credit` (null: not stated)
 * @property {Record<string, import('./content-language.js').ContentTranslation>} [translations] the same texts in other
 *   languages, by tag, each field optional (content-language.js chooses)
 * @property {boolean} has_colour
 * @property {number} last_level
 * @property {Array<{ level: number, vertices: number, faces: number, bytes: number, url: string, allowed: boolean }>} levels
 * @property {import('./quality-chart.js').QualityPoint[]} [quality] per-level quality, when measured at ingest
 * @property {ManifestColour} [colour]
 * @property {{ device: string, audience: string }} visitor
 * @property {{ level: number, reason: string | null, retry_after_s: number | null }} cap
 * @property {string} [up] which model axis points up (`x`, `y`, `z`, `-x`, `-y`, `-z`; default `y`)
 * @property {'mm' | 'cm' | 'm' | 'in' | null} [unit] the model's unit
 * @property {import('./geometry.js').Bounds} [bounds] every level's extent, model coordinates
 * @property {'mesh' | 'points'} [kind] a point cloud's levels are prefixes of a point stream (splats/point-model.js)
 * @property {number} [stream_format] 5: a charted stream, whose charts a pool of workers refines
 * @property {string} [parts] the part index of a charted stream (view-dependent refinement)
 * @property {string} [nested_parts] the part index of a nested stream (format 6: view-dependent refinement down its tree of charts)
 * @property {import('./rights.js').Rights} [rights] credit line and licence (absent from older servers)
 * @property {{ url: string, level: number, bytes: number } | null} [download] a GLB of the level this visitor may take, where the policy offers one
 */

/**
 * @typedef {{ url: string, bytes: number, media_type: string, width: number | null, height: number | null }} ManifestTexture
 * @typedef {{ mode: 'ccc', parameters: import('./ccc.js').CccParameters, cell_texture: ManifestTexture,
 *   colour_texture: ManifestTexture, colour_texture_low: ManifestTexture } | { mode: 'vertex' | 'none' }} ManifestColour
 */

/**
 * What tests and benchmarks read from `element.viewer.state`.
 * @typedef {object} ViewerState
 * @property {'loading' | 'refining' | 'complete' | 'capped' | 'error'} status
 * @property {number} shownLevel level on screen (-1: none yet)
 * @property {number} drawnLevel level in the last frame: `shownLevel`, or below it while the view
 *   moves and a coarser level stands in for it (motion.js; -1: no frame yet)
 * @property {number} decodedLevel newest level the worker sent
 * @property {number} readyLevel newest level complete on the GPU (on screen or held off it)
 * @property {number} targetLevel level the viewer is heading for (cap or `level` option)
 * @property {number} lastLevel
 * @property {number} vertices of the level on screen
 * @property {number} received payload bytes
 * @property {number} decodeMs time inside the WASM decoder (with a pool: the wall time of its batches)
 * @property {number} decoders workers decoding the stream (1, or a pool's size)
 * @property {number} deriveMs time computing normals, edges and θ in the decode worker
 * @property {number} normalsMs time the renderer spent deriving normals (levels sent without them)
 * @property {boolean | null} antialias whether the picture is multisampled (null before the
 *   renderer starts): not on a CPU rasteriser (rasteriser.js); never for a point cloud's splats
 * @property {number | null} firstFrameMs performance.now() of the first frame with a mesh
 * @property {Record<number, number>} shownAtMs performance.now() when each level was first drawn
 * @property {Record<number, number>} decodedAtMs performance.now() when the decode worker's notice of
 *   each level reached the page (decoded and posted; drawing it may take much longer on a CPU renderer)
 * @property {string | null} message cap or error text on screen
 * @property {'none' | 'vertex' | 'loading' | 'low' | 'full'} colour what colours the surface:
 *   nothing (clay), per-vertex colour, or the CCC texture (`loading` until the
 *   cell and low-resolution colour textures are in, then `low`, then `full`)
 * @property {Partial<Record<'requested' | 'low' | 'full', number>>} colourAtMs performance.now()
 *   when the textures were requested and when each colour texture was first drawn
 * @property {string | null} colourError why the CCC colour could not be shown (the model stays visible)
 * @property {boolean} relief the relief view is switched on
 * @property {number | null} reliefTop the top of the θ scale on screen in degrees (relief.js
 *   `reliefTop`); null while the picture is not in the relief view (off, or θ still on its way)
 */

/** @type {Map<string, Promise<WebAssembly.Module>>} */
const compiled = new Map();

/**
 * Compiles the decoder once per page; every viewer's worker instantiates it.
 * @param {string} url
 */
export function compileDecoder(url) {
  let module = compiled.get(url);
  if (!module) {
    module = WebAssembly.compileStreaming(fetch(url)).catch(async () => {
      // A server without the application/wasm type: compile from bytes.
      const response = await fetch(url);
      if (!response.ok) throw new Error(`the decoder could not be loaded (${response.status})`);
      return WebAssembly.compile(await response.arrayBuffer());
    });
    compiled.set(url, module);
  }
  return module;
}

/**
 * The most workers decoding one charted stream: past four, a tablet's
 * cores are wanted by the render worker and the page, and the charts
 * (at most four with `--charts auto`) run out.
 */
export const MAX_DECODERS = 4;

/** The charted stream format (codec/core/FORMAT.md). */
const CHARTED_FORMAT = 5;

/** The decode worker hears where the camera is at most this often (view-dependent refinement). */
const PART_CAMERA_MS = 150;

/** Toolbar buttons for a mesh only: hidden on a point cloud. */
const MESH_TOOLS = ['wireframe', 'relief', 'splats', 'measure'];

/** How many times a load waits out a 503 with Retry-After before it gives up. */
const BUSY_RETRIES = 20;

const REASONS = {
  audience: () => t('cap.audience'),
  device: (/** @type {string} */ device) => t(`cap.device.${device}`),
  load: (/** @type {string} */ _, /** @type {number | null} */ retry) => (retry ? t('cap.busyRetry', { seconds: retry }) : t('cap.busy')),
};

export class Viewer {
  /** @type {ViewerState} */
  state = {
    status: 'loading',
    shownLevel: -1,
    drawnLevel: -1,
    decodedLevel: -1,
    readyLevel: -1,
    targetLevel: 0,
    lastLevel: 0,
    vertices: 0,
    received: 0,
    decodeMs: 0,
    decoders: 1,
    deriveMs: 0,
    normalsMs: 0,
    antialias: null,
    firstFrameMs: null,
    shownAtMs: {},
    decodedAtMs: {},
    message: null,
    colour: 'none',
    colourAtMs: {},
    colourError: null,
    relief: false,
    reliefTop: null,
  };
  /** @type {Manifest | null} */
  manifest = null;
  /** @type {OrbitCamera | null} */
  camera = null;
  /**
   * Opened by start() once the requests are on their way: a render worker
   * drawing on the canvas handed to it where the browser can, else the
   * main thread (render-host.js). The first WebGL context of a page can
   * take a while (a GPU process to start; ~1 s with SwiftShader), and the
   * network need not wait for it.
   * @type {import('./render-host.js').RenderHost | null}
   */
  renderer = null;
  /** A point-cloud model's splats (null: a mesh). @type {PointModel | null} */
  points = null;
  /** The splat view of a mesh model's level (splats/mesh-splat-view.js). @type {MeshSplats} */
  meshSplats;
  /** @type {Promise<import('./render-host.js').RenderHost> | null} */
  #rendering = null;
  /** The port the newest decode worker posts its levels into. @type {MessagePort | null} */
  #levels = null;
  /** @type {Worker | null} */
  #worker = null;
  /** Decode helpers of a charted stream (chart-worker.js). @type {Worker[]} */
  #helpers = [];
  /** @type {ReturnType<typeof setTimeout> | null} */
  #retry = null;
  #wireframe = false;
  #relief = false;
  /** Bumped by stop(), so a start() still waiting for the network gives up. */
  #attempt = 0;
  /** The CCC colour textures: fetched after the first frame, kept across retries. */
  #colour = new ColourLoader({
    manifest: () => this.manifest,
    renderer: () => this.renderer,
    url: (path) => this.#apiUrl(path),
    set: (patch) => this.#set(patch),
  });
  /** Highest level decoded (null: up to the cap), and highest put on screen (null: each as it comes). */
  /** @type {number | null} */
  #decodeTo = null;
  /** @type {number | null} */
  #hold = null;
  /** @type {Array<{ level: number, resolve: () => void }>} */
  #readyWaiters = [];
  /** @type {Array<{ level: number, resolve: (at: number) => void }>} */
  #shownWaiters = [];
  /** The turntable's animation frame, while it turns. @type {number | null} */
  #turning = null;
  /** Model rotation, light, clay, section (program.js Look): sent to the renderer. */
  #look = DEFAULT_LOOK;
  /** @type {Map<number, (answer: { distance?: number, level?: number, error?: string }) => void>} */
  #geodesics = new Map();
  #nextGeodesic = 1;
  /** View-dependent refinement's state, from the decode worker (null: not refining by parts). @type {import('./part-refinement.js').PartsState | import('./nested-refinement.js').NestedState | null} */
  #parts = null;
  /** @type {ReturnType<typeof setTimeout> | null} */
  #partCameraTimer = null;
  #partCameraAt = 0;
  /** @type {Map<number, (answer: any) => void>} */
  #partCharts = new Map();
  /** The cap in force: from the manifest, or from a batch the server refused. */
  #cap = { level: 0, reason: /** @type {string | null} */ (null), retryAfterS: /** @type {number | null} */ (null) };

  /**
   * @param {import('./ui.js').ViewerUi} ui
   * @param {ViewerOptions} options
   */
  constructor(ui, options) {
    this.ui = ui;
    this.options = options;
    this.#decodeTo = options.hold ?? null;
    this.#hold = options.hold ?? null;
    this.meshSplats = new MeshSplats({
      ...this.#splatHost(),
      requestLevel: (id) => (this.#worker?.postMessage({ type: 'level-data', id }), this.#worker !== null),
      warn: (message) => this.ui.showNotice(message),
    });
    this.controls = new OrbitControls(ui.canvas, {
      camera: () => this.camera,
      changed: () => {
        this.renderer?.requestFrame();
        this.cameraMoved();
      },
      reset: () => this.resetView(),
      toggleWireframe: () => this.points === null && this.setWireframe(!this.#wireframe),
      toggleFullscreen: () => ui.toggleFullscreen(),
      interacted: (kind) => this.#emit('vitrine-interaction', { kind }),
      grabbed: (on) => this.renderer?.setGrabbed(on),
      pickCentre: () => this.inspection.pickCentre(),
    });
    ui.onNudge = (step) => this.controls.nudge(step);
    ui.onReset = () => this.resetView();
    ui.onWireframe = () => this.setWireframe(!this.#wireframe);
    ui.onRelief = () => this.setRelief(!this.#relief);
    ui.onSplats = () => this.setSplatView(!this.meshSplats.on);
    ui.onRetry = () => this.start();
    ui.onResize = () => {
      this.renderer?.requestFrame();
      this.cameraMoved();
    };
    /** Measurement, light, section, snapshot (inspection.js). */
    this.inspection = new Inspection(this);
    /** The curators' notes on the model (annotations.js). */
    this.annotations = new Annotations(this);
    /** The view's accessible name, description and loading announcements (view-text.js). */
    this.viewText = new ViewText(this);
    /** Share links, and the shared view or Content State opened with (share.js). */
    this.share = new ShareView(this);
    this.share.expect(options.view ?? {}, options.contentState ?? null);
    /** Guided tours of the version on screen (tour.js). */
    this.tours = new TourPlayer(this);
    this.tours.openAt(options.tour ?? null);
  }

  /** The look in force (program.js Look). */
  get look() {
    return this.#look;
  }

  /**
   * Changes the look (light, clay, section…) and redraws.
   * @param {Partial<import('./program.js').Look>} patch
   */
  setLook(patch) {
    this.#look = { ...this.#look, ...patch };
    this.renderer?.setLook(this.#look);
    this.annotations.place();
  }

  /** The camera moved or the view was resized: what is anchored to the model follows. */
  cameraMoved() {
    this.#sendPartCamera();
    this.annotations.place();
    this.inspection.place();
    this.viewText?.changed();
  }

  /**
   * View-dependent refinement's state (null when the model does not refine by parts):
   * charts, their depths, the final depth, resident vertices and the budget, bytes fetched;
   * for a nested stream (`kind: 'nested'`) per phase (nested-refinement.js NestedState).
   */
  partsState() {
    return this.#parts && structuredClone(this.#parts);
  }

  /**
   * One chart as the decode worker holds it (tests compare it with a whole decoder's chart).
   * @param {number} chart
   * @param {number} [phase] a nested stream's phase (default 0)
   * @returns {Promise<{ depth: number, positions: Float32Array, colours: Uint8Array | null, indices: Uint32Array }>}
   */
  partChart(chart, phase = 0) {
    const worker = this.#worker;
    if (!worker) return Promise.reject(new Error('no model loaded'));
    const id = this.#nextGeodesic++;
    return new Promise((resolve, reject) => {
      this.#partCharts.set(id, (answer) => (answer.error ? reject(new Error(answer.error)) : resolve(answer)));
      worker.postMessage({ type: 'part-chart', id, chart, phase });
    });
  }

  /** Where the camera looks, to the decode worker, at most every {@link PART_CAMERA_MS}. */
  #sendPartCamera() {
    if (!this.#parts || !this.camera || this.#partCameraTimer) return;
    const wait = this.#partCameraAt + PART_CAMERA_MS - performance.now();
    this.#partCameraTimer = setTimeout(() => {
      this.#partCameraTimer = null;
      this.#partCameraAt = performance.now();
      const camera = this.camera;
      if (!camera || !this.#worker) return;
      const m = this.#look.model;
      // prettier-ignore
      const model = new Float32Array([m[0], m[1], m[2], 0, m[3], m[4], m[5], 0, m[6], m[7], m[8], 0, 0, 0, 0, 1]);
      const clip = multiply(multiply(camera.projection(this.aspect()), camera.view()), model);
      const eye = unrotate(m, camera.basis().eye);
      const pixelsPerRadian = this.ui.canvas.height / camera.fovY;
      this.#worker.postMessage({ type: 'part-camera', camera: { eye, clip: Array.from(clip), pixelsPerRadian, aspect: this.aspect() } });
    }, Math.max(0, wait));
  }

  /** The view's aspect, as the renderer draws it. */
  aspect() {
    return this.ui.canvas.width / Math.max(1, this.ui.canvas.height);
  }

  /**
   * The camera, made once from the base mesh's bounds (or the manifest's)
   * turned upright, framed for the view's aspect.
   * @param {import('./geometry.js').Bounds} baseBounds
   */
  #makeCamera(baseBounds) {
    this.camera ??= new OrbitCamera(frameBox(this.#look, baseBounds), this.aspect());
    for (const resolve of this.#cameraWaiters.splice(0)) resolve(this.camera);
    return this.camera;
  }

  /** @type {Array<(camera: OrbitCamera) => void>} */
  #cameraWaiters = [];

  /**
   * Resolves once the camera is made (a level can reach the screen through
   * the render worker before the decode worker's notice makes it here).
   * @returns {Promise<OrbitCamera>}
   */
  whenCamera() {
    if (this.camera) return Promise.resolve(this.camera);
    return new Promise((resolve) => this.#cameraWaiters.push(resolve));
  }

  /**
   * Distance along the surface of the newest decoded level (the decode
   * worker's geodesic library), in model units.
   * @param {number[]} from
   * @param {number[]} to
   * @returns {Promise<{ distance: number, level: number }>}
   */
  surfaceDistance(from, to) {
    const worker = this.#worker;
    if (!worker) return Promise.reject(new Error('no model loaded'));
    const id = this.#nextGeodesic++;
    return new Promise((resolve, reject) => {
      this.#geodesics.set(id, (answer) =>
        answer.error !== undefined || answer.distance === undefined
          ? reject(new Error(answer.error ?? 'no distance'))
          : resolve({ distance: answer.distance, level: answer.level ?? -1 }),
      );
      worker.postMessage({ type: 'geodesic', id, from, to });
    });
  }

  /**
   * Lifts a `level` option or a hold and refines up to the visitor's cap
   * (the measurement's "refine to measure more precisely").
   */
  refine() {
    this.options.level = null;
    this.#decodeTo = null;
    this.#hold = null;
    this.renderer?.setHold(null);
    if (!this.manifest) return;
    const target = this.#target(this.#cap.level);
    if (target <= this.state.targetLevel) return;
    this.#set({ targetLevel: target, status: 'refining' });
    this.#extend(target);
  }

  /** Loads from scratch (also the retry after an error). */
  async start() {
    this.stop();
    const attempt = this.#attempt;
    this.#set({ status: 'loading', message: null });
    this.ui.showError(null);
    this.ui.showNotice(null);
    this.viewText.restart();
    try {
      // Manifest, decoder and worker script load in parallel.
      // The renderer starts beside them and is not waited for: the decode
      // worker posts levels into a MessagePort that the renderer takes
      // when it is ready (they queue there until then).
      const rendering = this.#openRenderer();
      rendering.catch(() => {}); // awaited below
      const [manifest, module, worker] = await Promise.all([
        this.#fetchManifest(attempt),
        compileDecoder(this.options.wasmUrl),
        this.#createWorker(this.options.workerUrl),
      ]);
      if (attempt !== this.#attempt) {
        worker.terminate();
        return;
      }
      if (manifest.kind === 'points') {
        worker.terminate();
        return await this.#beginPoints(manifest, module);
      }
      const levels = this.#begin(manifest, module, worker);
      this.#levels = levels;
      const renderer = await rendering;
      // Levels decoded before a failure are still shown (the error may come
      // before the renderer is ready); a retry's newer port replaces this one.
      if (this.#levels !== levels) return;
      // The look first: the render worker frames its camera with it when the base mesh arrives.
      renderer.setLook(this.#look);
      this.#set({ antialias: renderer.antialias });
      if (this.camera) renderer.camera = this.camera;
      // Normals are derived by the renderer when it has a thread of its own;
      // the main thread's fallback gets them from the decode worker.
      if (renderer.thread === 'main') worker.postMessage({ type: 'normals', which: 'always' });
      // Switched on before the renderer was ready.
      if (this.#relief) renderer.setRelief(true);
      if (this.#hold !== null) renderer.setHold(this.#hold);
      renderer.attach(levels);
    } catch (error) {
      if (attempt === this.#attempt) this.#fail(error instanceof Error ? error.message : String(error));
    }
  }

  stop() {
    this.#attempt++;
    this.#parts = null;
    this.#worker?.terminate();
    this.#worker = null;
    for (const helper of this.#helpers) helper.terminate();
    this.#helpers = [];
    this.points?.stop();
    if (this.#retry) clearTimeout(this.#retry);
    this.#retry = null;
  }

  resetView() {
    this.camera?.frame(this.aspect());
    this.renderer?.requestFrame();
    this.cameraMoved();
  }

  /**
   * Decodes up to `level` (within the cap) without showing more than the
   * hold allows: the quality study's m_b, made ready while m_a is on screen.
   * @param {number} level
   */
  prefetch(level) {
    this.#decodeTo = Math.max(this.#decodeTo ?? level, level);
    if (!this.manifest) return;
    const target = this.#target(this.#cap.level);
    if (target <= this.state.targetLevel) return;
    this.#set({ targetLevel: target, status: 'refining' });
    this.#extend(target);
  }

  /**
   * Shows levels up to `level` only (null: each as it arrives, the
   * default); a level above it is decoded (see prefetch) and waits on the
   * GPU until the hold rises to it, then swaps in at the next frame.
   * @param {number | null} level
   */
  display(level) {
    this.#hold = level;
    if (level !== null) this.prefetch(level);
    this.renderer?.setHold(level);
  }

  /**
   * Resolves once `level` (or a later one) is complete on the GPU, on
   * screen or held off it.
   * @param {number} level
   * @returns {Promise<void>}
   */
  whenReady(level) {
    if (this.state.readyLevel >= level) return Promise.resolve();
    return new Promise((resolve) => this.#readyWaiters.push({ level, resolve }));
  }

  /**
   * Resolves with performance.now() of the first frame that drew `level` (or a later one).
   * @param {number} level
   * @returns {Promise<number>}
   */
  whenShown(level) {
    const drawn = Object.keys(this.state.shownAtMs).map(Number).filter((l) => l >= level);
    if (drawn.length > 0) return Promise.resolve(this.state.shownAtMs[Math.min(...drawn)]);
    return new Promise((resolve) => this.#shownWaiters.push({ level, resolve }));
  }

  /**
   * Locks or unlocks the visitor's control of the camera (pointer, wheel and
   * keys on the canvas are ignored while locked).
   * @param {boolean} on
   */
  setLocked(on) {
    this.controls.locked = on;
  }

  /**
   * The turntable: from the home view, the camera orbits once about the
   * vertical axis in `periodMs`, with the visitor's controls locked; resolves
   * when the turn is complete (or stopTurntable()). A visitor who asked for
   * reduced motion (`prefers-reduced-motion: reduce`) sees the home view
   * held still for the same time instead.
   * @param {number} [periodMs]
   * @returns {Promise<void>}
   */
  turntable(periodMs = 12_000) {
    this.stopTurntable();
    const wasLocked = this.controls.locked;
    this.setLocked(true);
    const still = typeof matchMedia === 'function' && matchMedia('(prefers-reduced-motion: reduce)').matches;
    return new Promise((resolve) => {
      /** @type {number | null} */
      let start = null;
      let yaw = 0;
      this.#endTurn = () => {
        this.#endTurn = null;
        if (this.#turning !== null) cancelAnimationFrame(this.#turning);
        this.#turning = null;
        this.setLocked(wasLocked);
        resolve();
      };
      const frame = (/** @type {number} */ now) => {
        const camera = this.camera;
        if (camera && start === null && this.state.shownLevel >= 0) {
          camera.reset();
          start = now;
          yaw = camera.state.yaw;
        }
        if (camera && start !== null) {
          const t = Math.min(1, (now - start) / periodMs);
          if (!still) camera.state.yaw = yaw + 2 * Math.PI * t;
          this.renderer?.requestFrame();
          if (t >= 1) {
            this.#endTurn?.();
            return;
          }
        }
        this.#turning = requestAnimationFrame(frame);
      };
      this.#turning = requestAnimationFrame(frame);
    });
  }

  /** @type {(() => void) | null} */
  #endTurn = null;

  stopTurntable() {
    this.#endTurn?.();
  }

  /** The splat view of the mesh level on screen (a point cloud is always splats). @param {boolean} on */
  setSplatView(on) {
    if (on) this.meshSplats.show();
    else this.meshSplats.hide();
    this.ui.setSplats(this.meshSplats.on);
  }

  /** @param {boolean} on */
  setWireframe(on) {
    this.#wireframe = on;
    this.ui.setWireframe(on);
    this.renderer?.setWireframe(on);
    this.#worker?.postMessage({ type: 'wireframe', on });
  }

  /**
   * The relief view: each vertex coloured by its average normal deviation θ
   * (relief.js), computed by the decode worker for the level on screen and
   * every level after it while the view is on; the legend shows the scale
   * of the level drawn.
   * @param {boolean} on
   */
  setRelief(on) {
    this.#relief = on;
    this.ui.setRelief(on);
    this.renderer?.setRelief(on);
    this.#worker?.postMessage({ type: 'relief', on });
    this.#set({ relief: on });
  }

  /**
   * @param {Manifest} manifest
   * @param {WebAssembly.Module} module
   * @param {Worker} worker
   */
  #begin(manifest, module, worker) {
    this.manifest = manifest;
    this.#pointTools(false);
    this.points?.destroy();
    this.points = null;
    this.ui.setDetails(manifest);
    // The view's name follows the model at once (the description settles
    // with the camera); a debounced write could land long after the title.
    this.viewText.update();
    this.ui.setRights(manifest.rights, this.#download(manifest));
    this.ui.setQuality(manifest.quality ?? null);
    this.#look = { ...this.#look, model: upRotation(manifest.up), bounds: validBounds(manifest.bounds, null) };
    this.annotations.load();
    void this.tours.load();
    this.inspection.begin();
    this.#worker = worker;
    worker.onmessage = (event) => this.#message(event.data);
    worker.onerror = (event) => this.#fail(`the decoder failed: ${event.message}`);
    this.#cap = { level: manifest.cap.level, reason: manifest.cap.reason, retryAfterS: manifest.cap.retry_after_s };
    const target = this.#target(manifest.cap.level);
    this.#set({ status: 'refining', lastLevel: manifest.last_level, targetLevel: target });
    this.#colour.begin(manifest);
    // A drawn frame may already be on screen (a retry): then load now.
    if (this.state.firstFrameMs !== null) void this.#colour.load();
    const url = (/** @type {string} */ path) => this.#apiUrl(path);
    /** @type {import('./reconstruction.js').LoadRequest} */
    const request = {
      // The renderer sizes its vertex buffers once for the level it is heading for.
      capacity: manifest.levels[target]?.vertices,
      baseUrl: url(manifest.levels[0].url),
      batchUrls: manifest.levels.slice(1).map((l) => url(l.url)),
      upTo: target,
      show: this.options.level === null ? 'each' : 'last',
      showFrom: Math.min(this.state.shownLevel + 1, target),
      wireframe: this.#wireframe,
      relief: this.#relief,
      // A render worker derives the normals of the levels before the last
      // that it draws (see start(): if the renderer turns out to be on the
      // main thread, the decode worker is told to send them all).
      normals: (this.renderer ? this.renderer.thread === 'main' : !(this.options.offscreen && canTransfer(this.ui.canvas)))
        ? 'always'
        : 'last',
    };
    const index = manifest.parts ?? manifest.nested_parts;
    const refine = this.options.refine ?? (manifest.nested_parts && !manifest.parts ? 'view' : 'uniform');
    const byParts = Boolean(index) && refine === 'view' && this.options.level === null && this.#hold === null;
    if (byParts) {
      request.parts = {
        indexUrl: url(/** @type {string} */ (index)),
        nested: !manifest.parts,
        apiBase: this.options.manifestUrl,
        query: [...this.options.query],
        budget: this.options.vertexBudget ?? defaultBudget(manifest.visitor?.device),
      };
    }
    // Levels and edges go through a port to the renderer (a render worker
    // directly, or this page in the fallback); the page gets each level as
    // a notice without its buffers.
    const channel = new MessageChannel();
    const helpers = manifest.stream_format === CHARTED_FORMAT && !byParts ? this.#startHelpers(module) : [];
    worker.postMessage({ type: 'load', module, request, port: channel.port2, helpers }, [channel.port2, ...helpers]);
    return channel.port1;
  }

  /** Workers to decode a charted stream with: the decode worker and this many helpers. */
  #decoders() {
    const wanted = this.options.decoders ?? Math.min(navigator.hardwareConcurrency || 1, MAX_DECODERS);
    return Math.max(1, Math.min(wanted, MAX_DECODERS));
  }

  /**
   * Starts the decode worker's helpers (chart-worker.js), each with the
   * compiled codec and one end of a channel; returns the other ends, for
   * the decode worker. Commands wait in a channel until its helper is
   * ready; a helper that cannot start answers every command with an error
   * (the load fails and can be retried, as after any decode error).
   * @param {WebAssembly.Module} module
   * @returns {MessagePort[]}
   */
  #startHelpers(module) {
    const attempt = this.#attempt;
    const url = new URL('./chart-worker.js', this.options.workerUrl).href;
    /** @type {MessagePort[]} */
    const ports = [];
    for (let i = 1; i < this.#decoders(); i++) {
      const channel = new MessageChannel();
      ports.push(channel.port2);
      const port = channel.port1;
      const refuse = (/** @type {string} */ why) => {
        port.onmessage = () => port.postMessage({ type: 'error', message: `a decode helper failed: ${why}` });
      };
      this.#createWorker(url).then(
        (helper) => {
          if (attempt !== this.#attempt) {
            helper.terminate();
            return;
          }
          this.#helpers.push(helper);
          helper.onerror = (event) => this.#fail(`a decode helper failed: ${event.message}`);
          helper.postMessage({ type: 'init', module, port }, [port]);
        },
        (error) => refuse(error instanceof Error ? error.message : String(error)),
      );
    }
    return ports;
  }

  /**
   * A point cloud: its levels go to the splat worker, its splats over the canvas.
   * @param {Manifest} manifest
   * @param {WebAssembly.Module} module
   */
  #beginPoints(manifest, module) {
    this.manifest = manifest;
    this.ui.setDetails(manifest);
    this.viewText.update();
    this.ui.setRights(manifest.rights);
    this.#look = { ...this.#look, model: upRotation(manifest.up), bounds: validBounds(manifest.bounds, null) };
    this.#cap = { level: manifest.cap.level, reason: manifest.cap.reason, retryAfterS: manifest.cap.retry_after_s };
    const target = this.#target(manifest.cap.level);
    this.#set({ status: 'refining', lastLevel: manifest.last_level, targetLevel: target });
    this.#pointTools(true);
    this.points?.destroy();
    this.points = new PointModel({
      ...this.#splatHost(),
      camera: (bounds) => this.#makeCamera(bounds),
      shown: (level) => this.#shown(level),
      framed: (frame) => this.#framed(frame),
      set: (patch) => this.#set(patch),
      capped: (cap) => this.#capped(cap),
      fail: (message) => this.#fail(message),
    });
    const url = (/** @type {string} */ path) => this.#apiUrl(path);
    const levels = manifest.levels.slice(0, target + 1).map((l) => url(l.url));
    return this.points.start(module, { baseUrl: levels[0], batchUrls: levels.slice(1), upTo: target });
  }

  /**
   * Hides the tools that read a mesh (wireframe, relief, measure along the
   * surface, the splat view of a mesh level) on a point cloud; shows them
   * again for a mesh.
   * @param {boolean} points
   */
  #pointTools(points) {
    for (const action of MESH_TOOLS) this.ui.button(action).hidden = points;
  }

  /** What both splat views (splats/) borrow from the viewer. */
  #splatHost() {
    return {
      place: (/** @type {HTMLCanvasElement} */ canvas) => this.ui.canvas.after(canvas),
      background: this.options.background ?? BACKGROUND,
      current: () => this.camera,
      model: () => this.#look.model,
      createWorker: () => this.#createWorker(new URL('./splat-worker.js', this.options.workerUrl).href),
    };
  }

  /** The renderer, opened once per viewer (a retry keeps it); a failure is tried again on retry. */
  #openRenderer() {
    this.#rendering ??= openRenderer(
      this.ui.canvas,
      {
        onSwap: (level) => this.#shown(level),
        onHeld: (level) => this.#ready(level),
        onFrame: (frame) => this.#framed(frame),
        camera: (bounds) => this.#makeCamera(bounds),
      },
      {
        offscreen: this.options.offscreen,
        createWorker: () => this.#createWorker(this.options.renderWorkerUrl),
        background: this.options.background,
        antialias: this.options.antialias,
        motion: this.options.motion ?? 'auto',
      },
    ).then(
      (renderer) => (this.renderer = renderer),
      (error) => {
        this.#rendering = null;
        throw error;
      },
    );
    return this.#rendering;
  }

  /** @param {number} cap */
  #target(cap) {
    const limit = this.options.level ?? this.#decodeTo;
    return limit === null ? cap : Math.min(cap, limit);
  }

  /** @param {number} level complete on the GPU (held off screen, or swapped in) */
  #ready(level) {
    if (level <= this.state.readyLevel) return;
    this.#set({ readyLevel: level });
    const due = this.#readyWaiters.filter((w) => w.level <= level);
    this.#readyWaiters = this.#readyWaiters.filter((w) => w.level > level);
    for (const w of due) w.resolve();
  }

  /**
   * @param {string} type
   * @param {object} detail
   */
  #emit(type, detail) {
    this.ui.root.dispatchEvent(new CustomEvent(type, { detail, bubbles: true, composed: true }));
  }

  /**
   * @param {import('./reconstruction.js').PageMessage | import('./splats/mesh-splat-view.js').LevelData
   *   | { type: 'geodesic', id: number, distance?: number, level?: number, error?: string }
   *   | { type: 'parts', state: import('./part-refinement.js').PartsState | import('./nested-refinement.js').NestedState } | { type: 'part-chart', id: number }} message
   */
  #message(message) {
    if (message.type === 'level-data') return void this.meshSplats.receive(message);
    if (message.type === 'part-chart') {
      this.#partCharts.get(message.id)?.(message);
      this.#partCharts.delete(message.id);
      return;
    }
    if (message.type === 'parts') {
      const before = this.#parts;
      this.#parts = message.state;
      if (this.state.shownLevel >= 0) this.#set({ vertices: message.state.resident, received: message.state.bytesFetched });
      if (!before) this.#sendPartCamera();
      // Depths per chart (per phase and chart for a nested stream): compared flat, the shape never changes.
      if (!before || String(before.depths) !== String(message.state.depths)) this.#emit('vitrine-parts', { depths: message.state.depths });
      return;
    }
    if (message.type === 'geodesic') {
      this.#geodesics.get(message.id)?.(message);
      this.#geodesics.delete(message.id);
      return;
    }
    switch (message.type) {
      case 'level':
        // A notice: the buffers went to the renderer.
        if (!this.camera) {
          this.#makeCamera(message.baseBounds);
          if (this.renderer) {
            this.renderer.camera = this.camera;
            this.renderer.requestFrame();
          }
        }
        this.state.decodedAtMs[message.level] ??= performance.now();
        this.#set({
          decodedLevel: message.level,
          received: message.received,
          decodeMs: message.decodeMs,
          decoders: message.decoders,
          deriveMs: message.deriveMs,
        });
        break;
      case 'progress':
        this.#set({ received: message.received });
        break;
      case 'capped':
        this.#capped(message);
        break;
      case 'error': {
        const where = message.level < 0 ? 'the base mesh' : `level ${message.level + 1}`;
        const what = message.kind === 'decode' ? `could not decode ${where}` : 'a download failed';
        this.#fail(`${what}: ${message.message}`);
        break;
      }
      case 'done':
        break;
    }
  }

  /**
   * The cap fell after the manifest was read: the server refused a batch
   * (a mesh's or a point cloud's).
   * @param {{ level: number, reason: string | null, retryAfterS: number | null }} cap
   */
  #capped(cap) {
    this.#cap = { level: cap.level, reason: cap.reason, retryAfterS: cap.retryAfterS };
    this.#set({ targetLevel: cap.level });
    if (this.state.shownLevel >= cap.level) this.#announceCap();
  }

  /**
   * Loads up to `upTo`: the decode worker, or a point cloud's splat worker.
   * @param {number} upTo
   */
  #extend(upTo) {
    if (this.points) this.points.extend(upTo);
    else this.#worker?.postMessage({ type: 'extend', upTo });
  }

  /** @param {{ level: number, vertices: number, normalsMs: number }} level */
  #shown(level) {
    // By parts, the level's vertices count copies the renderer keeps aside: the charts' are the ones held.
    this.#set({ shownLevel: level.level, vertices: this.#parts?.resident ?? level.vertices, normalsMs: level.normalsMs });
    this.annotations.levelShown();
    this.inspection.levelShown();
    this.meshSplats.levelShown();
    this.viewText.levelShown(level.level, this.state.lastLevel);
    void this.share.levelShown();
    void this.tours.levelShown();
    this.#ready(level.level);
    if (level.level < this.state.targetLevel || this.state.status !== 'refining') return;
    const last = /** @type {Manifest} */ (this.manifest).last_level;
    if (this.#cap.level < Math.min(last, this.options.level ?? last)) this.#announceCap();
    else this.#set({ status: 'complete' });
  }

  /** @param {{ level: number | null, colourResolution: 'low' | 'full' | null, reliefTop: number | null, at: number }} frame */
  #framed(frame) {
    if (frame.reliefTop !== this.state.reliefTop) this.#set({ reliefTop: frame.reliefTop });
    if (frame.level !== null && frame.level !== this.state.drawnLevel) this.#set({ drawnLevel: frame.level });
    const resolution = frame.colourResolution;
    if (resolution && !(resolution in this.state.colourAtMs)) {
      this.state.colourAtMs[resolution] = frame.at;
      performance.mark(`vitrine:colour-${resolution}`);
    }
    const level = frame.level;
    if (level === null || level in this.state.shownAtMs) return;
    const now = frame.at;
    // Visible in DevTools and traces; the benchmark reads them.
    performance.mark(`vitrine:level-${level}`);
    this.state.shownAtMs[level] = now;
    const due = this.#shownWaiters.filter((w) => w.level <= level);
    this.#shownWaiters = this.#shownWaiters.filter((w) => w.level > level);
    for (const w of due) w.resolve(now);
    const first = this.state.firstFrameMs === null;
    this.state.firstFrameMs ??= now;
    // The colour textures wait for the first frame of the base mesh.
    if (first) void this.#colour.load();
    // The page's listeners run in a task of their own, after this one: the
    // render worker's report stays a small task however much they do.
    setTimeout(() => this.ui.root.dispatchEvent(new CustomEvent('vitrine-level', { detail: { level }, bubbles: true, composed: true })));
  }

  /**
   * The server holds refinement at the cap: say so, and ask again later if
   * the reason may pass (load).
   */
  #announceCap() {
    const { level, reason, retryAfterS } = this.#cap;
    const manifest = /** @type {Manifest} */ (this.manifest);
    const explain = REASONS[/** @type {keyof typeof REASONS} */ (reason ?? '')];
    // A function: the notice is written again when the visitor switches language.
    const notice = () =>
      t('cap.notice', {
        level,
        last: manifest.last_level,
        why: explain ? explain(manifest.visitor.device, retryAfterS) : t('cap.server'),
      });
    this.#set({ status: 'capped', message: notice() });
    this.ui.showNotice(notice);
    if (retryAfterS && !this.#retry) {
      // Plus 0–1 s of jitter, as for a 503: a crowd capped in the same
      // second must not come back in the same second.
      this.#retry = setTimeout(() => this.#recheck(), (retryAfterS + Math.random()) * 1000);
    }
  }

  /** Reads the manifest again and resumes if the cap rose. */
  async #recheck() {
    this.#retry = null;
    let manifest;
    try {
      manifest = await this.#fetchManifest();
    } catch {
      manifest = null;
    }
    if (!this.#worker && !this.points?.running) return;
    const current = /** @type {Manifest} */ (this.manifest);
    if (!manifest) {
      this.#retry = setTimeout(() => this.#recheck(), ((current.cap.retry_after_s ?? 10) + Math.random()) * 1000);
      return;
    }
    this.manifest = manifest;
    this.#cap = { level: manifest.cap.level, reason: manifest.cap.reason, retryAfterS: manifest.cap.retry_after_s };
    const target = this.#target(manifest.cap.level);
    if (target > this.state.targetLevel) {
      this.ui.showNotice(null);
      this.#set({ status: 'refining', message: null, targetLevel: target });
      this.#extend(target);
    } else {
      this.#cap.level = Math.min(this.#cap.level, this.state.targetLevel);
      this.#announceCap();
    }
  }

  /** @param {string} message */
  #fail(message) {
    this.stop();
    this.#set({ status: 'error', message });
    this.ui.showError(message);
    // The embedding page hears of it too (as of each level: 'vitrine-level').
    setTimeout(() => this.ui.root.dispatchEvent(new CustomEvent('vitrine-error', { detail: { message }, bubbles: true, composed: true })));
  }

  /** @param {Partial<ViewerState>} patch */
  #set(patch) {
    Object.assign(this.state, patch);
    this.ui.setProgress(this.state);
  }

  /** @returns {Promise<Manifest>} */
  /**
   * The model's manifest. When `attempt` is given (a load, not a re-check of
   * the cap), a 503 that says when to come back — the service admitting new
   * visitors gradually in a surge (`busy`), or shedding load — is waited out
   * and asked again, with 0–1 s of jitter so that refused visitors do not
   * all return at once; a stop or a new load ends the wait.
   * @param {number} [attempt]
   */
  async #fetchManifest(attempt) {
    for (let tries = 0; ; tries++) {
      let response;
      try {
        response = await fetch(this.#apiUrl(this.options.manifestUrl), { cache: 'no-store' });
      } catch (error) {
        throw new Error(`could not reach the server (${error instanceof Error ? error.message : error})`);
      }
      if (response.ok) {
        if (tries > 0) this.ui.showNotice(null);
        return response.json();
      }
      const body = await response.json().catch(() => null);
      const wait = response.status === 503 ? retryAfterSeconds(response, body) : null;
      if (attempt !== undefined && wait !== null && tries < BUSY_RETRIES) {
        const seconds = Math.min(Math.ceil(wait), 300);
        this.ui.showNotice(() => t('busy.waiting', { seconds }));
        await waitToRetry(seconds);
        if (attempt !== this.#attempt) throw new Error('stopped');
        continue;
      }
      const detail = body?.message ?? body?.error ?? response.statusText;
      throw new Error(`the server answered ${response.status} for this model (${detail})`);
    }
  }

  /**
   * The GLB the manifest offers this visitor, with the visitor's `token`
   * and `device` as every API request has them; null when none is offered.
   * @param {Manifest} manifest
   * @returns {{ href: string, bytes: number } | null}
   */
  #download(manifest) {
    const d = manifest.download;
    if (!d || typeof d.url !== 'string' || !Number.isFinite(d.bytes)) return null;
    return { href: this.#apiUrl(d.url), bytes: d.bytes };
  }

  /** @param {string} path relative to the manifest's URL */
  #apiUrl(path) {
    const url = new URL(path, this.options.manifestUrl);
    for (const [key, value] of this.options.query) url.searchParams.set(key, value);
    return url.href;
  }

  /**
   * A worker from the same origin, or via a blob URL when the page is another site's.
   * @param {string} href
   */
  async #createWorker(href) {
    const url = new URL(href);
    if (url.origin === location.origin) return new Worker(url);
    const response = await fetch(url);
    if (!response.ok) throw new Error(`the decode worker could not be loaded (${response.status})`);
    const blob = new Blob([await response.text()], { type: 'text/javascript' });
    return new Worker(URL.createObjectURL(blob));
  }
}
