// @ts-check
/**
 * Raw WebGL2 rather than a scene library: the viewer draws one indexed mesh
 * with one shader, and three.js alone would be ~170 KB gzipped of script for
 * a tablet to fetch and parse before the base mesh could appear; this file,
 * the camera and the controls are a few KB.
 *
 * A new level is uploaded into fresh buffers a slice per frame (at most
 * UPLOAD_BUDGET_MS of bufferSubData), while the previous level keeps being
 * drawn; the two are swapped when the upload is complete. So a 40 MB level
 * never becomes one long main-thread task. A fence after each frame's
 * commands holds the next slice back until the GPU has caught up: otherwise
 * a slow GPU (a tablet's, or SwiftShader) fills the command buffer and the
 * next bufferSubData blocks the main thread until it drains. The level's arrays are kept so a
 * lost WebGL context can be rebuilt without asking the worker again.
 */

import { multiply } from './camera.js';
import { GLSL_CCC, cccUniforms } from './ccc.js';
import { BACKGROUND, CLAY, GLSL_SHADE, WIRE_ALPHA, WIRE_COLOUR } from './shading.js';

const UPLOAD_BUDGET_MS = 6;
const UPLOAD_CHUNK_BYTES = 256 << 10;

const VERTEX_SHADER = `#version 300 es
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
layout(location = 2) in vec3 a_colour;
uniform mat4 u_view;
uniform mat4 u_viewProjection;
out vec3 v_normal;
out vec3 v_colour;
out vec3 v_world;
void main() {
  v_normal = mat3(u_view) * a_normal;
  v_colour = a_colour;
  v_world = a_position;
  gl_Position = u_viewProjection * vec4(a_position, 1.0);
}`;

const FRAGMENT_SHADER = `#version 300 es
precision highp float;
in vec3 v_normal;
in vec3 v_colour;
in vec3 v_world;
uniform bool u_wire;
uniform bool u_ccc;
out vec4 o_colour;
${GLSL_SHADE}
${GLSL_CCC}
void main() {
  if (u_wire) {
    o_colour = vec4(${WIRE_COLOUR.join(', ')}, ${WIRE_ALPHA});
    return;
  }
  // Vertices on no face have a zero normal: light them as facing the eye.
  vec3 n = dot(v_normal, v_normal) > 0.0 ? normalize(v_normal) : vec3(0.0, 0.0, 1.0);
  // Scans have holes: the inside is lit like the outside.
  if (!gl_FrontFacing) n = -n;
  // Colour from the cell complex (the same texture at every level) or per vertex.
  vec3 albedo = u_ccc ? cccColour(v_world) : v_colour;
  o_colour = vec4(shade(n, albedo), 1.0);
}`;

/** @typedef {import('./reconstruction.js').LevelMessage} LevelMessage */

/**
 * @typedef {object} GpuMesh
 * @property {LevelMessage} source
 * @property {WebGLVertexArrayObject} vao
 * @property {WebGLBuffer[]} buffers
 * @property {WebGLBuffer} indexBuffer
 * @property {WebGLBuffer | null} edgeBuffer
 * @property {Array<{ target: number, buffer: WebGLBuffer, data: ArrayBufferView, offset: number }>} uploads
 */

/**
 * A CCC colour mapping as the renderer holds it: the sources are kept so a
 * lost context can be rebuilt.
 * @typedef {object} ColourMapping
 * @property {import('./ccc.js').CccParameters} parameters
 * @property {import('./ccc.js').Pixels} cells the decoded cell texture
 */

/** @typedef {'low' | 'full'} AtlasResolution */

