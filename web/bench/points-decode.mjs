// @ts-check
// Point-stream decode speed in Node against Google's draco3d: the same
// points as a VPTS stream (every level, decoded by the viewer's .wasm, as
// the splat worker does) and as a Draco point cloud (kd-tree) decoded by
// draco3d's WebAssembly decoder. Median of --runs, one process, one core.
// The files come from the Rust example and DracoPy (same points, same bits):
//   cargo run --release -p vitrine-points --example stream_size -- 12 --write DIR scan.ply …
//   python3 scripts/peer_draco_points.py 12 DIR                  (DIR/scan.drc)
//   npm install --prefix /tmp/draco3d draco3d
//   node bench/points-decode.mjs --draco3d /tmp/draco3d/node_modules/draco3d DIR/scan …
import { readFileSync } from 'node:fs';
import { createRequire } from 'node:module';
import { join } from 'node:path';
import { parseArgs } from 'node:util';
import { VitrineCodec } from '../src/codec.js';
import { PointStream, splitHeader, splitLevels } from '../src/splats/point-stream.js';
import { wasmPath } from '../test/support/fixtures.mjs';

const { values, positionals } = parseArgs({
  allowPositionals: true,
  options: {
    draco3d: { type: 'string' },
    runs: { type: 'string', default: '5' },
  },
});
if (!values.draco3d || positionals.length === 0) {
  console.error('usage: node bench/points-decode.mjs --draco3d DIR FILE_STEM…');
  process.exit(2);
}
const runs = Number(values.runs);
const require = createRequire(import.meta.url);
const draco3d = require(join(values.draco3d, 'draco3d.js'));
const dracoModule = await draco3d.createDecoderModule({});
const codec = await VitrineCodec.instantiate(readFileSync(wasmPath));

/** @param {() => number} f @returns {{ ms: number, n: number }} */
function median(f) {
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

/** A Draco point cloud, positions read out as float32; the point count. @param {Uint8Array} bytes */
function decodeDraco(bytes) {
  const m = dracoModule;
  const decoder = new m.Decoder();
  const buffer = new m.DecoderBuffer();
  buffer.Init(new Int8Array(bytes.buffer, bytes.byteOffset, bytes.byteLength), bytes.byteLength);
  const cloud = new m.PointCloud();
  const status = decoder.DecodeBufferToPointCloud(buffer, cloud);
  if (!status.ok()) throw new Error(`draco3d: ${status.error_msg()}`);
  const n = cloud.num_points();
  const attribute = decoder.GetAttribute(cloud, decoder.GetAttributeId(cloud, m.POSITION));
  const floats = n * 3;
  const ptr = m._malloc(floats * 4);
  decoder.GetAttributeDataArrayForAllPoints(cloud, attribute, m.DT_FLOAT32, floats * 4, ptr);
  const out = new Float32Array(m.HEAPF32.buffer, ptr, floats).slice();
  m._free(ptr);
  m.destroy(cloud);
  m.destroy(buffer);
  m.destroy(decoder);
  return out.length / 3;
}

console.log('| points | file | ours: VPTS bytes, every level, ms | draco3d: bytes, ms | ours / draco3d |');
console.log('|---|---|---|---|---:|');
for (const stem of positionals) {
  const vpts = new Uint8Array(readFileSync(`${stem}.vpts`));
  const drc = new Uint8Array(readFileSync(`${stem}.drc`));
  const ours = median(() => decodeVpts(vpts));
  const peer = median(() => decodeDraco(drc));
  if (ours.n !== peer.n) console.error(`${stem}: ${ours.n} points decoded against draco3d's ${peer.n}`);
  console.log(
    `| ${ours.n} | ${stem.split('/').pop()} | ${vpts.length}, ${ours.ms.toFixed(1)} | ${drc.length}, ${peer.ms.toFixed(1)} | ${(ours.ms / peer.ms).toFixed(2)} |`,
  );
}
