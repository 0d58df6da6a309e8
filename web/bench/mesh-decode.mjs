// @ts-check
// Mesh decode speed in Node against Google's draco3d: every level of a
// plain stream (format 4) and of a charted one (format 5) by the viewer's
// .wasm — its charts decoded in turn as a viewer without workers does, and
// by the viewer's decode pool (src/decode-pool.js) of 2 and 4 workers, the
// helpers on worker threads — and the same mesh as a single-rate Draco mesh
// (Edgebreaker, positions only, 12 bits) decoded by draco3d's WebAssembly
// decoder on one thread, positions and indices read out. Median of --runs,
// one process. The files come from scripts/bench-charts.sh (STEM.vtr,
// STEM.v5.vtr, STEM.drc):
//   node bench/mesh-decode.mjs --draco3d /tmp/draco3d/node_modules/draco3d [--workers 2,4] DIR/igea …
// `--members 2,4` also times, for each pool size, every member's share of
// the charts decoded alone on this thread (the global layers, the cut and
// its charts, as a pool member decodes them): the slowest is that pool's
// critical path on a machine with a core per member, before merging and
// messages (which the pool rows above include).
import { existsSync, readFileSync } from 'node:fs';
import { createRequire } from 'node:module';
import { basename, join } from 'node:path';
import { parseArgs } from 'node:util';
import { Worker } from 'node:worker_threads';
import { PARTED_TAG, VitrineCodec, splitStream } from '../src/codec.js';
import { PooledDecoder, shareCharts } from '../src/decode-pool.js';
import { wasmPath } from '../test/support/fixtures.mjs';

const { values, positionals } = parseArgs({
  allowPositionals: true,
  options: {
    draco3d: { type: 'string' },
    runs: { type: 'string', default: '5' },
    workers: { type: 'string', default: '2,4' },
    members: { type: 'string', default: '' },
  },
});
if (!values.draco3d || positionals.length === 0) {
  console.error('usage: node bench/mesh-decode.mjs --draco3d DIR FILE_STEM…');
  process.exit(2);
}
const runs = Number(values.runs);
const require = createRequire(import.meta.url);
const draco3d = require(join(values.draco3d, 'draco3d.js'));
const dracoModule = await draco3d.createDecoderModule({});
const codec = await VitrineCodec.instantiate(readFileSync(wasmPath));
const pools = values.workers
  .split(',')
  .filter(Boolean)
  .map(Number)
  .filter((n) => n >= 2);
/** Helper threads, started once: the most any pool needs. */
const threads = Array.from(
  { length: Math.max(1, ...pools) - 1 },
  () => new Worker(new URL('./chart-worker-node.mjs', import.meta.url), { workerData: { wasm: wasmPath } }),
);
/** @type {import('../src/decode-pool.js').HelperPort[]} */
const ports = threads.map((thread) => {
  /** @type {import('../src/decode-pool.js').HelperPort} */
  const port = {
    onmessage: null,
    postMessage: (message, transfer) => thread.postMessage(message, /** @type {any} */ (transfer)),
  };
  thread.on('message', (data) => port.onmessage?.(new MessageEvent('message', { data })));
  return port;
});

/** @param {() => Promise<number>} f @returns {Promise<{ ms: number, n: number }>} */
async function medianAsync(f) {
  await f();
  let n = 0;
  const times = [];
  for (let r = 0; r < runs; r++) {
    const t0 = performance.now();
    n = await f();
    times.push(performance.now() - t0);
  }
  times.sort((a, b) => a - b);
  return { ms: times[times.length >> 1], n };
}

/**
 * Every level of a charted stream by a pool of `members` (this thread and
 * helper threads); the final vertex count.
 * @param {Uint8Array} bytes
 * @param {number} members
 */
async function decodePooled(bytes, members) {
  const { base, batches } = splitStream(bytes);
  const pool = new PooledDecoder(codec, base, ports.slice(0, members - 1));
  for (const batch of batches) await pool.apply(batch);
  const n = pool.view().vertices;
  pool.free();
  return n;
}

/**
 * Every level of a charted stream as one pool member decodes it: the charts
 * in `share` only, from the first parted batch on.
 * @param {Uint8Array} bytes
 * @param {number[]} share
 */
function decodeMember(bytes, share) {
  const { base, batches } = splitStream(bytes);
  const decoder = codec.decoder(base);
  let shared = false;
  for (const batch of batches) {
    if (!shared && batch[0] === PARTED_TAG) {
      decoder.refineOnly(share);
      shared = true;
    }
    decoder.apply(batch);
  }
  const n = decoder.chartCount();
  decoder.free();
  return n;
}

/**
 * How `members` members share a charted stream's charts (decode-pool.js's
 * rule, from the first parted batch's chart sizes).
 * @param {Uint8Array} bytes
 * @param {number} members
 */
function memberShares(bytes, members) {
  const { base, batches } = splitStream(bytes);
  const decoder = codec.decoder(base);
  /** @type {number[]} */
  let sizes = [];
  for (const batch of batches) {
    if (batch[0] === PARTED_TAG) {
      sizes = decoder.chartSizes(batch);
      break;
    }
    decoder.apply(batch);
  }
  decoder.free();
  return shareCharts(sizes, members);
}

/** @param {() => number} f @returns {{ ms: number, n: number }} */
function median(f) {
  f(); // warm-up (the wasm's tiers)
  let n = 0;
  const times = [];
  for (let r = 0; r < runs; r++) {
    const t0 = performance.now();
    n = f();
    times.push(performance.now() - t0);
  }
  times.sort((a, b) => a - b);
  return { ms: times[times.length >> 1], n };
}

