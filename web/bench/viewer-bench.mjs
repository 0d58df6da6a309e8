// @ts-check
// Viewer benchmarks in headless Chromium with WebGL2 on SwiftShader (a CPU
// renderer: frame times are not a GPU's), against the real `vitrine serve`
// with a ~1 M-vertex coloured torus:
// - time to first frame (base mesh drawn), from navigation start, on loopback
//   and with DevTools network emulation at 10 Mbit/s;
// - time to the last level (its frame issued, and drawn: the GPU finished,
//   gl.finish() after the viewer settles), and time spent in the WASM
//   decoder (all levels, inside the decode worker) and in normals / edges
//   (in the decode worker, or — normals — in the render worker, which derives
//   them for the levels it draws);
// - longest main-thread task of the page's renderer, from a DevTools trace
//   (RunTask events), during reconstruction (from the base mesh on screen to
//   the last level on screen) and over the whole load (start-up included),
//   and PerformanceObserver 'longtask' entries; with the render worker, its
//   longest task during reconstruction too.
// The viewer draws in a render worker (OffscreenCanvas) by default; the
// `main thread` rows load `?offscreen=off`, the fallback that draws on the
// page's main thread as the viewer did before.
// Two browser set-ups: the test flags (`--disable-gpu`: the compositor works
// in software and reads every WebGL frame back on the main thread, waiting
// for SwiftShader to finish drawing it), and the same without `--disable-gpu`
// (compositing on SwiftShader too: frames reach the screen as textures, as
// with any real GPU).
//   node bench/viewer-bench.mjs [--kilo-vertices 1000] [--runs 3]
import { loadavg } from 'node:os';
import { parseArgs } from 'node:util';
import { launch } from '../test/support/browser.mjs';
import { startService } from '../test/support/service.mjs';
import { tracedLoad } from './traced-load.mjs';

const { values } = parseArgs({
  options: { 'kilo-vertices': { type: 'string', default: '1000' }, runs: { type: 'string', default: '3' } },
});
const kilo = Number(values['kilo-vertices']);
const runs = Number(values.runs);

const t0 = performance.now();
const service = await startService({
  models: [{ slug: 'torus', title: 'Torus', kind: 'torus', kiloVertices: kilo, colour: true, policy: 'open' }],
});
console.error(`ingested the ${kilo}k-vertex torus in ${((performance.now() - t0) / 1000).toFixed(1)} s`);
const manifest = await (await fetch(`${service.url}/api/models/torus`)).json();
const totalBytes = manifest.levels.reduce((/** @type {number} */ s, /** @type {any} */ l) => s + l.bytes, 0);
/** @type {Awaited<ReturnType<typeof launch>> | undefined} */
let browser;
/**
 * One cold load (no HTTP cache) of a page, traced.
 * @param {string} path
 * @param {number | null} mbits emulated bandwidth, null for loopback
 */
async function load(path, mbits) {
  const { context } = /** @type {NonNullable<typeof browser>} */ (browser);
  const { events, state, drawnMs, collected: longtasks } = await tracedLoad(context, `${service.url}${path}`, {
    mbits,
    categories: ['devtools.timeline', 'disabled-by-default-devtools.timeline', 'toplevel', 'blink.user_timing'],
    initScript: () => {
      const w = /** @type {any} */ (window);
      w.__longtasks = [];
      new PerformanceObserver((list) => w.__longtasks.push(...list.getEntries().map((e) => e.duration))).observe({
        type: 'longtask',
        buffered: true,
      });
    },
    collect: (page) => page.evaluate(() => /** @type {any} */ (window).__longtasks),
  });
  if (state.status !== 'complete') throw new Error(`viewer ended as ${state.status}: ${state.message}`);
  return { state, drawnMs, longtasks, ...longestTasks(events, manifest.last_level) };
}

/**
 * Longest top-level tasks on the main thread of the page's renderer (not
 * Chromium's own pages), in ms: over the whole trace, and between the marks
 * the first `vitrine:level-k` mark and `vitrine:level-{last}` (the viewer
 * marks each level when it is first drawn).
 * @param {any[]} events
 * @param {number} last
 */
