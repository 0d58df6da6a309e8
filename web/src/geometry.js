// @ts-check
/**
 * Per-level derived geometry, computed in the decode worker so the main
 * thread only uploads: smooth vertex normals, the wireframe's edge list and
 * the bounding box.
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
 * @param {Float32Array} positions
 * @param {Uint32Array} indices
 * @returns {Int16Array}
 */
export function vertexNormals(positions, indices) {
  const n = positions.length / 3;
  const sum = new Float32Array(3 * n);
  for (let t = 0; t < indices.length; t += 3) {
    const a = 3 * indices[t];
    const b = 3 * indices[t + 1];
    const c = 3 * indices[t + 2];
    const ux = positions[b] - positions[a];
    const uy = positions[b + 1] - positions[a + 1];
    const uz = positions[b + 2] - positions[a + 2];
    const vx = positions[c] - positions[a];
    const vy = positions[c + 1] - positions[a + 1];
    const vz = positions[c + 2] - positions[a + 2];
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
  const packed = new Int16Array(3 * n);
  for (let i = 0; i < 3 * n; i += 3) {
    const x = sum[i];
    const y = sum[i + 1];
    const z = sum[i + 2];
    const length = Math.sqrt(x * x + y * y + z * z);
    if (length > 0) {
      const s = 32767 / length;
      packed[i] = Math.round(x * s);
      packed[i + 1] = Math.round(y * s);
      packed[i + 2] = Math.round(z * s);
    }
  }
  return packed;
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
