// @ts-check
/**
 * Readings with their error: the straight distance between two picks, in
 * the model's unit, with the error of the level they were picked on. Each
 * pick lies on the level's surface, which is within the level's Hausdorff
 * distance h × diagonal of the full-resolution surface (manifest
 * `levels[k].hausdorff`, or the ingest's quality curve), so the distance is
 * within 2 h × diagonal of the distance between the two nearest points of
 * the original. No DOM (unit-tested in Node).
 */
import { formatNumber, t } from './i18n/index.js';

/** @typedef {[number, number, number]} Vec3 */

/** Units the manifest may give and their names on screen (null: the model's own units). */
export const UNITS = /** @type {const} */ (['mm', 'cm', 'm', 'in']);

/**
 * @param {ArrayLike<number>} a
 * @param {ArrayLike<number>} b
 */
export function distance(a, b) {
  return Math.hypot(a[0] - b[0], a[1] - b[1], a[2] - b[2]);
}

/** @param {import('./geometry.js').Bounds} box */
export function diagonal(box) {
  return distance(box.min, box.max);
}

/**
 * The Hausdorff distance (fraction of the diagonal) of `level`: the
 * manifest's level entry, else the quality curve's point, else null (not measured).
 * @param {any} manifest
 * @param {number} level
 * @returns {number | null}
 */
export function levelHausdorff(manifest, level) {
  const own = manifest?.levels?.[level]?.hausdorff;
  if (Number.isFinite(own)) return own;
  const point = manifest?.quality?.find?.((/** @type {any} */ p) => p.level === level);
  return Number.isFinite(point?.hausdorff) ? point.hausdorff : null;
}

/**
 * Enough digits that the error shows (its first significant digit, at most
 * six decimals); without an error, four significant digits.
 * @param {number} value
 * @param {number | null} error
 */
function decimals(value, error) {
  const scale = error && error > 0 ? error : Math.abs(value) / 1000;
  if (!(scale > 0)) return 0;
  return Math.max(0, Math.min(6, -Math.floor(Math.log10(scale))));
}

/**
 * "12.4 mm ± 0.3 mm at this level": the distance and its error in the
 * model's unit (no unit: "units").
 * @param {number} value
 * @param {number | null} error null: the level's error was not measured
 * @param {string | null | undefined} unit
 */
export function formatReading(value, error, unit) {
  const places = decimals(value, error);
  const number = (/** @type {number} */ x) => formatNumber(x, { minimumFractionDigits: places, maximumFractionDigits: places });
  const known = /** @type {readonly string[]} */ (UNITS).includes(unit ?? '');
  const length = (/** @type {number} */ x) => (known ? `${number(x)} ${unit}` : t('measure.units', { value: number(x) }));
  if (error === null) return t('measure.unmeasured', { length: length(value) });
  return t('measure.reading', { length: length(value), error: length(error) });
}

/**
 * A straight measurement between two picks on a level.
 * @param {Vec3} a
 * @param {Vec3} b
 * @param {{ hausdorff: number | null, diagonal: number }} level
 * @returns {{ value: number, error: number | null }}
 */
export function measurement(a, b, level) {
  const value = distance(a, b);
  const error = level.hausdorff === null ? null : 2 * level.hausdorff * level.diagonal;
  return { value, error };
}
