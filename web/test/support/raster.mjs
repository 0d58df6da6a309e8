// @ts-check
/**
 * A CPU reference renderer for the end-to-end test: z-buffered triangles,
 * perspective-correct normals and colours, the viewer's camera matrices and
 * its lighting (`shade` from src/shading.js), no antialiasing. Its image is
 * compared with the browser's within a tolerance (edges and rasterisation
 * rules differ; shapes and shading must not).
 */
import { BACKGROUND, CLAY, shade } from '../../src/shading.js';
import { multiply } from '../../src/camera.js';

/**
 * @typedef {object} Scene
 * @property {Float32Array} positions
 * @property {Int16Array} normals
 * @property {Uint8Array | null} colours
 * @property {Uint32Array} indices
 * @property {Float32Array} view
 * @property {Float32Array} projection
 * @property {number} width
 * @property {number} height
 * @property {(position: [number, number, number]) => [number, number, number]} [albedoAt]
 *   colour (sRGB 0–1) at a world position, instead of per-vertex colour: the
 *   CCC lookup (src/ccc.js), evaluated per pixel like the fragment shader
 */

/**
 * @param {Scene} scene
 * @returns {Uint8Array} RGBA, rows bottom-up like gl.readPixels
 */
export function rasterize(scene) {
  const { positions, normals, colours, indices, view, width, height } = scene;
  const mvp = multiply(scene.projection, view);
  const n = positions.length / 3;
  // Window coordinates and 1/w per vertex.
  const sx = new Float64Array(n);
  const sy = new Float64Array(n);
  const sz = new Float64Array(n);
  const iw = new Float64Array(n);
  for (let v = 0; v < n; v++) {
    const [x, y, z] = [positions[3 * v], positions[3 * v + 1], positions[3 * v + 2]];
    const cx = mvp[0] * x + mvp[4] * y + mvp[8] * z + mvp[12];
    const cy = mvp[1] * x + mvp[5] * y + mvp[9] * z + mvp[13];
    const cz = mvp[2] * x + mvp[6] * y + mvp[10] * z + mvp[14];
    const cw = mvp[3] * x + mvp[7] * y + mvp[11] * z + mvp[15];
    iw[v] = 1 / cw;
    sx[v] = ((cx / cw + 1) / 2) * width;
    sy[v] = ((cy / cw + 1) / 2) * height;
    sz[v] = ((cz / cw + 1) / 2);
  }
  const depth = new Float32Array(width * height).fill(Infinity);
  const rgba = new Uint8Array(width * height * 4);
  const bg = BACKGROUND.map((c) => Math.round(c * 255));
  for (let p = 0; p < width * height; p++) rgba.set([bg[0], bg[1], bg[2], 255], 4 * p);
  for (let t = 0; t < indices.length; t += 3) {
    const [a, b, c] = [indices[t], indices[t + 1], indices[t + 2]];
    if (iw[a] <= 0 || iw[b] <= 0 || iw[c] <= 0) continue;
    const area = (sx[b] - sx[a]) * (sy[c] - sy[a]) - (sx[c] - sx[a]) * (sy[b] - sy[a]);
    if (area === 0) continue;
    const front = area > 0;
    const x0 = Math.max(0, Math.floor(Math.min(sx[a], sx[b], sx[c])));
    const x1 = Math.min(width - 1, Math.ceil(Math.max(sx[a], sx[b], sx[c])));
    const y0 = Math.max(0, Math.floor(Math.min(sy[a], sy[b], sy[c])));
    const y1 = Math.min(height - 1, Math.ceil(Math.max(sy[a], sy[b], sy[c])));
    for (let py = y0; py <= y1; py++) {
      for (let px = x0; px <= x1; px++) {
        const x = px + 0.5;
        const y = py + 0.5;
        const wa = ((sx[b] - x) * (sy[c] - y) - (sx[c] - x) * (sy[b] - y)) / area;
        const wb = ((sx[c] - x) * (sy[a] - y) - (sx[a] - x) * (sy[c] - y)) / area;
        const wc = 1 - wa - wb;
        if (wa < 0 || wb < 0 || wc < 0) continue;
        const z = wa * sz[a] + wb * sz[b] + wc * sz[c];
        const at = py * width + px;
        if (z >= depth[at] || z < 0 || z > 1) continue;
        depth[at] = z;
        // Perspective-correct interpolation weights.
        const pa = wa * iw[a];
        const pb = wb * iw[b];
        const pc = wc * iw[c];
        const sum = pa + pb + pc;
        const w = [pa / sum, pb / sum, pc / sum];
        const corners = [a, b, c];
        const normal = [0, 0, 0];
        let albedo = colours ? [0, 0, 0] : [...CLAY];
        /** @type {[number, number, number]} */
        const world = [0, 0, 0];
        for (let k = 0; k < 3; k++) {
          const v = corners[k];
          for (let i = 0; i < 3; i++) {
            normal[i] += (w[k] * normals[3 * v + i]) / 32767;
            world[i] += w[k] * positions[3 * v + i];
            if (colours) albedo[i] += (w[k] * colours[3 * v + i]) / 255;
          }
        }
        if (scene.albedoAt) albedo = scene.albedoAt(world);
        const viewNormal = [0, 1, 2].map(
          (r) => view[r] * normal[0] + view[4 + r] * normal[1] + view[8 + r] * normal[2],
        );
        const length = Math.hypot(...viewNormal);
        /** @type {[number, number, number]} */
        let nv = length > 0 ? [viewNormal[0] / length, viewNormal[1] / length, viewNormal[2] / length] : [0, 0, 1];
        if (!front) nv = [-nv[0], -nv[1], -nv[2]];
        const colour = shade(nv, /** @type {[number, number, number]} */ (albedo));
        rgba[4 * at] = Math.round(colour[0] * 255);
        rgba[4 * at + 1] = Math.round(colour[1] * 255);
        rgba[4 * at + 2] = Math.round(colour[2] * 255);
      }
    }
  }
  return rgba;
}

