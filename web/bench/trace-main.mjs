// @ts-check
// Where the page's main thread spends its time while the viewer refines:
// one cold load, traced with V8's sampling profiler, then the longest
// main-thread tasks during reconstruction, each with its wall and thread
// (CPU) time, the trace events inside it (script, GC, style, layout…) and
// the profiler's samples in it by function. Also the decode worker's time
// per level. For finding, not for tables (viewer-bench.mjs makes those).
//   node bench/trace-main.mjs [--kilo-vertices 1000] [--mbits 10] [--path /embed/torus] [--runs 1] [--out trace.json]
import { writeFileSync } from 'node:fs';
import { loadavg } from 'node:os';
import { parseArgs } from 'node:util';
import { launch } from '../test/support/browser.mjs';
import { startService } from '../test/support/service.mjs';
import { tracedLoad } from './traced-load.mjs';

const { values } = parseArgs({
  options: {
    'kilo-vertices': { type: 'string', default: '1000' },
    mbits: { type: 'string', default: '10' },
    path: { type: 'string', default: '/embed/torus' },
    runs: { type: 'string', default: '1' },
    top: { type: 'string', default: '3' },
    out: { type: 'string' },
  },
});
const kilo = Number(values['kilo-vertices']);
const mbits = Number(values.mbits);

const service = await startService({
  models: [{ slug: 'torus', title: 'Torus', kind: 'torus', kiloVertices: kilo, colour: true, policy: 'open' }],
});
const manifest = await (await fetch(`${service.url}/api/models/torus`)).json();
const browser = await launch({ width: 1024, height: 768 });

try {
  for (let run = 0; run < Number(values.runs); run++) await traceOnce(run);
} finally {
  await browser.close().catch(() => {});
  await service.stop();
}

/** @param {number} run */
async function traceOnce(run) {
  const { events, state } = await tracedLoad(browser.context, `${service.url}${values.path}`, {
    mbits: mbits > 0 ? mbits : null,
    categories: [
      'devtools.timeline',
      'disabled-by-default-devtools.timeline',
      'toplevel',
      'blink.user_timing',
      'v8',
      'v8.execute',
      'disabled-by-default-v8.cpu_profiler',
      'disabled-by-default-v8.gc',
    ],
  });
  if (values.out) writeFileSync(values.out.replace(/(\.json)?$/, `-${run}.json`), JSON.stringify({ traceEvents: events }));
  console.log(`\n=== run ${run}: load average ${loadavg().map((l) => l.toFixed(1)).join(' ')}; decodeMs ${state.decodeMs.toFixed(0)} deriveMs ${state.deriveMs.toFixed(0)}`);
  report(events, manifest.last_level);
}

/**
 * @param {any[]} events
 * @param {number} last
 */
