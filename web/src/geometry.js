// @ts-check
/**
 * Per-level derived geometry: smooth vertex normals (in the render worker,
 * for the levels it draws; in the decode worker when the renderer is on the
 * main thread — only levels sent before the page knew that, when a render
 * worker turned out to have no WebGL2, are derived there, a slice at a
 * time), the wireframe's edge list and the bounding box (decode worker).
 */

/**
 * @typedef {object} Bounds
 * @property {[number, number, number]} min
 * @property {[number, number, number]} max
 */

/**
 * Area-weighted smooth vertex normals (the unnormalised face cross product
 * weights each face by its area), packed as normalised int16 triples: half
 * the bytes of float32, and 1/32767 is far below what shading can show.
 * Vertices on no face get (0, 0, 0); the shader treats them as facing the eye.
 * The renderer computes them the same way a slice at a time
 * ({@link accumulateNormals}, {@link packNormals}).
 * @param {Float32Array} positions
 * @param {Uint32Array} indices
 * @returns {Int16Array}
 */
export function vertexNormals(positions, indices) {
  const n = positions.length / 3;
  const sum = new Float32Array(3 * n);
  accumulateNormals(positions, indices, sum, 0, indices.length);
  const packed = new Int16Array(3 * n);
  packNormals(sum, packed, 0, 3 * n);
  return packed;
}

/**
 * Adds the (area-weighted) normals of the triangles whose indices are
 * indices[from…to) to their corners' sums.
 * @param {Float32Array} positions
 * @param {Uint32Array} indices
 * @param {Float32Array} sum three per vertex
 * @param {number} from a multiple of 3
 * @param {number} to a multiple of 3
 */
export function accumulateNormals(positions, indices, sum, from, to) {
  for (let t = from; t < to; t += 3) {
    const a = 3 * indices[t];
    const b = 3 * indices[t + 1];
    const c = 3 * indices[t + 2];
    const ax = positions[a];
    const ay = positions[a + 1];
    const az = positions[a + 2];
    const ux = positions[b] - ax;
    const uy = positions[b + 1] - ay;
    const uz = positions[b + 2] - az;
    const vx = positions[c] - ax;
    const vy = positions[c + 1] - ay;
    const vz = positions[c + 2] - az;
    const nx = uy * vz - uz * vy;
    const ny = uz * vx - ux * vz;
    const nz = ux * vy - uy * vx;
    sum[a] += nx;
    sum[a + 1] += ny;
    sum[a + 2] += nz;
    sum[b] += nx;
    sum[b + 1] += ny;
    sum[b + 2] += nz;
    sum[c] += nx;
    sum[c + 1] += ny;
    sum[c + 2] += nz;
  }
}

/**
 * Normalises sum[from…to) (whole vertices) into int16 triples.
 * @param {Float32Array} sum
 * @param {Int16Array} packed
 * @param {number} from a multiple of 3
 * @param {number} to a multiple of 3
 */
export function packNormals(sum, packed, from, to) {
  for (let i = from; i < to; i += 3) {
    const x = sum[i];
    const y = sum[i + 1];
    const z = sum[i + 2];
    const q = x * x + y * y + z * z;
    if (q > 0) {
      const s = 32767 / Math.sqrt(q);
      packed[i] = Math.round(x * s);
      packed[i + 1] = Math.round(y * s);
      packed[i + 2] = Math.round(z * s);
    }
  }
}

/**
 * Every edge once, as GL_LINES index pairs. An interior edge is a pair of
 * opposite half-edges; it is emitted from the half-edge a→b with a < b. A
 * border edge has no twin and is emitted from its only half-edge, whatever
 * the order. Twins are found in a compressed list of outgoing half-edges per
 * vertex (counting sort), so the cost is linear with no hashing.
 * @param {Uint32Array} indices
 * @param {number} vertexCount
 * @returns {Uint32Array}
 */
export function edgeIndices(indices, vertexCount) {
  const start = new Uint32Array(vertexCount + 1);
  for (let t = 0; t < indices.length; t++) start[indices[t] + 1]++;
  for (let v = 0; v < vertexCount; v++) start[v + 1] += start[v];
  const fill = start.slice(0, vertexCount);
  const target = new Uint32Array(indices.length);
  for (let t = 0; t < indices.length; t += 3) {
    for (let k = 0; k < 3; k++) {
      const a = indices[t + k];
      target[fill[a]++] = indices[t + (k === 2 ? 0 : k + 1)];
    }
  }
  const edges = new Uint32Array(2 * indices.length);
  let count = 0;
  for (let a = 0; a < vertexCount; a++) {
    for (let h = start[a]; h < start[a + 1]; h++) {
      const b = target[h];
      if (a < b || !hasHalfEdge(start, target, b, a)) {
        edges[count++] = a;
        edges[count++] = b;
      }
    }
  }
  return edges.slice(0, count);
}

/**
 * @param {Uint32Array} start
 * @param {Uint32Array} target
 * @param {number} from
 * @param {number} to
 */
function hasHalfEdge(start, target, from, to) {
  for (let h = start[from]; h < start[from + 1]; h++) if (target[h] === to) return true;
  return false;
}

/**
 * @param {Float32Array} positions
 * @returns {Bounds}
 */
export function bounds(positions) {
  /** @type {[number, number, number]} */
  const min = [Infinity, Infinity, Infinity];
  /** @type {[number, number, number]} */
  const max = [-Infinity, -Infinity, -Infinity];
  for (let i = 0; i < positions.length; i += 3) {
    for (let k = 0; k < 3; k++) {
      const p = positions[i + k];
      if (p < min[k]) min[k] = p;
      if (p > max[k]) max[k] = p;
    }
  }
  if (positions.length === 0) return { min: [0, 0, 0], max: [0, 0, 0] };
  return { min, max };
}
