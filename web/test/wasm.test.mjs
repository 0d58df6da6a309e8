// @ts-check
// Node tests of the WebAssembly decoder on the committed streams in
// test/fixtures, written by the Rust encoder from generated samples: every
// level's buffers must be what the native decoder made of the same bytes
// when they were blessed (SHA-256 of each buffer, in NAME.json), so any
// change to the decoder's output fails here. If the change is meant,
// re-record them with `bash scripts/bless-fixtures.sh`. No CLI is run: only
// the wasm module must be built.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { existsSync, readFileSync } from 'node:fs';
import { VitrineCodec, splitStream, DecodeError } from '../src/codec.js';
import { fixture, fixtureNames, sha256, wasmPath } from './support/fixtures.mjs';

async function codec() {
  assert.ok(existsSync(wasmPath), `build the wasm first: ${wasmPath}`);
  return VitrineCodec.instantiate(readFileSync(wasmPath));
}

const BLESS = 'if the change is meant: bash scripts/bless-fixtures.sh';

/**
 * A level as the fixture's sidecar records it.
 * @param {import('../src/codec.js').Level} level
 */
function digest(level) {
  return {
    level: level.level,
    vertices: level.vertices,
    faces: level.indices.length / 3,
    positions: sha256(level.positions),
    indices: sha256(level.indices),
    colours: level.colours && sha256(level.colours),
  };
}

test('the committed fixtures: small, each the stream its sidecar was blessed from', () => {
  const names = fixtureNames();
  assert.deepEqual(names, ['charted-torus', 'nested-torus', 'painted-torus', 'plate', 'sphere', 'torus']);
  for (const name of names) {
    const f = fixture(name);
    assert.ok(f.stream.length < 16 << 10, `${name}.vtr is ${f.stream.length} bytes`);
    assert.equal(f.stream.length, f.streamDigest.bytes, `${name}.vtr size`);
    assert.equal(sha256(f.stream), f.streamDigest.sha256, `${name}.vtr is not the stream ${name}.json describes: ${BLESS}`);
    assert.ok(f.levels.length >= 3, `${name}: a base and several batches`);
    f.levels.forEach((level, k) => assert.equal(level.level, k));
    // Byte 4 is the stream's version: 5 for the charted stream (its later
    // batches in one part per chart), 6 for the nested one, 4 for the plain ones.
    assert.equal(f.stream[4], { 'charted-torus': 5, 'nested-torus': 6 }[name] ?? 4, `${name}.vtr version`);
  }
});

for (const name of fixtureNames()) {
  test(`wasm decodes ${name}.vtr exactly as the native decoder did`, async () => {
    const f = fixture(name);
    const { base, batches } = splitStream(f.stream);
    assert.equal(batches.length + 1, f.levels.length, 'levels');
    const decoder = (await codec()).decoder(base);
    for (let k = 0; k <= batches.length; k++) {
      if (k > 0) decoder.apply(batches[k - 1]);
      assert.deepEqual(digest(decoder.level()), f.levels[k], `${name} level ${k}: the decoder's output changed; ${BLESS}`);
      // The zero-copy views the decode worker reads are the same bytes.
      assert.deepEqual(digest(decoder.view()), f.levels[k], `${name} level ${k} through view()`);
    }
    if (name === 'painted-torus' || name === 'charted-torus' || name === 'nested-torus') assert.ok(f.levels.every((l) => l.colours !== null), 'colour at every level');
    else assert.ok(f.levels.every((l) => l.colours === null), 'no colour');
    decoder.free();
  });
}

/** @returns {[number, number]} a LEB128 varint at `at` and the offset after it */
function varint(/** @type {Uint8Array} */ bytes, /** @type {number} */ at) {
  let value = 0;
  for (let shift = 0; ; shift += 7) {
    const byte = bytes[at++];
    if (byte === undefined) throw new Error('varint runs past the end');
    value += (byte & 0x7f) * 2 ** shift;
    if (byte < 0x80) return [value, at];
  }
}

