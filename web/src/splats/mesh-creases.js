// @ts-check
/**
 * The creases of a mesh level, from its own geometry (seed 002's sharp
 * edges, found on faces instead of points): an edge whose two faces'
 * unit normals satisfy n_i·n_j < w_s is sharp, and faces joined across the
 * other edges form patches, a mesh's surfaces. A sherd's fracture face is
 * one patch, its glazed skin another.
 */

/** The seed's typical sharp-edge threshold w_s. */
export const SHARP_THRESHOLD = 0.9;

/**
 * Per face, the cross product of two edges: the normal times twice the
 * area (so sums weigh faces by area).
 * @param {Float32Array} positions
 * @param {Uint32Array} indices
 */
export function faceNormals(positions, indices) {
  const normals = new Float32Array(indices.length);
  for (let t = 0; t < indices.length; t += 3) {
    const a = 3 * indices[t];
    const b = 3 * indices[t + 1];
    const c = 3 * indices[t + 2];
    const ux = positions[b] - positions[a], uy = positions[b + 1] - positions[a + 1], uz = positions[b + 2] - positions[a + 2];
    const vx = positions[c] - positions[a], vy = positions[c + 1] - positions[a + 1], vz = positions[c + 2] - positions[a + 2];
    normals[t] = uy * vz - uz * vy;
    normals[t + 1] = uz * vx - ux * vz;
    normals[t + 2] = ux * vy - uy * vx;
  }
  return normals;
}

/**
 * The faces around each vertex, as compressed rows: vertex v's are
 * `faces[offsets[v]..offsets[v + 1]]`.
 * @param {Uint32Array} indices @param {number} vertexCount
 */
export function vertexFaces(indices, vertexCount) {
  const offsets = new Uint32Array(vertexCount + 1);
  for (let c = 0; c < indices.length; c++) offsets[indices[c] + 1]++;
  for (let v = 0; v < vertexCount; v++) offsets[v + 1] += offsets[v];
  const fill = offsets.slice(0, vertexCount);
  const faces = new Uint32Array(indices.length);
  for (let c = 0; c < indices.length; c++) faces[fill[indices[c]]++] = (c / 3) | 0;
  return { offsets, faces };
}

/**
 * The patch of every face: faces are joined across each edge whose faces
 * are not sharp (on an edge of more than two faces, each pair is
 * compared), so without a sharp edge a patch is a connected component.
 * @param {Uint32Array} indices
 * @param {Float32Array} normals from {@link faceNormals}
 * @param {{ offsets: Uint32Array, faces: Uint32Array }} around from {@link vertexFaces}
 * @param {number} threshold w_s
 * @returns {Uint32Array} per face, the smallest face index of its patch
 */
export function facePatches(indices, normals, around, threshold) {
  const faces = indices.length / 3;
  const parent = new Uint32Array(faces);
  for (let f = 0; f < faces; f++) parent[f] = f;
  /** @param {number} f */
  const root = (f) => {
    while (parent[f] !== f) f = parent[f] = parent[parent[f]];
    return f;
  };
  /** @param {number} f @param {number} g */
  const smooth = (f, g) => {
    const a = 3 * f, b = 3 * g;
    const d = normals[a] * normals[b] + normals[a + 1] * normals[b + 1] + normals[a + 2] * normals[b + 2];
    const la = normals[a] * normals[a] + normals[a + 1] * normals[a + 1] + normals[a + 2] * normals[a + 2];
    const lb = normals[b] * normals[b] + normals[b + 1] * normals[b + 1] + normals[b + 2] * normals[b + 2];
    const l = Math.sqrt(la * lb);
    return l > 0 && d >= threshold * l;
  };
  for (let f = 0; f < faces; f++) {
    for (let k = 0; k < 3; k++) {
      const a = indices[3 * f + k];
      const b = indices[3 * f + ((k + 1) % 3)];
      // The faces across edge ab: those around a that also hold b.
      for (let i = around.offsets[a]; i < around.offsets[a + 1]; i++) {
        const g = around.faces[i];
        if (g <= f || (indices[3 * g] !== b && indices[3 * g + 1] !== b && indices[3 * g + 2] !== b)) continue;
        if (smooth(f, g)) {
          const rf = root(f), rg = root(g);
          if (rf !== rg) parent[Math.max(rf, rg)] = Math.min(rf, rg);
        }
      }
    }
  }
  const patch = new Uint32Array(faces);
  for (let f = 0; f < faces; f++) patch[f] = root(f);
  return patch;
}
