// @ts-check
/**
 * The renderer's one shader program: its GLSL (lighting from shading.js, the
 * CCC colour lookup from ccc.js, the relief view's θ ramp from relief.js),
 * its uniforms (with the visitor's look: model rotation, key light, clay,
 * section plane; see bindLook), and the two textures the
 * CCC lookup samples (the cell texture on unit 0, the colour texture on
 * unit 1). renderer.js decides when each is made and bound.
 */

import { GLSL_CCC, cccUniforms } from './ccc.js';
import { GLSL_RELIEF } from './relief.js';
import { CLAY, GLSL_SHADE, KEY, WIRE_ALPHA, WIRE_COLOUR, halfVector } from './shading.js';

/** The colour of the cut where the section plane opens the model (its inside: back faces). */
export const SECTION_COLOUR = /** @type {[number, number, number]} */ ([0.86, 0.47, 0.26]);

/**
 * How the visitor looks at the model, beside the camera: the model's
 * rotation (frame.js upRotation: its up axis onto +Y), the key light
 * (light.js), clay instead of the model's colour, and the section plane
 * (unit normal and offset in upright world coordinates: what lies where
 * n·p > d is cut away; null: no section).
 * @typedef {object} Look
 * @property {number[]} model column-major 3×3
 * @property {import('./light.js').Light} light
 * @property {boolean} clay
 * @property {[number, number, number, number] | null} section
 * @property {import('./geometry.js').Bounds | null} bounds the model's bounds (model coordinates,
 *   from the manifest; null: the base mesh's): what the camera frames (frame.js frameBox)
 */

/** @type {Look} */
export const DEFAULT_LOOK = { model: [1, 0, 0, 0, 1, 0, 0, 0, 1], light: { key: KEY, fill: 1 }, clay: false, section: null, bounds: null };

export const VERTEX_SHADER = `#version 300 es
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
layout(location = 2) in vec3 a_colour;
layout(location = 3) in float a_theta;
uniform mat4 u_view;
uniform mat4 u_viewProjection;
uniform mat3 u_model;
out vec3 v_normal;
out vec3 v_colour;
out vec3 v_world;
out vec3 v_upright;
out float v_theta;
void main() {
  v_normal = mat3(u_view) * (u_model * a_normal);
  v_colour = a_colour;
  v_theta = a_theta;
  // Model coordinates for the colour lookup, upright ones for the section plane.
  v_world = a_position;
  v_upright = u_model * a_position;
  gl_Position = u_viewProjection * vec4(v_upright, 1.0);
}`;

export const FRAGMENT_SHADER = `#version 300 es
precision highp float;
in vec3 v_normal;
in vec3 v_colour;
in vec3 v_world;
in vec3 v_upright;
in float v_theta;
uniform bool u_wire;
uniform bool u_clay;
uniform bool u_sectionOn;
uniform vec4 u_section;
uniform bool u_ccc;
uniform bool u_relief;
uniform float u_reliefTop;
out vec4 o_colour;
${GLSL_SHADE}
${GLSL_CCC}
${GLSL_RELIEF}
void main() {
  // The section plane: the half beyond it is cut away.
  if (u_sectionOn && dot(v_upright, u_section.xyz) > u_section.w) discard;
  if (u_wire) {
    o_colour = vec4(${WIRE_COLOUR.join(', ')}, ${WIRE_ALPHA});
    return;
  }
  // Vertices on no face have a zero normal: light them as facing the eye.
  vec3 n = dot(v_normal, v_normal) > 0.0 ? normalize(v_normal) : vec3(0.0, 0.0, 1.0);
  // Where the section opens the model, its inside shows as the cut.
  if (u_sectionOn && !gl_FrontFacing) {
    o_colour = vec4(vec3(${SECTION_COLOUR.join(', ')}) * (0.55 + 0.45 * abs(normalize(v_normal).z)), 1.0);
    return;
  }
  // Scans have holes: the inside is lit like the outside.
  if (!gl_FrontFacing) n = -n;
  // The relief view: θ (radians) on the ramp from 0 to the level's scale top, under a head-light.
  if (u_relief) {
    o_colour = vec4(reliefShade(n, v_theta / u_reliefTop), 1.0);
    return;
  }
  // Colour from the cell complex (the same texture at every level) or per vertex.
  vec3 albedo = u_clay ? vec3(${CLAY.join(', ')}) : u_ccc ? cccColour(v_world) : v_colour;
  o_colour = vec4(shade(n, albedo), 1.0);
}`;

