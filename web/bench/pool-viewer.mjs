// @ts-check
// Time to the first level and to the last in headless Chromium for one scan,
// ingested twice into the real `vitrine serve`: as a plain stream (format 4,
// one decode worker) and charted (format 5, `--charts auto`), loaded with
// 1, 2 and 4 decode workers (`?decoders=`; src/decode-pool.js). Each load is
// cold (a fresh page, no HTTP cache) on loopback; times are from navigation
// start to the frame that first drew the level (ViewerState.shownAtMs) and,
// for the last level, also to when its decode worker's notice reached the
// page (ViewerState.decodedAtMs: decoded, normals derived, posted). On
// SwiftShader the two differ by seconds for a 2 M-vertex scan: the next
// frame waits until the GPU process has rasterised the previous level's
// (millions of triangles on the CPU), so "drawn" measures SwiftShader as much
// as decoding, and "decoded" is the pipeline a real GPU would wait for.
// `decode` is the decode worker's wall time in its batches (with a pool,
// waiting for the helpers included). The first level is the first frame with
// a mesh (the base, or a later level if the base was superseded before it
// was drawn). WebGL2 runs on SwiftShader, a CPU renderer that shares the
// machine's cores with the decoders. Median of --runs. `--antialias` runs the
// table once per value, alternating them load by load (`auto`: the viewer's rule, no multisampling on
// SwiftShader; `on`: multisampled as before 5 Dec 2026; src/rasteriser.js).
// Each load starts on a quiet machine: a closed page's GPU process can
// rasterise its last frame for seconds, which delayed the next page's
// navigation by up to 15 s.
//   node bench/pool-viewer.mjs --mesh /work/scans/igea-2m.ply [--runs 3] [--workers 1,2,4] [--antialias auto,on]
import { loadavg, cpus } from 'node:os';
import { parseArgs } from 'node:util';
import { launch } from '../test/support/browser.mjs';
import { startService } from '../test/support/service.mjs';
import { median, quiet } from './machine.mjs';

const { values } = parseArgs({
  options: {
    mesh: { type: 'string' },
    runs: { type: 'string', default: '3' },
    workers: { type: 'string', default: '1,2,4' },
    antialias: { type: 'string', default: 'auto' },
  },
});
if (!values.mesh) {
  console.error('usage: node bench/pool-viewer.mjs --mesh MESH [--runs 3] [--workers 1,2,4]');
  process.exit(2);
}
const runs = Number(values.runs);
const workers = values.workers.split(',').map(Number);
const antialiasModes = values.antialias.split(',');
for (const a of antialiasModes) if (!['auto', 'on', 'off'].includes(a)) throw new Error(`--antialias: auto, on or off, not ${a}`);

const t0 = performance.now();
const service = await startService({
  models: [
    { slug: 'plain', title: 'Plain', kind: 'file', file: values.mesh, policy: 'open', ingestArgs: ['--charts', 'off'] },
    { slug: 'charted', title: 'Charted', kind: 'file', file: values.mesh, policy: 'open', ingestArgs: ['--charts', 'auto'] },
  ],
});
console.error(`ingested ${values.mesh} twice in ${((performance.now() - t0) / 1000).toFixed(0)} s`);
/** @param {string} slug */
const manifest = async (slug) => (await fetch(`${service.url}/api/models/${slug}`)).json();
const plain = await manifest('plain');
const charted = await manifest('charted');
if (charted.stream_format !== 5) throw new Error(`--charts auto left ${values.mesh} plain (format ${charted.stream_format})`);
// GPU compositing (SwiftShader draws and composites): with the test flags'
// software compositor every frame of a 2 M-vertex level is read back on the
// renderer's main thread, which starves the decoders on a small machine.
const browser = await launch({ width: 800, height: 600, gpuCompositing: true });

/**
 * One cold load up to the last level.
 * @param {string} slug
 * @param {number} decoders
 * @param {number} last
 * @param {string} antialias
 */
