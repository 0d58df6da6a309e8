// @ts-check
/**
 * The render worker: draws the model on an OffscreenCanvas the page handed
 * over (HTMLCanvasElement.transferControlToOffscreen), so WebGL calls,
 * buffer uploads, and — with a software compositor — the read-back of every
 * frame happen on this thread, not on the page's main thread, which only
 * handles input and the interface.
 *
 * Levels come straight from the decode worker through a MessagePort
 * (transferred buffers; the page never sees them). The page sends the
 * camera, the canvas size, the wireframe and relief switches and the colour textures;
 * this worker answers with what was drawn (render-host.js mirrors it).
 *
 * On start it tries a WebGL2 context on a small OffscreenCanvas of its own
 * and says whether that worked, so the page keeps its canvas (and draws on
 * the main thread) where workers have no WebGL2 (Safari before 17, some
 * blocked GPUs).
 */

import { OrbitCamera } from './camera.js';
import { frameBox } from './frame.js';
import { occludedPoints, pickLevel } from './pick.js';
import { isSoftwareRasteriser, probeRenderer } from './rasteriser.js';
import { Renderer, frameStats } from './renderer.js';

/**
 * Commands from the page.
 * @typedef {{ type: 'canvas', canvas: OffscreenCanvas, width: number, height: number, background?: [number, number, number], antialias?: boolean | null,
 *     motion?: import('./motion.js').MotionMode }
 *   | { type: 'source', port: MessagePort }
 *   | { type: 'size', width: number, height: number }
 *   | { type: 'camera', state: import('./camera.js').OrbitState | null, radius?: number | null }
 *   | { type: 'look', look: import('./program.js').Look }
 *   | { type: 'pick', id: number, ray: import('./pick.js').Ray, snap: number }
 *   | { type: 'occlusion', id: number, eye: number[], points: number[][], tolerance: number }
 *   | { type: 'snapshot', id: number } | { type: 'frameStats', id: number }
 *   | { type: 'wireframe', on: boolean } | { type: 'grab', on: boolean }
 *   | { type: 'relief', on: boolean }
 *   | { type: 'hold', level: number | null }
 *   | { type: 'colourMapping', mapping: import('./renderer.js').ColourMapping | null }
 *   | { type: 'colourAtlas', source: ImageBitmap, resolution: import('./renderer.js').AtlasResolution }
 *   | { type: 'capture', id: number } | { type: 'finish', id: number }
 *   | { type: 'loseContext' } | { type: 'restoreContext' }} RenderCommand
 */

/**
 * Reports to the page.
 * @typedef {{ type: 'ready', webgl2: boolean }
 *   | { type: 'started', maxTextureSize: number, antialias: boolean }
 *   | { type: 'failed', message: string }
 *   | { type: 'swap', level: number, vertices: number, normalsMs: number }
 *   | { type: 'held', level: number }
 *   | { type: 'frame', level: number | null, colourResolution: import('./renderer.js').AtlasResolution | null,
 *       reliefTop: number | null, at: number }
 *   | { type: 'status', lost: boolean, settled: boolean, edges: boolean, frames: number }
 *   | { type: 'captured', id: number, width: number, height: number, rgba: Uint8Array }
 *   | { type: 'finished', id: number, at: number }
 *   | { type: 'answer', id: number, value: unknown }} RenderReport
 */

/**
 * The worker's global scope, typed here so this file is checked with the
 * page's libraries (the renderer it shares with the page uses DOM types).
 * @typedef {{ postMessage: (message: RenderReport, transfer?: Transferable[]) => void,
 *   onmessage: ((event: MessageEvent<RenderCommand>) => void) | null }} RenderScope
 */

const scope = /** @type {RenderScope} */ (/** @type {unknown} */ (self));

/** Bigger upload slices than on the main thread: only this worker's frames wait for them. */
const WORKER_UPLOAD = { uploadBudgetMs: 12, uploadChunkBytes: 1 << 20 };

/** @type {Renderer | null} */
let renderer = null;
/** @type {MessagePort | null} */
let source = null;
/** @type {import('./camera.js').OrbitState | null} */
let cameraState = null;
/** The page camera's radius (near and far planes), when it frames other bounds than the base mesh's. @type {number | null} */
let cameraRadius = null;
let lastStatus = '';
/** Level and colour texture of the last frame reported. */
let lastFrame = '';

/** @param {RenderReport} message @param {Transferable[]} [transfer] */
function report(message, transfer = []) {
  scope.postMessage(message, transfer);
}

/** Wall-clock milliseconds, so the page can place them on its own timeline. */
function epochNow() {
  return performance.timeOrigin + performance.now();
}

function sendStatus() {
  if (!renderer) return;
  const status = {
    lost: renderer.lost,
    settled: renderer.settled,
    edges: Boolean(renderer.current?.edgeBuffer && renderer.current.uploads.length === 0),
    frames: renderer.frames,
  };
  const key = JSON.stringify({ ...status, frames: 0 });
  // Frames alone are not worth a message each; state changes are.
  if (key === lastStatus) return;
  lastStatus = key;
  report({ type: 'status', ...status });
}

/** @param {import('./reconstruction.js').WorkerMessage} message */
function fromDecoder(message) {
  if (!renderer) return;
  if (message.type === 'level') {
    // The same camera the page makes from the same bounds; the page's moves follow as 'camera'.
    if (!renderer.camera) {
      // Framed for this canvas's aspect as the page frames its own.
      const { width, height } = renderer.canvas;
      renderer.camera = new OrbitCamera(frameBox(renderer.look, message.baseBounds), width / Math.max(1, height));
      if (cameraState) renderer.camera.state = structuredClone(cameraState);
      if (cameraRadius) renderer.camera.radius = cameraRadius;
    }
    renderer.show(message);
  } else if (message.type === 'edges') {
    renderer.addEdges(message.level, message.edges);
  } else if (message.type === 'relief') {
    renderer.addRelief(message.level, message.relief, message.top);
  }
  sendStatus();
}

