// @ts-check
/**
 * Colour through a cubic cell complex (CCC, codec/colour/CCC.md; thesis ch. 5):
 * a fragment at world position p finds its colour the same way at every
 * level — grid cube → cell → central projection onto the cube's faces →
 * tile → bilinear texel — so the viewer needs no per-vertex UVs and the
 * colour of a coarse level is the full-resolution surface's.
 *
 * The lookup is written twice, like the lighting in shading.js: as GLSL for
 * the fragment shader (`GLSL_CCC`) and as JavaScript (`CellComplex`), which
 * the Node tests check against hand-made complexes and the end-to-end test
 * checks the shader against. codec/colour/src/ccc/lookup.rs is the Rust twin.
 */

/**
 * The parameters the manifest carries (`colour.parameters`).
 * @typedef {object} CccParameters
 * @property {number} version
 * @property {[number, number, number]} origin world position of the grid's minimum corner
 * @property {number} cell_size edge of one cube, model units
 * @property {[number, number, number]} dims cubes per axis
 * @property {number} cells
 * @property {{ width: number, height: number, cells_offset: number }} cell_texture
 * @property {number} tile_size tile interior, texels per side
 * @property {number} gutter
 * @property {{ width: number, height: number, tiles_per_row: number, tiles: number }} atlas
 * @property {number} low_res_factor
 * @property {[number, number, number]} fallback_colour sRGB bytes
 */

/**
 * A decoded image: rows top to bottom, `channels` bytes per pixel.
 * @typedef {{ width: number, height: number, channels: number, data: Uint8Array }} Pixels
 */

/** Texels per cell after the grid: centre, first tile, face mask, mean colour. */
export const CELL_TEXELS = 4;

export class CccError extends Error {}

/**
 * Checks that the parameters describe a complex the viewer can draw and that
 * the cell texture is the size they say.
 * @param {CccParameters} p
 * @param {{ width: number, height: number }} [cellTexture] the decoded cell texture
 */
export function checkParameters(p, cellTexture) {
  if (!p || p.version !== 1) throw new CccError(`colour mapping version ${p?.version} is not supported (1 is)`);
  const positive = (/** @type {number} */ n) => Number.isInteger(n) && n > 0;
  if (!p.dims.every(positive) || !(p.cell_size > 0) || !p.origin.every(Number.isFinite)) {
    throw new CccError('the colour mapping has an empty grid');
  }
  const cubes = p.dims[0] * p.dims[1] * p.dims[2];
  const { width, height, cells_offset } = p.cell_texture;
  if (cells_offset !== cubes || cubes + CELL_TEXELS * p.cells > width * height) {
    throw new CccError('the cell texture cannot hold the grid and its cells');
  }
  if (!positive(p.tile_size) || !(p.gutter >= 0) || !positive(p.atlas.tiles_per_row) || !positive(p.low_res_factor)) {
    throw new CccError('the colour mapping has no tile layout');
  }
  if (cellTexture && (cellTexture.width !== width || cellTexture.height !== height)) {
    throw new CccError(`the cell texture is ${cellTexture.width}×${cellTexture.height}, not ${width}×${height}`);
  }
}

/**
 * The result of a lookup before the atlas is sampled.
 * @typedef {{ kind: 'fallback' | 'mean', colour: [number, number, number] }
 *   | { kind: 'tile', tile: number, face: number, uv: [number, number], x: number, y: number }} Lookup
 * `x`, `y`: the atlas position to sample, in full-resolution texel units
 * (texel centres at i + 0.5), already clamped inside the tile.
 */

/** The complex read from its cell texture, as the shader reads it. */
export class CellComplex {
  /**
   * @param {CccParameters} parameters
   * @param {Pixels} cells the decoded cell texture (RGB or RGBA)
   */
  constructor(parameters, cells) {
    checkParameters(parameters, cells);
    if (cells.channels < 3) throw new CccError('the cell texture has fewer than three channels');
    this.p = parameters;
    this.cells = cells;
  }

  /**
   * 24-bit number at linear index i.
   * @param {number} i
   */
  number(i) {
    const at = i * this.cells.channels;
    const d = this.cells.data;
    return d[at] | (d[at + 1] << 8) | (d[at + 2] << 16);
  }

  /**
   * @param {number} i
   * @returns {[number, number, number]}
   */
  texel(i) {
    const at = i * this.cells.channels;
    const d = this.cells.data;
    return [d[at], d[at + 1], d[at + 2]];
  }

