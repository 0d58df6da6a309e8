// @ts-check
/**
 * Occlusion culling for view-dependent refinement (issue 41): a tiny depth
 * map of the surface shown, rasterised on the CPU in the decode worker, and
 * whether a chart lies wholly behind it: a chart drawn in the map by its
 * own vertices' extent (screen rectangle, nearest depth), any other by its
 * bounding sphere. A chart hidden so
 * (the far side of a head seen close up) wants no part: without this, every
 * chart in the frustum not facing wholly away refined to under a pixel.
 * Pure: no DOM, no worker, no codec (test/occlusion.test.mjs in Node).
 *
 * Hand-written because what it needs is small and particular: a depth map
 * of at most {@link MAP_LONG_SIDE} pixels on the long side, built from
 * typed arrays the worker already holds, with a per-triangle tolerance (the
 * error the shown chart leaves), and a conservative sphere test. The GPU is
 * in another worker (its depth buffer would cost a read-back per frame),
 * and the occlusion libraries there are (masked occlusion culling, Umbra)
 * are native code for game engines, not a few hundred lines in a worker.
 *
 * Cost: one projection per vertex (three rows of the clip matrix) and, per
 * triangle, a bounding box that almost always holds no pixel centre when
 * the mesh is fine (2 M triangles on 64×48 pixels: ~0.0015 pixel each), so
 * linear in the union's size, nothing allocated but the map and one scratch
 * buffer. Measured on a 2-core machine shared with others: 2 M triangles
 * (1 M vertices) in 28 ms with a core free, 70–170 ms with the cores busy
 * (Node 20, a UV sphere: bench/occlusion-cost.mjs); in the decode worker
 * of bench/nested-closeup.mjs on igea 2 M (headless Chromium drawing with
 * SwiftShader on the same cores), 40–330 ms per map for 0.4–1.2 M
 * vertices. It is bounded by {@link OcclusionMap} (one map per camera, and
 * no sooner than a few times its cost after the last while the surface
 * changes) and `maxTriangles` (past it, every k-th triangle: for a fine
 * mesh that leaves most pixels empty, so in effect no culling, never a
 * wrong one). The test of a chart reads at most the map's pixels (4096).
 *
 * Why it is conservative (never hides what shows):
 * - a map pixel holds, over the triangles covering its centre, the least
 *   of (depth + that triangle's tolerance), so "the map is nearer than the
 *   sphere" means some shown triangle, even pushed back by its tolerance
 *   (the surface still to come lies within it), covers the centre in front
 *   of the sphere; an empty pixel holds +∞ and hides nothing;
 * - a sphere's rectangle is that of the cube around it (its eight corners
 *   projected); a drawn chart's, its vertices' grown by its tolerance on
 *   screen (a triangle in front of the eye projects inside its vertices'
 *   hull, so off the map it is out of view), its depth their nearest less
 *   its tolerance; every pixel it touches must be covered, so a chart seen
 *   through any pixel centre of the map refines; one seen only between
 *   centres (a sliver under a map pixel wide) may not: the price of a map
 *   this small;
 * - a sphere that crosses the near plane or holds the eye is never hidden;
 *   a triangle with a vertex behind the eye is not drawn (less is hidden);
 * - triangles left out (none, or a subsample when the union is huge) only
 *   leave pixels empty or farther: less is hidden, never more.
 * - a chart's own surface lies in its extent, or its sphere (inflated by
 *   its drift: see nested-selection.js), so it is never nearer than their
 *   nearest point: a chart does not hide itself.
 */

/** The map's long side in pixels; the short side follows the view's aspect. */
export const MAP_LONG_SIDE = 64;

/**
 * A depth map of the surface shown, for one camera.
 * @typedef {object} DepthMap
 * @property {number} width
 * @property {number} height
 * @property {Float32Array} depth per pixel, row by row: the least view depth
 *   (clip w) plus tolerance of the triangles covering its centre; +∞ none
 * @property {ArrayLike<number>} clip the camera's, column-major 4×4
 * @property {number} wScale |∂w/∂x| in model units: a length in the model is at most this much w
 * @property {number} triangles drawn (rasterised, not subsampled out)
 * @property {(Extent | null)[]} extents per occluder, its own: where it
 *   and the surface still to come in it lie (null: a vertex behind the eye)
 */

