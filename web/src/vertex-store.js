// @ts-check
/**
 * What the renderer keeps on the GPU, and how it gets there a slice at a time.
 *
 * Vertices are only ever appended from one level to the next, so positions
 * and colours live in one pair of buffers sized once for the last level
 * (the manifest's count): each level uploads only its new vertices there
 * ({@link VertexStore}). Normals, indices and edges change everywhere; a
 * new level gets fresh ones ({@link allocateMesh}). Either kind is written
 * by {@link uploadMesh} in slices of `chunk` bytes while the caller's
 * budget lasts.
 */

import { normalJob } from './normals-task.js';

/** @typedef {import('./reconstruction.js').LevelMessage} LevelMessage */

/** @typedef {{ target: number, buffer: WebGLBuffer, data: ArrayBufferView, offset: number }} Upload */

/**
 * One level on the GPU: its own normals, indices, edges and θ (the relief
 * view); positions and colours from the shared vertex store.
 * @typedef {object} GpuMesh
 * @property {LevelMessage} source
 * @property {WebGLVertexArrayObject} vao
 * @property {WebGLBuffer[]} buffers
 * @property {WebGLBuffer} indexBuffer
 * @property {WebGLBuffer | null} edgeBuffer
 * @property {WebGLBuffer | null} normalBuffer
 * @property {WebGLBuffer | null} reliefBuffer θ per vertex (attribute 3), when the level has it
 * @property {import('./normals-task.js').NormalJob | null} normalJob normals still to derive before they are uploaded
 * @property {Upload[]} uploads
 */

/**
 * Every vertex received so far (positions and colours never change once
 * sent), on the CPU and in two GPU buffers of `gpuCapacity` vertices;
 * `uploaded` vertices of them are on the GPU. The CPU arrays are kept so
 * a lost WebGL context can be rebuilt without asking the worker again.
 */
export class VertexStore {
  /** vertices the CPU arrays hold */
  capacity = 0;
  /** vertices received */
  count = 0;
  /** vertices on the GPU */
  uploaded = 0;
  /** vertices the GPU buffers hold */
  gpuCapacity = 0;
  positions = new Float32Array(0);
  /** @type {Uint8Array | null} */
  colours = null;
  /** @type {WebGLBuffer | null} */
  positionBuffer = null;
  /** @type {WebGLBuffer | null} */
  colourBuffer = null;

  /**
   * Keeps a level's new vertices (positions and colours never change once
   * sent, so a level carries only those from `firstVertex` on).
   * @param {LevelMessage} level
   */
  receive(level) {
    const first = level.firstVertex ?? 0;
    if (first > this.count) throw new Error(`level ${level.level} starts at vertex ${first}, but only ${this.count} were received`);
    const end = first + level.positions.length / 3;
    const needed = Math.max(end, level.vertices, level.capacity ?? 0);
    if (needed > this.capacity) {
      const positions = new Float32Array(3 * needed);
      positions.set(this.positions.subarray(0, 3 * this.count));
      this.positions = positions;
      if (this.colours) {
        const colours = new Uint8Array(3 * needed);
        colours.set(this.colours.subarray(0, 3 * this.count));
        this.colours = colours;
      }
      this.capacity = needed;
    }
    if (level.colours && !this.colours) this.colours = new Uint8Array(3 * this.capacity);
    this.positions.set(level.positions, 3 * first);
    if (level.colours && this.colours) this.colours.set(level.colours, 3 * first);
    this.count = Math.max(this.count, end);
    // Vertices sent again (a retry's new worker starts from 0) are the same; upload them again anyway.
    this.uploaded = Math.min(this.uploaded, first);
  }

  /** The context was lost with the GPU buffers: nothing is uploaded any more. */
  lose() {
    this.positionBuffer = null;
    this.colourBuffer = null;
    this.uploaded = 0;
    this.gpuCapacity = 0;
  }