/** @param {number} value */
function leb128(value) {
  /** @type {number[]} */
  const out = [];
  do {
    const low = value % 128;
    value = Math.floor(value / 128);
    out.push(value > 0 ? low | 0x80 : low);
  } while (value > 0);
  return out;
}

/**
 * @typedef {{ seeds: Array<[number, number]>, inserted: number, sections: Uint8Array[] }} Pass
 * @typedef {{ charts: number, labels: Uint8Array | null, parts: Array<Pass[] | null> }} Parted
 * @typedef {{ head: Uint8Array, level: number, before: number, after: number, faces: number, passes: Pass[], parted: Parted | null }} Batch
 */

/** The tag of a parted batch (a charted stream's, format 5). */
const PARTED = 0x50;

/**
 * Two passes (seeds, inserted vertices, connectivity, geometry and colour
 * sections) from `at`.
 * @param {Uint8Array} bytes
 * @param {number} at
 * @returns {[Pass[], number]}
 */
function parsePasses(bytes, at) {
  /** @type {Pass[]} */
  const passes = [];
  for (let p = 0; p < 2; p++) {
    let count;
    [count, at] = varint(bytes, at);
    /** @type {Array<[number, number]>} */
    const seeds = [];
    for (let s = 0; s < count; s++) {
      let a, b;
      [a, at] = varint(bytes, at);
      [b, at] = varint(bytes, at);
      seeds.push([a, b]);
    }
    let inserted;
    [inserted, at] = varint(bytes, at);
    const sections = [];
    for (let s = 0; s < 3; s++) {
      let n;
      [n, at] = varint(bytes, at);
      sections.push(bytes.slice(at, at + n));
      at += n;
    }
    passes.push({ seeds, inserted, sections });
  }
  return [passes, at];
}

/**
 * A batch chunk taken apart as codec/core/FORMAT.md lays it out: tag and
 * version, five header varints, then two passes, or for a parted batch the
 * number of charts, the chart labels (`labelled`: the stream's first parted
 * batch) and each chart's part (empty, or two passes).
 * @param {Uint8Array} bytes
 * @param {boolean} [labelled]
 * @returns {Batch}
 */
function parseBatch(bytes, labelled = false) {
  let at = 2;
  /** @type {number[]} */
  const header = [];
  for (let i = 0; i < 5; i++) [header[i], at] = varint(bytes, at);
  const [level, before, after, faces, length] = header;
  assert.equal(at + length, bytes.length, 'payload length');
  /** @type {Pass[]} */
  let passes = [];
  /** @type {Parted | null} */
  let parted = null;
  if (bytes[0] === PARTED) {
    let charts, n;
    [charts, at] = varint(bytes, at);
    /** @type {Uint8Array | null} */
    let labels = null;
    if (labelled) {
      [n, at] = varint(bytes, at);
      labels = bytes.slice(at, at + n);
      at += n;
    }
    /** @type {Array<Pass[] | null>} */
    const parts = [];
    for (let k = 0; k < charts; k++) {
      [n, at] = varint(bytes, at);
      if (n === 0) {
        parts.push(null);
        continue;
      }
      const [chartPasses, end] = parsePasses(bytes, at);
      assert.equal(end, at + n, 'the two passes fill the part');
      parts.push(chartPasses);
      at = end;
    }
    parted = { charts, labels, parts };
  } else {
    [passes, at] = parsePasses(bytes, at);
  }
  assert.equal(at, bytes.length, 'the passes fill the payload');
  return { head: bytes.slice(0, 2), level, before, after, faces, passes, parted };
}

