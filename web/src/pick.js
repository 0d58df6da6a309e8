// @ts-check
/**
 * Picking on the level on screen, on the CPU from its decoded geometry:
 * rays from the camera through a pixel, the nearest triangle a ray hits
 * (Möller–Trumbore, in double precision, every triangle in turn: no
 * acceleration structure to build per level, and a million triangles take
 * tens of milliseconds, once per click), whether a point is hidden behind
 * the surface, and where a point of the model lands on screen. No DOM: the
 * render worker (where the geometry is), the page and the unit tests share it.
 */

import { multiply } from './camera.js';
import { rotate, unrotate } from './frame.js';

/** @typedef {[number, number, number]} Vec3 */
/** @typedef {{ origin: Vec3, direction: Vec3 }} Ray */
/** @typedef {{ t: number, face: number, point: Vec3, triangle: [Vec3, Vec3, Vec3] }} Hit */
/**
 * A level to pick on: positions of every vertex received (at least `vertices`), its triangles.
 * @typedef {{ positions: Float32Array, vertices: number, indices: Uint32Array, level: number }} Surface
 */
/** @typedef {{ hit: Hit | null, vertex: Vec3 | null, level: number | null, ms: number }} PickResult */

/**
 * The nearest surface point of a level along a ray (model coordinates),
 * the vertex nearest to it within `snap` × t model units (null: none that
 * near), and the time it took. With a ray from viewRay (its direction's
 * forward component is 1, so t is the hit's depth), `snap` is the snapping
 * radius in pixels times pixelSize(camera, 1, height): the same number of
 * pixels at any depth.
 * @param {Surface | null} surface
 * @param {Ray} ray
 * @param {number} snap
 * @returns {PickResult}
 */
export function pickLevel(surface, ray, snap) {
  const t0 = performance.now();
  if (!surface) return { hit: null, vertex: null, level: null, ms: 0 };
  const hit = intersect(surface.positions, surface.indices, ray);
  const vertex = hit && snap > 0 ? nearestVertex(surface.positions, surface.vertices, hit.point, snap * hit.t) : null;
  return { hit, vertex, level: surface.level, ms: performance.now() - t0 };
}

/**
 * Which of `points` a level hides from `eye` (model coordinates; see occluded).
 * @param {Surface | null} surface
 * @param {ArrayLike<number>} eye
 * @param {ReadonlyArray<ArrayLike<number>>} points
 * @param {number} tolerance
 */
export function occludedPoints(surface, eye, points, tolerance) {
  return points.map((p) => (surface ? occluded(surface.positions, surface.indices, eye, p, tolerance) : false));
}

/**
 * The ray from the eye through a point of the view, in model coordinates.
 * @param {import('./camera.js').OrbitCamera} camera
 * @param {ArrayLike<number>} model the model rotation (frame.js upRotation)
 * @param {number} x CSS pixels from the view's left edge
 * @param {number} y CSS pixels from the view's top edge
 * @param {number} width the view in CSS pixels
 * @param {number} height
 * @returns {Ray}
 */
export function viewRay(camera, model, x, y, width, height) {
  const { eye, right, up, forward } = camera.basis();
  const tan = Math.tan(camera.fovY / 2);
  const sx = ((2 * x) / width - 1) * tan * (width / height);
  const sy = (1 - (2 * y) / height) * tan;
  const world = [0, 1, 2].map((k) => forward[k] + sx * right[k] + sy * up[k]);
  return { origin: unrotate(model, eye), direction: unrotate(model, world) };
}

/**
 * Where a model point lands in the view: CSS pixels from the top left, and
 * whether it is in front of the eye.
 * @param {import('./camera.js').OrbitCamera} camera
 * @param {ArrayLike<number>} model
 * @param {ArrayLike<number>} point model coordinates
 * @param {number} width
 * @param {number} height
 * @returns {{ x: number, y: number, depth: number, inFront: boolean }}
 */
export function projectPoint(camera, model, point, width, height) {
  const m = multiply(camera.projection(width / height), camera.view());
  const p = rotate(model, point);
  const cx = m[0] * p[0] + m[4] * p[1] + m[8] * p[2] + m[12];
  const cy = m[1] * p[0] + m[5] * p[1] + m[9] * p[2] + m[13];
  const cz = m[2] * p[0] + m[6] * p[1] + m[10] * p[2] + m[14];
  const cw = m[3] * p[0] + m[7] * p[1] + m[11] * p[2] + m[15];
  const inFront = cw > 1e-9;
  const w = inFront ? cw : 1e-9;
  return { x: ((cx / w + 1) / 2) * width, y: ((1 - cy / w) / 2) * height, depth: cz / w, inFront };
}

/**
 * The nearest triangle the ray hits at 0 < t < tMax (t in units of the
 * direction's length), or null.
 * @param {Float32Array} positions x, y, z per vertex
 * @param {Uint32Array} indices three per triangle
 * @param {Ray} ray
 * @param {number} [tMax]
 * @param {boolean} [any] stop at the first hit (an occlusion test), not the nearest
 * @returns {Hit | null}
 */