  /**
   * GPU buffers as large as the CPU arrays. Normally made once, at the last
   * level's size; if a level outgrows them (no capacity hint), they are
   * remade and what was uploaded is copied over at once, and the meshes'
   * vertex arrays point at the new ones.
   * @param {WebGL2RenderingContext} gl
   * @param {Array<GpuMesh | null>} meshes the meshes whose vertex arrays read the store
   */
  ensureGpu(gl, meshes) {
    const colours = Boolean(this.colours);
    if (this.gpuCapacity >= this.capacity && Boolean(this.colourBuffer) === colours && this.positionBuffer) return this;
    const old = [this.positionBuffer, this.colourBuffer];
    gl.bindVertexArray(null);
    this.positionBuffer = gl.createBuffer();
    gl.bindBuffer(gl.ARRAY_BUFFER, this.positionBuffer);
    gl.bufferData(gl.ARRAY_BUFFER, this.positions.byteLength, gl.STATIC_DRAW);
    if (this.uploaded > 0) gl.bufferSubData(gl.ARRAY_BUFFER, 0, this.positions, 0, 3 * this.uploaded);
    this.colourBuffer = null;
    if (this.colours) {
      this.colourBuffer = gl.createBuffer();
      gl.bindBuffer(gl.ARRAY_BUFFER, this.colourBuffer);
      gl.bufferData(gl.ARRAY_BUFFER, this.colours.byteLength, gl.STATIC_DRAW);
      if (this.uploaded > 0) gl.bufferSubData(gl.ARRAY_BUFFER, 0, this.colours, 0, 3 * this.uploaded);
    }
    this.gpuCapacity = this.capacity;
    for (const mesh of meshes) {
      if (!mesh?.vao) continue;
      gl.bindVertexArray(mesh.vao);
      gl.bindBuffer(gl.ARRAY_BUFFER, this.positionBuffer);
      gl.vertexAttribPointer(0, 3, gl.FLOAT, false, 0, 0);
      if (mesh.source.colours && this.colourBuffer) {
        gl.bindBuffer(gl.ARRAY_BUFFER, this.colourBuffer);
        gl.vertexAttribPointer(2, 3, gl.UNSIGNED_BYTE, true, 0, 0);
      }
    }
    gl.bindVertexArray(null);
    for (const b of old) if (b) gl.deleteBuffer(b);
    return this;
  }
}

/**
 * A level's vertex array and buffers, sized but empty: its normals (or,
 * when it came without them, a job to derive them), indices and edges are
 * queued for upload. Call `store.ensureGpu` first.
 * @param {WebGL2RenderingContext} gl
 * @param {VertexStore} store
 * @param {LevelMessage} level
 * @returns {GpuMesh}
 */
