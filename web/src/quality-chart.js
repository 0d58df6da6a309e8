// @ts-check
/**
 * The quality curve of a model as a small SVG chart: the manifest's
 * `quality` (measured at ingest with `vitrine ingest --quality`,
 * server/src/service/api.rs), one point per level. x is the level's vertex
 * count on a log scale; y is the error in 0–255 units, also on a log scale
 * (the two errors can differ by a hundredfold, and each falls by orders of
 * magnitude as a scan refines): the Lindstrom–Turk image RMSE over 24 views
 * and, when the model has colour, Roy's colour RMSE. A marker stands at the
 * level on screen. When the model has a quality study with answers
 * (`GET /api/study/{slug}/results`), a bar at each level shows the share of
 * participants who found that level's quality sufficient (0–100 % of the
 * plot's height).
 *
 * Pure functions of the data (no DOM), so Node tests them and the viewer's
 * panel inserts the string into its shadow root. Every number is formatted
 * here; no text from the manifest reaches the markup.
 */
import { formatNumber, t } from './i18n/index.js';

/**
 * One level's quality against the original.
 * @typedef {object} QualityPoint
 * @property {number} level 0 is the base mesh
 * @property {number} vertices
 * @property {number} hausdorff symmetric Hausdorff distance over the bounding-box diagonal
 * @property {number | null} roy_rmse Roy et al. colour RMSE (0–255), null without colour
 * @property {number} image_rmse Lindstrom–Turk luma RMSE (0–255) over 24 views
 */

/**
 * @typedef {object} ChartOptions
 * @property {number} [width] of the viewBox (default 260)
 * @property {number} [height] of the viewBox (default 130)
 * @property {ReadonlyArray<StudyLevel> | null} [study] the study's answers per level
 */

/**
 * One level's answers in the quality study (Q2 "Is this quality sufficient?").
 * @typedef {{ level: number, answers: number, sufficient: number }} StudyLevel
 */

/**
 * @typedef {'image_rmse' | 'roy_rmse'} SeriesKey
 * @typedef {{ level: number, x: number, y: number }} PlacedPoint
 * @typedef {{ key: SeriesKey, label: string, colour: string, points: PlacedPoint[] }} PlacedSeries
 */

/**
 * Where everything goes, in viewBox units (y grows downwards).
 * @typedef {object} ChartLayout
 * @property {number} width
 * @property {number} height
 * @property {{ left: number, right: number, top: number, bottom: number }} plot
 * @property {PlacedSeries[]} series lines to draw, image RMSE first
 * @property {{ level: number, x: number, points: Array<{ key: SeriesKey, y: number }> } | null} marker
 *   the level on screen, when it is on the curve
 * @property {Array<{ x: number, label: string }>} xTicks
 * @property {Array<{ y: number, label: string }>} yTicks
 * @property {Array<{ level: number, x: number, y: number, share: number, answers: number }>} study
 *   a bar per level with answers: from y down to the plot's bottom, share = sufficient / answers
 */

/** @type {ReadonlyArray<{ key: SeriesKey, label: string, colour: string }>} */
export const SERIES = [
  { key: 'image_rmse', label: 'quality.series.image', colour: '#88c0d0' },
  { key: 'roy_rmse', label: 'quality.series.colour', colour: '#ebcb8b' },
];

const MARGIN = { left: 26, right: 16, top: 16, bottom: 16 };
/** Closest two vertex-count labels may be, in viewBox units. */
const MIN_TICK_GAP = 32;

/** @param {unknown} v @returns {v is number} */
const finite = (v) => typeof v === 'number' && Number.isFinite(v);

/**
 * The usable points, by level: positive vertex counts and a finite image RMSE.
 * @param {ReadonlyArray<QualityPoint> | null | undefined} quality
 * @returns {QualityPoint[]}
 */
export function cleanPoints(quality) {
  if (!Array.isArray(quality)) return [];
  return quality
    .filter((p) => p && finite(p.level) && finite(p.vertices) && p.vertices > 0 && finite(p.image_rmse))
    .sort((a, b) => a.level - b.level);
}

/** The smallest error drawn: a level measured as exact sits on the chart's floor. */
export const MIN_ERROR = 0.01;

/** @param {number} n vertex count, for an axis label: 500, 2k, 10k, 1.5M */
export function formatCount(n) {
  if (n >= 1e6) return `${+(n / 1e6).toFixed(1)}M`;
  if (n >= 1e3) return `${+(n / 1e3).toFixed(1)}k`;
  return String(Math.round(n));
}

/**
 * Places the curve. `null` when there is nothing to draw.
 * @param {ReadonlyArray<QualityPoint> | null | undefined} quality
 * @param {number} level the level on screen (-1: none yet)
 * @param {ChartOptions} [options]
 * @returns {ChartLayout | null}
 */
