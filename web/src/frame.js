// @ts-check
/**
 * Upright and framed: the manifest's `up` (which model axis points up) as a
 * rotation of the model onto the viewer's +Y, the model's bounds after it,
 * and the camera distance at which a box fills most of the view for the
 * view's aspect. No DOM: the unit tests and the page use the same code.
 *
 * The rotation is a signed permutation (up is always a coordinate axis), so
 * a box stays a box and the matrix's transpose is its inverse.
 */

/** @typedef {[number, number, number]} Vec3 */
/** @typedef {'x' | 'y' | 'z' | '-x' | '-y' | '-z'} UpAxis */

/** The axes the manifest may name; anything else is read as the default "y". */
export const UP_AXES = /** @type {const} */ (['x', 'y', 'z', '-x', '-y', '-z']);

/**
 * The rotation taking the model's `up` axis onto +Y, as a column-major 3×3
 * matrix (WebGL's mat3). For a Z-up scan (+z up) it is a quarter turn about
 * +X that keeps the handedness: (x, y, z) → (x, z, −y).
 * @param {string | null | undefined} up
 * @returns {number[]} 9 numbers
 */
export function upRotation(up) {
  const axis = /** @type {readonly string[]} */ (UP_AXES).includes(up ?? '') ? /** @type {UpAxis} */ (up) : 'y';
  // Rows: where each world axis (x, y, z) reads its value from in model space.
  /** @type {Record<UpAxis, number[][]>} */
  const rows = {
    y: [[1, 0, 0], [0, 1, 0], [0, 0, 1]],
    '-y': [[1, 0, 0], [0, -1, 0], [0, 0, -1]],
    z: [[1, 0, 0], [0, 0, 1], [0, -1, 0]],
    '-z': [[1, 0, 0], [0, 0, -1], [0, 1, 0]],
    x: [[0, -1, 0], [1, 0, 0], [0, 0, 1]],
    '-x': [[0, 1, 0], [-1, 0, 0], [0, 0, 1]],
  };
  const r = rows[axis];
  // Column-major: m[c * 3 + r].
  return [r[0][0], r[1][0], r[2][0], r[0][1], r[1][1], r[2][1], r[0][2], r[1][2], r[2][2]];
}

/**
 * @param {ArrayLike<number>} m column-major 3×3
 * @param {ArrayLike<number>} p
 * @returns {Vec3} m · p
 */
export function rotate(m, p) {
  return [
    m[0] * p[0] + m[3] * p[1] + m[6] * p[2],
    m[1] * p[0] + m[4] * p[1] + m[7] * p[2],
    m[2] * p[0] + m[5] * p[1] + m[8] * p[2],
  ];
}

/**
 * @param {ArrayLike<number>} m column-major 3×3 rotation
 * @param {ArrayLike<number>} p
 * @returns {Vec3} mᵀ · p (the inverse rotation)
 */
export function unrotate(m, p) {
  return [
    m[0] * p[0] + m[1] * p[1] + m[2] * p[2],
    m[3] * p[0] + m[4] * p[1] + m[5] * p[2],
    m[6] * p[0] + m[7] * p[1] + m[8] * p[2],
  ];
}

/**
 * The box around the rotated corners of `box`.
 * @param {import('./geometry.js').Bounds} box
 * @param {ArrayLike<number>} m
 * @returns {import('./geometry.js').Bounds}
 */
export function rotateBounds(box, m) {
  /** @type {Vec3} */
  const min = [Infinity, Infinity, Infinity];
  /** @type {Vec3} */
  const max = [-Infinity, -Infinity, -Infinity];
  for (const c of corners(box)) {
    const p = rotate(m, c);
    for (let k = 0; k < 3; k++) {
      min[k] = Math.min(min[k], p[k]);
      max[k] = Math.max(max[k], p[k]);
    }
  }
  return { min, max };
}

/**
 * @param {import('./geometry.js').Bounds} box
 * @returns {Vec3[]} its eight corners
 */
export function corners(box) {
  /** @type {Vec3[]} */
  const out = [];
  for (let i = 0; i < 8; i++) {
    out.push([i & 1 ? box.max[0] : box.min[0], i & 2 ? box.max[1] : box.min[1], i & 4 ? box.max[2] : box.min[2]]);
  }
  return out;
}

/**
 * The bounds the viewer frames: the manifest's (every level's extent, in
 * model coordinates) when it has valid ones, else the base mesh's.
 * @param {unknown} manifestBounds
 * @template {import('./geometry.js').Bounds | null} F
 * @param {F} fallback
 * @returns {import('./geometry.js').Bounds | F}
 */
export function validBounds(manifestBounds, fallback) {
  const b = /** @type {any} */ (manifestBounds);
  const ok = (/** @type {unknown} */ v) => Array.isArray(v) && v.length === 3 && v.every((x) => Number.isFinite(x));
  if (b && ok(b.min) && ok(b.max) && b.min.every((/** @type {number} */ x, /** @type {number} */ k) => x <= b.max[k])) {
    return { min: [b.min[0], b.min[1], b.min[2]], max: [b.max[0], b.max[1], b.max[2]] };
  }
  return fallback;
}

/**
 * The distance from `target` at which every corner of `box`, seen from the
 * orbit direction (yaw, pitch), lies within `fill` of the half-width and
 * half-height of the view: the box fills most of the view whatever the
 * aspect (portrait phones included), instead of the bounding sphere fitting
 * the height only.
 * @param {import('./geometry.js').Bounds} box
 * @param {Vec3} target
 * @param {{ yaw: number, pitch: number, fovY: number, aspect: number, fill?: number }} view
 */
export function fitDistance(box, target, { yaw, pitch, fovY, aspect, fill = 0.9 }) {
  const back = [Math.cos(pitch) * Math.sin(yaw), Math.sin(pitch), Math.cos(pitch) * Math.cos(yaw)];
  const right = normalize([back[2], 0, -back[0]]);
  const up = [
    back[1] * right[2] - back[2] * right[1],
    back[2] * right[0] - back[0] * right[2],
    back[0] * right[1] - back[1] * right[0],
  ];
  const tanY = fill * Math.tan(fovY / 2);
  const tanX = tanY * Math.max(1e-3, aspect);
  let distance = 0;
  let radius = 0;
  for (const c of corners(box)) {
    const d = [c[0] - target[0], c[1] - target[1], c[2] - target[2]];
    const x = dot(d, right);
    const y = dot(d, up);
    const z = dot(d, back);
    radius = Math.max(radius, Math.hypot(x, y, z));
    distance = Math.max(distance, z + Math.abs(x) / tanX, z + Math.abs(y) / tanY);
  }
  // Never inside the box, whatever the aspect.
  return Math.max(distance, 1.05 * radius, 1e-6);
}

/** @param {ArrayLike<number>} a @param {ArrayLike<number>} b */
function dot(a, b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/** @param {number[]} a */
function normalize(a) {
  const l = Math.hypot(a[0], a[1], a[2]) || 1;
  return [a[0] / l, a[1] / l, a[2] / l];
}

/**
 * The box the camera frames, in world (upright) coordinates: the manifest's
 * bounds when the look has them, else the base mesh's, turned upright.
 * The page and the render worker both make their camera from it.
 * @param {{ model: ArrayLike<number>, bounds: import('./geometry.js').Bounds | null }} look
 * @param {import('./geometry.js').Bounds} baseBounds
 */
export function frameBox(look, baseBounds) {
  return rotateBounds(look.bounds ?? baseBounds, look.model);
}