async function load(slug, decoders, last, antialias) {
  await quiet();
  const page = await browser.context.newPage();
  await page.goto(`${service.url}/embed/${slug}?decoders=${decoders}${antialias === 'auto' ? '' : `&antialias=${antialias}`}`);
  await page.waitForFunction(
    (n) => /** @type {any} */ (document.querySelector('vitrine-viewer'))?.viewer?.state?.shownLevel === n,
    last,
    { timeout: 300_000, polling: 50 },
  );
  const s = await page.evaluate(() => /** @type {any} */ (document.querySelector('vitrine-viewer')).viewer.state);
  await page.close();
  if (s.decoders !== (slug === 'plain' ? 1 : decoders)) throw new Error(`${slug}: ${s.decoders} decoders, asked for ${decoders}`);
  return { first: s.firstFrameMs, decoded: s.decodedAtMs[last], last: s.shownAtMs[last], decode: s.decodeMs, vertices: s.vertices };
}

/** @typedef {{ first: number, decoded: number, last: number, decode: number, vertices: number }} Load */

/**
 * Medians of `runs` loads per antialias mode, the modes alternated load by
 * load (the VM's speed drifts by tens of per cent within minutes).
 * @param {string} slug
 * @param {number} decoders
 * @param {any} m the manifest
 * @returns {Promise<Map<string, Load>>}
 */
async function measure(slug, decoders, m) {
  await load(slug, decoders, m.last_level, antialiasModes[0]); // warm-up: the service's caches, Chromium's compile cache
  /** @type {Map<string, Load[]>} */
  const results = new Map(antialiasModes.map((a) => [a, []]));
  for (let r = 0; r < runs; r++) {
    for (const antialias of antialiasModes) {
      const x = await load(slug, decoders, m.last_level, antialias);
      console.error(`${slug}, ${decoders} decoders, antialias ${antialias}: first ${x.first.toFixed(0)} ms, last decoded ${x.decoded.toFixed(0)} ms, last ${x.last.toFixed(0)} ms, decode ${x.decode.toFixed(0)} ms`);
      results.get(antialias)?.push(x);
    }
  }
  /** @type {Map<string, Load>} */
  const medians = new Map();
  for (const [antialias, xs] of results) {
    medians.set(antialias, {
      first: median(xs.map((x) => x.first)),
      decoded: median(xs.map((x) => x.decoded)),
      last: median(xs.map((x) => x.last)),
      decode: median(xs.map((x) => x.decode)),
      vertices: xs[0].vertices,
    });
  }
  return medians;
}

console.log(`# ${new Date().toISOString()}, ${cpus().length} cores, load ${loadavg().map((x) => x.toFixed(2)).join(' ')}; median of ${runs} cold loads`);
console.log(`# plain: ${plain.last_level} batches, ${plain.levels.at(-1).vertices} vertices; charted: ${charted.last_level} batches`);
const ms = (/** @type {number} */ x) => `${x.toFixed(0)} ms`;
/** @type {string[]} */
const rows = [];
const bases = await measure('plain', 1, plain);
for (const [antialias, base] of bases) {
  rows.push(`| ${antialias} | format 4 | 1 | ${ms(base.first)} | ${ms(base.decoded)} | ${ms(base.last)} | ${ms(base.decode)} | 1.00 | 1.00 |`);
}
for (const w of workers) {
  for (const [antialias, r] of await measure('charted', w, charted)) {
    const base = /** @type {Load} */ (bases.get(antialias));
    if (r.vertices !== base.vertices) throw new Error(`charted: ${r.vertices} vertices, plain ${base.vertices}`);
    rows.push(`| ${antialias} | format 5 | ${w} | ${ms(r.first)} | ${ms(r.decoded)} | ${ms(r.last)} | ${ms(r.decode)} | ${(r.decoded / base.decoded).toFixed(2)} | ${(r.last / base.last).toFixed(2)} |`);
  }
}
console.log('| antialias | stream | decode workers | first level | last level decoded | last level drawn | decode (wall) | decoded / plain | drawn / plain |');
console.log('|---|---|---:|---:|---:|---:|---:|---:|---:|');
rows.sort((a, b) => antialiasModes.indexOf(a.split(' | ')[0].slice(2)) - antialiasModes.indexOf(b.split(' | ')[0].slice(2)));
for (const row of rows) console.log(row);
await browser.close();
await service.stop();
