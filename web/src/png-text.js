// @ts-check
/**
 * Text in a PNG the browser encoded (a snapshot): chunks added after IHDR,
 * each with its CRC (PNG spec §5.3, §11.3.4). Latin-1 text goes in `tEXt`,
 * which every reader knows; text beyond Latin-1 (a credit in Greek, the en
 * dash of "In Copyright – Educational Use Permitted") in uncompressed
 * `iTXt`, UTF-8, rather than mangled into `tEXt`.
 */

import { PngError } from './png.js';

const SIGNATURE = [0x89, 0x50, 0x4e, 0x47, 0x0d, 0x0a, 0x1a, 0x0a];

/** CRC-32 of PNG and zlib (ISO 3309), one byte at a time. */
const CRC_TABLE = (() => {
  const table = new Uint32Array(256);
  for (let n = 0; n < 256; n++) {
    let c = n;
    for (let k = 0; k < 8; k++) c = c & 1 ? 0xedb88320 ^ (c >>> 1) : c >>> 1;
    table[n] = c >>> 0;
  }
  return table;
})();

/** @param {Uint8Array} bytes @returns {number} unsigned */
export function crc32(bytes) {
  let c = 0xffffffff;
  for (const b of bytes) c = CRC_TABLE[(c ^ b) & 0xff] ^ (c >>> 8);
  return (c ^ 0xffffffff) >>> 0;
}

/**
 * @param {Uint8Array} png a whole PNG file
 * @param {Array<[string, string]>} entries keyword (1–79 Latin-1 characters, e.g. `Title`), text
 * @returns {Uint8Array} the same file with one text chunk per entry after IHDR
 */
export function addTextChunks(png, entries) {
  if (png.length < 33 || SIGNATURE.some((b, i) => png[i] !== b)) throw new PngError('not a PNG file');
  const view = new DataView(png.buffer, png.byteOffset, png.byteLength);
  if (view.getUint32(8) !== 13 || latin1(png.subarray(12, 16)) !== 'IHDR') throw new PngError('the first chunk is not IHDR');
  const afterHeader = 8 + 12 + 13;
  const chunks = entries.map(([keyword, text]) => textChunk(keyword, text));
  const out = new Uint8Array(png.length + chunks.reduce((n, c) => n + c.length, 0));
  out.set(png.subarray(0, afterHeader));
  let at = afterHeader;
  for (const c of chunks) {
    out.set(c, at);
    at += c.length;
  }
  out.set(png.subarray(afterHeader), at);
  return out;
}

/**
 * The text of a file's `tEXt` and uncompressed `iTXt` chunks, in order.
 * Every chunk's CRC is checked on the way.
 * @param {Uint8Array} png
 * @returns {Array<{ type: 'tEXt' | 'iTXt', keyword: string, text: string }>}
 */
export function readTextChunks(png) {
  if (png.length < 8 || SIGNATURE.some((b, i) => png[i] !== b)) throw new PngError('not a PNG file');
  const view = new DataView(png.buffer, png.byteOffset, png.byteLength);
  /** @type {Array<{ type: 'tEXt' | 'iTXt', keyword: string, text: string }>} */
  const found = [];
  let at = 8;
  while (at + 12 <= png.length) {
    const length = view.getUint32(at);
    const end = at + 8 + length;
    if (end + 4 > png.length) throw new PngError('a chunk runs past the end of the file');
    const type = latin1(png.subarray(at + 4, at + 8));
    if (crc32(png.subarray(at + 4, end)) !== view.getUint32(end)) throw new PngError(`chunk ${type} has a bad CRC`);
    const body = png.subarray(at + 8, end);
    const nul = body.indexOf(0);
    if (type === 'tEXt' && nul > 0) {
      found.push({ type, keyword: latin1(body.subarray(0, nul)), text: latin1(body.subarray(nul + 1)) });
    } else if (type === 'iTXt' && nul > 0 && body[nul + 1] === 0) {
      const language = body.indexOf(0, nul + 3);
      const translated = language < 0 ? -1 : body.indexOf(0, language + 1);
      if (translated >= 0) {
        const text = new TextDecoder().decode(body.subarray(translated + 1));
        found.push({ type, keyword: latin1(body.subarray(0, nul)), text });
      }
    }
    if (type === 'IEND') return found;
    at = end + 4;
  }
  throw new PngError('no IEND chunk');
}

/**
 * @param {string} keyword
 * @param {string} text
 */
function textChunk(keyword, text) {
  if (!/^[\x21-\x7e\xa1-\xff]([\x20-\x7e\xa1-\xff]{0,77}[\x21-\x7e\xa1-\xff])?$/.test(keyword)) {
    throw new PngError(`bad PNG keyword ${JSON.stringify(keyword)}`);
  }
  const key = latin1Bytes(keyword);
  if (/^[\n\x20-\x7e\xa0-\xff]*$/.test(text)) return chunk('tEXt', [key, [0], latin1Bytes(text)]);
  // iTXt: keyword, NUL, compression flag 0, method 0, no language tag, no translated keyword.
  return chunk('iTXt', [key, [0, 0, 0, 0, 0], new TextEncoder().encode(text)]);
}

/**
 * @param {string} type four letters
 * @param {ArrayLike<number>[]} parts the chunk's data
 */
function chunk(type, parts) {
  const length = parts.reduce((n, p) => n + p.length, 0);
  const out = new Uint8Array(12 + length);
  const view = new DataView(out.buffer);
  view.setUint32(0, length);
  out.set(latin1Bytes(type), 4);
  let at = 8;
  for (const p of parts) {
    out.set(p, at);
    at += p.length;
  }
  view.setUint32(8 + length, crc32(out.subarray(4, 8 + length)));
  return out;
}

/** @param {string} text only code points below 256 */
function latin1Bytes(text) {
  return Uint8Array.from(text, (c) => c.charCodeAt(0));
}

/** @param {Uint8Array} bytes */
function latin1(bytes) {
  return String.fromCharCode(...bytes);
}
