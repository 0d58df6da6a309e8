// @ts-check
/**
 * A point stream (VPTS, codec/points FORMAT.md) decoded level by level with
 * the WebAssembly exports of codec/wasm/src/points.rs, and its splats.
 * Levels are prefixes: the manifest's level 0 URL serves the header and the
 * first level chunk, level k's URL the k-th chunk after it.
 */

import { DecodeError } from '../codec.js';

/** Fixed header bytes before the level depths (format.rs `FIXED`). */
const HEADER_FIXED = 53;

const POINT_POSITIONS = 0;
const POINT_COLOURS = 1;
const POINT_NORMALS = 2;
const SPLAT_RADII = 0;
const SPLAT_SURFACE_IDS = 1;
const SPLAT_CLIP = 2;
const SPLAT_PLANES = 3;

/**
 * Splits level 0's payload into the header and the first chunk.
 * @param {Uint8Array} bytes
 * @returns {{ header: Uint8Array, chunk: Uint8Array }}
 */
export function splitHeader(bytes) {
  if (bytes.length < HEADER_FIXED || String.fromCharCode(...bytes.subarray(0, 4)) !== 'VPTS') {
    throw new DecodeError('not a point stream (truncated header or bad magic)');
  }
  const length = HEADER_FIXED + bytes[HEADER_FIXED - 1];
  if (bytes.length < length) throw new DecodeError('truncated point stream header');
  return { header: bytes.subarray(0, length), chunk: bytes.subarray(length) };
}

/**
 * Splits a whole stream into level 0's payload (header + first chunk) and
 * the other chunks: what a server serves on the level URLs (tests).
 * @param {Uint8Array} bytes
 * @returns {Uint8Array[]}
 */
export function splitLevels(bytes) {
  const { header } = splitHeader(bytes);
  const levels = bytes[HEADER_FIXED - 1];
  const view = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
  /** @type {Uint8Array[]} */
  const out = [];
  let at = header.length;
  for (let k = 0; k < levels; k++) {
    const end = at + 8 + view.getUint32(at, true);
    out.push(bytes.subarray(k === 0 ? 0 : at, end));
    at = end;
  }
  return out;
}

export class PointStream {
  #handle;
  #e;

  /**
   * @param {import('../codec.js').VitrineCodec} codec
   * @param {Uint8Array} header
   */
  constructor(codec, header) {
    this.codec = codec;
    this.#e = codec.exports;
    this.#write(header);
    this.#handle = this.#e.points_new(header.length);
    if (this.#handle === 0) throw codec.lastError();
  }

  /** @param {Uint8Array} bytes */
  #write(bytes) {
    const ptr = this.#e.input_reserve(bytes.length);
    new Uint8Array(this.#e.memory.buffer).set(bytes, ptr);
  }

  /** Decodes one level chunk (framing included). @param {Uint8Array} chunk */
  apply(chunk) {
    this.#write(chunk);
    if (this.#e.points_apply(this.#handle, chunk.length) !== 0) throw this.codec.lastError();
  }

  get count() {
    return this.#e.points_count(this.#handle);
  }

  get level() {
    return this.#e.points_level(this.#handle) - 1;
  }

  get levels() {
    return this.#e.points_levels(this.#handle);
  }

  /**
   * @param {'points' | 'splats'} family
   * @param {number} kind
   * @param {typeof Float32Array | typeof Uint32Array | typeof Uint8Array} Type
   */
  #copy(family, kind, Type) {
    const ptr = this.#e[`${family === 'points' ? 'points' : 'splat'}_buffer_ptr`](this.#handle, kind);
    const len = this.#e[`${family === 'points' ? 'points' : 'splat'}_buffer_len`](this.#handle, kind);
    if (len === 0) return null;
    return new Type(this.#e.memory.buffer.slice(ptr, ptr + len * Type.BYTES_PER_ELEMENT));
  }

  /**
   * Runs the splat preprocessing on the points decoded so far.
   * @param {number} sharpThreshold w_s (seed 002; 0.9 by default)
   * @returns {import('./splat-renderer.js').SplatSet}
   */
  splats(sharpThreshold = 0.9) {
    if (this.#e.points_splats(this.#handle, sharpThreshold) !== 0) throw this.codec.lastError();
    const count = this.count;
    return {
      count,
      positions: /** @type {Float32Array} */ (this.#copy('points', POINT_POSITIONS, Float32Array)),
      normals: /** @type {Float32Array} */ (this.#copy('points', POINT_NORMALS, Float32Array)),
      colours: /** @type {Uint8Array | null} */ (this.#copy('points', POINT_COLOURS, Uint8Array)),
      radii: drawnRadii(/** @type {Float32Array} */ (this.#copy('splats', SPLAT_RADII, Float32Array))),
      surfaceIds: /** @type {Uint32Array} */ (this.#copy('splats', SPLAT_SURFACE_IDS, Uint32Array)),
      clip: /** @type {Uint32Array} */ (this.#copy('splats', SPLAT_CLIP, Uint32Array)),
      planes: /** @type {Float32Array} */ (this.#copy('splats', SPLAT_PLANES, Float32Array) ?? new Float32Array(0)),
    };
  }

  free() {
    this.#e.points_free(this.#handle);
  }
}

/**
 * A point's splat radius (the mean distance to its 5 nearest neighbours)
 * leaves holes in a random sample; drawn 1.5 times as wide there are none
 * on a jittered cube over 24 views (codec/points/tests/silhouette.rs: 1,741
 * hole pixels at 1.0, 61 at 1.2, none from 1.5). Clip planes do not depend
 * on it.
 */
export const POINT_RADIUS_SCALE = 1.5;

/**
 * @param {Float32Array} radii scaled in place
 * @returns {Float32Array}
 */
function drawnRadii(radii) {
  for (let i = 0; i < radii.length; i++) radii[i] *= POINT_RADIUS_SCALE;
  return radii;
}
