// @ts-check
/**
 * View-dependent refinement of a charted stream (issue 41), the pure part:
 * which chart's next part to fetch for the view on screen, and which charts
 * give their vertices back when the next part would pass the vertex budget.
 * No DOM, no worker, no codec: part-refinement.js runs it in the decode
 * worker, test/part-selection.test.mjs in Node.
 *
 * A part's `error` is the largest distance, in model units, from a vertex
 * it inserts to the chart's coarser surface, and its `bulk_error` the
 * distance 90 % of them lie within. On screen an error is
 * error / distance × pixels per radian. A chart is refined by its parts'
 * refinement errors ({@link refinementError}: the bulk, or the largest
 * over {@link LARGEST_SPREAD}), while the largest of those of the parts it
 * has not applied yet is above {@link SCREEN_ERROR_PX} (the largest, not
 * the next one's: a chart may sit a batch out with an empty part, error 0,
 * and refine again after it). Occlusion keeps the largest errors: a bound.
 */

/** A chart refines while its remaining error on screen is above this many pixels. */
export const SCREEN_ERROR_PX = 1;

/**
 * How many times {@link SCREEN_ERROR_PX} a part's largest error may be on
 * screen once its bulk is under it: a scan's noisiest vertices stay out of
 * the refinement, a feature a few vertices carry (a spike, a thin ridge)
 * does not.
 */
export const LARGEST_SPREAD = 4;

/**
 * The error a part is refined by, in model units: its bulk error, or its
 * largest over {@link LARGEST_SPREAD} where that is more (an index measured
 * before bulk errors sends the largest as both: refined by it, as then).
 * @param {{ error: number, bulk_error?: number }} part
 */
export function refinementError(part) {
  return Math.max(part.bulk_error ?? part.error, part.error / LARGEST_SPREAD);
}

/** Parts requested at once, at most. */
export const PARTS_IN_FLIGHT = 3;

/** Resident vertices by the manifest's `visitor.device`, unless the page sets `vertex-budget`. */
export const VERTEX_BUDGETS = { phone: 500_000, tablet: 1_500_000, desktop: 4_000_000 };

/**
 * @param {string | null | undefined} device the manifest's `visitor.device`
 * @returns {number}
 */
export function defaultBudget(device) {
  return VERTEX_BUDGETS[/** @type {keyof typeof VERTEX_BUDGETS} */ (device ?? '')] ?? VERTEX_BUDGETS.desktop;
}

/** @typedef {[number, number, number]} Vec3 */
/** @typedef {{ centre: Vec3, radius: number }} Sphere */

/**
 * The sphere around a chart's vertices: the centre of their box, the
 * farthest vertex from it.
 * @param {Float32Array} positions x, y, z per vertex
 * @returns {Sphere}
 */
