// @ts-check
/**
 * The splat renderer and worker on a bare page, for splats.e2e.mjs (bundled
 * by the test with esbuild): `window.harness` loads splats from the worker
 * (a point stream's levels, or a mesh) or made on the page, and draws them
 * with a fixed camera.
 */
import { OrbitCamera } from '../src/camera.js';
import { BACKGROUND } from '../src/shading.js';
import { SplatView } from '../src/splats/splat-view.js';

const root = /** @type {HTMLElement} */ (document.getElementById('root'));
/** @type {OrbitCamera | null} */
let camera = null;
const view = new SplatView((canvas) => root.append(canvas), { camera: () => camera, background: BACKGROUND });
const worker = new Worker('/dist/splat-worker.js');
const module = WebAssembly.compileStreaming(fetch('/dist/vitrine_wasm.wasm'));

/** @param {import('../src/geometry.js').Bounds} box @param {Partial<import('../src/camera.js').OrbitState>} [state] */
function look(box, state) {
  camera = new OrbitCamera(box, view.canvas.clientWidth / view.canvas.clientHeight);
  Object.assign(camera.state, state ?? {});
}

/** @param {Uint8Array} rgba */
function base64(rgba) {
  let binary = '';
  for (let i = 0; i < rgba.length; i += 0x8000) binary += String.fromCharCode(...rgba.subarray(i, i + 0x8000));
  return btoa(binary);
}

/** @param {(m: any) => boolean} until */
function listen(until) {
  /** @type {any[]} */
  const messages = [];
  return new Promise((resolve) => {
    worker.onmessage = (event) => {
      const m = event.data;
      messages.push({ type: m.type, level: m.level, count: m.set?.count, message: m.message });
      if (m.type === 'splats') view.setSplats(m.set);
      if (until(m)) resolve(messages);
    };
  });
}

/** @type {any} */ (window).harness = {
  view,
  /** @param {string} base @param {string[]} batches @param {import('../src/geometry.js').Bounds} box */
  async points(base, batches, box) {
    look(box);
    const done = listen((m) => m.type === 'done' || m.type === 'error');
    worker.postMessage({ type: 'points', module: await module, baseUrl: new URL(base, location.href).href,
      batchUrls: batches.map((b) => new URL(b, location.href).href), upTo: batches.length });
    return done;
  },
  /**
   * @param {number[]} positions @param {number[]} indices @param {import('../src/geometry.js').Bounds} box
   * @param {Partial<import('../src/camera.js').OrbitState>} state @param {number} [sharpThreshold] w_s (default 0.9)
   */
  async mesh(positions, indices, box, state, sharpThreshold) {
    look(box, state);
    const done = listen((m) => m.type === 'splats');
    worker.postMessage({ type: 'mesh', id: 1, positions: new Float32Array(positions), indices: new Uint32Array(indices), colours: null, sharpThreshold });
    return done;
  },
  /** Points on a unit sphere, drawn without preprocessing (frame time). @param {number} count */
  synthetic(count) {
    const positions = new Float32Array(3 * count);
    const normals = new Float32Array(3 * count);
    const golden = Math.PI * (3 - Math.sqrt(5));
    for (let i = 0; i < count; i++) {
      const y = 1 - (2 * (i + 0.5)) / count;
      const r = Math.sqrt(1 - y * y);
      const x = Math.cos(golden * i) * r;
      const z = Math.sin(golden * i) * r;
      positions.set([x, y, z], 3 * i);
      normals.set([x, y, z], 3 * i);
    }
    const radius = 1.2 * Math.sqrt(4 / count);
    view.setSplats({ count, positions, normals, colours: null, radii: new Float32Array(count).fill(radius),
      surfaceIds: new Uint32Array(count), clip: new Uint32Array(count), planes: new Float32Array(0) });
    look({ min: [-1, -1, -1], max: [1, 1, 1] });
  },
  /** Turns the camera to `state` (from its home view). @param {Partial<import('../src/camera.js').OrbitState>} state */
  orbit(state) {
    if (camera) camera.state = { ...structuredClone(camera.home), ...state };
  },
  /** @param {Partial<import('../src/splats/splat-renderer.js').SplatOptions>} options */
  capture(options) {
    view.setOptions(options);
    const { width, height, rgba } = view.capture();
    return { width, height, data: base64(rgba), view: [...(camera?.view() ?? [])], projection: [...(camera?.projection(width / height) ?? [])] };
  },
  /** @param {number} frames */
  frameTime: (frames) => view.frameTime(frames),
};
