// @ts-check
/**
 * Splats from a mesh level, in the splat worker, with seed 002's features
 * taken from the mesh's own geometry (mesh-creases.js) instead of from a
 * neighbour graph. A vertex gets one splat per patch it touches, so a vertex
 * on a sharp edge is split: each side's splat has that side's
 * (area-weighted) normal and surface id. A splat whose vertex or a
 * neighbour lies on a crease with another patch gets that patch's plane
 * there as a clip partner, convex or concave by which side of the splat's
 * plane the other patch's faces lie (eq. 4.13–4.14 with the faces known),
 * and is clipped where any plane clips (one plane per other patch, so the
 * groups by surface id of seed 002 §7.2 are the planes themselves). The
 * radius is the mean length of the vertex's edges. With a threshold below
 * −1 no edge is sharp: one splat per vertex, one surface per connected
 * component, nothing clipped.
 */

import { SHARP_THRESHOLD, faceNormals, facePatches, vertexFaces } from './mesh-creases.js';

/** Most clip planes per splat (as the point preprocessing keeps). */
const MAX_PLANES = 8;

/**
 * @param {Float32Array} positions x, y, z per vertex
 * @param {Uint32Array} indices three per triangle
 * @param {Uint8Array | null} colours r, g, b per vertex
 * @param {number} [sharpThreshold] w_s
 * @returns {import('./splat-renderer.js').SplatSet}
 */
export function meshSplats(positions, indices, colours, sharpThreshold = SHARP_THRESHOLD) {
  const n = positions.length / 3;
  const faceNormal = faceNormals(positions, indices);
  const around = vertexFaces(indices, n);
  const patch = facePatches(indices, faceNormal, around, sharpThreshold);
  // One splat per (vertex, patch), a vertex's splats contiguous.
  const firstSplat = new Uint32Array(n + 1);
  /** @type {number[]} */
  const splatPatch = [];
  for (let v = 0; v < n; v++) {
    firstSplat[v] = splatPatch.length;
    for (let k = around.offsets[v]; k < around.offsets[v + 1]; k++) {
      const p = patch[around.faces[k]];
      if (!splatPatch.includes(p, firstSplat[v])) splatPatch.push(p);
    }
    if (splatPatch.length === firstSplat[v]) splatPatch.push(indices.length + v); // a lone vertex: an id of its own
  }
  firstSplat[n] = splatPatch.length;
  const count = splatPatch.length;
  const vertexOf = new Uint32Array(count);
  for (let v = 0; v < n; v++) vertexOf.fill(v, firstSplat[v], firstSplat[v + 1]);
  /** @param {number} v @param {number} p */
  const splatAt = (v, p) => {
    for (let s = firstSplat[v]; s < firstSplat[v + 1]; s++) if (splatPatch[s] === p) return s;
    return -1;
  };
  // Normals and the centroid of the splat's faces, per splat.
  const normals = new Float32Array(3 * count);
  const faceCentre = new Float32Array(3 * count);
  const faceCount = new Uint32Array(count);
  for (let v = 0; v < n; v++) {
    for (let k = around.offsets[v]; k < around.offsets[v + 1]; k++) {
      const f = around.faces[k];
      const s = splatAt(v, patch[f]);
      faceCount[s]++;
      for (let a = 0; a < 3; a++) {
        normals[3 * s + a] += faceNormal[3 * f + a];
        faceCentre[3 * s + a] += (positions[3 * indices[3 * f] + a] + positions[3 * indices[3 * f + 1] + a] + positions[3 * indices[3 * f + 2] + a]) / 3;
      }
    }
    for (let s = firstSplat[v]; s < firstSplat[v + 1]; s++) {
      const l = Math.hypot(normals[3 * s], normals[3 * s + 1], normals[3 * s + 2]);
      if (l > 0) for (let a = 0; a < 3; a++) normals[3 * s + a] /= l;
      else normals[3 * s + 2] = 1;
      for (let a = 0; a < 3; a++) faceCentre[3 * s + a] /= Math.max(1, faceCount[s]);
    }
  }
  const radii = edgeRadii(positions, indices, n);
  const splatPositions = new Float32Array(3 * count);
  const splatColours = colours ? new Uint8Array(3 * count) : null;
  const splatRadii = new Float32Array(count);
  const surfaceIds = new Uint32Array(count);
  for (let s = 0; s < count; s++) {
    const v = vertexOf[s];
    for (let a = 0; a < 3; a++) splatPositions[3 * s + a] = positions[3 * v + a];
    if (splatColours && colours) for (let a = 0; a < 3; a++) splatColours[3 * s + a] = colours[3 * v + a];
    splatRadii[s] = radii[v];
    surfaceIds[s] = splatPatch[s];
  }
  const { clip, planes } = creasePlanes({ positions, indices, around, firstSplat, splatPatch, vertexOf, normals, faceCentre, splatAt });
  return { count, positions: splatPositions, normals, colours: splatColours, radii: splatRadii, surfaceIds, clip, planes };
}