export function layoutQualityChart(quality, level, options = {}) {
  const points = cleanPoints(quality);
  if (points.length === 0) return null;
  const width = options.width ?? 260;
  const height = options.height ?? 130;
  const plot = { left: MARGIN.left, right: width - MARGIN.right, top: MARGIN.top, bottom: height - MARGIN.bottom };
  const logs = points.map((p) => Math.log10(p.vertices));
  const [lo, hi] = [Math.min(...logs), Math.max(...logs)];
  /** @param {number} vertices */
  const x = (vertices) =>
    hi > lo
      ? plot.left + ((Math.log10(vertices) - lo) / (hi - lo)) * (plot.right - plot.left)
      : (plot.left + plot.right) / 2;
  // y: whole decades around the errors.
  const errors = points
    .flatMap((p) => [p.image_rmse, ...(finite(p.roy_rmse) ? [p.roy_rmse] : [])])
    .map((v) => Math.log10(Math.max(MIN_ERROR, v)));
  const yLo = Math.floor(Math.min(...errors));
  const yHi = Math.max(yLo + 1, Math.ceil(Math.max(...errors)));
  /** @param {number} v */
  const y = (v) =>
    plot.bottom - ((Math.log10(Math.max(MIN_ERROR, v)) - yLo) / (yHi - yLo)) * (plot.bottom - plot.top);
  /** @type {PlacedSeries[]} */
  const series = [];
  for (const s of SERIES) {
    const placed = points
      .filter((p) => finite(p[s.key]))
      .map((p) => ({ level: p.level, x: x(p.vertices), y: y(/** @type {number} */ (p[s.key])) }));
    if (placed.length > 0) series.push({ ...s, points: placed });
  }
  const shown = points.find((p) => p.level === level);
  const marker = shown
    ? {
        level: shown.level,
        x: x(shown.vertices),
        points: series.flatMap((s) => {
          const p = s.points.find((q) => q.level === shown.level);
          return p ? [{ key: s.key, y: p.y }] : [];
        }),
      }
    : null;
  // The ends of the curve, and the powers of ten between them that have room.
  const first = points[0].vertices;
  const last = points[points.length - 1].vertices;
  /** @type {ChartLayout['xTicks']} */
  const xTicks = (hi > lo ? [first, last] : [first]).map((v) => ({ x: x(v), label: formatCount(v) }));
  for (let e = Math.ceil(lo); e <= hi; e++) {
    const at = x(10 ** e);
    if (xTicks.every((t) => Math.abs(t.x - at) >= MIN_TICK_GAP)) xTicks.push({ x: at, label: formatCount(10 ** e) });
  }
  xTicks.sort((a, b) => a.x - b.x);
  /** @type {ChartLayout['yTicks']} */
  const yTicks = [];
  for (let e = yLo; e <= yHi; e++) yTicks.push({ y: y(10 ** e), label: `${+(10 ** e).toFixed(Math.max(0, -e))}` });
  const byLevel = new Map(points.map((p) => [p.level, p]));
  const study = (options.study ?? [])
    .filter((l) => byLevel.has(l.level) && finite(l.answers) && l.answers > 0 && finite(l.sufficient))
    .map((l) => {
      const share = Math.max(0, Math.min(1, l.sufficient / l.answers));
      const vertices = /** @type {QualityPoint} */ (byLevel.get(l.level)).vertices;
      return { level: l.level, x: x(vertices), y: plot.bottom - share * (plot.bottom - plot.top), share, answers: l.answers };
    });
  return { width, height, plot, series, marker, xTicks, yTicks, study };
}

/**
 * The study's line for a level: how many found it sufficient.
 * @param {ReadonlyArray<StudyLevel> | null | undefined} study
 * @param {number} level
 * @returns {string} empty without answers at that level
 */
export function describeStudyLevel(study, level) {
  const l = study?.find((s) => s.level === level);
  if (!l || !(l.answers > 0)) return '';
  return t('quality.study', { count: l.answers, sufficient: l.sufficient, share: formatNumber(l.sufficient / l.answers, { style: 'percent' }) });
}

/** @param {number} v */
const f = (v) => `${+v.toFixed(1)}`;

/**
 * The chart as SVG markup; an empty string when there is no curve.
 * @param {ReadonlyArray<QualityPoint> | null | undefined} quality
 * @param {number} level the level on screen (-1: none yet)
 * @param {ChartOptions} [options]
 */
