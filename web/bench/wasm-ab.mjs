// @ts-check
// Two or more builds of the decoder's .wasm on the same streams, in one
// process, alternated round by round (A B C, B C A, …) so that a machine
// whose speed drifts slows every build alike: the WebAssembly counterpart of
// scripts/bench-ab.sh. Every level of each stream, decoded serially (a
// charted stream's charts in turn, as a viewer without workers does); prints
// each build's median, and refuses builds that decode a different final level.
// Last, each instance's linear memory: WebAssembly memory never shrinks, so
// it is the most any one decode of these streams needed (with the streams'
// input copies).
//   node bench/wasm-ab.mjs [--runs 9] BEFORE.wasm AFTER.wasm … STREAM.vtr …
// Keep a build aside with
//   cp ../target/wasm32-unknown-unknown/wasm/vitrine_wasm.wasm /tmp/before.wasm
import { readFileSync } from 'node:fs';
import { basename } from 'node:path';
import { parseArgs } from 'node:util';
import { VitrineCodec, splitStream } from '../src/codec.js';
import { median } from './machine.mjs';

const { values, positionals } = parseArgs({
  allowPositionals: true,
  options: { runs: { type: 'string', default: '9' } },
});
const wasms = positionals.filter((a) => a.endsWith('.wasm'));
const streams = positionals.filter((a) => !a.endsWith('.wasm'));
if (wasms.length < 2 || streams.length === 0) {
  console.error('usage: node bench/wasm-ab.mjs [--runs N] A.wasm B.wasm … STREAM.vtr …');
  process.exit(2);
}
const runs = Number(values.runs);
const codecs = await Promise.all(wasms.map((w) => VitrineCodec.instantiate(readFileSync(w))));

/**
 * Every level of `bytes` (what is timed); `check` reads the final level out
 * and returns its sizes and a checksum of its buffers.
 * @param {VitrineCodec} codec @param {Uint8Array} bytes @param {boolean} [check]
 */
function decode(codec, bytes, check = false) {
  const { base, batches } = splitStream(bytes);
  const decoder = codec.decoder(base);
  for (const batch of batches) decoder.apply(batch);
  let final = '';
  if (check) {
    const level = decoder.level();
    let sum = 0;
    for (const v of new Uint32Array(level.positions.buffer, level.positions.byteOffset, level.positions.length)) {
      sum = (sum * 31 + v) >>> 0;
    }
    for (const i of level.indices) sum = (sum * 31 + i) >>> 0;
    final = `${level.vertices} vertices, ${level.indices.length / 3} faces, sum ${sum}`;
  }
  decoder.free();
  return final;
}

console.log(`| stream | ${wasms.map((w) => basename(w)).join(' | ')} |`);
console.log(`|---|${wasms.map(() => '---:|').join('')}`);
for (const stream of streams) {
  const bytes = readFileSync(stream);
  const finals = codecs.map((codec) => decode(codec, bytes, true)); // also warms each up
  if (finals.some((f) => f !== finals[0])) throw new Error(`${stream}: builds disagree: ${finals.join(' / ')}`);
  /** @type {number[][]} */
  const times = codecs.map(() => []);
  for (let r = 0; r < runs; r++) {
    for (let k = 0; k < codecs.length; k++) {
      const i = (k + r) % codecs.length;
      const t0 = performance.now();
      decode(codecs[i], bytes);
      times[i].push(performance.now() - t0);
    }
  }
  console.log(`| ${basename(stream)} | ${times.map((t) => `${median(t).toFixed(1)} ms`).join(' | ')} |`);
}
const mib = (/** @type {VitrineCodec} */ codec) => (codec.exports.memory.buffer.byteLength / 2 ** 20).toFixed(0);
console.log(`| memory, the most | ${codecs.map((codec) => `${mib(codec)} MiB`).join(' | ')} |`);
