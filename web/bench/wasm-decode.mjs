// @ts-check
// WebAssembly decode speed in Node: every level of a ~1 M-vertex coloured
// torus written by the Rust encoder, decoded by the same .wasm the browser
// loads. Prints a markdown table row.
// With --per-level, also what the progressive decode worker does per level
// besides decoder_apply (reconstruction.js #postLevel): normals (now derived
// by the render worker when there is one), the copies out of WASM memory.
//   node bench/wasm-decode.mjs [--kilo-vertices 1000] [--runs 5] [--per-level]
import { readFileSync } from 'node:fs';
import { parseArgs } from 'node:util';
import { VitrineCodec, splitStream } from '../src/codec.js';
import { vertexNormals } from '../src/geometry.js';
import { encodedSample, wasmPath } from '../test/support/fixtures.mjs';

const { values } = parseArgs({
  options: {
    'kilo-vertices': { type: 'string', default: '1000' },
    runs: { type: 'string', default: '5' },
    'per-level': { type: 'boolean', default: false },
  },
});
const kilo = Number(values['kilo-vertices']);
const runs = Number(values.runs);

const started = performance.now();
const { stream } = encodedSample('torus', ['--kilo-vertices', String(kilo), '--colour']);
console.error(`encoded ${kilo}k-vertex torus in ${((performance.now() - started) / 1000).toFixed(1)} s: ${stream.length} bytes`);
const { base, batches } = splitStream(stream);
const codec = await VitrineCodec.instantiate(readFileSync(wasmPath));

/** @param {boolean} everyLevel copy each level out (and compute its normals), as the progressive viewer does */
function run(everyLevel) {
  const t0 = performance.now();
  let normalsMs = 0;
  const decoder = codec.decoder(base);
  let level = decoder.level();
  for (const batch of batches) {
    decoder.apply(batch);
    if (everyLevel) {
      level = decoder.level();
      const t = performance.now();
      vertexNormals(level.positions, level.indices);
      normalsMs += performance.now() - t;
    }
  }
  if (!everyLevel) level = decoder.level();
  const ms = performance.now() - t0 - normalsMs;
  decoder.free();
  return { ms, normalsMs, vertices: level.vertices };
}

/** @param {number[]} xs */
const median = (xs) => [...xs].sort((a, b) => a - b)[Math.floor(xs.length / 2)];
run(false); // warm-up (JIT of the wasm's tiers)
const direct = Array.from({ length: runs }, () => run(false));
const each = Array.from({ length: runs }, () => run(true));
const vertices = direct[0].vertices;
const ms = median(direct.map((r) => r.ms));
const eachMs = median(each.map((r) => r.ms));
const normalsMs = median(each.map((r) => r.normalsMs));
console.log(`| levels | final vertices | stream bytes | decode, all levels (median of ${runs}) | vertices/s | with every level copied out | + normals of every level |`);
console.log('|---|---|---|---|---|---|---|');
console.log(
  `| ${batches.length + 1} | ${vertices.toLocaleString('en')} | ${stream.length.toLocaleString('en')} | ${ms.toFixed(0)} ms | ` +
    `${(vertices / (ms / 1000) / 1e6).toFixed(2)} M | ${eachMs.toFixed(0)} ms | ${normalsMs.toFixed(0)} ms |`,
);
console.error(`node ${process.version}`);

if (values['per-level']) {
  /** @type {Record<string, number[]>[]} */
  const rows = [];
  for (let r = 0; r < runs; r++) {
    const decoder = codec.decoder(base);
    let sent = 0;
    for (let k = 0; k <= batches.length; k++) {
      const row = (rows[k] ??= { apply: [], normals: [], vertexCopies: [], indexCopy: [] });
      let t = performance.now();
      if (k > 0) decoder.apply(batches[k - 1]);
      row.apply.push(performance.now() - t);
      const view = decoder.view();
      t = performance.now();
      vertexNormals(view.positions, view.indices);
      row.normals.push(performance.now() - t);
      t = performance.now();
      view.positions.slice(3 * sent);
      view.colours?.slice(3 * sent);
      row.vertexCopies.push(performance.now() - t);
      t = performance.now();
      view.indices.slice();
      row.indexCopy.push(performance.now() - t);
      sent = view.vertices;
      Object.assign(row, { vertices: [view.vertices], faces: [view.indices.length / 3] });
    }
    decoder.free();
  }
  const ms = (/** @type {number[]} */ xs) => `${median(xs).toFixed(1)} ms`;
  console.log(`\nPer level (median of ${runs}):\n`);
  console.log('| level | vertices | triangles | decoder_apply | normals | new positions + colours copied | indices copied |');
  console.log('|---|---|---|---|---|---|---|');
  rows.forEach((row, k) =>
    console.log(
      `| ${k} | ${row.vertices[0].toLocaleString('en')} | ${row.faces[0].toLocaleString('en')} | ${k === 0 ? '–' : ms(row.apply)} | ` +
        `${ms(row.normals)} | ${ms(row.vertexCopies)} | ${ms(row.indexCopy)} |`,
    ),
  );
}
