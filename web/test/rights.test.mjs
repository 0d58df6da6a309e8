// @ts-check
// The credit line's parts, the snapshot's text, and the PNG text chunks
// written into a PNG and read back from its bytes (CRCs checked against
// zlib's, the pixels decoded again).
import assert from 'node:assert/strict';
import test from 'node:test';
import { crc32 as zlibCrc32, deflateSync } from 'node:zlib';
import { decodePng, PngError } from '../src/png.js';
import { addTextChunks, crc32, readTextChunks } from '../src/png-text.js';
import { copyrightNotice, creditLine, modelPageUrl, snapshotText } from '../src/rights.js';

const CC_BY = { id: 'CC-BY-4.0', name: 'CC BY 4.0', url: 'https://creativecommons.org/licenses/by/4.0/' };
const IN_COPYRIGHT_EDU = { id: 'InC-EDU', name: 'In Copyright – Educational Use Permitted', url: 'http://rightsstatements.org/vocab/InC-EDU/1.0/' };

test('the credit line shows the credit and the licence linked to its deed; nothing without either', () => {
  assert.deepEqual(creditLine({ credit: 'Scan: Museo Nacional, 2019', licence: CC_BY }), {
    credit: 'Scan: Museo Nacional, 2019',
    licence: { name: 'CC BY 4.0', href: 'https://creativecommons.org/licenses/by/4.0/' },
  });
  assert.deepEqual(creditLine({ credit: 'Scan: Museo Nacional', licence: null }), { credit: 'Scan: Museo Nacional', licence: null });
  assert.deepEqual(creditLine({ credit: null, licence: CC_BY })?.credit, null);
  assert.equal(creditLine({ credit: null, licence: null }), null);
  assert.equal(creditLine({ credit: '   ', licence: null }), null, 'a blank credit is none');
  assert.equal(creditLine(undefined), null, 'a server without rights');
  assert.equal(creditLine(null), null);
});

test('a licence URL that is not http(s) is shown as its name, never as a link', () => {
  const line = creditLine({ credit: null, licence: { id: 'X', name: 'Odd', url: 'javascript:alert(1)' } });
  assert.deepEqual(line, { credit: null, licence: { name: 'Odd', href: null } });
  assert.equal(creditLine({ credit: null, licence: { id: 'X', name: 'Odd', url: 'not a url' } })?.licence?.href, null);
});

test('the copyright notice is the one line the server writes into a GLB', () => {
  assert.equal(
    copyrightNotice({ credit: 'Scan: Test Museum', licence: CC_BY }),
    'Scan: Test Museum. Licence: CC BY 4.0 (https://creativecommons.org/licenses/by/4.0/)',
  );
  assert.equal(copyrightNotice({ credit: 'Scan: Test Museum', licence: null }), 'Scan: Test Museum');
  assert.equal(copyrightNotice({ credit: null, licence: CC_BY }), 'Licence: CC BY 4.0 (https://creativecommons.org/licenses/by/4.0/)');
  assert.equal(copyrightNotice({ credit: null, licence: null }), null);
});

test('the model page is found from the manifest URL, under a path prefix too', () => {
  assert.equal(modelPageUrl('http://127.0.0.1:8080/api/models/bust'), 'http://127.0.0.1:8080/m/bust');
  assert.equal(modelPageUrl('https://museum.example/3d/api/models/bust?token=x'), 'https://museum.example/3d/m/bust');
  assert.equal(modelPageUrl('https://museum.example/other/bust'), null);
  assert.equal(modelPageUrl('not a url'), null);
});

test('a snapshot carries the title, the rights when recorded, and the page', () => {
  const page = 'http://h/m/bust';
  assert.deepEqual(snapshotText({ title: 'Bust', rights: { credit: 'Scan: Test Museum', licence: CC_BY } }, page), [
    ['Title', 'Bust'],
    ['Copyright', 'Scan: Test Museum. Licence: CC BY 4.0 (https://creativecommons.org/licenses/by/4.0/)'],
    ['Comment', 'Snapshot from http://h/m/bust'],
  ]);
  assert.deepEqual(snapshotText({ title: 'Bust', rights: { credit: null, licence: null } }, null), [['Title', 'Bust']]);
});

/**
 * A 3 × 2 RGB PNG, chunks written here with zlib's CRC (not the one under test).
 * @returns {{ png: Uint8Array, pixels: Uint8Array }}
 */