/** @typedef {Record<string, WebGLUniformLocation | null>} Uniforms */

/**
 * Compiles and links the program, looks up its uniforms and leaves it in
 * use with the samplers on their fixed units. A lost context makes no
 * error: the program is made again when the context is restored.
 * @param {WebGL2RenderingContext} gl
 * @returns {{ program: WebGLProgram, uniforms: Uniforms }}
 */
export function createProgram(gl) {
  const program = gl.createProgram();
  for (const [type, source] of [
    [gl.VERTEX_SHADER, VERTEX_SHADER],
    [gl.FRAGMENT_SHADER, FRAGMENT_SHADER],
  ]) {
    const shader = /** @type {WebGLShader} */ (gl.createShader(/** @type {number} */ (type)));
    gl.shaderSource(shader, /** @type {string} */ (source));
    gl.compileShader(shader);
    if (!gl.getShaderParameter(shader, gl.COMPILE_STATUS) && !gl.isContextLost()) {
      throw new Error(`shader: ${gl.getShaderInfoLog(shader)}`);
    }
    gl.attachShader(program, shader);
  }
  gl.linkProgram(program);
  if (!gl.getProgramParameter(program, gl.LINK_STATUS) && !gl.isContextLost()) {
    throw new Error(`program: ${gl.getProgramInfoLog(program)}`);
  }
  /** @type {Uniforms} */
  const uniforms = {};
  const names = ['u_view', 'u_viewProjection', 'u_model', 'u_key', 'u_keyHalf', 'u_fillScale', 'u_clay', 'u_sectionOn', 'u_section', 'u_wire', 'u_ccc', 'u_relief', 'u_reliefTop', 'u_cells', 'u_atlas'];
  for (const name of [...names, ...Object.keys(cccUniforms(PLACEHOLDER, { width: 1, height: 1 }))]) {
    uniforms[name] = gl.getUniformLocation(program, name);
  }
  // Fixed texture units: an integer and a float sampler may not share one.
  gl.useProgram(program);
  gl.uniform1i(uniforms.u_cells, 0);
  gl.uniform1i(uniforms.u_atlas, 1);
  bindLook(gl, uniforms, DEFAULT_LOOK);
  return { program, uniforms };
}

/**
 * The look's uniforms (the program in use).
 * @param {WebGL2RenderingContext} gl
 * @param {Uniforms} u
 * @param {Look} look
 */
export function bindLook(gl, u, look) {
  gl.uniformMatrix3fv(u.u_model, false, look.model);
  gl.uniform3fv(u.u_key, look.light.key);
  gl.uniform3fv(u.u_keyHalf, halfVector(look.light.key));
  gl.uniform1f(u.u_fillScale, look.light.fill);
  gl.uniform1i(u.u_clay, look.clay ? 1 : 0);
  gl.uniform1i(u.u_sectionOn, look.section ? 1 : 0);
  if (look.section) gl.uniform4fv(u.u_section, look.section);
}

/**
 * The cell texture on unit 0: RGBA8UI read with texelFetch, so integers,
 * no filtering, no colour conversion. RGB data is widened to RGBA (RGB8UI
 * rows need not be 4-byte aligned, and RGBA8UI is the format every GPU
 * renders to).
 * @param {WebGL2RenderingContext} gl
 * @param {import('./ccc.js').Pixels} cells
 */
export function createCellTexture(gl, cells) {
  const { width, height, channels, data } = cells;
  let rgba = data;
  if (channels !== 4) {
    rgba = new Uint8Array(width * height * 4);
    for (let i = 0, j = 0; i < width * height; i++, j += channels) {
      rgba[4 * i] = data[j];
      rgba[4 * i + 1] = data[j + 1];
      rgba[4 * i + 2] = data[j + 2];
      rgba[4 * i + 3] = 255;
    }
  }
  const texture = gl.createTexture();
  gl.activeTexture(gl.TEXTURE0);
  gl.bindTexture(gl.TEXTURE_2D, texture);
  gl.pixelStorei(gl.UNPACK_ALIGNMENT, 1);
  gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA8UI, width, height, 0, gl.RGBA_INTEGER, gl.UNSIGNED_BYTE, rgba);
  gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER, gl.NEAREST);
  gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MAG_FILTER, gl.NEAREST);
  gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_S, gl.CLAMP_TO_EDGE);
  gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_T, gl.CLAMP_TO_EDGE);
  return texture;
}

