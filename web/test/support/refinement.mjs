// @ts-check
/**
 * What the tests of view-dependent refinement share, charted streams
 * (part-refinement.test.mjs, e2e/parts.e2e.mjs) and nested ones
 * (nested-refinement.test.mjs, e2e/nested.e2e.mjs): a camera close to a
 * chart, a refinement run in Node against a vertex store laid out as the
 * renderer's, and in the browser a page that records every failed request
 * and console error, waits for the refinement to settle and moves the camera.
 */
import assert from 'node:assert/strict';
import { existsSync, readFileSync } from 'node:fs';
import { VitrineCodec } from '../../src/codec.js';
import { OrbitCamera, multiply } from '../../src/camera.js';
import { boundingSphere } from '../../src/part-selection.js';
import { wasmPath } from './fixtures.mjs';

/** The codec, from the built wasm. */
export async function loadCodec() {
  assert.ok(existsSync(wasmPath), `build the wasm first: ${wasmPath}`);
  return VitrineCodec.instantiate(readFileSync(wasmPath));
}

/**
 * A camera close to a chart, looking at it from outside the model.
 * @param {Float32Array} positions the chart's (or one vertex of it)
 * @returns {import('../../src/part-selection.js').PartCamera}
 */
export function cameraOn(positions) {
  const { centre } = boundingSphere(positions);
  const c = new OrbitCamera({ min: [-2, -2, -2], max: [2, 2, 2] }, 1);
  const out = Math.hypot(...centre) || 1;
  const yaw = Math.atan2(centre[0], centre[2]);
  const pitch = Math.asin(Math.max(-1, Math.min(1, centre[1] / out)));
  c.state = { target: centre, distance: 0.05, yaw, pitch };
  return { eye: c.basis().eye, clip: Array.from(multiply(c.projection(1), c.view())), pixelsPerRadian: 1000 / c.fovY };
}

/**
 * The messages of a refinement run in Node: the vertex store as the
 * renderer lays out the levels posted (vertex-store.js: positions from
 * `firstVertex` on), the last level, the last state told, the other
 * messages (errors), and a way to wait for the state to settle.
 * @template {{ settled: boolean }} State
 */
export function refinementSink() {
  let store = new Float32Array(0);
  /** @type {import('../../src/reconstruction.js').LevelMessage | null} */
  let last = null;
  /** @type {State | null} */
  let state = null;
  /** @type {string[]} */
  const errors = [];
  /** @type {(() => void) | null} */
  let wake = null;
  return {
    errors,
    /** @type {import('../../src/reconstruction.js').Post} */
    post: (message) => {
      if (message.type !== 'level') return;
      const first = /** @type {number} */ (message.firstVertex);
      const grown = new Float32Array(Math.max(store.length, 3 * message.vertices));
      grown.set(store);
      grown.set(message.positions, 3 * first);
      store = grown;
      last = message;
    },
    /** @param {{ type: string, state?: any }} message */
    tell: (message) => {
      if (message.type === 'parts') state = message.state;
      else errors.push(JSON.stringify(message));
      wake?.();
    },
    /** The store and the last level posted, now. */
    posted: () => ({ store, last }),
    /** The last state told. */
    state: () => state,
    /**
     * Forgets the last state, runs `start` (a new camera) and waits for a settled state.
     * @param {() => void} start
     */
    async settle(start) {
      state = null;
      start();
      for (let i = 0; i < 1000 && !(/** @type {State | null} */ (state)?.settled); i++) {
        await new Promise((resolve) => {
          wake = () => resolve(undefined);
          setTimeout(resolve, 20);
        });
      }
      return /** @type {State | null} */ (state);
    },
  };
}

/**
 * A new page that records every failed request and console error, and every
 * request (the caller navigates, after any init script of its own).
 * @param {import('playwright-core').BrowserContext} context
 */
export async function openRecorded(context) {
  const page = await context.newPage();
  /** @type {string[]} */
  const problems = [];
  page.on('pageerror', (e) => problems.push(`page error: ${e.message}`));
  page.on('console', (m) => {
    if (m.type() === 'error') problems.push(`console: ${m.text()}`);
  });
  page.on('requestfailed', (r) => problems.push(`failed: ${r.url()}`));
  page.on('response', (r) => {
    if (r.status() >= 400) problems.push(`${r.status()}: ${r.url()}`);
  });
  /** @type {string[]} */
  const requests = [];
  page.on('request', (r) => requests.push(r.url()));
  return { page, problems, requests };
}

/**
 * Waits until the refinement has settled and the union it posted last is
 * on screen (its level: the finest chart's), or the viewer failed; then its
 * state, with the viewer's status and message.
 * @param {import('playwright-core').Page} page
 * @param {number} [timeout]
 * @returns {Promise<any>}
 */
export async function settledParts(page, timeout = 30_000) {
  await page.waitForFunction(
    () => {
      const v = /** @type {any} */ (document.querySelector('vitrine-viewer'))?.viewer;
      const p = v?.partsState();
      return v?.state.status === 'error' || (p && p.settled && v.state.shownLevel >= p.level);
    },
    undefined,
    { timeout, polling: 100 },
  );
  return page.evaluate(() => {
    const v = /** @type {any} */ (document.querySelector('vitrine-viewer')).viewer;
    return { ...v.partsState(), status: v.state.status, message: v.state.message };
  });
}

/**
 * Moves the page's camera to look at `target` from `distance`, straight along −z.
 * @param {import('playwright-core').Page} page
 * @param {[number, number, number]} target
 * @param {number} distance
 */
export async function lookAt(page, target, distance) {
  await page.evaluate(
    ({ target, distance }) => {
      const v = /** @type {any} */ (document.querySelector('vitrine-viewer')).viewer;
      v.camera.state = { target, distance, yaw: 0, pitch: 0 };
      v.renderer.requestFrame();
      v.cameraMoved();
    },
    { target, distance },
  );
}

/**
 * A stream decoded whole in Node, every batch, as a uniform viewer would.
 * @param {string} manifestUrl
 * @param {{ levels: { url: string }[] }} manifest
 */
export async function wholeDecoder(manifestUrl, manifest) {
  const codec = await loadCodec();
  /** @param {string} path */
  const get = async (path) => new Uint8Array(await (await fetch(new URL(path, manifestUrl))).arrayBuffer());
  const decoder = codec.decoder(await get(manifest.levels[0].url));
  for (const level of manifest.levels.slice(1)) decoder.apply(await get(level.url));
  return { codec, decoder };
}

/**
 * Whether some vertex satisfies `where`.
 * @param {ArrayLike<number>} positions x, y, z per vertex
 * @param {(x: number, y: number, z: number) => boolean} where
 */
export function some(positions, where) {
  for (let i = 0; i < positions.length; i += 3) if (where(positions[i], positions[i + 1], positions[i + 2])) return true;
  return false;
}
