// @ts-check
/**
 * The lighting model, once: the GLSL fragment shader is generated from these
 * constants and `shade` is its JavaScript twin, used by the Node reference
 * rasterizer the end-to-end test compares the page against. Lights are fixed
 * in view space (a studio rig that turns with the visitor), so every side of
 * a scan is lit when it faces the camera. The key light's direction and the
 * strength of the fill and ambient light are uniforms (the visitor moves the
 * key light, light.js); their defaults are the studio rig below.
 */

/** @typedef {[number, number, number]} Vec3 */

/** Clay grey (sRGB) for streams without colour. */
export const CLAY = /** @type {Vec3} */ ([0.78, 0.75, 0.70]);
/** Canvas clear colour (sRGB); tests look for pixels that differ from it. */
export const BACKGROUND = /** @type {Vec3} */ ([0.13, 0.14, 0.16]);
export const WIRE_COLOUR = /** @type {Vec3} */ ([0.05, 0.06, 0.08]);
export const WIRE_ALPHA = 0.45;

export const KEY = normalize([-0.45, 0.6, 0.75]);
const FILL = normalize([0.55, -0.15, 0.6]);
const KEY_INTENSITY = 0.8;
const FILL_INTENSITY = 0.35;
const SKY = 0.22;
const GROUND = 0.12;
const SPECULAR = 0.12;
const SHININESS = 32;
/**
 * Blinn half-vector of a key light for a viewer along +Z (view space).
 * @param {Vec3} key
 * @returns {Vec3}
 */
export function halfVector(key) {
  return normalize([key[0], key[1], key[2] + 1]);
}

/** The fragment shader's lighting function (u_key: unit key direction, view space; u_keyHalf its half-vector). */
export const GLSL_SHADE = `
uniform vec3 u_key;
uniform vec3 u_keyHalf;
uniform float u_fillScale;
vec3 shade(vec3 n, vec3 albedoSrgb) {
  vec3 albedo = pow(albedoSrgb, vec3(2.2));
  float ambient = u_fillScale * mix(${f(GROUND)}, ${f(SKY)}, 0.5 + 0.5 * n.y);
  float key = ${f(KEY_INTENSITY)} * max(dot(n, u_key), 0.0);
  float fill = u_fillScale * ${f(FILL_INTENSITY)} * max(dot(n, ${v(FILL)}), 0.0);
  float spec = ${f(SPECULAR)} * pow(max(dot(n, u_keyHalf), 0.0), ${f(SHININESS)});
  vec3 linear = albedo * (ambient + key + fill) + vec3(spec);
  return pow(clamp(linear, 0.0, 1.0), vec3(1.0 / 2.2));
}`;

/**
 * @param {Vec3} n unit normal in view space, facing the viewer
 * @param {Vec3} albedoSrgb 0..1
 * @param {{ key: Vec3, fill: number }} [light] the key light's unit direction and the fill's scale (default: the studio rig)
 * @returns {Vec3} sRGB 0..1
 */
export function shade(n, albedoSrgb, light = { key: KEY, fill: 1 }) {
  const half = halfVector(light.key);
  const ambient = light.fill * (GROUND + (SKY - GROUND) * (0.5 + 0.5 * n[1]));
  const key = KEY_INTENSITY * Math.max(dot(n, light.key), 0);
  const fill = light.fill * FILL_INTENSITY * Math.max(dot(n, FILL), 0);
  const spec = SPECULAR * Math.pow(Math.max(dot(n, half), 0), SHININESS);
  const total = ambient + key + fill;
  return /** @type {Vec3} */ (
    albedoSrgb.map((c) => Math.pow(Math.min(1, Math.max(0, Math.pow(c, 2.2) * total + spec)), 1 / 2.2))
  );
}

/** @param {Vec3} a @param {Vec3} b */
function dot(a, b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/** @param {Vec3} a @returns {Vec3} */
function normalize(a) {
  const l = Math.hypot(...a);
  return [a[0] / l, a[1] / l, a[2] / l];
}

/** @param {number} x */
function f(x) {
  return Number.isInteger(x) ? `${x}.0` : String(x);
}

/** @param {Vec3} a */
function v(a) {
  return `vec3(${a.map(f).join(', ')})`;
}
