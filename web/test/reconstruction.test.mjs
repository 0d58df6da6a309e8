// @ts-check
// The decode worker's reconstruction loop, in Node, on a stream written by the
// Rust encoder (the committed painted torus, test/fixtures), with a fake
// `fetch` that serves the stream split as the service serves it (base, then
// batch k at /batches/k).
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';
import { VitrineCodec, splitStream } from '../src/codec.js';
import { Reconstruction } from '../src/reconstruction.js';
import { normalDeviation, reliefTop } from '../src/relief.js';
import { fixture, wasmPath } from './support/fixtures.mjs';

const sample = fixture('painted-torus');
const parts = splitStream(sample.stream);
const last = parts.batches.length;
const module = new WebAssembly.Module(readFileSync(wasmPath));

/**
 * @typedef {{ status: number, body?: any, headers?: Record<string, string> }} Answer
 * @param {{ answer?: (k: number, attempt: number) => Answer | Uint8Array | null }} [options]
 *   k = 0 for the base; null: serve the real payload
 */
function service(options = {}) {
  /** @type {string[]} */
  const log = [];
  /** @type {Map<number, number>} */
  const attempts = new Map();
  /** @type {typeof fetch} */
  const fetchImpl = async (input) => {
    const url = String(input);
    const k = url.endsWith('/base') ? 0 : Number(url.split('/').pop());
    const attempt = (attempts.get(k) ?? 0) + 1;
    attempts.set(k, attempt);
    log.push(`fetch ${k}`);
    const special = options.answer?.(k, attempt) ?? null;
    if (special instanceof Uint8Array) return new Response(/** @type {BodyInit} */ (special));
    if (special) return new Response(JSON.stringify(special.body ?? {}), { status: special.status, headers: special.headers });
    return new Response(/** @type {BodyInit} */ (k === 0 ? parts.base : parts.batches[k - 1]));
  };
  return { log, fetchImpl };
}

/**
 * Runs a reconstruction until `until(messages)` holds.
 * @param {Partial<import('../src/reconstruction.js').LoadRequest>} request
 * @param {ReturnType<typeof service>} svc
 * @param {(messages: import('../src/reconstruction.js').WorkerMessage[]) => boolean} until
 */
async function reconstruct(request, svc, until) {
  const codec = await VitrineCodec.instantiate(module);
  /** @type {import('../src/reconstruction.js').WorkerMessage[]} */
  const messages = [];
  /** @type {() => void} */
  let check = () => {};
  const reached = new Promise((resolve) => (check = () => until(messages) && resolve(undefined)));
  const job = new Reconstruction(
    codec,
    {
      baseUrl: 'http://test/api/compressions/1/base',
      batchUrls: parts.batches.map((_, i) => `http://test/api/compressions/1/batches/${i + 1}`),
      upTo: last,
      show: 'each',
      wireframe: false,
      ...request,
    },
    (message) => {
      messages.push(message);
      if (message.type === 'level') svc.log.push(`level ${message.level}`);
      check();
    },
    svc.fetchImpl,
  );
  void job.run();
  await reached;
  return { job, messages, codec };
}

/** @param {import('../src/reconstruction.js').WorkerMessage[]} messages */
const levels = (messages) =>
  /** @type {import('../src/reconstruction.js').LevelMessage[]} */ (messages.filter((m) => m.type === 'level'));
/** @param {string} type */
const has = (type) => (/** @type {import('../src/reconstruction.js').WorkerMessage[]} */ m) => m.some((x) => x.type === type);

test('every level arrives in order, equal to a direct decode, with unit normals', async () => {
  const svc = service();
  const { messages, codec } = await reconstruct({}, svc, has('done'));
  const got = levels(messages);
  assert.deepEqual(got.map((l) => l.level), [...Array(last + 1).keys()]);
  const direct = codec.decoder(parts.base);
  // Vertices are sent once: each level carries those after the previous level's.
  let positions = new Float32Array(0);
  let colours = new Uint8Array(0);
  let sent = 0;
  for (const level of got) {
    if (level.level > 0) direct.apply(parts.batches[level.level - 1]);
    const expected = direct.level();
    assert.equal(level.firstVertex, sent, `level ${level.level} starts after the vertices already sent`);
    assert.equal(level.positions.length, 3 * (level.vertices - sent));
    positions = Float32Array.of(...positions, ...level.positions);
    colours = Uint8Array.of(...colours, ...(level.colours ?? []));
    sent = level.vertices;
    assert.deepEqual(positions, expected.positions);
    assert.deepEqual(level.indices, expected.indices);
    assert.deepEqual(colours, expected.colours);
    assert.ok(level.normals, `level ${level.level} carries its normals`);
    const normals = level.normals;
    assert.equal(normals.length, 3 * level.vertices);
    for (let i = 0; i < normals.length; i += 3) {
      const length = Math.hypot(normals[i], normals[i + 1], normals[i + 2]) / 32767;
      assert.ok(Math.abs(length - 1) < 1e-3, `normal ${i / 3} of level ${level.level} has length ${length}`);
    }
  }
  const total = [parts.base, ...parts.batches].reduce((s, p) => s + p.length, 0);
  assert.equal(got[last].received, total);
  assert.ok(got[last].decodeMs > 0);
});

