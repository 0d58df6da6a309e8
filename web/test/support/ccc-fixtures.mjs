// @ts-check
/**
 * Hand-made cubic cell complexes (codec/colour/CCC.md) and a PNG writer, for the
 * Node tests of src/ccc.js and src/png.js and the shader test in Chromium.
 */
import { deflateSync } from 'node:zlib';

/** @typedef {import('../../src/ccc.js').CccParameters} CccParameters */
/** @typedef {import('../../src/ccc.js').Pixels} Pixels */

/**
 * @typedef {object} CellSpec
 * @property {[number, number, number]} cube
 * @property {[number, number, number]} centre bytes q: (q + 0.5) / 256 of the edge
 * @property {number} first first tile
 * @property {number} mask faces with a tile
 * @property {[number, number, number]} mean
 */

/**
 * The cell texture of a complex, as the encoder lays it out.
 * @param {CccParameters} p
 * @param {CellSpec[]} cells
 * @returns {Pixels}
 */
export function cellTexture(p, cells) {
  const { width, height, cells_offset } = p.cell_texture;
  const data = new Uint8Array(width * height * 3);
  const put = (/** @type {number} */ i, /** @type {number[]} */ rgb) => data.set(rgb, 3 * i);
  const number = (/** @type {number} */ n) => [n & 255, (n >> 8) & 255, n >> 16];
  cells.forEach((cell, c) => {
    const [x, y, z] = cell.cube;
    put(x + p.dims[0] * (y + p.dims[1] * z), number(c + 1));
    const base = cells_offset + 4 * c;
    put(base, cell.centre);
    put(base + 1, number(cell.first));
    put(base + 2, [cell.mask, 0, 0]);
    put(base + 3, cell.mean);
  });
  return { width, height, channels: 3, data };
}

/**
 * One cell in the first of two cubes (the second is empty), its centre of
 * projection near the cube's floor, and a 2×2 tile of distinct colours on
 * each face in `mask`. A quad across the cubes at half height sees tiles
 * +z, ±x and +y, the mean colour where the ray leaves through a face
 * without a tile (−y by default) and the fallback colour over the empty cube.
 * @param {{ mask?: number, first?: number }} [options]
 */
export function quadComplex({ mask = 0b010111, first = 0 } = {}) {
  const faces = [0, 1, 2, 3, 4, 5].filter((f) => mask & (1 << f));
  const tiles = first + faces.length;
  const tileSize = 2;
  const gutter = 1;
  const side = tileSize + 2 * gutter;
  /** @type {CccParameters} */
  const parameters = {
    version: 1,
    origin: [-1, -0.5, -0.5],
    cell_size: 1,
    dims: [2, 1, 1],
    cells: 1,
    cell_texture: { width: 3, height: 2, cells_offset: 2 },
    tile_size: tileSize,
    gutter,
    atlas: { width: tiles * side, height: side, tiles_per_row: tiles, tiles },
    low_res_factor: 2,
    fallback_colour: [200, 190, 180],
  };
  /** @type {[number, number, number]} */
  const centreBytes = [128, 128, 0];
  /** @type {[number, number, number]} */
  const mean = [90, 60, 30];
  const cells = cellTexture(parameters, [{ cube: [0, 0, 0], centre: centreBytes, first, mask, mean }]);
  /** @type {Record<number, number>} */
  const tileOfFace = {};
  /** @type {Record<number, number[][]>} */
  const tileColours = {};
  const atlas = { width: parameters.atlas.width, height: parameters.atlas.height, channels: 3, data: new Uint8Array(0) };
  atlas.data = new Uint8Array(atlas.width * atlas.height * 3);
  faces.forEach((face, k) => {
    const tile = first + k;
    tileOfFace[face] = tile;
    // Saturated, well-separated colours: texel (i, j) of face f.
    const colours = [0, 1, 2, 3].map((texel) => [
      40 + 40 * face + (texel & 1) * 20,
      230 - 35 * face,
      30 + 60 * texel,
    ]);
    tileColours[face] = colours;
    for (let y = 0; y < side; y++) {
      for (let x = 0; x < side; x++) {
        // The gutter repeats the nearest interior texel.
        const i = Math.min(Math.max(x - gutter, 0), tileSize - 1);
        const j = Math.min(Math.max(y - gutter, 0), tileSize - 1);
        atlas.data.set(colours[i + 2 * j], 3 * (y * atlas.width + tile * side + x));
      }
    }
  });
  return {
    parameters,
    cells,
    atlas,
    tileOfFace,
    tileColours,
    mean,
    /** Centre of projection in cube units. */
    centre: centreBytes.map((q) => (q + 0.5) / 256),
  };
}