/** @param {Pass[]} passes */
function writePasses(passes) {
  /** @type {number[]} */
  const out = [];
  for (const pass of passes) {
    out.push(...leb128(pass.seeds.length));
    for (const [a, b] of pass.seeds) out.push(...leb128(a), ...leb128(b));
    out.push(...leb128(pass.inserted));
    for (const section of pass.sections) out.push(...leb128(section.length), ...section);
  }
  return out;
}

/** @param {Batch} batch */
function writeBatch(batch) {
  /** @type {number[]} */
  let payload = [];
  if (batch.parted) {
    payload.push(...leb128(batch.parted.charts));
    if (batch.parted.labels) payload.push(...leb128(batch.parted.labels.length), ...batch.parted.labels);
    for (const part of batch.parted.parts) {
      const bytes = part ? writePasses(part) : [];
      payload.push(...leb128(bytes.length), ...bytes);
    }
  } else {
    payload = writePasses(batch.passes);
  }
  const header = [batch.level, batch.before, batch.after, batch.faces, payload.length].flatMap(leb128);
  return Uint8Array.from([...batch.head, ...header, ...payload]);
}

/**
 * Whether batch `i` of `batches` is the stream's first parted batch (the
 * one that carries the chart labels).
 * @param {Uint8Array[]} batches
 * @param {number} i
 */
function labelled(batches, i) {
  return i === batches.findIndex((b) => b[0] === PARTED);
}

/**
 * Batch 1 of the painted torus, edited.
 * @param {(batch: Batch) => void} edit
 */
function edited(edit) {
  const { batches } = splitStream(fixture('painted-torus').stream);
  const batch = parseBatch(batches[0]);
  edit(batch);
  return writeBatch(batch);
}

/** The fixtures this file's batch parser reads: formats 4 and 5 (a nested stream's batches carry a phase). */
const flatFixtures = () => fixtureNames().filter((name) => name !== 'nested-torus');

test('the test can take a batch apart and put it together again byte for byte', () => {
  let parted = 0;
  for (const name of flatFixtures()) {
    const { batches } = splitStream(fixture(name).stream);
    batches.forEach((bytes, i) => {
      const batch = parseBatch(bytes, labelled(batches, i));
      if (batch.parted) parted++;
      assert.deepEqual(writeBatch(batch), bytes);
    });
  }
  assert.ok(parted >= 3, `${parted} parted batches in the fixtures`);
});

test('wasm reports truncated and out-of-order streams as errors', async () => {
  const f = fixture('painted-torus');
  const { base, batches } = splitStream(f.stream);
  const c = await codec();
  assert.throws(() => c.decoder(base.subarray(0, base.length - 7)), DecodeError);
  const d1 = c.decoder(base);
  assert.throws(() => d1.apply(batches[0].subarray(0, batches[0].length - 3)), /truncated/);
  const d2 = c.decoder(base);
  assert.throws(
    () => d2.apply(batches[1]),
    (/** @type {unknown} */ e) => e instanceof DecodeError && e.message === 'invalid stream: batch for level 2 applied at level 0',
  );
});