export function renderQualityChart(quality, level, options = {}) {
  const layout = layoutQualityChart(quality, level, options);
  if (!layout) return '';
  const { width, height, plot, series, marker, xTicks, yTicks, study } = layout;
  const parts = [
    `<svg xmlns="http://www.w3.org/2000/svg" class="quality-chart" viewBox="0 0 ${width} ${height}" ` +
      `width="${width}" height="${height}" role="img" aria-label="${escapeAttribute(describeChart(quality))}${
        study.length > 0 ? escapeAttribute(t('quality.chart.bars')) : ''
      }" ` +
      `font-family="system-ui, sans-serif" font-size="10">`,
    `<g class="axes" stroke="#4c566a" stroke-width="1">` +
      `<line x1="${plot.left}" y1="${plot.bottom}" x2="${plot.right}" y2="${plot.bottom}"/>` +
      `<line x1="${plot.left}" y1="${plot.top}" x2="${plot.left}" y2="${plot.bottom}"/></g>`,
  ];
  if (study.length > 0) {
    // Behind the lines: the share of "sufficient" answers per level.
    parts.push('<g class="study" fill="#a3be8c" fill-opacity="0.35">');
    for (const b of study) {
      parts.push(
        `<rect data-study-level="${b.level}" data-share="${+b.share.toFixed(3)}" x="${f(b.x - 3)}" y="${f(b.y)}" ` +
          `width="6" height="${f(plot.bottom - b.y)}"/>`,
      );
    }
    parts.push(
      `</g><g class="legend"><rect x="${plot.right - 62}" y="2" width="6" height="8" fill="#a3be8c" fill-opacity="0.6"/>` +
        `<text x="${plot.right - 53}" y="10" fill="#cfd5de">${escapeAttribute(t('quality.chart.sufficient'))}</text></g>`,
    );
  }
  for (const t of xTicks) {
    parts.push(
      `<text class="x-tick" x="${f(t.x)}" y="${height - 4}" text-anchor="middle" fill="#cfd5de">${t.label}</text>`,
    );
  }
  for (const t of yTicks) {
    parts.push(
      `<text class="y-tick" x="${plot.left - 3}" y="${f(t.y + 3)}" text-anchor="end" fill="#cfd5de">${t.label}</text>`,
    );
  }
  series.forEach((s, k) => {
    const line = s.points.map((p) => `${f(p.x)},${f(p.y)}`).join(' ');
    parts.push(
      `<polyline class="series" data-series="${s.key}" points="${line}" fill="none" stroke="${s.colour}" ` +
        `stroke-width="1.5" stroke-linejoin="round"/>`,
    );
    for (const p of s.points) {
      parts.push(
        `<circle data-series="${s.key}" data-level="${p.level}" cx="${f(p.x)}" cy="${f(p.y)}" r="1.8" ` +
          `fill="${s.colour}"/>`,
      );
    }
    const lx = plot.left + 4 + k * 100;
    parts.push(
      `<g class="legend"><line x1="${lx}" y1="7" x2="${lx + 10}" y2="7" stroke="${s.colour}" stroke-width="2"/>` +
        `<text x="${lx + 13}" y="10" fill="#cfd5de">${escapeAttribute(t(s.label))}</text></g>`,
    );
  });
  if (marker) {
    parts.push(
      `<g class="marker" data-marker="" data-level="${marker.level}">` +
        `<line x1="${f(marker.x)}" y1="${plot.top}" x2="${f(marker.x)}" y2="${plot.bottom}" stroke="#eceff4" ` +
        `stroke-width="1" stroke-dasharray="2 2"/>` +
        marker.points
          .map((p) => `<circle cx="${f(marker.x)}" cy="${f(p.y)}" r="3.2" fill="none" stroke="#eceff4" stroke-width="1.5"/>`)
          .join('') +
        `</g>`,
    );
  }
  parts.push('</svg>');
  return parts.join('');
}

/**
 * One line about a level: what the marker points at.
 * @param {ReadonlyArray<QualityPoint> | null | undefined} quality
 * @param {number} level
 * @returns {string} empty when the level is not on the curve
 */
export function describeLevel(quality, level) {
  const p = cleanPoints(quality).find((q) => q.level === level);
  if (!p) return '';
  const fixed = (/** @type {number} */ v, /** @type {number} */ digits) =>
    formatNumber(v, { minimumFractionDigits: digits, maximumFractionDigits: digits });
  const roy = finite(p.roy_rmse) ? t('quality.level.colour', { rmse: fixed(p.roy_rmse, 1) }) : '';
  const hausdorff = finite(p.hausdorff)
    ? t('quality.level.hausdorff', { share: formatNumber(p.hausdorff, { style: 'percent', minimumFractionDigits: 2 }) })
    : '';
  return t('quality.level', { level: p.level, rmse: fixed(p.image_rmse, 1) }) + roy + hausdorff;
}

/** @param {ReadonlyArray<QualityPoint> | null | undefined} quality */
function describeChart(quality) {
  const points = cleanPoints(quality);
  const [first, last] = [points[0], points[points.length - 1]];
  const rmse = (/** @type {number} */ v) => formatNumber(v, { minimumFractionDigits: 1, maximumFractionDigits: 1 });
  return t('quality.chart', {
    from: rmse(first.image_rmse),
    firstVertices: first.vertices,
    to: rmse(last.image_rmse),
    lastVertices: last.vertices,
  });
}

/** Catalogue text inside the chart's markup. @param {string} text */
function escapeAttribute(text) {
  return text.replace(/&/g, '&amp;').replace(/</g, '&lt;').replace(/"/g, '&quot;');
}
