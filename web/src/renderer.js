// @ts-check
/**
 * Raw WebGL2 rather than a scene library: the viewer draws one indexed mesh
 * with one shader, and three.js alone would be ~170 KB gzipped of script for
 * a tablet to fetch and parse before the base mesh could appear; this file,
 * the camera and the controls are a few KB.
 *
 * Vertices are only ever appended from one level to the next, so positions
 * and colours live in one pair of buffers sized once for the last level
 * (the manifest's count): each level uploads only its new vertices there.
 * Normals and indices change everywhere; a new level gets fresh ones,
 * uploaded a slice per frame (at most `uploadBudgetMs` of bufferSubData)
 * while the previous level keeps being drawn; the two are swapped when the
 * upload is complete. So a 40 MB level never becomes one long task (on the
 * main thread, or in the render worker where it would delay the camera). A fence after each frame's
 * commands holds the next slice back until the GPU has caught up: otherwise
 * a slow GPU (a tablet's, or SwiftShader) fills the command buffer and the
 * next bufferSubData blocks the thread until it drains. The level's arrays
 * (and every vertex received) are kept so a lost WebGL context can be
 * rebuilt without asking the worker again.
 *
 * The same class draws on the page's canvas (the fallback) or, in the render
 * worker, on the OffscreenCanvas the page handed over (render-worker.js).
 */

import { multiply } from './camera.js';
import { GLSL_CCC, cccUniforms } from './ccc.js';
import { accumulateNormals, packNormals } from './geometry.js';
import { BACKGROUND, CLAY, GLSL_SHADE, WIRE_ALPHA, WIRE_COLOUR } from './shading.js';

const UPLOAD_BUDGET_MS = 6;
const UPLOAD_CHUNK_BYTES = 256 << 10;
/** Triangles, then vertices, per step of a level's normals between budget checks (well under a millisecond). */
const NORMAL_TRIANGLES_PER_STEP = 8192;
const NORMAL_VERTICES_PER_STEP = 16384;

/**
 * requestAnimationFrame where the thread has one (pages; Chromium's and
 * Firefox's workers), else a timer.
 * @type {(callback: () => void) => number}
 */
const nextFrame =
  typeof requestAnimationFrame === 'function' ? (f) => requestAnimationFrame(f) : (f) => Number(setTimeout(f, 16));
/** @type {(id: number) => void} */
const cancelFrame = typeof cancelAnimationFrame === 'function' ? (id) => cancelAnimationFrame(id) : (id) => clearTimeout(id);

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

/** @typedef {{ target: number, buffer: WebGLBuffer, data: ArrayBufferView, offset: number }} Upload */

/**
 * A level's normals being derived here, a slice per frame (the level came
 * without them: LoadRequest.normals): face normals summed per corner up to
 * index `index`, then packed up to component `packed`.
 * @typedef {{ sum: Float32Array, normals: Int16Array, index: number, packed: number }} NormalJob
 */

/**
 * One level on the GPU: its own normals, indices and edges; positions and
 * colours from the shared vertex store.
 * @typedef {object} GpuMesh
 * @property {LevelMessage} source
 * @property {WebGLVertexArrayObject} vao
 * @property {WebGLBuffer[]} buffers
 * @property {WebGLBuffer} indexBuffer
 * @property {WebGLBuffer | null} edgeBuffer
 * @property {WebGLBuffer | null} normalBuffer
 * @property {NormalJob | null} normalJob normals still to derive before they are uploaded
 * @property {Upload[]} uploads
 */

/**
 * Every vertex received so far (positions and colours never change once
 * sent), on the CPU and in two GPU buffers of `capacity` vertices;
 * `uploaded` vertices of them are on the GPU.
 * @typedef {object} VertexStore
 * @property {number} capacity vertices the CPU arrays hold
 * @property {number} count vertices received
 * @property {number} uploaded vertices on the GPU
 * @property {number} gpuCapacity vertices the GPU buffers hold
 * @property {Float32Array} positions
 * @property {Uint8Array | null} colours
 * @property {WebGLBuffer | null} positionBuffer
 * @property {WebGLBuffer | null} colourBuffer
 */

/**
 * @typedef {object} RendererOptions
 * @property {number} [uploadBudgetMs] bufferSubData per frame (default 6 ms)
 * @property {number} [uploadChunkBytes] bytes per bufferSubData (default 256 KB)
 */

