// @ts-check
/**
 * Draws splats with WebGL2 in three passes (shaders.js): depth + surface id
 * into an R32UI target, additive accumulation into two RGBA16F targets, then
 * normalisation and Phong shading onto the canvas. Float render targets need
 * EXT_color_buffer_float; without it the constructor throws
 * {@link SplatUnsupported} with a message for the visitor.
 */

import { SHADERS } from './shaders.js';

/**
 * What the renderer draws, one entry per splat (the splat worker's output).
 * @typedef {object} SplatSet
 * @property {number} count
 * @property {Float32Array} positions x, y, z
 * @property {Float32Array} normals x, y, z (unit)
 * @property {Uint8Array | null} colours r, g, b (sRGB); null: clay grey
 * @property {Float32Array} radii
 * @property {Uint32Array} surfaceIds
 * @property {Uint32Array} clip one word per splat (clip.rs layout)
 * @property {Float32Array} planes a, b, c, d per plane
 */

/**
 * @typedef {object} SplatOptions
 * @property {boolean} surfaceIds accumulate only the front surface id (off: every
 *   fragment within the depth tolerance, as plain surface splatting does)
 * @property {boolean} clipping cut discs at their partner planes
 * @property {number} tolerance depth tolerance in splat radii
 * @property {number} scale radius factor
 */

/** @type {SplatOptions} */
export const DEFAULT_SPLAT_OPTIONS = { surfaceIds: true, clipping: true, tolerance: 1, scale: 1 };

export class SplatUnsupported extends Error {}

const PLANE_TEXTURE_WIDTH = 1024;
const CLAY = 190;
const IDENTITY = [1, 0, 0, 0, 1, 0, 0, 0, 1];

/**
 * @param {WebGL2RenderingContext} gl
 * @param {string} vertex
 * @param {string} fragment
 */
function program(gl, vertex, fragment) {
  const p = /** @type {WebGLProgram} */ (gl.createProgram());
  for (const [type, source] of /** @type {const} */ ([
    [gl.VERTEX_SHADER, vertex],
    [gl.FRAGMENT_SHADER, fragment],
  ])) {
    const s = /** @type {WebGLShader} */ (gl.createShader(type));
    gl.shaderSource(s, source);
    gl.compileShader(s);
    if (!gl.getShaderParameter(s, gl.COMPILE_STATUS)) throw new Error(`splat shader: ${gl.getShaderInfoLog(s)}`);
    gl.attachShader(p, s);
  }
  gl.linkProgram(p);
  if (!gl.getProgramParameter(p, gl.LINK_STATUS)) throw new Error(`splat program: ${gl.getProgramInfoLog(p)}`);
  /** @type {Record<string, WebGLUniformLocation | null>} */
  const u = {};
  const n = gl.getProgramParameter(p, gl.ACTIVE_UNIFORMS);
  for (let i = 0; i < n; i++) {
    const info = /** @type {WebGLActiveInfo} */ (gl.getActiveUniform(p, i));
    u[info.name] = gl.getUniformLocation(p, info.name);
  }
  return { p, u };
}

/**
 * 4×4 inverse (column-major), for the shading pass's view positions.
 * @param {Float32Array} m
 */
export function invert(m) {
  const [a00, a01, a02, a03, a10, a11, a12, a13, a20, a21, a22, a23, a30, a31, a32, a33] = m;
  const b00 = a00 * a11 - a01 * a10, b01 = a00 * a12 - a02 * a10, b02 = a00 * a13 - a03 * a10;
  const b03 = a01 * a12 - a02 * a11, b04 = a01 * a13 - a03 * a11, b05 = a02 * a13 - a03 * a12;
  const b06 = a20 * a31 - a21 * a30, b07 = a20 * a32 - a22 * a30, b08 = a20 * a33 - a23 * a30;
  const b09 = a21 * a32 - a22 * a31, b10 = a21 * a33 - a23 * a31, b11 = a22 * a33 - a23 * a32;
  const det = b00 * b11 - b01 * b10 + b02 * b09 + b03 * b08 - b04 * b07 + b05 * b06;
  const d = 1 / det;
  // prettier-ignore
  return new Float32Array([
    (a11 * b11 - a12 * b10 + a13 * b09) * d, (a02 * b10 - a01 * b11 - a03 * b09) * d,
    (a31 * b05 - a32 * b04 + a33 * b03) * d, (a22 * b04 - a21 * b05 - a23 * b03) * d,
    (a12 * b08 - a10 * b11 - a13 * b07) * d, (a00 * b11 - a02 * b08 + a03 * b07) * d,
    (a32 * b02 - a30 * b05 - a33 * b01) * d, (a20 * b05 - a22 * b02 + a23 * b01) * d,
    (a10 * b10 - a11 * b08 + a13 * b06) * d, (a01 * b08 - a00 * b10 - a03 * b06) * d,
    (a30 * b04 - a31 * b02 + a33 * b00) * d, (a21 * b02 - a20 * b04 - a23 * b00) * d,
    (a11 * b07 - a10 * b09 - a12 * b06) * d, (a00 * b09 - a01 * b07 + a02 * b06) * d,
    (a31 * b01 - a30 * b03 - a32 * b00) * d, (a20 * b03 - a21 * b01 + a22 * b00) * d,
  ]);
}