function report(events, last) {
  const committed = events.find((e) => e.args?.data?.processId && String(e.args.data.url).startsWith(service.url));
  const pid = committed?.args.data.processId;
  const threads = new Map(events.filter((e) => e.pid === pid && e.name === 'thread_name').map((e) => [e.tid, e.args.name]));
  const tid = [...threads].find(([, name]) => name === 'CrRendererMain')?.[0];
  const marks = events.filter((e) => e.pid === pid && String(e.name).startsWith('vitrine:level-'));
  const from = Math.min(...marks.map((e) => e.ts));
  const to = marks.find((e) => e.name === `vitrine:level-${last}`)?.ts;
  if (to === undefined) throw new Error('no last-level mark');
  console.log(`levels drawn: ${marks.map((m) => `${m.name.slice(14)}@${((m.ts - from) / 1000).toFixed(0)}ms`).join(' ')}`);
  const isTask = (/** @type {any} */ e) => e.name === 'RunTask' || e.name === 'ThreadControllerImpl::RunTask';
  const mine = events.filter((e) => e.pid === pid && e.tid === tid && e.ph === 'X');
  const tasks = mine.filter((e) => isTask(e) && e.ts + e.dur >= from && e.ts <= to).sort((a, b) => b.dur - a.dur);
  const samples = profileSamples(events, pid, tid);
  console.log(`main thread: ${tasks.length} tasks during reconstruction, ${samples.length} profiler samples`);
  for (const task of tasks.slice(0, Number(values.top))) {
    const end = task.ts + task.dur;
    console.log(
      `\n task at +${((task.ts - from) / 1000).toFixed(0)} ms: ${(task.dur / 1000).toFixed(1)} ms wall, ` +
        `${task.tdur === undefined ? '?' : (task.tdur / 1000).toFixed(1)} ms thread time`,
    );
    const inside = mine.filter((e) => e !== task && e.ts >= task.ts && e.ts < end && e.dur >= 500);
    for (const e of inside.slice(0, 25)) {
      const data = e.args?.data ?? {};
      const what = data.functionName ?? data.type ?? data.url ?? '';
      console.log(
        `   ${' '.repeat(Math.min(6, depth(inside, e)))}${e.name} ${what} ${(e.dur / 1000).toFixed(1)} ms` +
          `${e.tdur === undefined ? '' : ` (cpu ${(e.tdur / 1000).toFixed(1)})`}`,
      );
    }
    const hits = samples.filter((s) => s.ts >= task.ts && s.ts < end);
    /** @type {Map<string, number>} */
    const self = new Map();
    /** @type {Map<string, number>} */
    const total = new Map();
    for (const s of hits) {
      self.set(s.stack[0], (self.get(s.stack[0]) ?? 0) + 1);
      for (const f of new Set(s.stack)) total.set(f, (total.get(f) ?? 0) + 1);
    }
    const top = (/** @type {Map<string, number>} */ m) =>
      [...m].sort((a, b) => b[1] - a[1]).slice(0, 12).map(([f, n]) => `${n} ${f}`).join('\n     ');
    console.log(`   samples: ${hits.length}\n   self:\n     ${top(self)}\n   total:\n     ${top(total)}`);
  }
  // All script the page ran during reconstruction: its calls by thread time, and the samples in them by function.
  const calls = mine.filter((e) => e.name === 'FunctionCall' && e.ts + e.dur >= from && e.ts <= to);
  const cpu = calls.reduce((sum, e) => sum + (e.tdur ?? 0), 0) / 1000;
  const wall = calls.reduce((sum, e) => sum + e.dur, 0) / 1000;
  const worst = [...calls].sort((a, b) => (b.tdur ?? 0) - (a.tdur ?? 0)).slice(0, 5);
  console.log(`\nscript on the main thread during reconstruction: ${calls.length} calls, ${wall.toFixed(0)} ms wall, ${cpu.toFixed(1)} ms thread time`);
  console.log(`  most thread time: ${worst.map((e) => `${e.args?.data?.functionName}@+${((e.ts - from) / 1000).toFixed(0)} ${(e.tdur / 1000).toFixed(1)}/${(e.dur / 1000).toFixed(1)} ms`).join(', ')}`);
  /** @type {Map<string, number>} */
  const bySelf = new Map();
  for (const s of samples) {
    if (!calls.some((e) => s.ts >= e.ts && s.ts < e.ts + e.dur)) continue;
    bySelf.set(s.stack[0], (bySelf.get(s.stack[0]) ?? 0) + 1);
  }
  console.log(`  samples inside them, by function: ${[...bySelf].sort((a, b) => b[1] - a[1]).slice(0, 15).map(([f, n]) => `${n} ${f}`).join(' | ')}`);
  const workers = events.filter((e) => e.pid === pid && e.ph === 'X' && isTask(e) && e.tid !== tid && e.dur > 20_000 && e.ts + e.dur >= from && e.ts <= to);
  /** @type {Map<string, number[]>} */
  const byThread = new Map();
  for (const e of workers) {
    const name = `${threads.get(e.tid) ?? e.tid}`;
    byThread.set(name, [...(byThread.get(name) ?? []), Math.round(e.dur / 1000)]);
  }
  console.log('\nother threads, tasks > 20 ms during reconstruction:');
  for (const [name, durs] of byThread) console.log(`  ${name}: ${durs.join(' ')}`);
}

/** @param {any[]} all @param {any} e */
function depth(all, e) {
  return all.filter((o) => o !== e && o.ts <= e.ts && o.ts + o.dur >= e.ts + e.dur).length;
}

/**
 * The V8 sampling profiler's samples of one thread: time and stack (leaf first).
 * @param {any[]} events
 * @param {number} pid
 * @param {number} tid
 */
function profileSamples(events, pid, tid) {
  const profiles = events.filter((e) => e.pid === pid && e.tid === tid && e.name === 'Profile');
  /** @type {{ ts: number, stack: string[] }[]} */
  const out = [];
  for (const profile of profiles) {
    /** @type {Map<number, { name: string, parent?: number }>} */
    const nodes = new Map();
    let ts = profile.args.data.startTime;
    const chunks = events.filter((e) => e.pid === pid && e.name === 'ProfileChunk' && e.id === profile.id);
    for (const chunk of chunks) {
      const cpu = chunk.args.data.cpuProfile ?? {};
      for (const n of cpu.nodes ?? []) {
        const f = n.callFrame;
        const where = f.url ? `${f.url.split('/').pop()}:${f.lineNumber + 1}` : '';
        nodes.set(n.id, { name: `${f.functionName || '(anonymous)'} ${where}`.trim(), parent: n.parent });
      }
      const deltas = chunk.args.data.timeDeltas ?? [];
      (cpu.samples ?? []).forEach((/** @type {number} */ id, /** @type {number} */ i) => {
        ts += deltas[i] ?? 0;
        const stack = [];
        for (let n = nodes.get(id), guard = 0; n && guard < 200; n = n.parent === undefined ? undefined : nodes.get(n.parent), guard++) {
          stack.push(n.name);
        }
        out.push({ ts, stack });
      });
    }
  }
  return out;
}
