// @ts-check
// Orbiting a large scan in headless Chromium, where WebGL2 runs on
// SwiftShader (a CPU rasteriser sharing the machine's cores with the
// decoders, as on a computer whose GPU the browser blocklists): frames a
// second while the visitor drags, and when the last level is decoded and
// drawn, with the viewer's `motion` modes alternated load by load (`full`:
// the level on screen in every frame, as before 5 Dec 2026; `auto`: a
// coarser level while moving where the level's frames are slow; motion.js).
// Three scenarios, a load each:
// - `rest`: the last level on screen, then a drag of --seconds;
// - `wheel`: the last level on screen, then a wheel turn every 400 ms for
//   --seconds (zooming in, then out): pauses that a drag does not have;
// - `refine`: a drag from the first frame until the last level is decoded,
//   then the mouse released (when is that level drawn?).
// Times are from navigation start (ViewerState.decodedAtMs, shownAtMs);
// frames are the render worker's (renderer.js frameStats). Each load starts
// on a quiet machine. Median of --runs.
//   node bench/orbit-bench.mjs --mesh /work/scans/igea-2m.ply [--runs 3] [--seconds 5] [--modes full,auto] [--scenarios rest,wheel,refine]
import { cpus, loadavg } from 'node:os';
import { parseArgs } from 'node:util';
import { launch } from '../test/support/browser.mjs';
import { startService } from '../test/support/service.mjs';
import { median, quiet } from './machine.mjs';

const { values } = parseArgs({
  options: {
    mesh: { type: 'string' },
    runs: { type: 'string', default: '3' },
    seconds: { type: 'string', default: '5' },
    modes: { type: 'string', default: 'full,auto' },
    scenarios: { type: 'string', default: 'rest,wheel,refine' },
  },
});
if (!values.mesh) {
  console.error('usage: node bench/orbit-bench.mjs --mesh MESH [--runs 3] [--seconds 5] [--modes full,auto]');
  process.exit(2);
}
const runs = Number(values.runs);
const seconds = Number(values.seconds);
const modes = values.modes.split(',');
for (const m of modes) if (!['auto', 'full', 'coarse'].includes(m)) throw new Error(`--modes: auto, full or coarse, not ${m}`);
const scenarios = /** @type {Array<'rest' | 'wheel' | 'refine'>} */ (values.scenarios.split(','));
for (const x of scenarios) if (!['rest', 'wheel', 'refine'].includes(x)) throw new Error(`--scenarios: rest, wheel or refine, not ${x}`);

const t0 = performance.now();
const service = await startService({ models: [{ slug: 'scan', title: 'Scan', kind: 'file', file: values.mesh, policy: 'open' }] });
console.error(`ingested ${values.mesh} in ${((performance.now() - t0) / 1000).toFixed(0)} s`);
const manifest = await (await fetch(`${service.url}/api/models/scan`)).json();
const last = manifest.last_level;
// GPU compositing on SwiftShader, as pool-viewer.mjs: frames reach the screen as textures.
const browser = await launch({ width: 800, height: 600, gpuCompositing: true });

/** @typedef {import('../src/renderer.js').FrameStats} FrameStats */
/** @typedef {import('../src/viewer.js').ViewerState} ViewerState */
/** @typedef {import('playwright-core').Page} Page */

/** @param {Page} page @returns {Promise<ViewerState>} */
const state = (page) => page.evaluate(() => /** @type {any} */ (document.querySelector('vitrine-viewer')).viewer.state);
/** @param {Page} page @returns {Promise<FrameStats>} */
const stats = (page) => page.evaluate(() => /** @type {any} */ (document.querySelector('vitrine-viewer')).viewer.renderer.frameStats());
/** @param {number} ms */
const sleep = (ms) => new Promise((resolve) => setTimeout(resolve, ms));

/**
 * Drags in circles around the canvas's centre (a move every ~16 ms) until
 * `done` says so; the button stays down.
 * @param {Page} page
 * @param {() => Promise<boolean>} done checked every 10 moves
 */
async function drag(page, done) {
  await page.mouse.move(400, 300);
  await page.mouse.down();
  for (let i = 0; ; i++) {
    const a = i / 20;
    await page.mouse.move(400 + 120 * Math.cos(a), 300 + 60 * Math.sin(a));
    await sleep(16);
    if (i % 10 === 9 && (await done())) return;
  }
}

/**
 * @typedef {object} Orbit
 * @property {number} fps frames a second during the drag
 * @property {number} standInShare the share of those frames that drew the stand-in
 * @property {number} levelFrames frames of the level itself during the motion (seconds each on SwiftShader)
 * @property {number | null} standInLevel
 * @property {number} decoded last level decoded (ms from navigation; `refine`)
 * @property {number} drawn last level drawn (ms from navigation; `refine`), or after the
 *   mouse was released (ms; `rest`)
 * @property {{ triangles: number, ms: number } | null} timed the last timed frame of a level
 */

