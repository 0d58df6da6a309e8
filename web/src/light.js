// @ts-check
/**
 * The key light the visitor moves: a direction in view space (it turns with
 * the camera, as the studio rig of shading.js does), set by dragging on a
 * small disc (the disc is the hemisphere facing the visitor seen from the
 * front: the centre is a light behind the visitor's head, the rim a light
 * grazing the surface) or by a raking-light preset: light from one side at
 * a low angle, with little fill, so that inscriptions and tool marks cast
 * shadows. No DOM (unit-tested in Node).
 */

import { KEY } from './shading.js';

/** @typedef {[number, number, number]} Vec3 */
/** @typedef {{ key: Vec3, fill: number }} Light */

/** The studio rig (shading.js). */
export const STUDIO = /** @type {Light} */ ({ key: KEY, fill: 1 });

/** Raking light: this many degrees above the image plane, fill and ambient scaled down to this. */
export const RAKING_ELEVATION_DEG = 12;
export const RAKING_FILL = 0.2;

/** The four raking presets: where the light comes from, on screen. */
export const RAKING = /** @type {const} */ ({ left: [-1, 0], right: [1, 0], top: [0, 1], bottom: [0, -1] });

/**
 * @param {keyof typeof RAKING} from
 * @returns {Light}
 */
export function rakingLight(from) {
  const [dx, dy] = RAKING[from];
  const e = (RAKING_ELEVATION_DEG * Math.PI) / 180;
  return { key: [Math.cos(e) * dx, Math.cos(e) * dy, Math.sin(e)], fill: RAKING_FILL };
}

/**
 * The light for a point on the disc widget: (u, v) in −1…1 from its centre,
 * v up; outside the disc, the nearest point of its rim (a grazing light).
 * @param {number} u
 * @param {number} v
 * @param {number} [fill]
 * @returns {Light}
 */
export function discLight(u, v, fill = 1) {
  const r = Math.hypot(u, v);
  const s = r > 1 ? 1 / r : 1;
  const x = u * s;
  const y = v * s;
  // Keep a sliver above the plane so the rim still lights what faces the visitor.
  const z = Math.sqrt(Math.max(0, 1 - x * x - y * y));
  const l = Math.hypot(x, y, Math.max(z, 0.02));
  return { key: [x / l, y / l, Math.max(z, 0.02) / l], fill };
}

/**
 * Where a light's direction sits on the disc (its projection on the image plane).
 * @param {Light} light
 * @returns {[number, number]}
 */
export function discPosition(light) {
  return [light.key[0], light.key[1]];
}