test("normals: 'last' sends only the level it stops at with normals; 'always' every level from then on", async () => {
  const svc = service();
  const cap = 2;
  const { job, messages } = await reconstruct({ upTo: cap, normals: 'last' }, svc, has('done'));
  const sent = levels(messages);
  assert.deepEqual(sent.map((l) => l.level), [...Array(cap + 1).keys()]);
  for (const level of sent.slice(0, -1)) assert.equal(level.normals, null, `level ${level.level}`);
  assert.ok(sent.slice(0, -1).every((l) => l.deriveMs === 0), 'nothing derived in the decode worker before the last level');
  assert.equal(sent[cap].normals?.length, 3 * sent[cap].vertices, 'the level it stops at');
  job.setNormals('always');
  messages.length = 0;
  const done = new Promise((resolve) => {
    const post = job.post;
    job.post = (message, transfer) => {
      post(message, transfer);
      if (message.type === 'done') resolve(undefined);
    };
  });
  job.extend(cap + 2);
  await done;
  const next = levels(messages);
  assert.deepEqual(next.map((l) => l.level), [cap + 1, cap + 2]);
  for (const level of next) assert.equal(level.normals?.length, 3 * level.vertices, `level ${level.level}`);
  job.cancel();
});

test('batch k + 1 is requested before level k is decoded', async () => {
  const svc = service();
  await reconstruct({}, svc, has('done'));
  for (let k = 1; k < last; k++) {
    assert.ok(svc.log.indexOf(`fetch ${k + 1}`) < svc.log.indexOf(`level ${k}`), svc.log.join(', '));
  }
  // Nothing is fetched twice.
  assert.equal(svc.log.filter((e) => e.startsWith('fetch')).length, last + 1);
});

test('stops at the cap without fetching above it, resumes when extended', async () => {
  const svc = service();
  const cap = 3;
  const { job, messages } = await reconstruct({ upTo: cap }, svc, has('done'));
  assert.equal(Math.max(...levels(messages).map((l) => l.level)), cap);
  assert.ok(!svc.log.includes(`fetch ${cap + 1}`), svc.log.join(', '));
  const more = new Promise((resolve) => {
    const post = job.post;
    job.post = (m, t) => {
      post(m, t);
      if (m.type === 'level' && m.level === last) resolve(undefined);
    };
  });
  job.extend(last);
  await more;
  assert.deepEqual(levels(messages).map((l) => l.level), [...Array(last + 1).keys()]);
});

test('a batch refused by the server (cap fell) is reported and fetched again on resume', async () => {
  const svc = service({
    answer: (k, attempt) =>
      k === 4 && attempt === 1
        ? { status: 429, body: { error: 'level_capped', cap: 3, reason: 'load', retry_after_s: 7 }, headers: { 'retry-after': '7' } }
        : null,
  });
  const { job, messages } = await reconstruct({}, svc, has('capped'));
  const capped = messages.find((m) => m.type === 'capped');
  assert.deepEqual(capped, { type: 'capped', level: 3, status: 429, reason: 'load', retryAfterS: 7 });
  const resumed = new Promise((resolve) => {
    const post = job.post;
    job.post = (m, t) => {
      post(m, t);
      if (m.type === 'level' && m.level === last) resolve(undefined);
    };
  });
  job.extend(last);
  await resumed;
  assert.equal(svc.log.filter((e) => e === 'fetch 4').length, 2);
});

test('show: last posts only the level asked for', async () => {
  const { messages } = await reconstruct({ show: 'last', upTo: 5 }, service(), has('done'));
  assert.deepEqual(levels(messages).map((l) => l.level), [5]);
  // Whole: no level was sent before it.
  const [level] = levels(messages);
  assert.equal(level.firstVertex, 0);
  assert.equal(level.positions.length, 3 * level.vertices);
});

test('capacity: the requested vertex count reaches every level, for buffers sized once', async () => {
  const { messages } = await reconstruct({ capacity: 123_456 }, service(), has('done'));
  for (const level of levels(messages)) assert.equal(level.capacity, Math.max(123_456, level.vertices));
});

test('showFrom: a retry does not step back through levels already shown', async () => {
  const { messages } = await reconstruct({ showFrom: 3 }, service(), has('done'));
  assert.deepEqual(levels(messages).map((l) => l.level), [...Array(last + 1).keys()].slice(3));
});

