// @ts-check
// What each level of a point stream costs the browser (issue 42): the
// splat worker decodes a level, then runs the whole splat preprocessing
// (radii, neighbour graph, surface ids, clip partners; normals estimated
// when the stream has none) on every point decoded so far. This times both,
// level by level, with the viewer's .wasm in one Node process (one core),
// median of --runs, and prints the preprocessing's sum over the levels
// against the last level's alone: what preprocessing once would save.
//   cargo run --release -p vitrine-points --example point_depths -- MESH 300000 14 1 --ingest-stream /tmp/cloud.vpts
//   node bench/splat-levels.mjs [--runs 5] /tmp/cloud.vpts
import { readFileSync } from 'node:fs';
import { parseArgs } from 'node:util';
import { VitrineCodec } from '../src/codec.js';
import { PointStream, splitHeader, splitLevels } from '../src/splats/point-stream.js';
import { wasmPath } from '../test/support/fixtures.mjs';

const { values, positionals } = parseArgs({
  allowPositionals: true,
  options: { runs: { type: 'string', default: '5' } },
});
if (positionals.length !== 1) {
  console.error('usage: node bench/splat-levels.mjs [--runs N] STREAM.vpts');
  process.exit(2);
}
const runs = Number(values.runs);
const codec = await VitrineCodec.instantiate(readFileSync(wasmPath));
const levels = splitLevels(new Uint8Array(readFileSync(positionals[0])));

/** @type {{ points: number, decode: number[], splats: number[] }[]} */
const rows = levels.map(() => ({ points: 0, decode: [], splats: [] }));
for (let r = 0; r < runs; r++) {
  const { header, chunk } = splitHeader(levels[0]);
  const stream = new PointStream(codec, header);
  levels.forEach((level, k) => {
    let t = performance.now();
    stream.apply(k === 0 ? chunk : level);
    rows[k].decode.push(performance.now() - t);
    t = performance.now();
    stream.splats();
    rows[k].splats.push(performance.now() - t);
    rows[k].points = stream.count;
  });
  stream.free();
}

/** @param {number[]} v */
const median = (v) => [...v].sort((a, b) => a - b)[v.length >> 1];
console.log('level\tpoints\tdecode_ms\tsplats_ms\tsplats_us_per_point');
let sum = 0;
rows.forEach((row, k) => {
  const s = median(row.splats);
  sum += s;
  console.log(`${k}\t${row.points}\t${median(row.decode).toFixed(1)}\t${s.toFixed(1)}\t${((s * 1000) / row.points).toFixed(2)}`);
});
const last = median(rows[rows.length - 1].splats);
console.log(`preprocessing over all levels ${sum.toFixed(0)} ms, the last level alone ${last.toFixed(0)} ms (${(sum / last).toFixed(2)}×)`);