function longestTasks(events, last) {
  const committed = events.find((e) => e.args?.data?.processId && String(e.args.data.url).startsWith(service.url));
  const pid = committed?.args.data.processId;
  const tid = events.find((e) => e.pid === pid && e.name === 'thread_name' && e.args?.name === 'CrRendererMain')?.tid;
  const marks = events.filter((e) => e.pid === pid && String(e.name).startsWith('vitrine:level-'));
  const workerTid = events.find((e) => e.pid === pid && e.name === 'vitrine:render-worker')?.tid;
  const from = Math.min(...marks.map((e) => e.ts));
  const to = marks.find((e) => e.name === `vitrine:level-${last}`)?.ts;
  if (pid === undefined || tid === undefined || to === undefined) throw new Error('the trace lacks the page or its marks');
  let all = 0;
  let during = 0;
  let script = 0;
  let worker = 0;
  // Thread (CPU) time of the longest task and script: on a loaded machine a
  // task's wall time also counts the time its thread waited for a core.
  let duringCpu = 0;
  let scriptCpu = 0;
  /** @type {any} */
  let longest = null;
  for (const e of events) {
    if (e.ph !== 'X' || e.pid !== pid) continue;
    const inWindow = e.ts + e.dur >= from && e.ts <= to;
    if (workerTid !== undefined && e.tid === workerTid && inWindow && (e.name === 'RunTask' || e.name === 'ThreadControllerImpl::RunTask')) {
      worker = Math.max(worker, e.dur / 1000);
    }
    if (e.tid !== tid) continue;
    // The viewer's own code: script run from a task (frame callback, worker
    // message, resize observer), GL calls and their waits included.
    if (e.name === 'FunctionCall' && inWindow && e.dur / 1000 > script) {
      script = e.dur / 1000;
      scriptCpu = (e.tdur ?? 0) / 1000;
    }
    if (e.name !== 'RunTask' && e.name !== 'ThreadControllerImpl::RunTask') continue;
    all = Math.max(all, e.dur / 1000);
    if (inWindow && e.dur / 1000 > during) {
      during = e.dur / 1000;
      duringCpu = (e.tdur ?? 0) / 1000;
      longest = e;
    }
  }
  // What the longest task did: its longest inner events (stderr, for reading the table).
  const inside = longest
    ? events
        .filter((e) => e.ph === 'X' && e.pid === pid && e.tid === tid && e !== longest && e.ts >= longest.ts && e.ts < longest.ts + longest.dur && e.dur >= 1000)
        .sort((a, b) => b.dur - a.dur)
        .slice(0, 4)
        .map((e) => `${e.name}${e.args?.data?.functionName ? ` ${e.args.data.functionName}` : ''} ${(e.dur / 1000).toFixed(0)}/${((e.tdur ?? 0) / 1000).toFixed(1)} ms`)
    : [];
  return {
    longestMs: all,
    longestDuringMs: during,
    longestDuringCpuMs: duringCpu,
    longestDuringInside: inside,
    longestScriptMs: script,
    longestScriptCpuMs: scriptCpu,
    longestWorkerMs: workerTid === undefined ? null : worker,
  };
}

/** @param {number[]} xs */
const median = (xs) => [...xs].sort((a, b) => a - b)[Math.floor(xs.length / 2)];
/** @param {number} ms */
const s = (ms) => `${(ms / 1000).toFixed(2)} s`;

/** @type {Array<[string, string, number | null, boolean]>} */
const scenarios = [
  ['progressive, loopback', '/embed/torus', null, false],
  ['progressive, 10 Mbit/s', '/embed/torus', 10, false],
  [`direct to level ${manifest.last_level}, loopback`, `/embed/torus?level=${manifest.last_level}`, null, false],
  ['main thread: progressive, loopback', '/embed/torus?offscreen=off', null, false],
  ['main thread: progressive, 10 Mbit/s', '/embed/torus?offscreen=off', 10, false],
  ['progressive, loopback, GPU compositing', '/embed/torus', null, true],
  ['progressive, 10 Mbit/s, GPU compositing', '/embed/torus', 10, true],
  ['main thread: progressive, loopback, GPU compositing', '/embed/torus?offscreen=off', null, true],
];
const only = process.env.VITRINE_BENCH_ONLY;
console.log(`Model: torus, ${manifest.levels.at(-1).vertices.toLocaleString('en')} vertices, ${manifest.levels.length} levels, ` +
  `base ${manifest.levels[0].vertices.toLocaleString('en')} vertices / ${manifest.levels[0].bytes.toLocaleString('en')} bytes, ` +
  `all payloads ${totalBytes.toLocaleString('en')} bytes. Median of ${runs} cold loads each (longest tasks: worst run).\n`);
