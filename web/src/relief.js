// @ts-check
/**
 * The relief view (issue 18): each vertex coloured by its average normal
 * deviation θ (seed 004, with the fixes of ../codec/simplify/src/deviation.rs,
 * whose `normal_deviation` this mirrors), for conservators looking at
 * erosion and tool marks.
 *
 * - N_v: the normalised mean of the unit normals of the faces around v;
 * - N_region: the normalised, area-weighted sum of the unit normals of
 *   every face touching v or a vertex one or two edges away (two rings);
 * - θ = arccos(clamp(N_v · N_region, −1, 1)) in [0, π]; 0 for a vertex on
 *   no face (or whose normals cancel).
 *
 * θ is computed in the decode worker for every level posted while the view
 * is on (reconstruction.js), in double precision like the Rust reference,
 * with a compressed (CSR) vertex → faces adjacency and stamp arrays: no
 * allocation per vertex, nothing cleared between vertices. It is sent as a
 * Float32Array with the top of its colour scale ({@link reliefTop}: the 98th
 * percentile of the level's θ, rounded up to a round number of degrees).
 *
 * The colour ramp is viridis (matplotlib's, CC0): nine stops, linear between
 * them, in sRGB. {@link GLSL_RELIEF} is the shader's copy and
 * {@link reliefColour} its JavaScript twin; the legend's CSS gradient uses
 * the same stops, so the legend shows exactly the colours of the ramp.
 */

/** @typedef {[number, number, number]} Vec3 */

/** viridis at t = 0, 1/8, …, 1 (viridisLite's `viridis(9)`), sRGB bytes. */
export const RAMP = /** @type {ReadonlyArray<Vec3>} */ ([
  [0x44, 0x01, 0x54],
  [0x47, 0x2d, 0x7b],
  [0x3b, 0x52, 0x8b],
  [0x2c, 0x72, 0x8e],
  [0x21, 0x90, 0x8c],
  [0x27, 0xad, 0x81],
  [0x5d, 0xc8, 0x63],
  [0xaa, 0xdc, 0x32],
  [0xfd, 0xe7, 0x25],
]);

/** Which share of a level's vertices lie at or below the top of its scale. */
export const SCALE_PERCENTILE = 0.98;
/** The scale's top is never below this (a plane would have a top of 0°). */
export const MIN_TOP_DEGREES = 1;

/**
 * Lighting of the relief view in the shader: a head-light, so the ramp's
 * colours are kept on surfaces facing the viewer and darkened towards the
 * silhouette (shape stays readable, hue carries θ).
 */
export const RELIEF_AMBIENT = 0.6;

/** The GLSL of the ramp: `reliefColour(t)`, t in [0, 1] (clamped), sRGB. */
export const GLSL_RELIEF = `
const vec3 RELIEF_RAMP[${RAMP.length}] = vec3[](
  ${RAMP.map((c) => `vec3(${c.map((x) => (x / 255).toFixed(6)).join(', ')})`).join(',\n  ')}
);
vec3 reliefColour(float t) {
  float x = clamp(t, 0.0, 1.0) * ${(RAMP.length - 1).toFixed(1)};
  int i = min(int(floor(x)), ${RAMP.length - 2});
  return mix(RELIEF_RAMP[i], RELIEF_RAMP[i + 1], x - float(i));
}
vec3 reliefShade(vec3 n, float t) {
  return reliefColour(t) * (${RELIEF_AMBIENT.toFixed(2)} + ${(1 - RELIEF_AMBIENT).toFixed(2)} * max(n.z, 0.0));
}`;

/**
 * The ramp's colour at t (clamped to [0, 1]), sRGB 0..1: the shader's
 * `reliefColour`, in JavaScript.
 * @param {number} t
 * @returns {Vec3}
 */
export function reliefColour(t) {
  const x = Math.min(1, Math.max(0, t)) * (RAMP.length - 1);
  const i = Math.min(Math.floor(x), RAMP.length - 2);
  const f = x - i;
  const a = RAMP[i];
  const b = RAMP[i + 1];
  return /** @type {Vec3} */ ([0, 1, 2].map((k) => (a[k] + (b[k] - a[k]) * f) / 255));
}

