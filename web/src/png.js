// @ts-check
/**
 * A small PNG decoder for the cell texture of a CCC colour mapping
 * (codec/colour/CCC.md). The cell texture is data, not a picture: every byte is
 * part of a 24-bit number, so it must reach the shader exactly. Decoding it
 * here (the browser's DecompressionStream inflates, this file undoes the row
 * filters) leaves no room for colour management, gamma or premultiplication
 * to touch a byte, whatever the browser does with images.
 *
 * 8-bit greyscale, grey + alpha, RGB and RGBA, not interlaced: what the
 * encoder writes (8-bit RGB) and then some.
 */

const SIGNATURE = [0x89, 0x50, 0x4e, 0x47, 0x0d, 0x0a, 0x1a, 0x0a];
/** Channels per colour type. */
const CHANNELS = /** @type {Record<number, number>} */ ({ 0: 1, 2: 3, 4: 2, 6: 4 });

/**
 * @typedef {object} DecodedPng
 * @property {number} width
 * @property {number} height
 * @property {number} channels 1, 2, 3 or 4
 * @property {Uint8Array} data rows top to bottom, `channels` bytes per pixel, no padding
 */

export class PngError extends Error {}

/**
 * @param {Uint8Array} bytes a whole PNG file
 * @returns {Promise<DecodedPng>}
 */
export async function decodePng(bytes) {
  const { width, height, channels, idat } = parseChunks(bytes);
  const raw = await inflate(idat);
  return { width, height, channels, data: unfilter(raw, width, height, channels) };
}

/**
 * @param {Uint8Array} bytes
 * @returns {{ width: number, height: number, channels: number, idat: Uint8Array }}
 */
export function parseChunks(bytes) {
  if (bytes.length < 8 || SIGNATURE.some((b, i) => bytes[i] !== b)) throw new PngError('not a PNG file');
  const view = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
  let at = 8;
  let width = 0;
  let height = 0;
  let channels = 0;
  /** @type {Uint8Array[]} */
  const parts = [];
  let ended = false;
  while (at + 8 <= bytes.length) {
    const length = view.getUint32(at);
    const type = String.fromCharCode(...bytes.subarray(at + 4, at + 8));
    const body = at + 8;
    if (body + length + 4 > bytes.length) throw new PngError(`chunk ${type} runs past the end of the file`);
    if (type === 'IHDR') {
      if (length < 13) throw new PngError('short IHDR chunk');
      width = view.getUint32(body);
      height = view.getUint32(body + 4);
      const [depth, colourType, , , interlace] = bytes.subarray(body + 8, body + 13);
      if (depth !== 8) throw new PngError(`bit depth ${depth} is not supported (8 is)`);
      if (!(colourType in CHANNELS)) throw new PngError(`colour type ${colourType} is not supported`);
      if (interlace !== 0) throw new PngError('interlaced PNGs are not supported');
      if (width === 0 || height === 0) throw new PngError('empty image');
      channels = CHANNELS[colourType];
    } else if (type === 'IDAT') {
      parts.push(bytes.subarray(body, body + length));
    } else if (type === 'IEND') {
      ended = true;
      break;
    }
    at = body + length + 4;
  }
  if (!channels) throw new PngError('no IHDR chunk');
  if (!parts.length || !ended) throw new PngError('truncated PNG (no image data or no IEND)');
  const idat = new Uint8Array(parts.reduce((n, p) => n + p.length, 0));
  let offset = 0;
  for (const p of parts) {
    idat.set(p, offset);
    offset += p.length;
  }
  return { width, height, channels, idat };
}

/**
 * zlib inflate (DecompressionStream's 'deflate' is the zlib format, checksum included).
 * @param {Uint8Array} zlib
 */
async function inflate(zlib) {
  try {
    const stream = new Blob([/** @type {Uint8Array<ArrayBuffer>} */ (zlib)]).stream().pipeThrough(new DecompressionStream('deflate'));
    return new Uint8Array(await new Response(stream).arrayBuffer());
  } catch (error) {
    throw new PngError(`damaged image data (${error instanceof Error ? error.message : error})`);
  }
}

/**
 * Undoes the per-row filters (PNG spec §9).
 * @param {Uint8Array} raw filter byte + row, per row
 * @param {number} width
 * @param {number} height
 * @param {number} channels bytes per pixel
 */
export function unfilter(raw, width, height, channels) {
  const stride = width * channels;
  if (raw.length < height * (stride + 1)) throw new PngError(`image data too short for ${width}×${height}`);
  const out = new Uint8Array(height * stride);
  const bpp = channels;
  for (let y = 0; y < height; y++) {
    const filter = raw[y * (stride + 1)];
    const src = y * (stride + 1) + 1;
    const row = y * stride;
    const up = row - stride;
    switch (filter) {
      case 0:
        out.set(raw.subarray(src, src + stride), row);
        break;
      case 1:
        for (let i = 0; i < stride; i++) out[row + i] = raw[src + i] + (i >= bpp ? out[row + i - bpp] : 0);
        break;
      case 2:
        for (let i = 0; i < stride; i++) out[row + i] = raw[src + i] + (y > 0 ? out[up + i] : 0);
        break;
      case 3:
        for (let i = 0; i < stride; i++) {
          const a = i >= bpp ? out[row + i - bpp] : 0;
          const b = y > 0 ? out[up + i] : 0;
          out[row + i] = raw[src + i] + ((a + b) >> 1);
        }
        break;
      case 4:
        for (let i = 0; i < stride; i++) {
          const a = i >= bpp ? out[row + i - bpp] : 0;
          const b = y > 0 ? out[up + i] : 0;
          const c = i >= bpp && y > 0 ? out[up + i - bpp] : 0;
          const p = a + b - c;
          const pa = Math.abs(p - a);
          const pb = Math.abs(p - b);
          const pc = Math.abs(p - c);
          out[row + i] = raw[src + i] + (pa <= pb && pa <= pc ? a : pb <= pc ? b : c);
        }
        break;
      default:
        throw new PngError(`row ${y} has unknown filter ${filter}`);
    }
  }
  return out;
}