console.log('| scenario | first frame | last level shown | last level drawn (GPU done) | WASM decode, all levels | normals + edges | longest main-thread task during reconstruction (its thread time) | of which the viewer\'s script (thread time) | longest over the whole load | long tasks > 50 ms | longest render-worker task during reconstruction |');
console.log('|---|---|---|---|---|---|---|---|---|---|---|');
let version = '';
/** Every scenario, one browser per compositing mode. */
async function measure() {
  for (const gpu of [false, true]) {
    browser = await launch({ width: 1024, height: 768, gpuCompositing: gpu });
    version = (await browser.context.browser()?.version()) ?? version;
    for (const [name, path, mbits, compositing] of scenarios) {
      // VITRINE_BENCH_ONLY: rows whose name contains it, or is it exactly with a leading '='.
      const wanted = !only || (only.startsWith('=') ? name === only.slice(1) : name.includes(only));
      if (compositing === gpu && wanted) await scenario(name, path, mbits);
    }
    await browser.close();
  }
}

/**
 * @param {string} name
 * @param {string} path
 * @param {number | null} mbits
 */
async function scenario(name, path, mbits) {
  /** @type {any[]} */
  const results = [];
  for (let i = 0; i < runs; i++) results.push(await load(path, mbits));
  const pick = (/** @type {(r: any) => number} */ f) => median(results.map(f));
  const worst = (/** @type {(r: any) => number} */ f) => Math.max(...results.map(f));
  const last = manifest.last_level;
  /** The worst run's wall time, with that task's thread time. @param {string} wall @param {string} cpu */
  const cpuOfWorst = (wall, cpu) => {
    const r = results.reduce((a, b) => (b[wall] > a[wall] ? b : a));
    return `${r[wall].toFixed(0)} ms (${r[cpu].toFixed(1)} ms CPU)`;
  };
  console.log(
    `| ${name} | ${s(pick((r) => r.state.firstFrameMs))} | ${s(pick((r) => r.state.shownAtMs[last]))} | ${s(pick((r) => r.drawnMs))} | ` +
      `${s(pick((r) => r.state.decodeMs))} | ${s(pick((r) => r.state.deriveMs + (r.state.normalsMs ?? 0)))} | ` +
      `${cpuOfWorst('longestDuringMs', 'longestDuringCpuMs')} | ${cpuOfWorst('longestScriptMs', 'longestScriptCpuMs')} | ` +
      `${worst((r) => r.longestMs).toFixed(0)} ms | ${worst((r) => r.longtasks.length)} | ` +
      `${results[0].longestWorkerMs === null ? '–' : `${worst((r) => r.longestWorkerMs).toFixed(0)} ms`} |`,
  );
  for (const r of results) {
    const { state, drawnMs, longestMs, longestDuringMs, longestDuringCpuMs, longestDuringInside, longestScriptMs, longestScriptCpuMs, longestWorkerMs, longtasks } = r;
    const { shownAtMs, firstFrameMs, decodeMs, deriveMs, normalsMs } = state;
    console.error(name, JSON.stringify({ firstFrameMs, shownAtMs, decodeMs, deriveMs, normalsMs, drawnMs, longestMs, longestDuringMs, longestDuringCpuMs, longestDuringInside, longestScriptMs, longestScriptCpuMs, longestWorkerMs, longtasks }));
  }
}

try {
  await measure();
} finally {
  await browser?.close().catch(() => {});
  await service.stop();
}
console.log(
  `\nChromium ${version} headless, WebGL2 on SwiftShader (--use-angle=swiftshader), 1024×768, ` +
    `${process.platform} ${process.arch}, load average ${loadavg().map((l) => l.toFixed(1)).join(' ')}.`,
);
