// @ts-check
// The decode pool (src/decode-pool.js): a charted stream decoded by 2–4
// members gives every level byte for byte as the native decoder does (the
// fixture's hashes); charts are shared out fairly; damage in a helper's
// chart or in the batch is an error, never a wrong level. The helpers run
// in-process here (the Node bench and the browser test run them on threads).
import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';
import test from 'node:test';
import { ChartHelper } from '../src/chart-helper.js';
import { DecodeError, PARTED_TAG, VitrineCodec, splitStream } from '../src/codec.js';
import { PooledDecoder, RESERVE_AHEAD, shareCharts } from '../src/decode-pool.js';
import { Reconstruction } from '../src/reconstruction.js';
import { fixture, sha256, wasmPath } from './support/fixtures.mjs';

const wasm = readFileSync(wasmPath);
const charted = fixture('charted-torus');

/**
 * `n` helpers, each with its own instance of the codec, answering on a
 * later task as a worker would; a reply is cloned, as postMessage does.
 * @param {number} n
 * @returns {Promise<import('../src/decode-pool.js').HelperPort[]>}
 */
async function helpers(n) {
  const ports = [];
  for (let i = 0; i < n; i++) {
    const helper = new ChartHelper(await VitrineCodec.instantiate(wasm));
    /** @type {import('../src/decode-pool.js').HelperPort} */
    const port = {
      onmessage: null,
      postMessage(command) {
        const copy = structuredClone(command);
        setImmediate(() => {
          const { reply } = helper.handle(copy);
          port.onmessage?.(new MessageEvent('message', { data: structuredClone(reply) }));
        });
      },
    };
    ports.push(port);
  }
  return ports;
}

/** @param {import('../src/codec.js').Level} level */
function digest(level) {
  return {
    vertices: level.vertices,
    positions: sha256(level.positions),
    indices: sha256(level.indices),
    colours: level.colours && sha256(level.colours),
  };
}

test('a charted stream decoded by a pool of 2, 3 or 4 gives the native levels', async () => {
  const { base, batches } = splitStream(charted.stream);
  assert.ok(batches.some((b) => b[0] === PARTED_TAG), 'the fixture has parted batches');
  for (const members of [2, 3, 4]) {
    const codec = await VitrineCodec.instantiate(wasm);
    const pool = new PooledDecoder(codec, base, await helpers(members - 1));
    assert.equal(pool.members, members);
    for (const [k, batch] of batches.entries()) {
      await pool.apply(batch);
      const want = charted.levels[k + 1];
      assert.deepEqual(
        digest(pool.view()),
        { vertices: want.vertices, positions: want.positions, indices: want.indices, colours: want.colours },
        `${members} members, level ${k + 1}`,
      );
    }
    const shares = /** @type {number[][]} */ (pool.shares);
    assert.deepEqual(shares.flat().sort((a, b) => a - b), [0, 1, 2, 3], 'every chart goes to one member');
    assert.ok(shares.every((s) => s.length > 0), `${members} members all have charts: ${JSON.stringify(shares)}`);
    assert.ok(pool.sizes && pool.sizes.length === 4, 'the chart sizes read before the first parted batch');
    // A copy is not a view: it stays as it is after the pool is freed.
    const last = pool.level();
    pool.free();
    assert.equal(sha256(last.indices), charted.levels[batches.length].indices);
  }
});

test('charts are shared out largest first, each to the least loaded member, helpers first on a tie', () => {
  // 10 and 9 open the two shares (10 to the helper); the ones go to
  // whichever is lighter, the helper on a tie.
  assert.deepEqual(shareCharts([10, 1, 1, 1, 9], 2), [[1, 3, 4], [0, 2]]);
  // Five equal charts on four members: a helper gets two.
  assert.deepEqual(shareCharts([5, 5, 5, 5, 5], 4), [[3], [0, 4], [1], [2]]);
  // More members than charts: the decode worker goes without.
  assert.deepEqual(shareCharts([3, 7], 3), [[], [1], [0]]);
});