test('wasm refuses corrupt batches: apply fails with the reason', async () => {
  const f = fixture('painted-torus');
  const { base, batches } = splitStream(f.stream);
  const c = await codec();
  /**
   * Applies a corrupt batch 1 to a fresh decoder; it must throw a DecodeError matching `reason`.
   * @param {Uint8Array} corrupt
   * @param {RegExp} reason
   */
  const refused = (corrupt, reason) => {
    assert.notDeepEqual(corrupt, batches[0], 'the batch was changed');
    const decoder = c.decoder(base);
    assert.throws(
      () => decoder.apply(corrupt),
      (/** @type {unknown} */ e) => e instanceof DecodeError && /^invalid stream: /.test(e.message) && reason.test(e.message),
      `expected a DecodeError matching ${reason}`,
    );
    // Still at the base: the level number did not move.
    assert.equal(decoder.level().level, 0);
    return decoder;
  };

  // Counts that disagree with the header's level table are refused before
  // anything changes: the intact batch then applies as if nothing happened.
  for (const corrupt of [
    edited((b) => (b.after += 1)),
    edited((b) => (b.before -= 1)),
    edited((b) => (b.faces += 2)),
  ]) {
    const decoder = refused(corrupt, /^invalid stream: batch counts disagree with the level table$/);
    decoder.apply(batches[0]);
    assert.deepEqual(digest(decoder.level()), f.levels[1], 'the intact batch after the refused one');
    decoder.free();
  }
  // A pass claiming one vertex more than the batch adds.
  const more = refused(
    edited((b) => (b.passes[0].inserted += 1)),
    /^invalid stream: passes insert a different number of vertices than the batch$/,
  );
  more.apply(batches[0]);
  assert.deepEqual(digest(more.level()), f.levels[1]);
  more.free();

  // A seed gate from a vertex to itself is no edge: found during the
  // traversal, after the level began to change, so the decoder refuses
  // whatever comes next until it starts again from the base.
  const seeded = edited((b) => {
    const pass = /** @type {Pass} */ (b.passes.find((p) => p.seeds.length > 0));
    pass.seeds[0] = [pass.seeds[0][0], pass.seeds[0][0]];
  });
  const broken = refused(seeded, /^invalid stream: seed gate is not an edge of the mesh$/);
  assert.throws(() => broken.apply(batches[0]), /an earlier batch failed part-way: decode again from the base/);
  broken.free();

  // A seed vertex that does not exist yet.
  refused(
    edited((b) => {
      const pass = /** @type {Pass} */ (b.passes.find((p) => p.seeds.length > 0));
      pass.seeds[0] = [f.levels[0].vertices + 5, pass.seeds[0][1]];
    }),
    /^invalid stream: seed gate names a vertex that does not exist yet$/,
  ).free();

});

test('wasm refuses every batch of every fixture with flipped bytes', async () => {
  const c = await codec();
  /** Every byte of the connectivity codes: the traversal finds other patches than the pass declares, or runs out of codes. */
  const connectivity = (/** @type {Uint8Array} */ bytes, /** @type {boolean} */ first) => {
    const b = parseBatch(bytes, first);
    const passes = b.parted ? b.parted.parts.flatMap((part) => part ?? []) : b.passes;
    for (const pass of passes) pass.sections[0] = pass.sections[0].map((x) => x ^ 0x5a);
    return writeBatch(b);
  };
  /** Every seventh byte from the 40th on, wherever it falls (header fields, seeds, any section). */
  const scattered = (/** @type {Uint8Array} */ bytes) => {
    const out = Uint8Array.from(bytes);
    for (let at = 40; at < out.length; at += 7) out[at] ^= 0x5a;
    return out;
  };
  for (const name of flatFixtures()) {
    const { base, batches } = splitStream(fixture(name).stream);
    for (const [flip, reason] of /** @type {Array<[(b: Uint8Array, first: boolean) => Uint8Array, RegExp]>} */ ([
      [connectivity, /pass insert|patch faces do not match their pattern|truncated entropy-coded payload/],
      [scattered, /./],
    ])) {
      batches.forEach((batch, i) => {
        // Batch i + 1 flipped, on a decoder at level i: apply must throw, and the level stay at i.
        const corrupt = flip(batch, labelled(batches, i));
        assert.notDeepEqual(corrupt, batch);
        const probe = c.decoder(base);
        for (let k = 0; k < i; k++) probe.apply(batches[k]);
        assert.throws(
          () => probe.apply(corrupt),
          (/** @type {unknown} */ e) => e instanceof DecodeError && /^invalid stream: /.test(e.message) && reason.test(e.message),
          `${name} batch ${i + 1} (${flip.name}): expected a DecodeError matching ${reason}`,
        );
        assert.equal(probe.level().level, i, `${name}: still at level ${i}`);
        probe.free();
      });
    }
  }
});