export function boundingSphere(positions) {
  if (positions.length < 3) return { centre: [0, 0, 0], radius: 0 };
  const lo = [Infinity, Infinity, Infinity];
  const hi = [-Infinity, -Infinity, -Infinity];
  for (let i = 0; i < positions.length; i += 3) {
    for (let k = 0; k < 3; k++) {
      const v = positions[i + k];
      if (v < lo[k]) lo[k] = v;
      if (v > hi[k]) hi[k] = v;
    }
  }
  /** @type {Vec3} */
  const centre = [(lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, (lo[2] + hi[2]) / 2];
  let r2 = 0;
  for (let i = 0; i < positions.length; i += 3) {
    const dx = positions[i] - centre[0];
    const dy = positions[i + 1] - centre[1];
    const dz = positions[i + 2] - centre[2];
    r2 = Math.max(r2, dx * dx + dy * dy + dz * dz);
  }
  return { centre, radius: Math.sqrt(r2) };
}

/**
 * How far a chart's finer surface may turn from its normals at the cut:
 * added to the cone of the cut's face normals before a chart is taken to
 * face away from the camera.
 */
export const CONE_MARGIN = (15 * Math.PI) / 180;

/** @typedef {{ axis: Vec3, angle: number }} NormalCone */

/**
 * The cone of a chart's face normals: the area-weighted mean normal and the
 * largest angle from it to a face's normal (plus {@link CONE_MARGIN}); π
 * when the normals do not keep to one side (the chart never faces away).
 * @param {Float32Array} positions
 * @param {Uint32Array} indices
 * @returns {NormalCone}
 */
export function normalCone(positions, indices) {
  const normals = [];
  const axis = [0, 0, 0];
  for (let t = 0; t < indices.length; t += 3) {
    const [a, b, c] = [3 * indices[t], 3 * indices[t + 1], 3 * indices[t + 2]];
    const u = [0, 1, 2].map((k) => positions[b + k] - positions[a + k]);
    const v = [0, 1, 2].map((k) => positions[c + k] - positions[a + k]);
    const n = [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]];
    for (let k = 0; k < 3; k++) axis[k] += n[k];
    normals.push(n);
  }
  const length = Math.hypot(axis[0], axis[1], axis[2]);
  if (length === 0) return { axis: [0, 0, 1], angle: Math.PI };
  /** @type {Vec3} */
  const unit = [axis[0] / length, axis[1] / length, axis[2] / length];
  let cos = 1;
  for (const n of normals) {
    const l = Math.hypot(n[0], n[1], n[2]);
    if (l > 0) cos = Math.min(cos, (n[0] * unit[0] + n[1] * unit[1] + n[2] * unit[2]) / l);
  }
  return { axis: unit, angle: Math.min(Math.PI, Math.acos(Math.max(-1, cos)) + CONE_MARGIN) };
}

/**
 * Whether every face a chart can have faces away from the eye (seen from
 * anywhere on its bounding sphere): then the chart is hidden behind the
 * rest of the surface, whatever the frustum says.
 * @param {NormalCone} cone
 * @param {Sphere} sphere
 * @param {Vec3} eye
 */
export function facesAway(cone, sphere, eye) {
  const d = [sphere.centre[0] - eye[0], sphere.centre[1] - eye[1], sphere.centre[2] - eye[2]];
  const length = Math.hypot(d[0], d[1], d[2]);
  if (length <= sphere.radius || cone.angle >= Math.PI / 2) return false;
  const spread = Math.asin(sphere.radius / length);
  const angle = Math.acos(Math.max(-1, Math.min(1, (d[0] * cone.axis[0] + d[1] * cone.axis[1] + d[2] * cone.axis[2]) / length)));
  return angle < Math.PI / 2 - cone.angle - spread;
}

/**
 * Where the camera is, in model coordinates.
 * @typedef {object} PartCamera
 * @property {Vec3} eye
 * @property {number[]} clip column-major 4×4, model coordinates → clip space
 * @property {number} pixelsPerRadian the view's height in pixels over its vertical field of view
 * @property {number} [aspect] the view's width over its height (occlusion.js's map follows it; absent: square)
 */

/**
 * The six planes of a clip matrix (Gribb and Hartmann), each [a, b, c, d]
 * with a·x + b·y + c·z + d ≥ 0 inside, normalised.
 * @param {ArrayLike<number>} m column-major 4×4
 * @returns {number[][]}
 */
export function frustumPlanes(m) {
  /** @param {number} r */
  const row = (r) => [m[r], m[4 + r], m[8 + r], m[12 + r]];
  const w = row(3);
  const planes = [];
  for (const r of [0, 1, 2]) {
    const x = row(r);
    planes.push(w.map((v, i) => v + x[i]), w.map((v, i) => v - x[i]));
  }
  return planes.map((p) => {
    const n = Math.hypot(p[0], p[1], p[2]) || 1;
    return p.map((v) => v / n);
  });
}

/**
 * @param {number[][]} planes
 * @param {Sphere} sphere
 */
export function inFrustum(planes, sphere) {
  const [x, y, z] = sphere.centre;
  return planes.every((p) => p[0] * x + p[1] * y + p[2] * z + p[3] >= -sphere.radius);
}

/**
 * Distance from the eye to the nearest point of a sphere (a small positive
 * number inside it, so the error on screen stays finite).
 * @param {Vec3} eye
 * @param {Sphere} sphere
 */
