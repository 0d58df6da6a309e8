// @ts-check
/**
 * Splats from a mesh level, in the splat worker: the vertices are the
 * centres, their (area-weighted) vertex normals the normals. The WebAssembly
 * preprocessing (`points_splats`) starts from a decoded point stream and has
 * no entry for raw positions + normals, so a mesh's splats are derived here
 * from its connectivity instead: the radius is the mean length of a vertex's
 * edges (the mesh's own neighbours, where points need the 5 nearest), the
 * surface id is the connected component, and no splat is clipped (a mesh's
 * creases are in its triangles, which this view does not draw).
 */

import { accumulateNormals } from '../geometry.js';

/**
 * @param {Float32Array} positions x, y, z per vertex
 * @param {Uint32Array} indices three per triangle
 * @param {Uint8Array | null} colours r, g, b per vertex
 * @returns {import('./splat-renderer.js').SplatSet}
 */
export function meshSplats(positions, indices, colours) {
  const n = positions.length / 3;
  const sum = new Float32Array(3 * n);
  accumulateNormals(positions, indices, sum, 0, indices.length);
  const normals = new Float32Array(3 * n);
  for (let v = 0; v < n; v++) {
    const x = sum[3 * v], y = sum[3 * v + 1], z = sum[3 * v + 2];
    const l = Math.hypot(x, y, z);
    if (l > 0) normals.set([x / l, y / l, z / l], 3 * v);
    else normals[3 * v + 2] = 1;
  }
  // Each triangle edge is seen by each of its two vertices (twice in all
  // on a closed mesh), so the mean over what each vertex sees is fair.
  const length = new Float32Array(n);
  const edges = new Uint32Array(n);
  const parent = new Uint32Array(n);
  for (let v = 0; v < n; v++) parent[v] = v;
  /** @param {number} v */
  const root = (v) => {
    while (parent[v] !== v) v = parent[v] = parent[parent[v]];
    return v;
  };
  for (let t = 0; t < indices.length; t += 3) {
    for (let k = 0; k < 3; k++) {
      const a = indices[t + k];
      const b = indices[t + ((k + 1) % 3)];
      const d = Math.hypot(positions[3 * a] - positions[3 * b], positions[3 * a + 1] - positions[3 * b + 1], positions[3 * a + 2] - positions[3 * b + 2]);
      length[a] += d;
      length[b] += d;
      edges[a]++;
      edges[b]++;
      const ra = root(a);
      const rb = root(b);
      if (ra !== rb) parent[Math.max(ra, rb)] = Math.min(ra, rb);
    }
  }
  let total = 0;
  let counted = 0;
  for (let v = 0; v < n; v++) {
    total += length[v];
    counted += edges[v];
  }
  const fallback = counted > 0 ? total / counted : 1;
  const radii = new Float32Array(n);
  for (let v = 0; v < n; v++) radii[v] = edges[v] > 0 ? length[v] / edges[v] : fallback;
  const surfaceIds = new Uint32Array(n);
  for (let v = 0; v < n; v++) surfaceIds[v] = root(v);
  return { count: n, positions, normals, colours, radii, surfaceIds, clip: new Uint32Array(n), planes: new Float32Array(0) };
}