  /**
   * Where the colour of world position p comes from.
   * @param {ArrayLike<number>} point
   * @param {number} [inset] how far inside the tile's interior the sample point stays, in
   *   full-resolution texels: 0.5 (CCC.md) for the full atlas; see `sampleInset`
   * @returns {Lookup}
   */
  lookup(point, inset = 0.5) {
    const p = this.p;
    const fallback = /** @type {[number, number, number]} */ (p.fallback_colour.map((c) => c / 255));
    const g = [0, 1, 2].map((a) => (point[a] - p.origin[a]) / p.cell_size);
    const cube = g.map(Math.floor);
    if (cube.some((c, a) => c < 0 || c >= p.dims[a])) return { kind: 'fallback', colour: fallback };
    const cell = this.number(cube[0] + p.dims[0] * (cube[1] + p.dims[1] * cube[2])) - 1;
    if (cell < 0 || cell >= p.cells) return { kind: 'fallback', colour: fallback };
    const base = p.cell_texture.cells_offset + CELL_TEXELS * cell;
    const centre = this.texel(base).map((q) => (q + 0.5) / 256);
    const first = this.number(base + 1);
    const mask = this.texel(base + 2)[0];
    const mean = /** @type {[number, number, number]} */ (this.texel(base + 3).map((c) => c / 255));
    const local = g.map((c, a) => c - cube[a]);
    const d = local.map((c, a) => c - centre[a]);
    const exit = exitFace(centre, d);
    if (!exit) return { kind: 'mean', colour: mean };
    const { face, uv } = exit;
    if (!(mask & (1 << face))) return { kind: 'mean', colour: mean };
    const tile = first + popcount(mask & ((1 << face) - 1));
    const t = p.tile_size;
    const gutter = p.gutter;
    const side = t + 2 * gutter;
    const col = tile % p.atlas.tiles_per_row;
    const row = Math.floor(tile / p.atlas.tiles_per_row);
    const inTile = uv.map((c) => Math.min(Math.max(gutter + c * t, gutter + inset), gutter + t - inset));
    return { kind: 'tile', tile, face, uv, x: col * side + inTile[0], y: row * side + inTile[1] };
  }

  /**
   * Colour (sRGB, 0–1) at world position p, sampling `atlas` (the full or
   * the low-resolution colour texture) bilinearly like the GPU.
   * @param {ArrayLike<number>} point
   * @param {Pixels} atlas
   * @returns {[number, number, number]}
   */
  colourAt(point, atlas) {
    const scale = atlas.width / this.p.atlas.width;
    const found = this.lookup(point, sampleInset(this.p, scale));
    if (found.kind !== 'tile') return found.colour;
    return bilinear(atlas, found.x * scale, found.y * scale);
  }
}

/**
 * How far inside a tile's interior the sample point is kept, in
 * full-resolution texels. Full atlas: half a texel, so bilinear filtering
 * reads the tile and its gutter only (CCC.md, "Atlas"). Low-resolution atlas
 * (scale 1/f): half a low-resolution texel, f/2, so the filter's footprint
 * stays over the tile's interior rather than reaching across a gutter that
 * the reduction has shrunk below one texel into the next tile (at most half
 * the tile, for tiles smaller than f).
 * @param {CccParameters} p
 * @param {number} scale atlas texels per layout texel
 */
export function sampleInset(p, scale) {
  return Math.min(Math.max(0.5, 0.5 / scale), p.tile_size / 2);
}

/**
 * The face the ray from the centre along d leaves the unit cube by, and the
 * exit point's face coordinates; null when d = 0. Faces: 0 +x, 1 −x, 2 +y,
 * 3 −y, 4 +z, 5 −z; ties go to the lower axis.
 * @param {number[]} centre in cube units
 * @param {number[]} d
 * @returns {{ face: number, uv: [number, number] } | null}
 */
export function exitFace(centre, d) {
  let best = Infinity;
  let axis = -1;
  for (let a = 0; a < 3; a++) {
    if (d[a] === 0) continue;
    const t = ((d[a] > 0 ? 1 : 0) - centre[a]) / d[a];
    if (t < best) {
      best = t;
      axis = a;
    }
  }
  if (axis < 0) return null;
  const e = centre.map((c, a) => c + d[a] * best);
  const [b0, b1] = axis === 0 ? [1, 2] : axis === 1 ? [0, 2] : [0, 1];
  const clamp = (/** @type {number} */ v) => Math.min(Math.max(v, 0), 1);
  return { face: 2 * axis + (d[axis] < 0 ? 1 : 0), uv: [clamp(e[b0]), clamp(e[b1])] };
}

/** @param {number} n */
function popcount(n) {
  let count = 0;
  for (let m = n; m; m &= m - 1) count++;
  return count;
}

/**
 * Bilinear sample at texel-space coordinates (texel centres at i + 0.5),
 * edges clamped: what LINEAR filtering with CLAMP_TO_EDGE does.
 * @param {Pixels} image
 * @param {number} x
 * @param {number} y
 * @returns {[number, number, number]}
 */