test('a damaged batch becomes a decode error message', async () => {
  const truncated = parts.batches[1].subarray(0, parts.batches[1].length - 5);
  const svc = service({ answer: (k) => (k === 2 ? truncated : null) });
  const { messages } = await reconstruct({}, svc, has('error'));
  const error = messages.find((m) => m.type === 'error');
  assert.equal(error?.type === 'error' && error.kind, 'decode');
  assert.match(error?.type === 'error' ? error.message : '', /damaged/);
  assert.equal(Math.max(...levels(messages).map((l) => l.level)), 1);
});

test('HTTP and transport failures become network error messages', async () => {
  const http = await reconstruct({}, service({ answer: (k) => (k === 3 ? { status: 500 } : null) }), has('error'));
  assert.match(JSON.stringify(http.messages.find((m) => m.type === 'error')), /"network".*500 for the batch 3/);
  const down = service();
  const failing = down.fetchImpl;
  down.fetchImpl = async (input, init) => {
    if (String(input).endsWith('/2')) throw new TypeError('Failed to fetch');
    return failing(input, init);
  };
  const transport = await reconstruct({}, down, has('error'));
  assert.match(JSON.stringify(transport.messages.find((m) => m.type === 'error')), /"network".*Failed to fetch/);
});

test('a 503 with Retry-After on a payload is waited out and the load goes on', async () => {
  const svc = service({
    answer: (k, attempt) =>
      k === 2 && attempt <= 2 ? { status: 503, body: { error: 'database_unavailable', retry_after_s: 0 }, headers: { 'retry-after': '0' } } : null,
  });
  const { messages } = await reconstruct({}, svc, has('done'));
  assert.equal(messages.find((m) => m.type === 'error'), undefined);
  assert.equal(Math.max(...levels(messages).map((l) => l.level)), last);
  assert.equal(svc.log.filter((line) => line === 'fetch 2').length, 3);
  // Without Retry-After a 503 is an error at once.
  const bare = await reconstruct({}, service({ answer: (k) => (k === 2 ? { status: 503 } : null) }), has('error'));
  assert.match(JSON.stringify(bare.messages.find((m) => m.type === 'error')), /"network".*503 for the batch 2/);
});

test('wireframe: each edge of the closed torus once', async () => {
  const { messages } = await reconstruct({ wireframe: true, upTo: 2 }, service(), has('done'));
  for (const level of levels(messages)) {
    const edges = /** @type {Uint32Array} */ (level.edges);
    assert.equal(edges.length / 2, (3 * level.faces) / 2, `level ${level.level}`);
    const seen = new Set();
    for (let i = 0; i < edges.length; i += 2) {
      const key = Math.min(edges[i], edges[i + 1]) * 1e7 + Math.max(edges[i], edges[i + 1]);
      assert.ok(!seen.has(key));
      seen.add(key);
    }
  }
});

test('relief: each level posted while it is on carries θ; switched on later, θ of the level posted follows once', async () => {
  const cap = 2;
  const { job, messages, codec } = await reconstruct({ upTo: cap, relief: false }, service(), has('done'));
  for (const level of levels(messages)) assert.equal(level.relief, null, `level ${level.level} without θ`);
  const direct = codec.decoder(parts.base);
  for (let k = 1; k <= cap; k++) direct.apply(parts.batches[k - 1]);
  const expected = (/** @type {number} */ k) => {
    if (k > direct.level().level) direct.apply(parts.batches[k - 1]);
    const { positions, indices } = direct.level();
    return normalDeviation(positions, indices);
  };
  messages.length = 0;
  job.setRelief(true);
  const late = /** @type {Array<Extract<import('../src/reconstruction.js').WorkerMessage, { type: 'relief' }>>} */ (
    messages.filter((m) => m.type === 'relief')
  );
  assert.equal(late.length, 1);
  assert.equal(late[0].level, cap);
  assert.deepEqual(late[0].relief, expected(cap));
  assert.equal(late[0].top, reliefTop(late[0].relief));
  // Already sent: switching off and on again sends nothing.
  job.setRelief(false);
  job.setRelief(true);
  assert.equal(messages.filter((m) => m.type === 'relief').length, 1);
  messages.length = 0;
  const done = new Promise((resolve) => {
    const post = job.post;
    job.post = (message, transfer) => {
      post(message, transfer);
      if (message.type === 'done') resolve(undefined);
    };
  });
  job.extend(cap + 2);
  await done;
  const next = levels(messages);
  assert.deepEqual(next.map((l) => l.level), [cap + 1, cap + 2]);
  for (const level of next) {
    assert.deepEqual(level.relief, expected(level.level), `θ of level ${level.level}`);
    assert.equal(level.reliefTop, reliefTop(/** @type {Float32Array} */ (level.relief)));
  }
  assert.equal(messages.filter((m) => m.type === 'relief').length, 0, 'no separate θ for levels that carry it');
  direct.free();
  job.cancel();
});