/**
 * One cold load and one drag.
 * @param {string} mode
 * @param {'rest' | 'wheel' | 'refine'} scenario
 * @returns {Promise<Orbit>}
 */
async function orbit(mode, scenario) {
  await quiet();
  const page = await browser.context.newPage();
  await page.goto(`${service.url}/embed/scan?motion=${mode}`);
  const shown = (/** @type {number} */ n) =>
    page.waitForFunction(
      ([n]) => /** @type {any} */ (document.querySelector('vitrine-viewer'))?.viewer?.state?.shownAtMs?.[n] !== undefined,
      [n],
      { timeout: 300_000, polling: 50 },
    );
  if (scenario !== 'refine') {
    await shown(last);
    await page.evaluate(() => /** @type {any} */ (document.querySelector('vitrine-viewer')).viewer.renderer.finish());
  } else {
    await page.waitForFunction(() => /** @type {any} */ (document.querySelector('vitrine-viewer'))?.viewer?.state?.firstFrameMs != null, null, {
      timeout: 300_000,
      polling: 50,
    });
  }
  const before = await stats(page);
  const start = performance.now();
  const until = start + seconds * 1000;
  if (scenario === 'wheel') {
    await page.mouse.move(400, 300);
    const turns = Math.floor((seconds * 1000) / 400);
    for (let i = 0; i < turns; i++) {
      await page.mouse.wheel(0, i < turns / 2 ? -120 : 120);
      await sleep(400);
    }
  } else {
    await drag(page, async () =>
      scenario === 'rest' ? performance.now() >= until : (await state(page)).decodedAtMs[last] !== undefined,
    );
  }
  const after = await stats(page);
  const elapsed = (performance.now() - start) / 1000;
  await page.mouse.up();
  const released = await page.evaluate(() => performance.now());
  if (scenario !== 'refine') {
    // The level itself, drawn again once the view rests, and that frame done
    // on the GPU (after the frames queued while dragging).
    await page.waitForFunction((n) => /** @type {any} */ (document.querySelector('vitrine-viewer')).viewer.state.drawnLevel === n, last, {
      timeout: 60_000,
      polling: 20,
    });
    await page.evaluate(() => /** @type {any} */ (document.querySelector('vitrine-viewer')).viewer.renderer.finish());
  } else {
    await shown(last);
  }
  const s = await state(page);
  const restedAt = await page.evaluate(() => performance.now());
  await page.close();
  const frames = after.frames - before.frames;
  return {
    fps: frames / elapsed,
    standInShare: (after.standInFrames - before.standInFrames) / Math.max(1, frames),
    levelFrames: frames - (after.standInFrames - before.standInFrames),
    standInLevel: after.standInLevel,
    decoded: s.decodedAtMs[last],
    drawn: scenario === 'refine' ? s.shownAtMs[last] : restedAt - released,
    timed: after.timedFrame,
  };
}

console.log(
  `# ${new Date().toISOString()}, ${cpus().length} cores, load ${loadavg().map((x) => x.toFixed(2)).join(' ')}; ` +
    `${values.mesh}: ${last} batches, ${manifest.levels.at(-1).faces} triangles at the last level, format ${manifest.stream_format}; median of ${runs} cold loads`,
);
const rows = [];
for (const scenario of scenarios) {
  /** @type {Map<string, Orbit[]>} */
  const results = new Map(modes.map((m) => [m, []]));
  for (let r = 0; r < runs; r++) {
    for (const mode of modes) {
      const x = await orbit(mode, scenario);
      console.error(
        `${scenario}, ${mode}: ${x.fps.toFixed(1)} frames/s (stand-in ${(100 * x.standInShare).toFixed(0)} %, level ${x.standInLevel}; ${x.levelFrames} of the level), ` +
          `decoded ${x.decoded.toFixed(0)} ms, drawn ${x.drawn.toFixed(0)} ms, timed ${JSON.stringify(x.timed)}`,
      );
      results.get(mode)?.push(x);
    }
  }
  for (const [mode, xs] of results) {
    const m = (/** @type {(x: Orbit) => number} */ f) => median(xs.map(f));
    rows.push(
      `| ${scenario} | ${mode} | ${m((x) => x.fps).toFixed(1)} | ${(100 * m((x) => x.standInShare)).toFixed(0)} % | ${m((x) => x.levelFrames)} | ` +
        `${scenario === 'refine' ? `${m((x) => x.decoded).toFixed(0)} ms` : '–'} | ${m((x) => x.drawn).toFixed(0)} ms |`,
    );
  }
}
console.log('| motion of the view | `motion` | frames/s while moving | stand-in frames | frames of the level while moving | last level decoded | last level drawn (refine) / drawn again after the motion |');
console.log('|---|---|---:|---:|---:|---:|---:|');
for (const row of rows) console.log(row);
await browser.close();
await service.stop();