/**
 * Mean length of each vertex's edges (each triangle edge is seen by both
 * its vertices, twice in all on a closed mesh, so the mean is fair); a
 * vertex on no edge gets the mean over all.
 * @param {Float32Array} positions @param {Uint32Array} indices @param {number} n
 */
function edgeRadii(positions, indices, n) {
  const length = new Float32Array(n);
  const edges = new Uint32Array(n);
  for (let t = 0; t < indices.length; t += 3) {
    for (let k = 0; k < 3; k++) {
      const a = indices[t + k];
      const b = indices[t + ((k + 1) % 3)];
      const d = Math.hypot(positions[3 * a] - positions[3 * b], positions[3 * a + 1] - positions[3 * b + 1], positions[3 * a + 2] - positions[3 * b + 2]);
      length[a] += d;
      length[b] += d;
      edges[a]++;
      edges[b]++;
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
  return radii;
}

/**
 * Clip planes (clip.rs layout: one word per splat, a, b, c, d per plane,
 * the sign folded in): for splat s of patch A at vertex v, each other
 * patch B on a crease with A at v or at one of v's neighbours u gets one
 * plane, B's at the nearest such u.
 * @param {{ positions: Float32Array, indices: Uint32Array, around: { offsets: Uint32Array, faces: Uint32Array },
 *   firstSplat: Uint32Array, splatPatch: number[], vertexOf: Uint32Array, normals: Float32Array,
 *   faceCentre: Float32Array, splatAt: (v: number, p: number) => number }} m
 */
function creasePlanes(m) {
  const { positions, indices, around, firstSplat, splatPatch, vertexOf, normals, faceCentre, splatAt } = m;
  const count = splatPatch.length;
  const clip = new Uint32Array(count);
  /** @type {number[]} */
  const planes = [];
  /** Nearest crease vertex per other patch: [patch, squared distance, vertex]. @type {[number, number, number][]} */
  const found = [];
  for (let s = 0; s < count; s++) {
    const v = vertexOf[s];
    const own = splatPatch[s];
    found.length = 0;
    const consider = (/** @type {number} */ u) => {
      if (firstSplat[u + 1] - firstSplat[u] < 2 || splatAt(u, own) < 0) return;
      const d2 = (positions[3 * u] - positions[3 * v]) ** 2 + (positions[3 * u + 1] - positions[3 * v + 1]) ** 2 + (positions[3 * u + 2] - positions[3 * v + 2]) ** 2;
      for (let t = firstSplat[u]; t < firstSplat[u + 1]; t++) {
        if (splatPatch[t] === own) continue;
        const at = found.findIndex((x) => x[0] === splatPatch[t]);
        if (at < 0) found.push([splatPatch[t], d2, u]);
        else if (d2 < found[at][1]) found[at] = [splatPatch[t], d2, u];
      }
    };
    consider(v);
    for (let k = around.offsets[v]; k < around.offsets[v + 1]; k++) {
      const f = around.faces[k];
      for (let c = 0; c < 3; c++) if (indices[3 * f + c] !== v) consider(indices[3 * f + c]);
    }
    if (found.length === 0) continue;
    found.sort((a, b) => a[1] - b[1] || a[0] - b[0]);
    const first = planes.length / 4;
    const kept = found.slice(0, MAX_PLANES);
    for (const [p, , u] of kept) {
      const t = splatAt(u, p);
      const mine = splatAt(u, own);
      const nb = [normals[3 * t], normals[3 * t + 1], normals[3 * t + 2]];
      const at = [positions[3 * u], positions[3 * u + 1], positions[3 * u + 2]];
      // B's faces below A's plane at u: a convex crease (clip beyond B's
      // plane); above it: concave (clip behind B's plane).
      let side = 0;
      for (let a = 0; a < 3; a++) side += (faceCentre[3 * t + a] - at[a]) * normals[3 * mine + a];
      const sign = side > 0 ? -1 : 1;
      planes.push(sign * nb[0], sign * nb[1], sign * nb[2], -sign * (nb[0] * at[0] + nb[1] * at[1] + nb[2] * at[2]));
    }
    clip[s] = kept.length | (1 << 4) | (first << 6);
  }
  return { clip, planes: new Float32Array(planes) };
}