export function intersect(positions, indices, ray, tMax = Infinity, any = false) {
  const [ox, oy, oz] = ray.origin;
  const [dx, dy, dz] = ray.direction;
  let best = tMax;
  let face = -1;
  const vertices = positions.length / 3;
  for (let f = 0, n = indices.length - 2; f < n; f += 3) {
    const a = 3 * indices[f];
    const b = 3 * indices[f + 1];
    const c = 3 * indices[f + 2];
    if (a >= 3 * vertices || b >= 3 * vertices || c >= 3 * vertices) continue;
    const ax = positions[a];
    const ay = positions[a + 1];
    const az = positions[a + 2];
    const e1x = positions[b] - ax;
    const e1y = positions[b + 1] - ay;
    const e1z = positions[b + 2] - az;
    const e2x = positions[c] - ax;
    const e2y = positions[c + 1] - ay;
    const e2z = positions[c + 2] - az;
    // p = d × e2
    const px = dy * e2z - dz * e2y;
    const py = dz * e2x - dx * e2z;
    const pz = dx * e2y - dy * e2x;
    const det = e1x * px + e1y * py + e1z * pz;
    if (det > -1e-300 && det < 1e-300) continue;
    const inv = 1 / det;
    const tx = ox - ax;
    const ty = oy - ay;
    const tz = oz - az;
    const u = (tx * px + ty * py + tz * pz) * inv;
    if (u < 0 || u > 1) continue;
    // q = s × e1
    const qx = ty * e1z - tz * e1y;
    const qy = tz * e1x - tx * e1z;
    const qz = tx * e1y - ty * e1x;
    const v = (dx * qx + dy * qy + dz * qz) * inv;
    if (v < 0 || u + v > 1) continue;
    const t = (e2x * qx + e2y * qy + e2z * qz) * inv;
    if (t > 1e-9 && t < best) {
      best = t;
      face = f / 3;
      if (any) break;
    }
  }
  if (face < 0) return null;
  /** @type {[Vec3, Vec3, Vec3]} */
  const triangle = /** @type {any} */ (
    [0, 1, 2].map((k) => {
      const i = 3 * indices[3 * face + k];
      return [positions[i], positions[i + 1], positions[i + 2]];
    })
  );
  /** @type {Vec3} */
  const point = [ox + best * dx, oy + best * dy, oz + best * dz];
  return { t: best, face, point, triangle };
}

/**
 * Whether the surface hides `point` from `eye`: a hit on the segment
 * before the point, farther than `tolerance` (model units) from it — a
 * coarse level's surface lies within its Hausdorff distance of the point,
 * on either side.
 * @param {Float32Array} positions
 * @param {Uint32Array} indices
 * @param {ArrayLike<number>} eye model coordinates
 * @param {ArrayLike<number>} point
 * @param {number} tolerance
 */
export function occluded(positions, indices, eye, point, tolerance) {
  /** @type {Vec3} */
  const direction = [point[0] - eye[0], point[1] - eye[1], point[2] - eye[2]];
  const length = Math.hypot(...direction);
  if (length <= tolerance) return false;
  const ray = { origin: /** @type {Vec3} */ ([eye[0], eye[1], eye[2]]), direction };
  return intersect(positions, indices, ray, 1 - tolerance / length, true) !== null;
}

/**
 * The vertex nearest to `point` within `radius` (model units), or null:
 * picks snap to it, so that a measurement goes from vertex to vertex
 * (corners and edges of an object are vertices of the scan). A scan over
 * the vertices, a few milliseconds for a million.
 * @param {Float32Array} positions
 * @param {number} count vertices to look at
 * @param {ArrayLike<number>} point
 * @param {number} radius
 * @returns {Vec3 | null}
 */
export function nearestVertex(positions, count, point, radius) {
  let best = radius * radius;
  let found = -1;
  const [x, y, z] = [point[0], point[1], point[2]];
  for (let v = 0, n = Math.min(count, positions.length / 3); v < n; v++) {
    const dx = positions[3 * v] - x;
    const dy = positions[3 * v + 1] - y;
    const dz = positions[3 * v + 2] - z;
    const d = dx * dx + dy * dy + dz * dz;
    if (d <= best) {
      best = d;
      found = v;
    }
  }
  return found < 0 ? null : [positions[3 * found], positions[3 * found + 1], positions[3 * found + 2]];
}

/**
 * The size of a CSS pixel in model units at `distance` from the eye.
 * @param {import('./camera.js').OrbitCamera} camera
 * @param {number} distance
 * @param {number} height the view in CSS pixels
 */
export function pixelSize(camera, distance, height) {
  return (2 * distance * Math.tan(camera.fovY / 2)) / height;
}