/** Near and far of a perspective matrix (camera.js `projection`). @param {Float32Array} p */
function nearFar(p) {
  const a = p[10];
  const b = p[14];
  return { near: b / (a - 1), far: b / (a + 1) };
}

export class SplatRenderer {
  /** @type {WebGL2RenderingContext} */
  gl;
  count = 0;
  /** @type {[number, number, number]} */
  background;
  #splat;
  #depth;
  #shade;
  #vao;
  /** @type {WebGLBuffer[]} */
  #buffers = [];
  #planes;
  /** @type {{ width: number, height: number, fbDepth: WebGLFramebuffer, fbAccum: WebGLFramebuffer, textures: WebGLTexture[] } | null} */
  #targets = null;

  /**
   * @param {WebGL2RenderingContext} gl
   * @param {[number, number, number]} background 0–1
   */
  constructor(gl, background) {
    this.gl = gl;
    this.background = background;
    if (!gl.getExtension('EXT_color_buffer_float')) {
      throw new SplatUnsupported('The splat view needs float render targets (EXT_color_buffer_float), which this browser does not offer.');
    }
    this.#splat = program(gl, SHADERS.splat, SHADERS.accumulate);
    this.#depth = program(gl, SHADERS.splat, SHADERS.depth);
    this.#shade = program(gl, SHADERS.shadeVertex, SHADERS.shade);
    this.#vao = /** @type {WebGLVertexArrayObject} */ (gl.createVertexArray());
    gl.bindVertexArray(this.#vao);
    const corners = this.#buffer(new Float32Array([-1, -1, 1, -1, -1, 1, 1, 1]));
    gl.bindBuffer(gl.ARRAY_BUFFER, corners);
    gl.enableVertexAttribArray(0);
    gl.vertexAttribPointer(0, 2, gl.FLOAT, false, 0, 0);
    gl.bindVertexArray(null);
    this.#planes = /** @type {WebGLTexture} */ (gl.createTexture());
    this.#planeTexture(new Float32Array(4));
  }

  /** @param {ArrayBufferView} data */
  #buffer(data) {
    const gl = this.gl;
    const b = /** @type {WebGLBuffer} */ (gl.createBuffer());
    gl.bindBuffer(gl.ARRAY_BUFFER, b);
    gl.bufferData(gl.ARRAY_BUFFER, data, gl.STATIC_DRAW);
    this.#buffers.push(b);
    return b;
  }