/**
 * Where a piece of surface lies for the camera: a rectangle on the map (in
 * pixels, not clipped) and its nearest view depth (clip w).
 * @typedef {{ x0: number, x1: number, y0: number, y1: number, nearest: number }} Extent
 */

/**
 * One shown piece of surface: its vertices, triangles and how far the
 * surface still to come may lie behind (or before) it, in model units.
 * @typedef {{ positions: Float32Array, indices: Uint32Array, tolerance: number }} Occluder
 */

/** Clip w below this (in front of the eye by less) is taken as behind the eye. */
const NEAR_W = 1e-9;

/** Projected vertices, reused across maps: x, y in pixels, 1/w. */
let scratch = new Float32Array(0);

/**
 * The map for a camera's clip matrix and aspect (width over height).
 * @param {Occluder[]} occluders
 * @param {ArrayLike<number>} clip column-major 4×4, model → clip
 * @param {number} aspect
 * @param {{ longSide?: number, maxTriangles?: number }} [options]
 *   maxTriangles: past it every k-th triangle is drawn (less hidden, never more)
 * @returns {DepthMap}
 */
export function depthMap(occluders, clip, aspect, { longSide = MAP_LONG_SIDE, maxTriangles = Infinity } = {}) {
  const a = Number.isFinite(aspect) && aspect > 0 ? aspect : 1;
  const width = a >= 1 ? longSide : Math.max(1, Math.round(longSide * a));
  const height = a >= 1 ? Math.max(1, Math.round(longSide / a)) : longSide;
  const depth = new Float32Array(width * height).fill(Infinity);
  const m = clip;
  const wScale = Math.hypot(m[3], m[7], m[11]);
  // The matrix's rows as locals: the projection is the other loop over everything.
  const [a0, a1, a2, a3] = [m[0], m[4], m[8], m[12]];
  const [b0, b1, b2, b3] = [m[1], m[5], m[9], m[13]];
  const [w0, w1, w2, w3] = [m[3], m[7], m[11], m[15]];
  const halfWidth = width / 2;
  const halfHeight = height / 2;
  const total = occluders.reduce((n, o) => n + o.indices.length / 3, 0);
  const stride = total > maxTriangles ? Math.ceil(total / maxTriangles) : 1;
  let drawn = 0;
  /** @type {(Extent | null)[]} */
  const extents = [];
  // How far on the map a shift of one model unit at view depth 1 may move a
  // point on screen (d(x/w) = (dx − ndc·dw) / w, |ndc| ≤ 1 on the map).
  const spread = Math.max((Math.hypot(a0, a1, a2) + wScale) * halfWidth, (Math.hypot(b0, b1, b2) + wScale) * halfHeight);
  for (const { positions, indices, tolerance } of occluders) {
    const vertices = positions.length / 3;
    if (scratch.length < 3 * vertices) scratch = new Float32Array(3 * vertices);
    const s = scratch;
    let behind = false;
    let nearest = Infinity;
    let [ex0, ex1, ey0, ey1] = [Infinity, -Infinity, Infinity, -Infinity];
    for (let v = 0; v < 3 * vertices; v += 3) {
      const x = positions[v];
      const y = positions[v + 1];
      const z = positions[v + 2];
      const w = w0 * x + w1 * y + w2 * z + w3;
      if (!(w > NEAR_W)) {
        s[v + 2] = -1; // behind the eye: its triangles are not drawn
        behind = true;
        continue;
      }
      const q = 1 / w;
      const sx = ((a0 * x + a1 * y + a2 * z + a3) * q + 1) * halfWidth;
      const sy = ((b0 * x + b1 * y + b2 * z + b3) * q + 1) * halfHeight;
      s[v] = sx;
      s[v + 1] = sy;
      s[v + 2] = q;
      if (w < nearest) nearest = w;
      if (sx < ex0) ex0 = sx;
      if (sx > ex1) ex1 = sx;
      if (sy < ey0) ey0 = sy;
      if (sy > ey1) ey1 = sy;
    }
    const slack = tolerance * wScale;
    // The surface to come in this piece lies within its tolerance of it:
    // nearer by at most that, and on screen that much (at its depth) wider.
    const near = nearest - slack;
    if (behind || vertices === 0 || !(near > NEAR_W)) extents.push(null);
    else {
      const grow = (tolerance * spread) / near + 1;
      extents.push({ x0: ex0 - grow, x1: ex1 + grow, y0: ey0 - grow, y1: ey1 + grow, nearest: near });
    }
    for (let t = 0; t < indices.length; t += 3 * stride) {
      const i0 = 3 * indices[t];
      const i1 = 3 * indices[t + 1];
      const i2 = 3 * indices[t + 2];
      const q0 = s[i0 + 2];
      const q1 = s[i1 + 2];
      const q2 = s[i2 + 2];
      if (q0 < 0 || q1 < 0 || q2 < 0) continue;
      const x0 = s[i0];
      const y0 = s[i0 + 1];
      const x1 = s[i1];
      const y1 = s[i1 + 1];
      const x2 = s[i2];
      const y2 = s[i2 + 1];
      // Pixel centres (i + ½) inside the box: most fine triangles hold none
      // (written out, not Math.min/max: this is the loop over every triangle).
      let lo = x0 < x1 ? x0 : x1;
      let hi = x0 < x1 ? x1 : x0;
      if (x2 < lo) lo = x2;
      else if (x2 > hi) hi = x2;
      let px0 = Math.ceil(lo - 0.5);
      let px1 = Math.floor(hi - 0.5);
      if (px0 > px1) continue;
      lo = y0 < y1 ? y0 : y1;
      hi = y0 < y1 ? y1 : y0;
      if (y2 < lo) lo = y2;
      else if (y2 > hi) hi = y2;
      let py0 = Math.ceil(lo - 0.5);
      let py1 = Math.floor(hi - 0.5);
      if (py0 > py1) continue;
      if (px0 < 0) px0 = 0;
      if (px1 > width - 1) px1 = width - 1;
      if (py0 < 0) py0 = 0;
      if (py1 > height - 1) py1 = height - 1;
      if (px0 > px1 || py0 > py1) continue;
      const area = (x1 - x0) * (y2 - y0) - (x2 - x0) * (y1 - y0);
      if (area === 0) continue;
      drawn++;
      // Either winding: the surface is seen from both sides near a rim.
      const sign = area > 0 ? 1 : -1;
      const inv = 1 / Math.abs(area);
      for (let py = py0; py <= py1; py++) {
        const cy = py + 0.5;
        for (let px = px0; px <= px1; px++) {
          const cx = px + 0.5;
          const b0 = sign * ((x1 - cx) * (y2 - cy) - (x2 - cx) * (y1 - cy));
          const b1 = sign * ((x2 - cx) * (y0 - cy) - (x0 - cx) * (y2 - cy));
          const b2 = sign * ((x0 - cx) * (y1 - cy) - (x1 - cx) * (y0 - cy));
          if (b0 < 0 || b1 < 0 || b2 < 0) continue;
          // 1/w is affine on screen: the centre's depth from its barycentrics.
          const q = (b0 * q0 + b1 * q1 + b2 * q2) * inv;
          const value = 1 / q + slack;
          const k = py * width + px;
          if (value < depth[k]) depth[k] = value;
        }
      }
    }
  }
  return { width, height, depth, clip: Array.from(m), wScale, triangles: drawn, extents };
}