/**
 * Pixels that differ from the clear colour by more than a few levels.
 * @param {Uint8Array} rgba
 */
export function foreground(rgba) {
  const bg = BACKGROUND.map((c) => Math.round(c * 255));
  const mask = new Uint8Array(rgba.length / 4);
  for (let p = 0; p < mask.length; p++) {
    const d = Math.abs(rgba[4 * p] - bg[0]) + Math.abs(rgba[4 * p + 1] - bg[1]) + Math.abs(rgba[4 * p + 2] - bg[2]);
    mask[p] = d > 12 ? 1 : 0;
  }
  return mask;
}

/**
 * @param {Uint8Array} a RGBA
 * @param {Uint8Array} b RGBA of the same size
 * @returns {{ iou: number, meanDiff: number, badFraction: number, foreground: number }}
 *   silhouette intersection over union; mean absolute channel difference and
 *   fraction of pixels off by more than 32 in some channel, both over the
 *   pixels inside both silhouettes
 */
export function compareImages(a, b) {
  const ma = foreground(a);
  const mb = foreground(b);
  let both = 0;
  let either = 0;
  let diff = 0;
  let bad = 0;
  for (let p = 0; p < ma.length; p++) {
    if (ma[p] || mb[p]) either++;
    if (!(ma[p] && mb[p])) continue;
    both++;
    let worst = 0;
    for (let i = 0; i < 3; i++) {
      const d = Math.abs(a[4 * p + i] - b[4 * p + i]);
      diff += d;
      worst = Math.max(worst, d);
    }
    if (worst > 32) bad++;
  }
  return {
    iou: either ? both / either : 1,
    meanDiff: both ? diff / (3 * both) : 0,
    badFraction: both ? bad / both : 0,
    foreground: either,
  };
}