  /** @param {Float32Array} planes */
  #planeTexture(planes) {
    const gl = this.gl;
    const texels = Math.max(1, planes.length / 4);
    const width = Math.min(PLANE_TEXTURE_WIDTH, texels);
    const height = Math.ceil(texels / width);
    const data = new Float32Array(width * height * 4);
    data.set(planes);
    gl.bindTexture(gl.TEXTURE_2D, this.#planes);
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA32F, width, height, 0, gl.RGBA, gl.FLOAT, data);
    for (const p of [gl.TEXTURE_MIN_FILTER, gl.TEXTURE_MAG_FILTER]) gl.texParameteri(gl.TEXTURE_2D, p, gl.NEAREST);
  }

  /**
   * Replaces the splats on the GPU.
   * @param {SplatSet} s
   */
  setSplats(s) {
    const gl = this.gl;
    for (const b of this.#buffers.splice(1)) gl.deleteBuffer(b);
    gl.bindVertexArray(this.#vao);
    /** @param {number} loc @param {ArrayBufferView} data @param {number} size @param {number} type @param {boolean} normalized */
    const attribute = (loc, data, size, type, normalized) => {
      gl.bindBuffer(gl.ARRAY_BUFFER, this.#buffer(data));
      gl.enableVertexAttribArray(loc);
      if (type === gl.UNSIGNED_INT) gl.vertexAttribIPointer(loc, size, type, 0, 0);
      else gl.vertexAttribPointer(loc, size, type, normalized, 0, 0);
      gl.vertexAttribDivisor(loc, 1);
    };
    attribute(1, s.positions, 3, gl.FLOAT, false);
    attribute(2, s.normals, 3, gl.FLOAT, false);
    attribute(3, s.colours ?? new Uint8Array(s.count * 3).fill(CLAY), 3, gl.UNSIGNED_BYTE, true);
    attribute(4, s.radii, 1, gl.FLOAT, false);
    attribute(5, s.surfaceIds, 1, gl.UNSIGNED_INT, false);
    attribute(6, s.clip, 1, gl.UNSIGNED_INT, false);
    gl.bindVertexArray(null);
    this.#planeTexture(s.planes);
    this.count = s.count;
  }

  /** @param {number} width @param {number} height */
  #ensureTargets(width, height) {
    const gl = this.gl;
    if (this.#targets?.width === width && this.#targets.height === height) return this.#targets;
    if (this.#targets) {
      for (const t of this.#targets.textures) gl.deleteTexture(t);
      gl.deleteFramebuffer(this.#targets.fbDepth);
      gl.deleteFramebuffer(this.#targets.fbAccum);
    }
    /** @param {number} internal @param {number} format @param {number} type */
    const texture = (internal, format, type) => {
      const t = /** @type {WebGLTexture} */ (gl.createTexture());
      gl.bindTexture(gl.TEXTURE_2D, t);
      gl.texImage2D(gl.TEXTURE_2D, 0, internal, width, height, 0, format, type, null);
      for (const p of [gl.TEXTURE_MIN_FILTER, gl.TEXTURE_MAG_FILTER]) gl.texParameteri(gl.TEXTURE_2D, p, gl.NEAREST);
      return t;
    };
    const depth = texture(gl.DEPTH_COMPONENT32F, gl.DEPTH_COMPONENT, gl.FLOAT);
    const surface = texture(gl.R32UI, gl.RED_INTEGER, gl.UNSIGNED_INT);
    const colour = texture(gl.RGBA16F, gl.RGBA, gl.HALF_FLOAT);
    const normal = texture(gl.RGBA16F, gl.RGBA, gl.HALF_FLOAT);
    const fbDepth = /** @type {WebGLFramebuffer} */ (gl.createFramebuffer());
    gl.bindFramebuffer(gl.FRAMEBUFFER, fbDepth);
    gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.DEPTH_ATTACHMENT, gl.TEXTURE_2D, depth, 0);
    gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, surface, 0);
    const fbAccum = /** @type {WebGLFramebuffer} */ (gl.createFramebuffer());
    gl.bindFramebuffer(gl.FRAMEBUFFER, fbAccum);
    gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, colour, 0);
    gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT1, gl.TEXTURE_2D, normal, 0);
    gl.drawBuffers([gl.COLOR_ATTACHMENT0, gl.COLOR_ATTACHMENT1]);
    if (gl.checkFramebufferStatus(gl.FRAMEBUFFER) !== gl.FRAMEBUFFER_COMPLETE) {
      throw new SplatUnsupported('The splat view could not render to float targets in this browser.');
    }
    gl.bindFramebuffer(gl.FRAMEBUFFER, null);
    this.#targets = { width, height, fbDepth, fbAccum, textures: [depth, surface, colour, normal] };
    return this.#targets;
  }

  /**
   * Draws one frame onto the canvas (the default framebuffer).
   * @param {{ view: Float32Array, projection: Float32Array, width: number, height: number, model?: ArrayLike<number> }} camera
   *   model: the upright rotation (frame.js upRotation, column-major 3×3; identity without)
   * @param {SplatOptions} options
   */
  draw(camera, options) {
    const gl = this.gl;
    const { width, height } = camera;
    const t = this.#ensureTargets(width, height);
    const [depth, surface, colour, normal] = t.textures;
    const { near, far } = nearFar(camera.projection);
    gl.viewport(0, 0, width, height);
    gl.disable(gl.BLEND);
    gl.disable(gl.CULL_FACE);

    /** @param {{ p: WebGLProgram, u: Record<string, WebGLUniformLocation | null> }} prog */
    const discs = (prog) => {
      gl.useProgram(prog.p);
      gl.uniformMatrix4fv(prog.u.u_view, false, camera.view);
      gl.uniformMatrix4fv(prog.u.u_projection, false, camera.projection);
      gl.uniformMatrix3fv(prog.u.u_model, false, new Float32Array(camera.model ?? IDENTITY));
      gl.uniform1f(prog.u.u_scale, options.scale);
      gl.uniform1i(prog.u.u_clipping, options.clipping ? 1 : 0);
      gl.activeTexture(gl.TEXTURE0);
      gl.bindTexture(gl.TEXTURE_2D, this.#planes);
      gl.uniform1i(prog.u.u_planes, 0);
    };
    const instances = () => {
      gl.bindVertexArray(this.#vao);
      if (this.count > 0) gl.drawArraysInstanced(gl.TRIANGLE_STRIP, 0, 4, this.count);
      gl.bindVertexArray(null);
    };

    // (a) depth and surface id of the front fragment.
    gl.bindFramebuffer(gl.FRAMEBUFFER, t.fbDepth);
    gl.enable(gl.DEPTH_TEST);
    gl.depthFunc(gl.LESS);
    gl.depthMask(true);
    gl.clearBufferuiv(gl.COLOR, 0, new Uint32Array([0xffffffff, 0, 0, 0]));
    gl.clearBufferfv(gl.DEPTH, 0, new Float32Array([1]));
    discs(this.#depth);
    instances();

    // (b) additive accumulation of the front surface within the tolerance.
    gl.bindFramebuffer(gl.FRAMEBUFFER, t.fbAccum);
    gl.disable(gl.DEPTH_TEST);
    gl.depthMask(false);
    gl.clearBufferfv(gl.COLOR, 0, new Float32Array(4));
    gl.clearBufferfv(gl.COLOR, 1, new Float32Array(4));
    gl.enable(gl.BLEND);
    gl.blendFunc(gl.ONE, gl.ONE);
    const acc = this.#splat;
    discs(acc);
    gl.activeTexture(gl.TEXTURE1);
    gl.bindTexture(gl.TEXTURE_2D, depth);
    gl.uniform1i(acc.u.u_depth, 1);
    gl.activeTexture(gl.TEXTURE2);
    gl.bindTexture(gl.TEXTURE_2D, surface);
    gl.uniform1i(acc.u.u_front, 2);
    gl.uniform1i(acc.u.u_surfaceIds, options.surfaceIds ? 1 : 0);
    gl.uniform1f(acc.u.u_near, near);
    gl.uniform1f(acc.u.u_far, far);
    gl.uniform1f(acc.u.u_tolerance, options.tolerance);
    instances();
    gl.disable(gl.BLEND);

    // (c) normalise and shade.
    gl.bindFramebuffer(gl.FRAMEBUFFER, null);
    const sh = this.#shade;
    gl.useProgram(sh.p);
    gl.activeTexture(gl.TEXTURE0);
    gl.bindTexture(gl.TEXTURE_2D, colour);
    gl.uniform1i(sh.u.u_colour, 0);
    gl.activeTexture(gl.TEXTURE1);
    gl.bindTexture(gl.TEXTURE_2D, normal);
    gl.uniform1i(sh.u.u_normal, 1);
    gl.activeTexture(gl.TEXTURE2);
    gl.bindTexture(gl.TEXTURE_2D, depth);
    gl.uniform1i(sh.u.u_depth, 2);
    gl.uniformMatrix4fv(sh.u.u_inverseProjection, false, invert(camera.projection));
    gl.uniform2f(sh.u.u_size, width, height);
    gl.uniform3fv(sh.u.u_background, this.background);
    gl.drawArrays(gl.TRIANGLES, 0, 3);
    gl.depthMask(true);
  }
}
