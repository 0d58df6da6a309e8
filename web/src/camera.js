// @ts-check
/**
 * An orbit camera around a target point, and the few 4×4 matrix operations
 * the viewer needs (column-major, as WebGL expects). No DOM: the Node
 * reference rasterizer uses the same matrices as the page.
 */

/** @typedef {[number, number, number]} Vec3 */

/**
 * @typedef {object} OrbitState
 * @property {Vec3} target point looked at
 * @property {number} distance from target to eye
 * @property {number} yaw radians about +Y
 * @property {number} pitch radians above the horizon
 */

import { fitDistance } from './frame.js';

const FOV_Y = (40 * Math.PI) / 180;
const PITCH_LIMIT = Math.PI / 2 - 0.01;

export class OrbitCamera {
  /**
   * @param {import('./geometry.js').Bounds} box in world (upright) coordinates
   * @param {number} [aspect] the view's width / height: the home view fits the
   *   box to it (frame()); without it, the bounding sphere fits the height
   */
  constructor(box, aspect) {
    this.box = box;
    const centre = /** @type {Vec3} */ (box.min.map((lo, k) => (lo + box.max[k]) / 2));
    const radius = Math.max(1e-6, Math.hypot(...box.max.map((hi, k) => hi - box.min[k])) / 2);
    this.radius = radius;
    this.fovY = FOV_Y;
    /** A three-quarter view, far enough that the bounding sphere fits with a margin. */
    /** @type {OrbitState} */
    this.home = { target: centre, distance: (1.1 * radius) / Math.sin(FOV_Y / 2), yaw: 0.5, pitch: 0.4 };
    /** @type {OrbitState} */
    this.state = structuredClone(this.home);
    if (aspect) this.frame(aspect);
  }

  /**
   * Home view for a view of this aspect: the box fills most of it
   * (frame.js fitDistance); the current view becomes the home view.
   * @param {number} aspect width / height
   */
  frame(aspect) {
    const { target, yaw, pitch } = this.home;
    this.home.distance = fitDistance(this.box, target, { yaw, pitch, fovY: this.fovY, aspect });
    this.state = structuredClone(this.home);
  }

  reset() {
    this.state = structuredClone(this.home);
  }

  /**
   * Drag by pixels: a drag across the viewport's height turns half a turn.
   * @param {number} dx
   * @param {number} dy
   * @param {number} height viewport height in the same units
   */
  rotate(dx, dy, height) {
    const s = this.state;
    s.yaw -= (Math.PI * dx) / height;
    s.pitch = Math.max(-PITCH_LIMIT, Math.min(PITCH_LIMIT, s.pitch + (Math.PI * dy) / height));
  }

  /** @param {number} factor > 1 moves away */
  zoom(factor) {
    const s = this.state;
    s.distance = Math.max(0.05 * this.radius, Math.min(20 * this.radius, s.distance * factor));
  }

  /**
   * Moves the target so the point under the pointer follows it.
   * @param {number} dx
   * @param {number} dy
   * @param {number} height viewport height in the same units
   */
  pan(dx, dy, height) {
    const s = this.state;
    const perPixel = (2 * s.distance * Math.tan(this.fovY / 2)) / height;
    const { right, up } = this.basis();
    for (let k = 0; k < 3; k++) s.target[k] += (-dx * right[k] + dy * up[k]) * perPixel;
  }

  /** @returns {{ eye: Vec3, right: Vec3, up: Vec3, forward: Vec3 }} */
  basis() {
    const { target, distance, yaw, pitch } = this.state;
    /** @type {Vec3} */
    const back = [Math.cos(pitch) * Math.sin(yaw), Math.sin(pitch), Math.cos(pitch) * Math.cos(yaw)];
    /** @type {Vec3} */
    const eye = [target[0] + distance * back[0], target[1] + distance * back[1], target[2] + distance * back[2]];
    const right = normalize(cross([0, 1, 0], back));
    const up = cross(back, right);
    return { eye, right, up, forward: [-back[0], -back[1], -back[2]] };
  }

  /** @returns {Float32Array} world → view */
  view() {
    const { eye, right, up, forward } = this.basis();
    // prettier-ignore
    return new Float32Array([
      right[0], up[0], -forward[0], 0,
      right[1], up[1], -forward[1], 0,
      right[2], up[2], -forward[2], 0,
      -dot(right, eye), -dot(up, eye), dot(forward, eye), 1,
    ]);
  }

  /**
   * Near and far planes hug the bounding sphere so depth precision goes to the model.
   * @param {number} aspect width / height
   * @returns {Float32Array}
   */
  projection(aspect) {
    const d = this.state.distance;
    const far = d + 2 * this.radius;
    const near = Math.max(d - 2 * this.radius, far / 1000);
    const f = 1 / Math.tan(this.fovY / 2);
    // prettier-ignore
    return new Float32Array([
      f / aspect, 0, 0, 0,
      0, f, 0, 0,
      0, 0, (far + near) / (near - far), -1,
      0, 0, (2 * far * near) / (near - far), 0,
    ]);
  }
}

/**
 * @param {Float32Array} a
 * @param {Float32Array} b
 * @returns {Float32Array} a · b
 */
export function multiply(a, b) {
  const out = new Float32Array(16);
  for (let c = 0; c < 4; c++) {
    for (let r = 0; r < 4; r++) {
      let sum = 0;
      for (let k = 0; k < 4; k++) sum += a[k * 4 + r] * b[c * 4 + k];
      out[c * 4 + r] = sum;
    }
  }
  return out;
}

/** @param {Vec3} a @param {Vec3} b @returns {Vec3} */
function cross(a, b) {
  return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
}

/** @param {Vec3} a @param {Vec3} b */
function dot(a, b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/** @param {Vec3} a @returns {Vec3} */
function normalize(a) {
  const l = Math.hypot(...a) || 1;
  return [a[0] / l, a[1] / l, a[2] / l];
}