test('a header claiming 50 M vertices in its last level: the pool reserves only what the batches verify', async () => {
  const { base, batches } = splitStream(charted.stream);
  // The level table (codec/core/FORMAT.md): 12 bytes a level from byte 28,
  // vertices then faces; the last level claims the decoder's default limit.
  const hostile = base.slice();
  const table = new DataView(hostile.buffer, hostile.byteOffset, hostile.byteLength);
  const at = 28 + 12 * batches.length;
  const [before, facesBefore] = [table.getUint32(at - 12, true), table.getUint32(at - 8, true)];
  const claimed = 50_000_000;
  table.setUint32(at, claimed, true);
  table.setUint32(at + 4, facesBefore + 2 * (claimed - before), true);
  const codec = await VitrineCodec.instantiate(wasm);
  const pool = new PooledDecoder(codec, hostile, await helpers(1));
  let merged = 0;
  for (const [k, batch] of batches.slice(0, -1).entries()) {
    await pool.apply(batch);
    const level = pool.view();
    assert.equal(sha256(level.indices), charted.levels[k + 1].indices, `level ${k + 1}`);
    if (batch[0] !== PARTED_TAG) continue;
    merged++;
    // The merged level's arrays, not the decoder's memory, once the charts are shared.
    assert.ok(
      level.positions.buffer.byteLength <= RESERVE_AHEAD * 12 * level.vertices,
      `level ${k + 1}: ${level.positions.buffer.byteLength} bytes for ${level.vertices} vertices`,
    );
  }
  assert.ok(merged >= 1, 'the pool merged a level');
  const memory = /** @type {WebAssembly.Memory} */ (codec.exports.memory).buffer.byteLength;
  assert.ok(memory < 64 << 20, `the decoder's memory: ${memory} bytes`);
  await assert.rejects(pool.apply(/** @type {Uint8Array} */ (batches.at(-1))), DecodeError);
  pool.free();
});

test('damage in a chart a helper refines fails the batch with a decode error', async () => {
  const { base, batches } = splitStream(charted.stream);
  const k = batches.findIndex((b) => b[0] === PARTED_TAG);
  let refused = 0;
  // Flip bytes across the whole first parted batch: each one is an error
  // (from this member, a helper, or the merge) or, where the coder happens
  // to read a valid level, a level of the right counts; never a hang.
  const batch = batches[k];
  for (let at = 12; at < batch.length; at += Math.ceil(batch.length / 23)) {
    const pool = new PooledDecoder(await VitrineCodec.instantiate(wasm), base, await helpers(2));
    for (const b of batches.slice(0, k)) await pool.apply(b);
    const bad = batch.slice();
    bad[at] ^= 0x5a;
    try {
      await pool.apply(bad);
      assert.equal(pool.view().vertices, charted.levels[k + 1].vertices);
    } catch (error) {
      assert.ok(error instanceof DecodeError, `byte ${at}: ${error}`);
      refused++;
    }
    pool.free();
  }
  assert.ok(refused > 0, 'some damage is refused');
});

test('the decode worker refines a charted stream with its helpers: every level posted is the native one', async () => {
  const { base, batches } = splitStream(charted.stream);
  /** @type {typeof fetch} */
  const fetchImpl = async (input) => {
    const url = String(input);
    return new Response(/** @type {BodyInit} */ (url.endsWith('/base') ? base : batches[Number(url.split('/').pop()) - 1]));
  };
  /** @type {import('../src/reconstruction.js').LevelMessage[]} */
  const posted = [];
  /** @type {{ resolve: (value: unknown) => void, reject: (error: Error) => void }} */
  const done = { resolve: () => {}, reject: () => {} };
  const finished = new Promise((resolve, reject) => Object.assign(done, { resolve, reject }));
  const job = new Reconstruction(
    await VitrineCodec.instantiate(wasm),
    {
      baseUrl: 'http://test/base',
      batchUrls: batches.map((_, k) => `http://test/batches/${k + 1}`),
      upTo: batches.length,
      show: 'each',
      wireframe: true,
    },
    (message) => {
      if (message.type === 'level') posted.push(message);
      if (message.type === 'done') done.resolve(undefined);
      if (message.type === 'error') done.reject(new Error(message.message));
    },
    fetchImpl,
    await helpers(2),
  );
  void job.run();
  await finished;
  assert.deepEqual(posted.map((l) => l.level), [...Array(batches.length + 1).keys()]);
  // Positions and colours arrive once (from firstVertex on): put them together.
  let positions = new Float32Array(0);
  let colours = new Uint8Array(0);
  for (const level of posted) {
    positions = Float32Array.of(...positions, ...level.positions);
    colours = Uint8Array.of(...colours, ...(level.colours ?? []));
    const want = charted.levels[level.level];
    assert.equal(sha256(positions), want.positions, `level ${level.level}`);
    assert.equal(sha256(level.indices), want.indices, `level ${level.level}`);
    assert.equal(want.colours && sha256(colours), want.colours);
    assert.ok(level.edges && level.edges.length > 0, 'the wireframe reads the merged level');
  }
  assert.equal(posted[posted.length - 1].decoders, 3);
  job.cancel();
});