export function sphereDistance(eye, sphere) {
  const d = Math.hypot(sphere.centre[0] - eye[0], sphere.centre[1] - eye[1], sphere.centre[2] - eye[2]) - sphere.radius;
  return Math.max(d, 1e-6 * Math.max(1, sphere.radius));
}

/**
 * Where a chart stands for a camera: its distance, and whether it is in
 * view (in the frustum, and not facing away).
 * @param {number[][]} planes the camera's ({@link frustumPlanes})
 * @param {Vec3} eye
 * @param {{ sphere: Sphere, cone?: NormalCone }} chart
 */
export function sight(planes, eye, chart) {
  const distance = sphereDistance(eye, chart.sphere);
  const visible = inFrustum(planes, chart.sphere) && !(chart.cone && facesAway(chart.cone, chart.sphere, eye));
  return { distance, visible };
}

/**
 * An error in model units at `distance`, in pixels on screen.
 * @param {number} error
 * @param {number} distance
 * @param {PartCamera} camera
 */
export function onScreen(error, distance, camera) {
  return (error / distance) * camera.pixelsPerRadian;
}

/**
 * Most wanted first: the largest error on screen, then the nearest.
 * @param {{ pixels: number, distance: number }} a
 * @param {{ pixels: number, distance: number }} b
 */
export function byNeed(a, b) {
  return b.pixels - a.pixels || a.distance - b.distance;
}

/**
 * What gives its vertices back first: out of view before in view, the
 * farthest first out of view, in view the smallest error `cutPixels` it
 * would show once given back.
 * @param {{ visible: boolean, distance: number, cutPixels: number }} a
 * @param {{ visible: boolean, distance: number, cutPixels: number }} b
 */
export function byLeastNeeded(a, b) {
  return Number(a.visible) - Number(b.visible) || (a.visible ? a.cutPixels - b.cutPixels : b.distance - a.distance);
}

/**
 * The part index as the service sends it (`GET …/parts`).
 * @typedef {object} PartIndex
 * @property {number} charts
 * @property {number} first_level the first parted batch's level
 * @property {string} head_url
 * @property {string} part_url with `{level}` and `{chart}`
 * @property {{ level: number, chart: number, bytes: number, inserted: number, error: number, bulk_error?: number }[]} parts
 */

/**
 * The index by chart and depth: `table[chart][depth]` is the part that
 * takes the chart from depth to depth + 1, `remaining[chart][depth]` the
 * largest refinement error of that part and every later one of the chart,
 * `bound[chart][depth]` the largest error (for occlusion).
 * @param {PartIndex} index
 */
export function partTable(index) {
  const depths = 1 + Math.max(...index.parts.map((p) => p.level)) - index.first_level;
  /** @type {PartIndex['parts'][]} */
  const table = Array.from({ length: index.charts }, () => new Array(depths));
  for (const part of index.parts) table[part.chart][part.level - index.first_level] = part;
  for (const [chart, parts] of table.entries()) {
    for (let d = 0; d < depths; d++) if (!parts[d]) throw new Error(`the part index has no part for chart ${chart} at level ${index.first_level + d}`);
  }
  return {
    table,
    remaining: table.map((parts) => remainingMax(parts, refinementError)),
    bound: table.map((parts) => remainingMax(parts, (p) => p.error)),
    finalDepth: depths,
  };
}

/**
 * For a chart's parts in order, `r[d]` is the largest `of(part)` over part
 * `d` and every later one (`r[parts.length]` is 0): the error still to come
 * once `d` parts are applied.
 * @template T
 * @param {T[]} parts
 * @param {(part: T) => number} of
 */
export function remainingMax(parts, of) {
  const r = new Array(parts.length + 1).fill(0);
  for (let d = parts.length - 1; d >= 0; d--) r[d] = Math.max(of(parts[d]), r[d + 1]);
  return r;
}