/** @typedef {HTMLCanvasElement | OffscreenCanvas} AnyCanvas */

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
  /** Milliseconds spent deriving normals of levels that came without them. */
  normalsMs = 0;
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
  /** @type {VertexStore} */
  #store = {
    capacity: 0,
    count: 0,
    uploaded: 0,
    gpuCapacity: 0,
    positions: new Float32Array(0),
    colours: null,
    positionBuffer: null,
    colourBuffer: null,
  };
  /** @type {LevelMessage | null} the newest level, waiting for the first one to be on screen */
  #next = null;
  /** @type {any} WEBGL_lose_context, for tests */
  #loseContext = null;

  /**
   * @param {AnyCanvas} canvas
   * @param {import('./camera.js').OrbitCamera | null} camera
   * @param {{ onSwap?: (level: LevelMessage) => void, onFrame?: () => void, onTick?: () => void }} hooks
   *   onSwap: a level is complete on the GPU and replaces the previous one;
   *   onFrame: a frame was drawn; onTick: after every animation frame's work
   * @param {RendererOptions} [options]
   */
  constructor(canvas, camera, hooks = {}, options = {}) {
    this.canvas = canvas;
    this.camera = camera;
    this.hooks = hooks;
    this.uploadBudgetMs = options.uploadBudgetMs ?? UPLOAD_BUDGET_MS;
    this.uploadChunkBytes = options.uploadChunkBytes ?? UPLOAD_CHUNK_BYTES;
    const gl = /** @type {WebGL2RenderingContext | null} */ (
      canvas.getContext('webgl2', { antialias: true, powerPreference: 'high-performance' })
    );
    if (!gl) throw new Error('this browser has no WebGL2');
    this.gl = gl;
    canvas.addEventListener('webglcontextlost', (event) => {
      event.preventDefault();
      this.lost = true;
      if (this.#raf !== null) cancelFrame(this.#raf);
      this.#raf = null;
    });
    canvas.addEventListener('webglcontextrestored', () => this.#restore());
    this.#init();
  }

  /** Loses the WebGL context on purpose (tests of the recovery). */
  loseContext() {
    this.#loseContext = this.gl.getExtension('WEBGL_lose_context');
    this.#loseContext?.loseContext();
  }

  /** Waits until the GPU has drawn everything asked of it (benchmarks: when the last frame is really done). */
  finish() {
    if (!this.lost) this.gl.finish();
  }

  /** Restores a context lost by loseContext(). */
  restoreContext() {
    this.#loseContext?.restoreContext();
  }

  /** Nothing waiting to be uploaded: the newest level is complete on the GPU. */
  get settled() {
    return !this.lost && !this.pending && !this.#next && Boolean(this.current) && this.current?.uploads.length === 0;
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
    this.#store.positionBuffer = null;
    this.#store.colourBuffer = null;
    this.#store.uploaded = 0;
    this.#store.gpuCapacity = 0;
    this.#init();
    this.#uploadColour();
    const newest = this.#next ?? this.pending?.source ?? this.current?.source;
    this.#next = null;
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
    this.#receive(level);
    if (this.lost) {
      this.#next = null;
      this.pending = { ...emptyMesh(), source: level };
      return;
    }
    // The first level to arrive is drawn first (the base mesh at once), even
    // when newer ones arrive with it; after that the newest wins.
    if (this.pending && !this.current) {
      this.#next = level;
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
    if (this.#raf === null && !this.lost) this.#raf = nextFrame(() => this.#frame());
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
    const start = performance.now();
    const inBudget = () => performance.now() - start < this.uploadBudgetMs;
    if (pending && caughtUp) {
      issued = true;
      if (this.#upload(pending, pending.source.vertices, inBudget)) {
        if (this.current) this.#release(this.current);
        this.current = pending;
        this.pending = null;
        this.#dirty = true;
        this.hooks.onSwap?.(pending.source);
        if (this.#next) {
          this.pending = this.#allocate(this.#next);
          this.#next = null;
        }
      }
    } else if (this.current?.uploads.length && caughtUp) {
      issued = true;
      if (this.#upload(this.current, this.current.source.vertices, inBudget)) this.#dirty = true;
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
    this.hooks.onTick?.();
  }

  /**
   * @param {LevelMessage} level
   * @returns {GpuMesh}
   */
  #allocate(level) {
    const gl = this.gl;
    const store = this.#ensureStore();
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
    gl.bindBuffer(gl.ARRAY_BUFFER, store.positionBuffer);
    gl.enableVertexAttribArray(0);
    gl.vertexAttribPointer(0, 3, gl.FLOAT, false, 0, 0);
    /** @type {NormalJob | null} */
    let normalJob = null;
    let normalBuffer;
    if (level.normals) {
      normalBuffer = buffer(gl.ARRAY_BUFFER, level.normals);
    } else {
      // Derived here (#deriveNormals), then uploaded like the rest.
      normalBuffer = gl.createBuffer();
      gl.bindBuffer(gl.ARRAY_BUFFER, normalBuffer);
      gl.bufferData(gl.ARRAY_BUFFER, 6 * level.vertices, gl.STATIC_DRAW);
      buffers.push(normalBuffer);
      normalJob = { sum: new Float32Array(3 * level.vertices), normals: new Int16Array(3 * level.vertices), index: 0, packed: 0 };
    }
    gl.enableVertexAttribArray(1);
    gl.vertexAttribPointer(1, 3, gl.SHORT, true, 0, 0);
    if (level.colours && store.colourBuffer) {
      gl.bindBuffer(gl.ARRAY_BUFFER, store.colourBuffer);
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
    if (normalJob) this.#queueNormals();
    return { source: level, vao, buffers, indexBuffer, edgeBuffer, normalBuffer, normalJob, uploads };
  }

  /** @type {MessagePort | null} */
  #normalsPort = null;
  #normalsQueued = false;

  /**
   * Derives the pending level's normals in tasks of their own, a budget's
   * worth each, not in animation frames: they are CPU work, and need not
   * wait for the GPU (a frame can be late by seconds on SwiftShader) nor
   * for the frame rate; between two slices the thread takes its messages
   * (camera moves). A MessageChannel rather than setTimeout, which is
   * clamped to 4 ms after a few nested calls.
   */
  #queueNormals() {
    if (this.#normalsQueued) return;
    this.#normalsQueued = true;
    if (!this.#normalsPort) {
      const channel = new MessageChannel();
      channel.port1.onmessage = () => this.#normalsTask();
      this.#normalsPort = channel.port2;
    }
    this.#normalsPort.postMessage(null);
  }

  #normalsTask() {
    this.#normalsQueued = false;
    const mesh = this.pending;
    if (!mesh?.normalJob || this.lost) return;
    const start = performance.now();
    this.#deriveNormals(mesh, () => performance.now() - start < this.uploadBudgetMs);
    if (mesh.normalJob) this.#queueNormals();
    else this.#schedule();
  }

  /**
   * Derives a level's normals (geometry.js, the decode worker's own
   * algorithm) while the budget lasts; when they are complete, the level
   * keeps them (a lost context does not derive them again) and their upload
   * is queued.
   * @param {GpuMesh} mesh
   * @param {() => boolean} inBudget
   */
  #deriveNormals(mesh, inBudget) {
    const job = /** @type {NormalJob} */ (mesh.normalJob);
    const t0 = performance.now();
    const indices = mesh.source.indices;
    // Every vertex of the level was received with it or before (vertices are only appended).
    const positions = this.#store.positions;
    while (job.index < indices.length && inBudget()) {
      const end = Math.min(indices.length, job.index + 3 * NORMAL_TRIANGLES_PER_STEP);
      accumulateNormals(positions, indices, job.sum, job.index, end);
      job.index = end;
    }
    while (job.index === indices.length && job.packed < job.sum.length && inBudget()) {
      const end = Math.min(job.sum.length, job.packed + 3 * NORMAL_VERTICES_PER_STEP);
      packNormals(job.sum, job.normals, job.packed, end);
      job.packed = end;
    }
    this.normalsMs += performance.now() - t0;
    if (job.index < indices.length || job.packed < job.sum.length) return;
    mesh.normalJob = null;
    mesh.source.normals = job.normals;
    if (this.lost || !mesh.normalBuffer) return;
    mesh.uploads.unshift({ target: this.gl.ARRAY_BUFFER, buffer: mesh.normalBuffer, data: job.normals, offset: 0 });
  }

  /**
   * Keeps a level's new vertices (positions and colours never change once
   * sent, so a level carries only those from `firstVertex` on).
   * @param {LevelMessage} level
   */
  #receive(level) {
    const store = this.#store;
    const first = level.firstVertex ?? 0;
    if (first > store.count) throw new Error(`level ${level.level} starts at vertex ${first}, but only ${store.count} were received`);
    const end = first + level.positions.length / 3;
    const needed = Math.max(end, level.vertices, level.capacity ?? 0);
    if (needed > store.capacity) {
      const positions = new Float32Array(3 * needed);
      positions.set(store.positions.subarray(0, 3 * store.count));
      store.positions = positions;
      if (store.colours) {
        const colours = new Uint8Array(3 * needed);
        colours.set(store.colours.subarray(0, 3 * store.count));
        store.colours = colours;
      }
      store.capacity = needed;
    }
    if (level.colours && !store.colours) store.colours = new Uint8Array(3 * store.capacity);
    store.positions.set(level.positions, 3 * first);
    if (level.colours && store.colours) store.colours.set(level.colours, 3 * first);
    store.count = Math.max(store.count, end);
    // Vertices sent again (a retry's new worker starts from 0) are the same; upload them again anyway.
    store.uploaded = Math.min(store.uploaded, first);
  }

  /**
   * GPU buffers for the vertex store, as large as its CPU arrays. Normally
   * made once, at the last level's size; if a level outgrows them (no
   * capacity hint), they are remade and what was uploaded is copied over at
   * once, and the meshes' vertex arrays point at the new ones.
   */
  #ensureStore() {
    const gl = this.gl;
    const store = this.#store;
    const colours = Boolean(store.colours);
    if (store.gpuCapacity >= store.capacity && Boolean(store.colourBuffer) === colours && store.positionBuffer) return store;
    const old = [store.positionBuffer, store.colourBuffer];
    gl.bindVertexArray(null);
    store.positionBuffer = gl.createBuffer();
    gl.bindBuffer(gl.ARRAY_BUFFER, store.positionBuffer);
    gl.bufferData(gl.ARRAY_BUFFER, store.positions.byteLength, gl.STATIC_DRAW);
    if (store.uploaded > 0) gl.bufferSubData(gl.ARRAY_BUFFER, 0, store.positions, 0, 3 * store.uploaded);
    store.colourBuffer = null;
    if (store.colours) {
      store.colourBuffer = gl.createBuffer();
      gl.bindBuffer(gl.ARRAY_BUFFER, store.colourBuffer);
      gl.bufferData(gl.ARRAY_BUFFER, store.colours.byteLength, gl.STATIC_DRAW);
      if (store.uploaded > 0) gl.bufferSubData(gl.ARRAY_BUFFER, 0, store.colours, 0, 3 * store.uploaded);
    }
    store.gpuCapacity = store.capacity;
    for (const mesh of [this.current, this.pending]) {
      if (!mesh?.vao) continue;
      gl.bindVertexArray(mesh.vao);
      gl.bindBuffer(gl.ARRAY_BUFFER, store.positionBuffer);
      gl.vertexAttribPointer(0, 3, gl.FLOAT, false, 0, 0);
      if (mesh.source.colours && store.colourBuffer) {
        gl.bindBuffer(gl.ARRAY_BUFFER, store.colourBuffer);
        gl.vertexAttribPointer(2, 3, gl.UNSIGNED_BYTE, true, 0, 0);
      }
    }
    gl.bindVertexArray(null);
    for (const b of old) if (b) gl.deleteBuffer(b);
    return store;
  }

  /**
   * Uploads slices until the frame's budget is spent: first the vertex
   * store up to the mesh's vertex count, then the mesh's own buffers.
   * @param {GpuMesh} mesh
   * @param {number} vertices
   * @param {() => boolean} inBudget
   * @returns {boolean} whether the mesh is complete (normals derived and everything uploaded)
   */
  #upload(mesh, vertices, inBudget) {
    const gl = this.gl;
    const store = this.#ensureStore();
    const chunk = this.uploadChunkBytes;
    gl.bindVertexArray(null);
    while (store.uploaded < vertices && inBudget()) {
      // The same vertex range of positions (12 bytes each) and colours (3).
      const end = Math.min(vertices, store.uploaded + Math.max(1, Math.floor(chunk / 12)));
      gl.bindBuffer(gl.ARRAY_BUFFER, store.positionBuffer);
      gl.bufferSubData(gl.ARRAY_BUFFER, 12 * store.uploaded, store.positions, 3 * store.uploaded, 3 * (end - store.uploaded));
      if (store.colours && store.colourBuffer) {
        gl.bindBuffer(gl.ARRAY_BUFFER, store.colourBuffer);
        gl.bufferSubData(gl.ARRAY_BUFFER, 3 * store.uploaded, store.colours, 3 * store.uploaded, 3 * (end - store.uploaded));
      }
      store.uploaded = end;
    }
    while (mesh.uploads.length > 0 && inBudget()) {
      const job = mesh.uploads[0];
      const bytes = new Uint8Array(job.data.buffer, job.data.byteOffset, job.data.byteLength);
      const end = Math.min(bytes.length, job.offset + chunk);
      gl.bindBuffer(job.target, job.buffer);
      gl.bufferSubData(job.target, job.offset, bytes, job.offset, end - job.offset);
      job.offset = end;
      if (end === bytes.length) mesh.uploads.shift();
    }
    return !mesh.normalJob && mesh.uploads.length === 0 && store.uploaded >= vertices;
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
  return { vao: none, buffers: [], indexBuffer: none, edgeBuffer: null, normalBuffer: null, normalJob: null, uploads: [] };
}