export class Renderer {
  /** @type {WebGL2RenderingContext} */
  gl;
  /** @type {GpuMesh | null} */
  current = null;
  /** @type {GpuMesh | null} */
  pending = null;
  wireframe = false;
  lost = false;
  frames = 0;
  /** @type {number | null} */
  #raf = null;
  #dirty = false;
  /** @type {WebGLSync | null} */
  #fence = null;
  /** @type {WebGLProgram | null} */
  #program = null;
  /** @type {Record<string, WebGLUniformLocation | null>} */
  #uniforms = {};
  /** @type {ColourMapping | null} */
  #mapping = null;
  /** @type {{ source: TexImageSource, width: number, height: number, resolution: AtlasResolution } | null} */
  #atlas = null;
  /** @type {WebGLTexture | null} */
  #cellTexture = null;
  /** @type {WebGLTexture | null} */
  #atlasTexture = null;

  /**
   * @param {HTMLCanvasElement} canvas
   * @param {import('./camera.js').OrbitCamera | null} camera
   * @param {{ onSwap?: (level: LevelMessage) => void, onFrame?: () => void }} hooks
   */
  constructor(canvas, camera, hooks = {}) {
    this.canvas = canvas;
    this.camera = camera;
    this.hooks = hooks;
    const gl = canvas.getContext('webgl2', { antialias: true, powerPreference: 'high-performance' });
    if (!gl) throw new Error('this browser has no WebGL2');
    this.gl = gl;
    canvas.addEventListener('webglcontextlost', (event) => {
      event.preventDefault();
      this.lost = true;
      if (this.#raf !== null) cancelAnimationFrame(this.#raf);
      this.#raf = null;
    });
    canvas.addEventListener('webglcontextrestored', () => this.#restore());
    this.#init();
  }

  #init() {
    const gl = this.gl;
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
    this.#program = program;
    const names = ['u_view', 'u_viewProjection', 'u_wire', 'u_ccc', 'u_cells', 'u_atlas'];
    for (const name of [...names, ...Object.keys(cccUniforms(PLACEHOLDER, { width: 1, height: 1 }))]) {
      this.#uniforms[name] = gl.getUniformLocation(program, name);
    }
    // Fixed texture units: an integer and a float sampler may not share one.
    gl.useProgram(program);
    gl.uniform1i(this.#uniforms.u_cells, 0);
    gl.uniform1i(this.#uniforms.u_atlas, 1);
    gl.enable(gl.DEPTH_TEST);
    gl.clearColor(BACKGROUND[0], BACKGROUND[1], BACKGROUND[2], 1);
  }

  #restore() {
    this.lost = false;
    this.#fence = null;
    this.#cellTexture = null;
    this.#atlasTexture = null;
    this.#init();
    this.#uploadColour();
    const newest = this.pending?.source ?? this.current?.source;
    this.current = null;
    this.pending = null;
    if (newest) this.show(newest);
    this.requestFrame();
  }

  /**
   * Starts uploading a level; the newest level wins over one still uploading.
   * @param {LevelMessage} level
   */
  show(level) {
    if (this.lost) {
      this.pending = { ...emptyMesh(), source: level };
      return;
    }
    if (this.pending) this.#release(this.pending);
    this.pending = this.#allocate(level);
    this.#schedule();
  }

  /**
   * Wire edges computed after the level was sent (wireframe switched on).
   * @param {number} level
   * @param {Uint32Array} edges
   */
  addEdges(level, edges) {
    for (const mesh of [this.pending, this.current]) {
      if (mesh && mesh.source.level === level && !mesh.source.edges) {
        mesh.source.edges = edges;
        if (this.lost) continue;
        const gl = this.gl;
        mesh.edgeBuffer = gl.createBuffer();
        gl.bindVertexArray(null);
        gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, mesh.edgeBuffer);
        gl.bufferData(gl.ELEMENT_ARRAY_BUFFER, edges.byteLength, gl.STATIC_DRAW);
        mesh.uploads.push({ target: gl.ELEMENT_ARRAY_BUFFER, buffer: mesh.edgeBuffer, data: edges, offset: 0 });
      }
    }
    this.requestFrame();
  }

  /**
   * Sets (or clears) the CCC colour mapping. It is drawn once a colour
   * texture is set too (`setColourAtlas`); until then levels keep their
   * per-vertex colour, or clay.
   * @param {ColourMapping | null} mapping
   */
  setColourMapping(mapping) {
    this.#mapping = mapping;
    this.#atlas = null;
    this.#uploadColour();
    this.requestFrame();
  }

  /**
   * Sets the colour texture: the low-resolution one first, the full one
   * when it arrives. Uploaded at once (one texImage2D).
   * @param {TexImageSource & { width: number, height: number }} source a decoded JPEG (ImageBitmap)
   * @param {AtlasResolution} resolution
   */
  setColourAtlas(source, resolution) {
    this.#atlas = { source, width: source.width, height: source.height, resolution };
    this.#uploadColour();
    this.requestFrame();
  }

  /** Which colour texture is drawn: null without a CCC mapping. */
  get colourResolution() {
    return this.#mapping && this.#atlas ? this.#atlas.resolution : null;
  }

  /** The largest texture side this GPU takes. */
  get maxTextureSize() {
    return /** @type {number} */ (this.gl.getParameter(this.gl.MAX_TEXTURE_SIZE));
  }

  /** (Re)creates the GPU textures from the kept sources. */
  #uploadColour() {
    if (this.lost) return;
    const gl = this.gl;
    if (!this.#mapping) {
      if (this.#cellTexture) gl.deleteTexture(this.#cellTexture);
      this.#cellTexture = null;
    } else if (!this.#cellTexture) {
      // RGBA8UI read with texelFetch: integers, no filtering, no colour
      // conversion. RGB data is widened to RGBA (RGB8UI rows need not be
      // 4-byte aligned, and RGBA8UI is the format every GPU renders to).
      const { width, height, channels, data } = this.#mapping.cells;
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
      this.#cellTexture = gl.createTexture();
      gl.activeTexture(gl.TEXTURE0);
      gl.bindTexture(gl.TEXTURE_2D, this.#cellTexture);
      gl.pixelStorei(gl.UNPACK_ALIGNMENT, 1);
      gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA8UI, width, height, 0, gl.RGBA_INTEGER, gl.UNSIGNED_BYTE, rgba);
      gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER, gl.NEAREST);
      gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MAG_FILTER, gl.NEAREST);
      gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_S, gl.CLAMP_TO_EDGE);
      gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_T, gl.CLAMP_TO_EDGE);
    }
    if (this.#atlasTexture) gl.deleteTexture(this.#atlasTexture);
    this.#atlasTexture = null;
    if (this.#atlas) {
      this.#atlasTexture = gl.createTexture();
      gl.activeTexture(gl.TEXTURE1);
      gl.bindTexture(gl.TEXTURE_2D, this.#atlasTexture);
      // Bytes as stored: no colour-space conversion, no premultiplication,
      // row 0 at the top (the atlas layout's y grows downward, like t).
      gl.pixelStorei(gl.UNPACK_COLORSPACE_CONVERSION_WEBGL, gl.NONE);
      gl.pixelStorei(gl.UNPACK_PREMULTIPLY_ALPHA_WEBGL, false);
      gl.pixelStorei(gl.UNPACK_FLIP_Y_WEBGL, false);
      gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA8, gl.RGBA, gl.UNSIGNED_BYTE, this.#atlas.source);
      // Bilinear, no mipmaps: a mip level would blend neighbouring tiles.
      gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER, gl.LINEAR);
      gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MAG_FILTER, gl.LINEAR);
      gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_S, gl.CLAMP_TO_EDGE);
      gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_T, gl.CLAMP_TO_EDGE);
    }
    gl.activeTexture(gl.TEXTURE0);
  }

  /** @param {boolean} on */
  setWireframe(on) {
    this.wireframe = on;
    this.requestFrame();
  }

  /**
   * Draws now and reads the pixels back in the same task, before the
   * compositor clears the drawing buffer (tests and benchmarks).
   * @returns {{ width: number, height: number, rgba: Uint8Array }} rows bottom-up
   */
  capture() {
    const gl = this.gl;
    this.#draw();
    const { width, height } = this.canvas;
    const rgba = new Uint8Array(width * height * 4);
    gl.readPixels(0, 0, width, height, gl.RGBA, gl.UNSIGNED_BYTE, rgba);
    return { width, height, rgba };
  }

  /** Draws at the next animation frame (camera moved, resized, …). */
  requestFrame() {
    this.#dirty = true;
    this.#schedule();
  }

  #schedule() {
    if (this.#raf === null && !this.lost) this.#raf = requestAnimationFrame(() => this.#frame());
  }

  /**
   * Uploads a slice; draws only when something visible changed, so the GPU
   * (on tablets, or SwiftShader) is not redrawing an unchanged picture
   * while buffers stream in.
   */
  #frame() {
    this.#raf = null;
    if (this.lost) return;
    const gl = this.gl;
    const caughtUp = !this.#fence || gl.getSyncParameter(this.#fence, gl.SYNC_STATUS) === gl.SIGNALED;
    let issued = false;
    const pending = this.pending;
    if (pending && caughtUp) {
      issued = true;
      if (this.#upload(pending)) {
        if (this.current) this.#release(this.current);
        this.current = pending;
        this.pending = null;
        this.#dirty = true;
        this.hooks.onSwap?.(pending.source);
      }
    } else if (this.current?.uploads.length && caughtUp) {
      issued = true;
      if (this.#upload(this.current)) this.#dirty = true;
    }
    if (this.#dirty) {
      this.#dirty = false;
      issued = true;
      this.#draw();
      this.frames++;
      this.hooks.onFrame?.();
    }
    if (issued) {
      if (this.#fence) gl.deleteSync(this.#fence);
      this.#fence = gl.fenceSync(gl.SYNC_GPU_COMMANDS_COMPLETE, 0);
      gl.flush();
    }
    if (this.pending || this.current?.uploads.length) this.#schedule();
  }

  /**
   * @param {LevelMessage} level
   * @returns {GpuMesh}
   */
  #allocate(level) {
    const gl = this.gl;
    const vao = /** @type {WebGLVertexArrayObject} */ (gl.createVertexArray());
    gl.bindVertexArray(vao);
    /** @type {GpuMesh['uploads']} */
    const uploads = [];
    /** @type {WebGLBuffer[]} */
    const buffers = [];
    /**
     * @param {number} target
     * @param {ArrayBufferView} data
     */
    const buffer = (target, data) => {
      const b = gl.createBuffer();
      gl.bindBuffer(target, b);
      gl.bufferData(target, data.byteLength, gl.STATIC_DRAW);
      uploads.push({ target, buffer: b, data, offset: 0 });
      buffers.push(b);
      return b;
    };
    buffer(gl.ARRAY_BUFFER, level.positions);
    gl.enableVertexAttribArray(0);
    gl.vertexAttribPointer(0, 3, gl.FLOAT, false, 0, 0);
    buffer(gl.ARRAY_BUFFER, level.normals);
    gl.enableVertexAttribArray(1);
    gl.vertexAttribPointer(1, 3, gl.SHORT, true, 0, 0);
    if (level.colours) {
      buffer(gl.ARRAY_BUFFER, level.colours);
      gl.enableVertexAttribArray(2);
      gl.vertexAttribPointer(2, 3, gl.UNSIGNED_BYTE, true, 0, 0);
    } else {
      gl.disableVertexAttribArray(2);
    }
    const indexBuffer = buffer(gl.ELEMENT_ARRAY_BUFFER, level.indices);
    gl.bindVertexArray(null);
    let edgeBuffer = null;
    if (level.edges) {
      edgeBuffer = buffer(gl.ELEMENT_ARRAY_BUFFER, level.edges);
      buffers.pop();
    }
    return { source: level, vao, buffers, indexBuffer, edgeBuffer, uploads };
  }

  /**
   * Uploads slices until the frame's budget is spent.
   * @param {GpuMesh} mesh
   * @returns {boolean} whether the mesh is complete
   */
  #upload(mesh) {
    const gl = this.gl;
    const start = performance.now();
    gl.bindVertexArray(null);
    while (mesh.uploads.length > 0 && performance.now() - start < UPLOAD_BUDGET_MS) {
      const job = mesh.uploads[0];
      const bytes = new Uint8Array(job.data.buffer, job.data.byteOffset, job.data.byteLength);
      const end = Math.min(bytes.length, job.offset + UPLOAD_CHUNK_BYTES);
      gl.bindBuffer(job.target, job.buffer);
      gl.bufferSubData(job.target, job.offset, bytes, job.offset, end - job.offset);
      job.offset = end;
      if (end === bytes.length) mesh.uploads.shift();
    }
    return mesh.uploads.length === 0;
  }

  /** @param {GpuMesh} mesh */
  #release(mesh) {
    const gl = this.gl;
    for (const b of mesh.buffers) gl.deleteBuffer(b);
    if (mesh.edgeBuffer) gl.deleteBuffer(mesh.edgeBuffer);
    gl.deleteVertexArray(mesh.vao);
  }

  /** Switches the shader to the CCC lookup when a mapping and a colour texture are on the GPU. */
  #bindColour() {
    const gl = this.gl;
    const on = Boolean(this.#mapping && this.#atlas && this.#cellTexture && this.#atlasTexture);
    gl.uniform1i(this.#uniforms.u_ccc, on ? 1 : 0);
    if (!on || !this.#mapping || !this.#atlas) return;
    gl.activeTexture(gl.TEXTURE0);
    gl.bindTexture(gl.TEXTURE_2D, this.#cellTexture);
    gl.activeTexture(gl.TEXTURE1);
    gl.bindTexture(gl.TEXTURE_2D, this.#atlasTexture);
    gl.activeTexture(gl.TEXTURE0);
    const u = this.#uniforms;
    const values = cccUniforms(this.#mapping.parameters, this.#atlas);
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

  #draw() {
    const gl = this.gl;
    gl.viewport(0, 0, this.canvas.width, this.canvas.height);
    gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT);
    const mesh = this.current;
    if (!mesh || !this.camera || !this.#program) return;
    const view = this.camera.view();
    const projection = this.camera.projection(this.canvas.width / Math.max(1, this.canvas.height));
    gl.useProgram(this.#program);
    gl.uniformMatrix4fv(this.#uniforms.u_view, false, view);
    gl.uniformMatrix4fv(this.#uniforms.u_viewProjection, false, multiply(projection, view));
    gl.bindVertexArray(mesh.vao);
    if (!mesh.source.colours) gl.vertexAttrib4f(2, CLAY[0], CLAY[1], CLAY[2], 1);
    const wire = this.wireframe && mesh.edgeBuffer && mesh.uploads.length === 0;
    if (wire) {
      // Push the surface back a little so the lines on it win the depth test.
      gl.enable(gl.POLYGON_OFFSET_FILL);
      gl.polygonOffset(1, 1);
    }
    gl.uniform1i(this.#uniforms.u_wire, 0);
    this.#bindColour();
    gl.drawElements(gl.TRIANGLES, mesh.source.indices.length, gl.UNSIGNED_INT, 0);
    gl.disable(gl.POLYGON_OFFSET_FILL);
    if (wire && mesh.source.edges) {
      // Translucent lines: dense levels stay readable instead of turning black.
      gl.enable(gl.BLEND);
      gl.blendFunc(gl.SRC_ALPHA, gl.ONE_MINUS_SRC_ALPHA);
      gl.depthMask(false);
      gl.uniform1i(this.#uniforms.u_wire, 1);
      gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, mesh.edgeBuffer);
      gl.drawElements(gl.LINES, mesh.source.edges.length, gl.UNSIGNED_INT, 0);
      gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, mesh.indexBuffer);
      gl.depthMask(true);
      gl.disable(gl.BLEND);
    }
    gl.bindVertexArray(null);
  }
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

/** @returns {Omit<GpuMesh, 'source'>} */
function emptyMesh() {
  const none = /** @type {any} */ (null);
  return { vao: none, buffers: [], indexBuffer: none, edgeBuffer: null, uploads: [] };
}