export function allocateMesh(gl, store, level) {
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
  /** @type {GpuMesh['normalJob']} */
  let job = null;
  let normalBuffer;
  if (level.normals) {
    normalBuffer = buffer(gl.ARRAY_BUFFER, level.normals);
  } else {
    // Derived by the renderer (normals-task.js), then uploaded like the rest.
    normalBuffer = gl.createBuffer();
    gl.bindBuffer(gl.ARRAY_BUFFER, normalBuffer);
    gl.bufferData(gl.ARRAY_BUFFER, 6 * level.vertices, gl.STATIC_DRAW);
    buffers.push(normalBuffer);
    job = normalJob(level.vertices);
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
  let reliefBuffer = null;
  if (level.relief) {
    reliefBuffer = buffer(gl.ARRAY_BUFFER, level.relief);
    gl.enableVertexAttribArray(3);
    gl.vertexAttribPointer(3, 1, gl.FLOAT, false, 0, 0);
  } else {
    gl.disableVertexAttribArray(3);
  }
  const indexBuffer = buffer(gl.ELEMENT_ARRAY_BUFFER, level.indices);
  gl.bindVertexArray(null);
  let edgeBuffer = null;
  if (level.edges) {
    edgeBuffer = buffer(gl.ELEMENT_ARRAY_BUFFER, level.edges);
    buffers.pop();
  }
  return { source: level, vao, buffers, indexBuffer, edgeBuffer, normalBuffer, reliefBuffer, normalJob: job, uploads };
}

/**
 * A mesh with no GPU objects: a level received while the context is lost,
 * allocated when it is restored.
 * @returns {Omit<GpuMesh, 'source'>}
 */
export function emptyMesh() {
  const none = /** @type {any} */ (null);
  return {
    vao: none,
    buffers: [],
    indexBuffer: none,
    edgeBuffer: null,
    normalBuffer: null,
    reliefBuffer: null,
    normalJob: null,
    uploads: [],
  };
}

/**
 * Wire edges that came after the level (wireframe switched on): a buffer
 * for them, queued for upload.
 * @param {WebGL2RenderingContext} gl
 * @param {GpuMesh} mesh
 * @param {Uint32Array} edges
 */
export function addEdgeBuffer(gl, mesh, edges) {
  mesh.edgeBuffer = gl.createBuffer();
  gl.bindVertexArray(null);
  gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, mesh.edgeBuffer);
  gl.bufferData(gl.ELEMENT_ARRAY_BUFFER, edges.byteLength, gl.STATIC_DRAW);
  mesh.uploads.push({ target: gl.ELEMENT_ARRAY_BUFFER, buffer: mesh.edgeBuffer, data: edges, offset: 0 });
}

/**
 * θ that came after the level (relief view switched on): a buffer for it
 * on attribute 3 of the level's vertex array, queued for upload.
 * @param {WebGL2RenderingContext} gl
 * @param {GpuMesh} mesh
 * @param {Float32Array} relief
 */
export function addReliefBuffer(gl, mesh, relief) {
  const buffer = /** @type {WebGLBuffer} */ (gl.createBuffer());
  gl.bindVertexArray(mesh.vao);
  gl.bindBuffer(gl.ARRAY_BUFFER, buffer);
  gl.bufferData(gl.ARRAY_BUFFER, relief.byteLength, gl.STATIC_DRAW);
  gl.enableVertexAttribArray(3);
  gl.vertexAttribPointer(3, 1, gl.FLOAT, false, 0, 0);
  gl.bindVertexArray(null);
  mesh.reliefBuffer = buffer;
  mesh.buffers.push(buffer);
  mesh.uploads.push({ target: gl.ARRAY_BUFFER, buffer, data: relief, offset: 0 });
}

/**
 * Whether a mesh's θ is on the GPU (its buffer made and fully uploaded).
 * @param {GpuMesh} mesh
 */
export function reliefReady(mesh) {
  const buffer = mesh.reliefBuffer;
  return Boolean(buffer) && !mesh.uploads.some((upload) => upload.buffer === buffer);
}

/**
 * Uploads slices until the budget is spent: first the vertex store up to
 * the mesh's vertex count, then the mesh's own buffers.
 * @param {WebGL2RenderingContext} gl
 * @param {VertexStore} store with its GPU buffers made (`ensureGpu`)
 * @param {GpuMesh} mesh
 * @param {number} vertices
 * @param {number} chunk bytes per bufferSubData
 * @param {() => boolean} inBudget
 * @returns {boolean} whether the mesh is complete (normals derived and everything uploaded)
 */
export function uploadMesh(gl, store, mesh, vertices, chunk, inBudget) {
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

/**
 * @param {WebGL2RenderingContext} gl
 * @param {GpuMesh} mesh
 */
export function releaseMesh(gl, mesh) {
  for (const b of mesh.buffers) gl.deleteBuffer(b);
  if (mesh.edgeBuffer) gl.deleteBuffer(mesh.edgeBuffer);
  gl.deleteVertexArray(mesh.vao);
}