/**
 * One chart as the selection sees it.
 * @typedef {object} ChartState
 * @property {number} depth parts applied
 * @property {Sphere} sphere
 * @property {NormalCone} [cone] its face normals at the cut (absent: never taken to face away)
 * @property {boolean} [busy] a part of it is on its way
 * @property {boolean} [yielded] reset to make room for another chart: not refined
 *   again for the same camera (else two charts would take the room in turn)
 */

/**
 * How far the surface still to come may lie from a chart's shown, in model
 * units, for occlusion (occlusion.js): twice the largest error of its parts
 * not applied (their sum, as errors halve from level to level, is under it).
 * @param {ReturnType<typeof partTable>} parts
 * @param {number} chart
 * @param {number} depth
 */
export function occluderTolerance(parts, chart, depth) {
  return 2 * parts.bound[chart][depth];
}

/**
 * A chart's sphere for occlusion: the one at its cut grown by the sum of its
 * parts' errors (how far they may move its surface out of it), so its own
 * surface never hides it.
 * @param {ReturnType<typeof partTable>} parts
 * @param {number} chart
 * @param {Sphere} sphere at the cut
 * @returns {Sphere}
 */
export function occlusionSphere(parts, chart, sphere) {
  return { centre: sphere.centre, radius: sphere.radius + parts.table[chart].reduce((e, p) => e + p.error, 0) };
}

/**
 * How each chart stands for this camera: in view (in the frustum, not
 * facing away, and not hidden behind the surface shown: `hidden`) or not,
 * distance, the
 * error on screen of what it has not applied yet (`pixels`) and of
 * everything past the cut (`cutPixels`: its error if it were reset).
 * @param {ChartState[]} charts
 * @param {ReturnType<typeof partTable>} parts
 * @param {PartCamera} camera
 * @param {(chart: number) => boolean} [hidden] absent: nothing is
 */
export function assess(charts, parts, camera, hidden) {
  const planes = frustumPlanes(camera.clip);
  return charts.map((c, chart) => {
    const seen = sight(planes, camera.eye, c);
    const distance = seen.distance;
    const visible = seen.visible && !hidden?.(chart);
    const pixels = onScreen(parts.remaining[chart][c.depth], distance, camera);
    const cutPixels = onScreen(parts.remaining[chart][0], distance, camera);
    return { chart, distance, visible, pixels, cutPixels };
  });
}

/**
 * The charts whose next part to fetch, most wanted first: in view, below
 * the final depth and the cap, with their remaining error above the
 * threshold on screen; the largest error first (for parts of one level,
 * the nearest chart first).
 * @param {ChartState[]} charts
 * @param {ReturnType<typeof partTable>} parts
 * @param {PartCamera} camera
 * @param {{ firstLevel: number, capLevel: number, threshold?: number, hidden?: (chart: number) => boolean }} limits
 */
export function wantedParts(charts, parts, camera, { firstLevel, capLevel, threshold = SCREEN_ERROR_PX, hidden }) {
  return assess(charts, parts, camera, hidden)
    .filter((a) => {
      const c = charts[a.chart];
      return !c.busy && !c.yielded && a.visible && c.depth < parts.finalDepth && firstLevel + c.depth <= capLevel && a.pixels > threshold;
    })
    .sort(byNeed);
}

/**
 * Which charts give their vertices back first to make room for `wanted`:
 * those refined past the cut and not busy; out of view first (farthest
 * first), then those in view whose error on screen, once reset to the cut,
 * would still be smaller than `wanted`'s now (smallest first). A chart
 * reset for room so never wants it back more than the chart that took it,
 * so two charts do not take the room in turn, and a small budget goes to
 * the largest errors on screen.
 * @param {ChartState[]} charts
 * @param {ReturnType<typeof assess>} assessed
 * @param {number} wanted the chart that needs the room
 * @returns {number[]}
 */
export function evictionOrder(charts, assessed, wanted) {
  const need = assessed[wanted].pixels;
  return assessed
    .filter((a) => a.chart !== wanted && charts[a.chart].depth > 0 && !charts[a.chart].busy && (!a.visible || a.cutPixels < need))
    .sort(byLeastNeeded)
    .map((a) => a.chart);
}
