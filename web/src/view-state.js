// @ts-check
/**
 * A view you can link to: the viewer's state as the fragment of a page's
 * address (`/m/{slug}#camera=…&light=…`), and back. The fragment, not the
 * query: it never reaches the server (a shared view does not split the
 * page's cache or fill its logs) and changing it reloads nothing. The
 * language and a held level keep their query parameters (`?lang=`, read by
 * the server before any script runs, and `?level=`). The element takes the
 * same text in its `view` attribute, a tour step stores it as its view.
 *
 * Fields, each optional, numbers in the viewer's world frame (model units,
 * turned upright: frame.js):
 * - `camera=tx,ty,tz,distance,yaw,pitch` the orbit (camera.js OrbitState)
 * - `light=x,y,z,fill` the key light, in view space (light.js)
 * - `section=axis,fraction,flip` the section pane: `x|y|z`, 0–1 along the
 *   model's extent, `1` for the other side
 * - `note=id` the annotation open
 * - `measure=ax,ay,az,bx,by,bz` the two picks of a measurement, model units
 * A field that does not parse is left out (the rest still applies). No DOM
 * (unit-tested in Node).
 */

/** @typedef {[number, number, number]} Vec3 */

/**
 * @typedef {object} ViewState
 * @property {import('./camera.js').OrbitState} [camera]
 * @property {import('./light.js').Light} [light]
 * @property {{ axis: 'x' | 'y' | 'z', fraction: number, flip: boolean }} [section]
 * @property {string} [note]
 * @property {[Vec3, Vec3]} [measure]
 */

/** Longest fragment read: a view is a few hundred characters. */
export const MAX_VIEW_LENGTH = 2048;

/** Significant digits written: well under a pixel at any zoom the camera allows. */
const DIGITS = 9;

/** @param {number} x */
function number(x) {
  return String(Number(x.toPrecision(DIGITS)));
}

/**
 * @param {string | undefined | null} text
 * @param {number} count
 * @returns {number[] | null}
 */
function numbers(text, count) {
  if (!text) return null;
  const parts = text.split(',');
  if (parts.length !== count) return null;
  const values = parts.map((p) => (p.trim() === '' ? NaN : Number(p)));
  return values.every(Number.isFinite) ? values : null;
}

/**
 * The fragment (without `#`) for a view.
 * @param {ViewState} view
 */
export function formatView(view) {
  const fields = new URLSearchParams();
  if (view.camera) {
    const { target, distance, yaw, pitch } = view.camera;
    fields.set('camera', [...target, distance, yaw, pitch].map(number).join(','));
  }
  if (view.light) fields.set('light', [...view.light.key, view.light.fill].map(number).join(','));
  if (view.section) fields.set('section', `${view.section.axis},${number(view.section.fraction)},${view.section.flip ? 1 : 0}`);
  if (view.note !== undefined) fields.set('note', view.note);
  if (view.measure) fields.set('measure', view.measure.flat().map(number).join(','));
  // Commas are safe in a fragment; keep them readable.
  return fields.toString().replace(/%2C/g, ',');
}

/**
 * A view from a fragment (with or without `#`); fields that do not parse are dropped.
 * @param {string | null | undefined} fragment
 * @returns {ViewState}
 */
export function parseView(fragment) {
  /** @type {ViewState} */
  const view = {};
  if (!fragment || fragment.length > MAX_VIEW_LENGTH) return view;
  const fields = new URLSearchParams(fragment.replace(/^#/, ''));
  const camera = numbers(fields.get('camera'), 6);
  if (camera && camera[3] > 0) {
    view.camera = { target: [camera[0], camera[1], camera[2]], distance: camera[3], yaw: camera[4], pitch: camera[5] };
  }
  const light = numbers(fields.get('light'), 4);
  if (light && Math.hypot(light[0], light[1], light[2]) > 0 && light[3] >= 0 && light[3] <= 1) {
    const l = Math.hypot(light[0], light[1], light[2]);
    view.light = { key: [light[0] / l, light[1] / l, light[2] / l], fill: light[3] };
  }
  const section = fields.get('section')?.split(',');
  if (section?.length === 3 && ['x', 'y', 'z'].includes(section[0])) {
    const fraction = Number(section[1]);
    if (section[1] !== '' && fraction >= 0 && fraction <= 1 && (section[2] === '0' || section[2] === '1')) {
      view.section = { axis: /** @type {'x' | 'y' | 'z'} */ (section[0]), fraction, flip: section[2] === '1' };
    }
  }
  const note = fields.get('note');
  if (note && note.length <= 64) view.note = note;
  const measure = numbers(fields.get('measure'), 6);
  if (measure) view.measure = [[measure[0], measure[1], measure[2]], [measure[3], measure[4], measure[5]]];
  return view;
}

/** @param {ViewState} view */
export function isEmptyView(view) {
  return Object.keys(view).length === 0;
}