/** Every level of a stream; the final vertex count. @param {Uint8Array} bytes */
function decodeVtr(bytes) {
  const { base, batches } = splitStream(bytes);
  const decoder = codec.decoder(base);
  for (const batch of batches) decoder.apply(batch);
  const n = decoder.level().vertices;
  decoder.free();
  return n;
}

/** A Draco mesh, positions (float32) and indices read out; the vertex count. @param {Uint8Array} bytes */
function decodeDraco(bytes) {
  const m = dracoModule;
  const decoder = new m.Decoder();
  const buffer = new m.DecoderBuffer();
  buffer.Init(new Int8Array(bytes.buffer, bytes.byteOffset, bytes.byteLength), bytes.byteLength);
  const mesh = new m.Mesh();
  const status = decoder.DecodeBufferToMesh(buffer, mesh);
  if (!status.ok()) throw new Error(`draco3d: ${status.error_msg()}`);
  const n = mesh.num_points();
  const attribute = decoder.GetAttribute(mesh, decoder.GetAttributeId(mesh, m.POSITION));
  const floats = n * 3;
  const ptr = m._malloc(floats * 4);
  decoder.GetAttributeDataArrayForAllPoints(mesh, attribute, m.DT_FLOAT32, floats * 4, ptr);
  const positions = new Float32Array(m.HEAPF32.buffer, ptr, floats).slice();
  m._free(ptr);
  const indexBytes = mesh.num_faces() * 12;
  const iptr = m._malloc(indexBytes);
  decoder.GetTrianglesUInt32Array(mesh, indexBytes, iptr);
  const indices = new Uint32Array(m.HEAPU32.buffer, iptr, indexBytes / 4).slice();
  m._free(iptr);
  const faces = mesh.num_faces();
  m.destroy(mesh);
  m.destroy(buffer);
  m.destroy(decoder);
  if (positions.length !== 3 * n || indices.length !== 3 * faces) throw new Error('draco3d: short read');
  return n;
}

const poolHeads = pools.map((w) => `format 5, ${w} workers`);
console.log(
  `| mesh | vertices | format 4, wasm | format 5, wasm, 1 worker | ${poolHeads.join(' | ')} | draco3d | format 4 / draco3d | ${pools.map((w) => `${w} workers / draco3d`).join(' | ')} | format 4 / format 5 (1 worker) | ${pools.map((w) => `format 4 / ${w} workers`).join(' | ')} |`,
);
console.log(`|---|---:|---:|---:|${pools.map(() => '---:|').join('')}---:|---:|${pools.map(() => '---:|').join('')}---:|${pools.map(() => '---:|').join('')}`);
for (const stem of positionals) {
  const [vtr, drc] = [readFileSync(`${stem}.vtr`), readFileSync(`${stem}.drc`)];
  const v5 = existsSync(`${stem}.v5.vtr`) ? readFileSync(`${stem}.v5.vtr`) : null;
  const plain = median(() => decodeVtr(vtr));
  const charted = v5 ? median(() => decodeVtr(v5)) : null;
  /** @type {Array<{ ms: number, n: number } | null>} */
  const pooled = [];
  for (const w of pools) {
    const result = v5 ? await medianAsync(() => decodePooled(v5, w)) : null;
    if (result && charted && result.n !== charted.n) throw new Error(`${w} workers decoded ${result.n} vertices, one ${charted.n}`);
    pooled.push(result);
  }
  const draco = median(() => decodeDraco(drc));
  const ms = (/** @type {number} */ x) => `${x.toFixed(1)} ms`;
  const cells = (/** @type {(r: { ms: number }) => string} */ f) => pooled.map((r) => (r ? f(r) : '–')).join(' | ');
  console.log(
    `| ${basename(stem)} | ${plain.n} | ${ms(plain.ms)} | ${charted ? ms(charted.ms) : '–'} | ${cells((r) => ms(r.ms))} | ${ms(draco.ms)} | ${(plain.ms / draco.ms).toFixed(2)} | ${cells((r) => (r.ms / draco.ms).toFixed(2))} | ${charted ? (plain.ms / charted.ms).toFixed(2) : '–'} | ${cells((r) => (plain.ms / r.ms).toFixed(2))} |`,
  );
}
const memberCounts = values.members.split(',').filter(Boolean).map(Number);
if (memberCounts.length > 0) {
  console.log();
  console.log('| mesh | members | charts per member | each member alone | slowest (critical path) | draco3d | critical path / draco3d |');
  console.log('|---|---:|---|---|---:|---:|---:|');
  for (const stem of positionals) {
    if (!existsSync(`${stem}.v5.vtr`)) continue;
    const v5 = readFileSync(`${stem}.v5.vtr`);
    const drc = readFileSync(`${stem}.drc`);
    const draco = median(() => decodeDraco(drc));
    for (const members of memberCounts) {
      const shares = memberShares(v5, members).filter((share) => share.length > 0);
      const alone = shares.map((share) => median(() => decodeMember(v5, share)).ms);
      const slowest = Math.max(...alone);
      console.log(
        `| ${basename(stem)} | ${members} | ${shares.map((share) => share.join('+')).join(', ')} | ${alone.map((ms) => ms.toFixed(1)).join(', ')} ms | ${slowest.toFixed(1)} ms | ${draco.ms.toFixed(1)} ms | ${(slowest / draco.ms).toFixed(2)} |`,
      );
    }
  }
}
for (const thread of threads) await thread.terminate();