/**
 * Whether a sphere lies wholly behind the map's surface: at every map pixel
 * its screen rectangle touches, the map holds something nearer than its
 * nearest point. Never for a sphere that crosses the near plane, holds the
 * eye, or lies off the map.
 * @param {DepthMap} map
 * @param {import('./part-selection.js').Sphere} sphere
 */
export function occluded(map, sphere) {
  const m = map.clip;
  const [cx, cy, cz] = sphere.centre;
  const r = sphere.radius;
  const wc = m[3] * cx + m[7] * cy + m[11] * cz + m[15];
  const nearest = wc - r * map.wScale;
  if (!(nearest > NEAR_W)) return false;
  // The near plane (w + z ≥ 0 in clip space) as a model-space plane.
  const nx = m[3] + m[2];
  const ny = m[7] + m[6];
  const nz = m[11] + m[10];
  const nLength = Math.hypot(nx, ny, nz);
  if (nLength > 0 && (nx * cx + ny * cy + nz * cz + m[15] + m[14]) / nLength < r) return false;
  let x0 = Infinity;
  let x1 = -Infinity;
  let y0 = Infinity;
  let y1 = -Infinity;
  for (let corner = 0; corner < 8; corner++) {
    const x = cx + (corner & 1 ? r : -r);
    const y = cy + (corner & 2 ? r : -r);
    const z = cz + (corner & 4 ? r : -r);
    const w = m[3] * x + m[7] * y + m[11] * z + m[15];
    if (!(w > NEAR_W)) return false;
    const sx = (((m[0] * x + m[4] * y + m[8] * z + m[12]) / w + 1) / 2) * map.width;
    const sy = (((m[1] * x + m[5] * y + m[9] * z + m[13]) / w + 1) / 2) * map.height;
    x0 = Math.min(x0, sx);
    x1 = Math.max(x1, sx);
    y0 = Math.min(y0, sy);
    y1 = Math.max(y1, sy);
  }
  return covered(map, { x0, x1, y0, y1, nearest });
}