/** The ramp as a CSS gradient, left (θ = 0) to right (the scale's top). */
export function rampGradient() {
  const stops = RAMP.map((c, i) => `rgb(${c.join(' ')}) ${((100 * i) / (RAMP.length - 1)).toFixed(1)}%`);
  return `linear-gradient(to right, ${stops.join(', ')})`;
}

/**
 * The faces around each vertex, as compressed rows: faces of vertex v are
 * `faces[offsets[v] … offsets[v + 1])`, in face order (as Rust's VertexFaces).
 * @param {Uint32Array} indices three per face
 * @param {number} vertexCount
 */
export function vertexFaces(indices, vertexCount) {
  const offsets = new Uint32Array(vertexCount + 1);
  for (let i = 0; i < indices.length; i++) offsets[indices[i] + 1]++;
  for (let v = 0; v < vertexCount; v++) offsets[v + 1] += offsets[v];
  const next = offsets.slice(0, vertexCount);
  const faces = new Uint32Array(indices.length);
  for (let i = 0; i < indices.length; i++) faces[next[indices[i]]++] = (i / 3) | 0;
  return { offsets, faces };
}

/**
 * Unit normal (three per face, zero for a degenerate face) and area of
 * every face, in double precision.
 * @param {Float32Array} positions
 * @param {Uint32Array} indices
 */
function faceNormals(positions, indices) {
  const count = indices.length / 3;
  const normals = new Float64Array(3 * count);
  const areas = new Float64Array(count);
  for (let f = 0; f < count; f++) {
    const a = 3 * indices[3 * f];
    const b = 3 * indices[3 * f + 1];
    const c = 3 * indices[3 * f + 2];
    const ux = positions[b] - positions[a];
    const uy = positions[b + 1] - positions[a + 1];
    const uz = positions[b + 2] - positions[a + 2];
    const vx = positions[c] - positions[a];
    const vy = positions[c + 1] - positions[a + 1];
    const vz = positions[c + 2] - positions[a + 2];
    const nx = uy * vz - uz * vy;
    const ny = uz * vx - ux * vz;
    const nz = ux * vy - uy * vx;
    const length = Math.sqrt(nx * nx + ny * ny + nz * nz);
    if (length > 0) {
      normals[3 * f] = nx / length;
      normals[3 * f + 1] = ny / length;
      normals[3 * f + 2] = nz / length;
      areas[f] = 0.5 * length;
    }
  }
  return { normals, areas };
}

/**
 * θ of every vertex in radians, in [0, π] (codec/simplify's
 * `normal_deviation`): the angle between the vertex's own normal (the
 * normalised mean of its faces' unit normals) and its region's (the
 * area-weighted unit normals of every face touching it or a vertex one or
 * two edges away). 0 for a vertex on no face.
 * @param {Float32Array} positions x, y, z of at least `vertexCount` vertices
 * @param {Uint32Array} indices three per face
 * @param {number} [vertexCount]
 * @returns {Float32Array}
 */
export function normalDeviation(positions, indices, vertexCount = positions.length / 3) {
  const n = vertexCount;
  const { normals, areas } = faceNormals(positions, indices);
  const { offsets, faces } = vertexFaces(indices, n);
  // Marks are reset by stamping with the current vertex: nothing is cleared per vertex.
  const vertexSeen = new Int32Array(n).fill(-1);
  const faceSeen = new Int32Array(areas.length).fill(-1);
  // The two-ring neighbourhood of the current vertex (at most every vertex).
  const ring = new Uint32Array(n);
  const theta = new Float32Array(n);
  for (let v = 0; v < n; v++) {
    let ox = 0;
    let oy = 0;
    let oz = 0;
    for (let k = offsets[v]; k < offsets[v + 1]; k++) {
      const f = 3 * faces[k];
      ox += normals[f];
      oy += normals[f + 1];
      oz += normals[f + 2];
    }
    if (ox === 0 && oy === 0 && oz === 0) continue;
    let size = 0;
    ring[size++] = v;
    vertexSeen[v] = v;
    let rx = 0;
    let ry = 0;
    let rz = 0;
    // Two rings out: the corners of the faces around each vertex of the ring
    // so far. Those faces are the region's faces of v and its first ring;
    // they are summed on the way.
    let start = 0;
    for (let step = 0; step < 2; step++) {
      const end = size;
      for (let r = start; r < end; r++) {
        const w = ring[r];
        for (let k = offsets[w]; k < offsets[w + 1]; k++) {
          const f = faces[k];
          if (faceSeen[f] !== v) {
            faceSeen[f] = v;
            const area = areas[f];
            rx += area * normals[3 * f];
            ry += area * normals[3 * f + 1];
            rz += area * normals[3 * f + 2];
          }
          for (let c = 0; c < 3; c++) {
            const u = indices[3 * f + c];
            if (vertexSeen[u] !== v) {
              vertexSeen[u] = v;
              ring[size++] = u;
            }
          }
        }
      }
      start = end;
    }
    // The faces of the second ring's vertices not summed yet.
    for (let r = start; r < size; r++) {
      const w = ring[r];
      for (let k = offsets[w]; k < offsets[w + 1]; k++) {
        const f = faces[k];
        if (faceSeen[f] === v) continue;
        faceSeen[f] = v;
        const area = areas[f];
        rx += area * normals[3 * f];
        ry += area * normals[3 * f + 1];
        rz += area * normals[3 * f + 2];
      }
    }
    const own = Math.sqrt(ox * ox + oy * oy + oz * oz);
    const region = Math.sqrt(rx * rx + ry * ry + rz * rz);
    if (!(own > 0) || !(region > 0)) continue;
    const dot = (ox * rx + oy * ry + oz * rz) / (own * region);
    theta[v] = Math.acos(Math.min(1, Math.max(-1, dot)));
  }
  return theta;
}