export function bilinear(image, x, y) {
  const { width, height, channels, data } = image;
  const fx0 = x - 0.5;
  const fy0 = y - 0.5;
  const x0 = Math.floor(fx0);
  const y0 = Math.floor(fy0);
  const fx = fx0 - x0;
  const fy = fy0 - y0;
  const at = (/** @type {number} */ xi, /** @type {number} */ yi) =>
    (Math.min(Math.max(yi, 0), height - 1) * width + Math.min(Math.max(xi, 0), width - 1)) * channels;
  const [a, b, c, d] = [at(x0, y0), at(x0 + 1, y0), at(x0, y0 + 1), at(x0 + 1, y0 + 1)];
  return /** @type {[number, number, number]} */ (
    [0, 1, 2].map((k) => {
      const top = data[a + k] * (1 - fx) + data[b + k] * fx;
      const bottom = data[c + k] * (1 - fx) + data[d + k] * fx;
      return (top * (1 - fy) + bottom * fy) / 255;
    })
  );
}

/**
 * The shader's lookup. Uniforms are set by the renderer from the
 * parameters (`cccUniforms`); the cell texture is an RGBA8UI texture read
 * with texelFetch, so every byte arrives as the integer it is.
 */
export const GLSL_CCC = `
uniform highp usampler2D u_cells;
uniform sampler2D u_atlas;
uniform vec3 u_origin;
uniform float u_cellSize;
uniform ivec3 u_dims;
uniform int u_cellsOffset;
uniform int u_cellsWidth;
uniform int u_cellCount;
uniform vec3 u_tile;       // tile_size, gutter, inset (sampleInset)
uniform int u_tilesPerRow;
uniform vec2 u_atlasScale; // layout texels -> normalized atlas coordinates
uniform vec3 u_fallback;

uvec3 cccTexel(int i) {
  return texelFetch(u_cells, ivec2(i % u_cellsWidth, i / u_cellsWidth), 0).rgb;
}

int cccNumber(uvec3 t) {
  return int(t.r | (t.g << 8u) | (t.b << 16u));
}

vec3 cccColour(vec3 p) {
  vec3 g = (p - u_origin) / u_cellSize;
  ivec3 cube = ivec3(floor(g));
  if (any(lessThan(cube, ivec3(0))) || any(greaterThanEqual(cube, u_dims))) return u_fallback;
  int cell = cccNumber(cccTexel(cube.x + u_dims.x * (cube.y + u_dims.y * cube.z))) - 1;
  if (cell < 0 || cell >= u_cellCount) return u_fallback;
  int base = u_cellsOffset + ${CELL_TEXELS} * cell;
  vec3 centre = (vec3(cccTexel(base)) + 0.5) / 256.0;
  int first = cccNumber(cccTexel(base + 1));
  int mask = int(cccTexel(base + 2).r);
  vec3 mean = vec3(cccTexel(base + 3)) / 255.0;
  vec3 d = (g - vec3(cube)) - centre;
  float best = 0.0;
  int axis = -1;
  for (int a = 0; a < 3; a++) {
    if (d[a] == 0.0) continue;
    float t = ((d[a] > 0.0 ? 1.0 : 0.0) - centre[a]) / d[a];
    if (axis < 0 || t < best) {
      best = t;
      axis = a;
    }
  }
  if (axis < 0) return mean;
  int face = 2 * axis + (d[axis] < 0.0 ? 1 : 0);
  if ((mask & (1 << face)) == 0) return mean;
  vec3 e = centre + d * best;
  vec2 uv = clamp(axis == 0 ? e.yz : (axis == 1 ? e.xz : e.xy), 0.0, 1.0);
  int below = mask & ((1 << face) - 1);
  int tile = first;
  for (int f = 0; f < 6; f++) tile += (below >> f) & 1;
  float size = u_tile.x;
  float gutter = u_tile.y;
  vec2 corner = vec2(float(tile % u_tilesPerRow), float(tile / u_tilesPerRow)) * (size + 2.0 * gutter);
  vec2 inTile = clamp(gutter + uv * size, gutter + u_tile.z, gutter + size - u_tile.z);
  return texture(u_atlas, (corner + inTile) * u_atlasScale).rgb;
}`;

/**
 * Uniform values for GLSL_CCC.
 * @param {CccParameters} p
 * @param {{ width: number, height: number }} atlas the colour texture in use (full or low resolution)
 */
export function cccUniforms(p, atlas) {
  const scale = atlas.width / p.atlas.width;
  return {
    u_origin: p.origin,
    u_cellSize: p.cell_size,
    u_dims: p.dims,
    u_cellsOffset: p.cell_texture.cells_offset,
    u_cellsWidth: p.cell_texture.width,
    u_cellCount: p.cells,
    u_tile: [p.tile_size, p.gutter, sampleInset(p, scale)],
    u_tilesPerRow: p.atlas.tiles_per_row,
    u_atlasScale: [scale / atlas.width, scale / atlas.height],
    u_fallback: p.fallback_colour.map((c) => c / 255),
  };
}
