// @ts-check
// WebAssembly decode time of point streams whose attributes are coded
// against the parent (old) and predicted from the neighbourhood (new, header
// flag bit 2): every level, decoded by the viewer's .wasm as the splat worker
// does; the two interleaved run by run, medians. One process, one core.
//   cargo run --release -p vitrine-points --example point_attrs -- ../shared/data/meshes --write DIR
//   cargo build -p vitrine-wasm --target wasm32-unknown-unknown --release
//   VITRINE_WASM=target/wasm32-unknown-unknown/release/vitrine_wasm.wasm \
//     node web/bench/points-attrs-decode.mjs DIR/lucy-300000-12 …   (reads STEM-old.vpts, STEM-new.vpts)
import { readFileSync } from 'node:fs';
import { parseArgs } from 'node:util';
import { VitrineCodec } from '../src/codec.js';
import { PointStream, splitHeader, splitLevels } from '../src/splats/point-stream.js';
import { wasmPath } from '../test/support/fixtures.mjs';

const { values, positionals } = parseArgs({
  allowPositionals: true,
  options: { runs: { type: 'string', default: '11' } },
});
if (positionals.length === 0) {
  console.error('usage: node bench/points-attrs-decode.mjs [--runs N] STEM…');
  process.exit(2);
}
const runs = Number(values.runs);
const codec = await VitrineCodec.instantiate(readFileSync(wasmPath));

/** Every level of a VPTS stream; the point count. @param {Uint8Array} bytes */
function decodeVpts(bytes) {
  const levels = splitLevels(bytes);
  const { header, chunk } = splitHeader(levels[0]);
  const stream = new PointStream(codec, header);
  stream.apply(chunk);
  for (const level of levels.slice(1)) stream.apply(level);
  const n = stream.count;
  stream.free();
  return n;
}

/** @param {number[]} t */
const median = (t) => t.sort((a, b) => a - b)[t.length >> 1];

console.log('| stream | points | old bytes, ms | new bytes, ms | new / old time |');
console.log('|---|---|---|---|---:|');
for (const stem of positionals) {
  const old = new Uint8Array(readFileSync(`${stem}-old.vpts`));
  const neu = new Uint8Array(readFileSync(`${stem}-new.vpts`));
  /** @type {number[][]} */
  const times = [[], []];
  let n = 0;
  for (let r = 0; r < runs; r++) {
    for (const [k, bytes] of [old, neu].entries()) {
      const t0 = performance.now();
      n = decodeVpts(bytes);
      times[k].push(performance.now() - t0);
    }
  }
  const [a, b] = times.map(median);
  console.log(
    `| ${stem.split('/').pop()} | ${n} | ${old.length}, ${a.toFixed(1)} | ${neu.length}, ${b.toFixed(1)} | ${(b / a).toFixed(2)} |`,
  );
}