/** Histogram bins per degree for the percentile: the scale's top is found to 0.01°. */
const BINS_PER_DEGREE = 100;

/**
 * The top of a level's colour scale, in degrees: the 98th percentile of its
 * θ ({@link SCALE_PERCENTILE}, from a histogram of 0.01° bins: linear time,
 * no sort), rounded up to a multiple of its tick step ({@link reliefTicks}),
 * and at least {@link MIN_TOP_DEGREES}. θ above the top is drawn in the
 * ramp's last colour.
 * @param {Float32Array} theta radians
 */
export function reliefTop(theta) {
  const bins = 180 * BINS_PER_DEGREE;
  const histogram = new Uint32Array(bins + 1);
  const scale = (180 / Math.PI) * BINS_PER_DEGREE;
  for (let i = 0; i < theta.length; i++) histogram[Math.min(bins, Math.floor(theta[i] * scale))]++;
  const wanted = Math.ceil(SCALE_PERCENTILE * theta.length);
  let seen = 0;
  let bin = 0;
  while (bin < bins && seen + histogram[bin] < wanted) seen += histogram[bin++];
  const percentile = (bin + 1) / BINS_PER_DEGREE;
  return roundTop(Math.max(MIN_TOP_DEGREES, percentile));
}

/**
 * A tick step of 1, 2 or 5 × 10^k degrees: the smallest at least `raw`.
 * @param {number} raw
 */
function niceStep(raw) {
  const magnitude = 10 ** Math.floor(Math.log10(raw));
  for (const m of [1, 2, 5, 10]) {
    const step = m * magnitude;
    if (step >= raw * (1 - 1e-9)) return step;
  }
  return 10 * magnitude;
}

/**
 * Rounds a scale top up to a multiple of the step that divides it into at
 * most four intervals (13.7° → 15°, steps of 5°; 22° → 30°, steps of 10°);
 * at most 180°.
 * @param {number} degrees > 0
 */
export function roundTop(degrees) {
  const step = niceStep(degrees / 4);
  return Math.min(180, clean(Math.ceil(degrees / step - 1e-9) * step));
}

/**
 * The legend's tick values, in degrees, from 0 to `top` (a value from
 * {@link reliefTop}): two to five of them, on the same step.
 * @param {number} top degrees
 * @returns {number[]}
 */
export function reliefTicks(top) {
  const step = niceStep(top / 4);
  /** @type {number[]} */
  const ticks = [];
  for (let k = 0; k * step <= top * (1 + 1e-9); k++) ticks.push(clean(k * step));
  if (ticks[ticks.length - 1] < top * (1 - 1e-9)) ticks.push(top);
  return ticks;
}

/**
 * A tick label: "0°", "0.5°", "15°".
 * @param {number} degrees
 */
export function formatDegrees(degrees) {
  return `${Number(degrees.toPrecision(6))}°`;
}

/** @param {number} x rounded to 10 significant digits (0.30000000000000004 → 0.3) */
function clean(x) {
  return Number(x.toPrecision(10));
}