/**
 * An 8-bit PNG (colour type 2 or 6) with the given row filters, in turn, and
 * the compressed data split into IDAT chunks of `idatChunk` bytes.
 * @param {Pixels} image
 * @param {{ filters?: number[], idatChunk?: number }} [options]
 */
export function encodePng(image, { filters = [0], idatChunk = 1 << 16 } = {}) {
  const { width, height, channels, data } = image;
  const stride = width * channels;
  const raw = new Uint8Array(height * (stride + 1));
  for (let y = 0; y < height; y++) {
    const filter = filters[y % filters.length];
    raw[y * (stride + 1)] = filter;
    for (let i = 0; i < stride; i++) {
      const x = data[y * stride + i];
      const a = i >= channels ? data[y * stride + i - channels] : 0;
      const b = y > 0 ? data[(y - 1) * stride + i] : 0;
      const c = i >= channels && y > 0 ? data[(y - 1) * stride + i - channels] : 0;
      let predicted = 0;
      if (filter === 1) predicted = a;
      else if (filter === 2) predicted = b;
      else if (filter === 3) predicted = (a + b) >> 1;
      else if (filter === 4) {
        const p = a + b - c;
        const [pa, pb, pc] = [Math.abs(p - a), Math.abs(p - b), Math.abs(p - c)];
        predicted = pa <= pb && pa <= pc ? a : pb <= pc ? b : c;
      }
      raw[y * (stride + 1) + 1 + i] = (x - predicted) & 255;
    }
  }
  const zlib = deflateSync(raw);
  const ihdr = new Uint8Array(13);
  const view = new DataView(ihdr.buffer);
  view.setUint32(0, width);
  view.setUint32(4, height);
  ihdr.set([8, channels === 4 ? 6 : 2, 0, 0, 0], 8);
  /** @type {Array<[string, Uint8Array]>} */
  const chunks = [['IHDR', ihdr]];
  for (let at = 0; at < zlib.length; at += idatChunk) chunks.push(['IDAT', zlib.subarray(at, at + idatChunk)]);
  chunks.push(['IEND', new Uint8Array(0)]);
  /** @type {number[]} */
  const out = [0x89, 0x50, 0x4e, 0x47, 0x0d, 0x0a, 0x1a, 0x0a];
  for (const [type, body] of chunks) {
    const typed = [...type].map((ch) => ch.charCodeAt(0));
    const length = body.length;
    out.push(length >>> 24, (length >>> 16) & 255, (length >>> 8) & 255, length & 255);
    const crc = crc32([...typed, ...body]);
    out.push(...typed, ...body, crc >>> 24, (crc >>> 16) & 255, (crc >>> 8) & 255, crc & 255);
  }
  return new Uint8Array(out);
}

/** @param {number[]} bytes */
function crc32(bytes) {
  let crc = ~0;
  for (const byte of bytes) {
    crc ^= byte;
    for (let k = 0; k < 8; k++) crc = crc & 1 ? (crc >>> 1) ^ 0xedb88320 : crc >>> 1;
  }
  return ~crc >>> 0;
}