/**
 * Whether an extent lies wholly off the map: the chart, and the surface to
 * come in it, are out of view (its vertices' rectangle is the tight frustum
 * test a bounding sphere's is not: a triangle in front of the eye projects
 * inside its vertices' hull).
 * @param {DepthMap} map
 * @param {Extent} extent
 */
export function offMap(map, { x0, x1, y0, y1 }) {
  return x1 < 0 || y1 < 0 || x0 > map.width || y0 > map.height;
}

/**
 * Whether the map holds something nearer than the extent's nearest depth
 * at every pixel its rectangle touches (clipped to the map; none: no).
 * @param {DepthMap} map
 * @param {Extent} extent
 */
export function covered(map, { x0, x1, y0, y1, nearest }) {
  const px0 = Math.max(0, Math.floor(x0));
  const px1 = Math.min(map.width - 1, Math.floor(x1));
  const py0 = Math.max(0, Math.floor(y0));
  const py1 = Math.min(map.height - 1, Math.floor(y1));
  if (!(px0 <= px1 && py0 <= py1)) return false;
  for (let py = py0; py <= py1; py++) {
    for (let px = px0; px <= px1; px++) if (!(map.depth[py * map.width + px] < nearest)) return false;
  }
  return true;
}

/**
 * The depth map of a refinement's camera, kept while it stays right: made
 * again for each camera (a map answers only for the camera it was made
 * for), and when the surface shown changed since it was made, no sooner
 * than `gap` times its last cost after it (an older map of the same camera
 * stays right, as the surface still to come lies within the tolerance of
 * the one it was made from: it only hides less). So at most 1 / (1 + gap)
 * of the worker's time goes to maps while parts arrive.
 */
export class OcclusionMap {
  /** @type {{ map: DepthMap, camera: object, generation: number, at: number, ms: number, extents: WeakMap<object, Extent | null> } | null} */
  #last = null;
  /** Maps made so far. */
  made = 0;

  /** @param {{ gap: number, maxTriangles: number }} options */
  constructor(options) {
    this.options = options;
  }

  /**
   * @param {import('./part-selection.js').PartCamera} camera
   * @param {number} generation counts the changes of the surface shown
   * @param {() => (Occluder & { key: object })[]} occluders the surface shown now, each
   *   with a key (its chart) that {@link hides} knows it by
   */
  refresh(camera, generation, occluders) {
    const last = this.#last;
    const now = performance.now();
    if (last && last.camera === camera && (last.generation === generation || now - last.at < this.options.gap * last.ms)) return;
    const pieces = occluders();
    const map = depthMap(pieces, camera.clip, camera.aspect ?? 1, { maxTriangles: this.options.maxTriangles });
    /** @type {WeakMap<object, Extent | null>} */
    const extents = new WeakMap();
    for (const [k, piece] of pieces.entries()) extents.set(piece.key, map.extents[k]);
    const done = performance.now();
    this.#last = { map, camera, generation, at: done, ms: done - now, extents };
    this.made++;
  }

  /**
   * Whether a chart is hidden for `camera` (never when the map is another
   * camera's): a chart drawn in the map by its own extent there (its
   * vertices then, grown by its tolerance: much tighter than a sphere; off
   * the map, it is out of view), another (one made since, an expanded
   * parent) by its sphere.
   * @param {import('./part-selection.js').PartCamera | null} camera
   * @param {object} key
   * @param {() => import('./part-selection.js').Sphere} sphere
   */
  hides(camera, key, sphere) {
    const last = this.#last;
    if (last === null || last.camera !== camera) return false;
    const extent = last.extents.get(key);
    if (extent === null) return false;
    return extent ? offMap(last.map, extent) || covered(last.map, extent) : occluded(last.map, sphere());
  }

  /** The last map's cost in milliseconds (0: none yet). */
  get ms() {
    return this.#last?.ms ?? 0;
  }
}