/**
 * The colour texture (atlas) on unit 1, bytes as stored: no colour-space
 * conversion, no premultiplication, row 0 at the top (the atlas layout's y
 * grows downward, like t). Leaves unit 1 active.
 * @param {WebGL2RenderingContext} gl
 * @param {TexImageSource} source
 */
export function createAtlasTexture(gl, source) {
  const texture = gl.createTexture();
  gl.activeTexture(gl.TEXTURE1);
  gl.bindTexture(gl.TEXTURE_2D, texture);
  gl.pixelStorei(gl.UNPACK_COLORSPACE_CONVERSION_WEBGL, gl.NONE);
  gl.pixelStorei(gl.UNPACK_PREMULTIPLY_ALPHA_WEBGL, false);
  gl.pixelStorei(gl.UNPACK_FLIP_Y_WEBGL, false);
  gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA8, gl.RGBA, gl.UNSIGNED_BYTE, source);
  // Bilinear, no mipmaps: a mip level would blend neighbouring tiles.
  gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER, gl.LINEAR);
  gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MAG_FILTER, gl.LINEAR);
  gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_S, gl.CLAMP_TO_EDGE);
  gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_T, gl.CLAMP_TO_EDGE);
  return texture;
}

/**
 * The CCC lookup's switch, textures and uniforms: off (per-vertex colour or
 * clay) when `ccc` is null.
 * @param {WebGL2RenderingContext} gl
 * @param {Uniforms} u
 * @param {{ parameters: import('./ccc.js').CccParameters, atlas: { width: number, height: number },
 *   cellTexture: WebGLTexture, atlasTexture: WebGLTexture } | null} ccc
 */
export function bindCcc(gl, u, ccc) {
  gl.uniform1i(u.u_ccc, ccc ? 1 : 0);
  if (!ccc) return;
  gl.activeTexture(gl.TEXTURE0);
  gl.bindTexture(gl.TEXTURE_2D, ccc.cellTexture);
  gl.activeTexture(gl.TEXTURE1);
  gl.bindTexture(gl.TEXTURE_2D, ccc.atlasTexture);
  gl.activeTexture(gl.TEXTURE0);
  const values = cccUniforms(ccc.parameters, ccc.atlas);
  gl.uniform3fv(u.u_origin, values.u_origin);
  gl.uniform1f(u.u_cellSize, values.u_cellSize);
  gl.uniform3iv(u.u_dims, values.u_dims);
  gl.uniform1i(u.u_cellsOffset, values.u_cellsOffset);
  gl.uniform1i(u.u_cellsWidth, values.u_cellsWidth);
  gl.uniform1i(u.u_cellCount, values.u_cellCount);
  gl.uniform3fv(u.u_tile, values.u_tile);
  gl.uniform1i(u.u_tilesPerRow, values.u_tilesPerRow);
  gl.uniform2fv(u.u_atlasScale, values.u_atlasScale);
  gl.uniform3fv(u.u_fallback, values.u_fallback);
}

/**
 * The relief view's switch and scale: on with the top of the θ scale in
 * degrees (θ at or above it takes the ramp's last colour), off when null.
 * @param {WebGL2RenderingContext} gl
 * @param {Uniforms} u
 * @param {number | null} topDegrees
 */
export function bindRelief(gl, u, topDegrees) {
  gl.uniform1i(u.u_relief, topDegrees === null ? 0 : 1);
  if (topDegrees !== null) gl.uniform1f(u.u_reliefTop, (topDegrees * Math.PI) / 180);
}

/** Parameters that only name the uniforms (their values are not used). */
const PLACEHOLDER = /** @type {import('./ccc.js').CccParameters} */ ({
  version: 1,
  origin: [0, 0, 0],
  cell_size: 1,
  dims: [1, 1, 1],
  cells: 0,
  cell_texture: { width: 1, height: 1, cells_offset: 1 },
  tile_size: 1,
  gutter: 0,
  atlas: { width: 1, height: 1, tiles_per_row: 1, tiles: 0 },
  low_res_factor: 1,
  fallback_colour: [0, 0, 0],
});