/**
 * @param {OffscreenCanvas} canvas @param {number} width @param {number} height
 * @param {[number, number, number] | undefined} background
 * @param {boolean | null | undefined} antialias multisample (null or absent: on a GPU only; rasteriser.js)
 * @param {import('./motion.js').MotionMode | undefined} motion what is drawn while the view moves (motion.js)
 */
function start(canvas, width, height, background, antialias, motion) {
  canvas.width = width;
  canvas.height = height;
  try {
    renderer = new Renderer(
      canvas,
      null,
      {
        onSwap: (level) => report({ type: 'swap', level: level.level, vertices: level.vertices, normalsMs: renderer?.normalsMs ?? 0 }),
        onHeld: (level) => report({ type: 'held', level: level.level }),
        onFrame: () => {
          // The page wants each level's, colour texture's and relief
          // scale's first frame, and each change between the level and
          // its stand-in (motion.js), not every frame of an orbit: one
          // small message per change.
          const level = renderer?.drawn?.source.level ?? null;
          const colourResolution = renderer?.colourResolution ?? null;
          const reliefTop = renderer?.reliefTop ?? null;
          const key = `${level} ${colourResolution} ${reliefTop}`;
          if (key === lastFrame) return;
          lastFrame = key;
          report({ type: 'frame', level, colourResolution, reliefTop, at: epochNow() });
        },
        onTick: sendStatus,
      },
      { ...WORKER_UPLOAD, background, motion, antialias: antialias ?? (rendererName !== null && !isSoftwareRasteriser(rendererName)) },
    );
  } catch (error) {
    report({ type: 'failed', message: error instanceof Error ? error.message : String(error) });
    return;
  }
  canvas.addEventListener('webglcontextlost', () => queueMicrotask(sendStatus));
  canvas.addEventListener('webglcontextrestored', () => queueMicrotask(sendStatus));
  report({ type: 'started', maxTextureSize: renderer.maxTextureSize, antialias: renderer.antialias });
  sendStatus();
}

scope.onmessage = (event) => {
  const command = event.data;
  switch (command.type) {
    case 'canvas':
      start(command.canvas, command.width, command.height, command.background, command.antialias, command.motion);
      break;
    case 'source':
      // A new decode worker (a retry): the old one's port is closed, so nothing late arrives from it.
      source?.close();
      source = command.port;
      source.onmessage = (e) => fromDecoder(e.data);
      break;
    case 'size':
      if (!renderer) break;
      if (renderer.canvas.width !== command.width || renderer.canvas.height !== command.height) {
        renderer.canvas.width = command.width;
        renderer.canvas.height = command.height;
      }
      renderer.requestFrame();
      break;
    case 'camera':
      cameraState = command.state;
      cameraRadius = command.radius ?? cameraRadius;
      if (renderer?.camera && cameraState) renderer.camera.state = structuredClone(cameraState);
      if (renderer?.camera && cameraRadius) renderer.camera.radius = cameraRadius;
      renderer?.requestFrame();
      break;
    case 'wireframe':
      renderer?.setWireframe(command.on);
      break;
    case 'grab':
      renderer?.setGrabbed(command.on);
      break;
    case 'relief':
      renderer?.setRelief(command.on);
      break;
    case 'hold':
      renderer?.setHold(command.level);
      break;
    case 'colourMapping':
      renderer?.setColourMapping(command.mapping);
      break;
    case 'colourAtlas':
      renderer?.setColourAtlas(command.source, command.resolution);
      break;
    case 'capture': {
      if (!renderer) break;
      const { width, height, rgba } = renderer.capture();
      report({ type: 'captured', id: command.id, width, height, rgba }, [rgba.buffer]);
      break;
    }
    case 'look':
      renderer?.setLook(command.look);
      break;
    case 'pick':
      report({ type: 'answer', id: command.id, value: pickLevel(renderer?.surface() ?? null, command.ray, command.snap) });
      break;
    case 'occlusion':
      report({ type: 'answer', id: command.id, value: occludedPoints(renderer?.surface() ?? null, command.eye, command.points, command.tolerance) });
      break;
    case 'snapshot': {
      const id = command.id;
      if (!renderer) break;
      renderer.snapshot().then(
        (blob) => report({ type: 'answer', id, value: blob }),
        (error) => report({ type: 'answer', id, value: { error: String(error) } }),
      );
      break;
    }
    case 'frameStats':
      report({ type: 'answer', id: command.id, value: renderer ? frameStats(renderer) : null });
      break;
    case 'finish':
      renderer?.finish();
      report({ type: 'finished', id: command.id, at: epochNow() });
      break;
    case 'loseContext':
      renderer?.loseContext();
      break;
    case 'restoreContext':
      renderer?.restoreContext();
      break;
  }
};

/**
 * Whether this worker can draw WebGL2 at all, before the page gives up its
 * canvas: the renderer's name, or null (rasteriser.js; it also decides
 * antialiasing).
 */
const rendererName = typeof OffscreenCanvas === 'function' ? probeRenderer() : null;

// Names this thread in DevTools traces (the benchmark finds its tasks by it).
performance.mark('vitrine:render-worker');
report({ type: 'ready', webgl2: rendererName !== null });