function smallPng() {
  const pixels = Uint8Array.from({ length: 3 * 2 * 3 }, (_, i) => (i * 37) & 0xff);
  const raw = new Uint8Array(2 * (1 + 9));
  for (let y = 0; y < 2; y++) raw.set(pixels.subarray(y * 9, y * 9 + 9), y * 10 + 1);
  const header = new Uint8Array(13);
  const view = new DataView(header.buffer);
  view.setUint32(0, 3);
  view.setUint32(4, 2);
  header.set([8, 2, 0, 0, 0], 8);
  /** @param {string} type @param {Uint8Array} data */
  const chunk = (type, data) => {
    const out = Buffer.alloc(12 + data.length);
    out.writeUInt32BE(data.length, 0);
    out.write(type, 4, 'latin1');
    out.set(data, 8);
    out.writeUInt32BE(zlibCrc32(out.subarray(4, 8 + data.length)), 8 + data.length);
    return out;
  };
  const png = Buffer.concat([
    Buffer.from([0x89, 0x50, 0x4e, 0x47, 0x0d, 0x0a, 0x1a, 0x0a]),
    chunk('IHDR', header),
    chunk('IDAT', deflateSync(raw)),
    chunk('IEND', new Uint8Array(0)),
  ]);
  return { png: new Uint8Array(png), pixels };
}

/**
 * Every chunk's type, and whether its CRC is zlib's CRC-32 of type and data.
 * @param {Uint8Array} png
 */
function chunks(png) {
  const b = Buffer.from(png.buffer, png.byteOffset, png.byteLength);
  const out = [];
  for (let at = 8; at < b.length; ) {
    const length = b.readUInt32BE(at);
    out.push({ type: b.toString('latin1', at + 4, at + 8), crcOk: b.readUInt32BE(at + 8 + length) === zlibCrc32(b.subarray(at + 4, at + 8 + length)) });
    at += 12 + length;
  }
  return out;
}

test('crc32 is zlib\'s', () => {
  for (const text of ['', 'IEND', 'tEXtTitle\0Bust', 'x'.repeat(1000)]) {
    const bytes = new TextEncoder().encode(text);
    assert.equal(crc32(bytes), zlibCrc32(bytes), JSON.stringify(text.slice(0, 20)));
  }
});

test('text chunks go after IHDR with valid CRCs, read back from the bytes, and leave the pixels alone', async () => {
  const { png, pixels } = smallPng();
  const entries = /** @type {Array<[string, string]>} */ ([
    ['Title', 'Bust of a Woman'],
    ['Copyright', 'Scan: Test Museum. Licence: CC BY 4.0 (https://creativecommons.org/licenses/by/4.0/)'],
    ['Comment', 'Snapshot from http://127.0.0.1/m/bust'],
  ]);
  const labelled = addTextChunks(png, entries);
  assert.deepEqual(chunks(labelled), [
    { type: 'IHDR', crcOk: true },
    { type: 'tEXt', crcOk: true },
    { type: 'tEXt', crcOk: true },
    { type: 'tEXt', crcOk: true },
    { type: 'IDAT', crcOk: true },
    { type: 'IEND', crcOk: true },
  ]);
  assert.deepEqual(
    readTextChunks(labelled),
    entries.map(([keyword, text]) => ({ type: 'tEXt', keyword, text })),
  );
  // The tEXt layout itself: keyword, NUL, Latin-1 text.
  const at = 8 + 25;
  assert.equal(Buffer.from(labelled.subarray(at + 8, at + 8 + 21)).toString('latin1'), 'Title\0Bust of a Woman');
  const decoded = await decodePng(labelled);
  assert.deepEqual([decoded.width, decoded.height, decoded.channels], [3, 2, 3]);
  assert.deepEqual(decoded.data, pixels);
  assert.deepEqual(readTextChunks(png), [], 'the original had none');
});

test('text beyond Latin-1 goes in iTXt as UTF-8; Latin-1 accents stay in tEXt', () => {
  const { png } = smallPng();
  const labelled = addTextChunks(png, [
    ['Copyright', `Scan: Μουσείο. Licence: ${IN_COPYRIGHT_EDU.name}`],
    ['Title', 'Tête de femme'],
  ]);
  assert.deepEqual(chunks(labelled).map((c) => `${c.type} ${c.crcOk}`), ['IHDR true', 'iTXt true', 'tEXt true', 'IDAT true', 'IEND true']);
  assert.deepEqual(readTextChunks(labelled), [
    { type: 'iTXt', keyword: 'Copyright', text: 'Scan: Μουσείο. Licence: In Copyright – Educational Use Permitted' },
    { type: 'tEXt', keyword: 'Title', text: 'Tête de femme' },
  ]);
  const tEXt = Buffer.from(labelled).indexOf('Title\0');
  assert.equal(labelled[tEXt + 7], 0xea, 'ê as one Latin-1 byte');
});

test('a damaged chunk, a file that is not a PNG, and a bad keyword are refused', () => {
  const { png } = smallPng();
  const labelled = addTextChunks(png, [['Title', 'Bust']]);
  const damaged = labelled.slice();
  damaged[8 + 25 + 10] ^= 1;
  assert.throws(() => readTextChunks(damaged), /tEXt has a bad CRC/);
  assert.throws(() => addTextChunks(new Uint8Array(40), [['Title', 'x']]), PngError);
  assert.throws(() => addTextChunks(png, [[' Title', 'x']]), /bad PNG keyword/);
  assert.throws(() => addTextChunks(png, [['', 'x']]), /bad PNG keyword/);
  assert.throws(() => readTextChunks(png.subarray(0, png.length - 12)), /no IEND/);
});
