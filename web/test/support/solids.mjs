// @ts-check
/**
 * The true silhouette of a solid made of axis-aligned boxes (a cube, an
 * L-shaped block), ray-cast on the CPU through a capture's camera, and how
 * far a rendered image's foreground is from it: for the splat tests, which
 * compare clipped and unclipped splats against the surface they sample.
 * Also a box as a triangle mesh, its sharp edges the box's.
 */
import { multiply } from '../../src/camera.js';
import { invert } from '../../src/splats/splat-renderer.js';

/** @typedef {{ min: [number, number, number], max: [number, number, number] }} Box */

/**
 * Whether the segment o + t·d, t in [0, 1], meets the box (slab test).
 * @param {number[]} o @param {number[]} d @param {Box} box
 */
function meets(o, d, box) {
  let near = 0;
  let far = 1;
  for (let k = 0; k < 3; k++) {
    if (Math.abs(d[k]) < 1e-12) {
      if (o[k] < box.min[k] || o[k] > box.max[k]) return false;
      continue;
    }
    const a = (box.min[k] - o[k]) / d[k];
    const b = (box.max[k] - o[k]) / d[k];
    near = Math.max(near, Math.min(a, b));
    far = Math.min(far, Math.max(a, b));
  }
  return near <= far;
}

/**
 * Pixels whose ray (from the near to the far plane) meets any of the
 * boxes, rows bottom-up like gl.readPixels.
 * @param {{ view: ArrayLike<number>, projection: ArrayLike<number>, width: number, height: number }} camera
 * @param {Box[]} boxes
 */
export function castBoxes(camera, boxes) {
  const { width, height } = camera;
  const inverse = invert(multiply(new Float32Array(camera.projection), new Float32Array(camera.view)));
  /** @param {number} x @param {number} y @param {number} z */
  const unproject = (x, y, z) => {
    const v = [0, 1, 2, 3].map((r) => inverse[r] * x + inverse[4 + r] * y + inverse[8 + r] * z + inverse[12 + r]);
    return [v[0] / v[3], v[1] / v[3], v[2] / v[3]];
  };
  const mask = new Uint8Array(width * height);
  for (let y = 0; y < height; y++) {
    for (let x = 0; x < width; x++) {
      const nx = ((x + 0.5) / width) * 2 - 1;
      const ny = ((y + 0.5) / height) * 2 - 1;
      const o = unproject(nx, ny, -1);
      const f = unproject(nx, ny, 1);
      const d = [f[0] - o[0], f[1] - o[1], f[2] - o[2]];
      mask[y * width + x] = boxes.some((b) => meets(o, d, b)) ? 1 : 0;
    }
  }
  return mask;
}

/**
 * Silhouette error (pixels where the image's foreground and the truth
 * differ) and holes (background pixels deep inside the truth: the pixel and
 * its 8 neighbours see the solid, so the silhouette's own boundary counts
 * as error, not as a hole).
 * @param {Uint8Array} shown foreground mask of the image
 * @param {Uint8Array} truth
 * @param {number} width
 */
export function silhouetteError(shown, truth, width) {
  const height = truth.length / width;
  let error = 0;
  let holes = 0;
  let inside = 0;
  for (let y = 0; y < height; y++) {
    for (let x = 0; x < width; x++) {
      const p = y * width + x;
      error += shown[p] ^ truth[p];
      let deep = true;
      for (let dy = -1; dy <= 1 && deep; dy++) {
        for (let dx = -1; dx <= 1 && deep; dx++) {
          const a = x + dx;
          const b = y + dy;
          deep = a >= 0 && b >= 0 && a < width && b < height && truth[b * width + a] === 1;
        }
      }
      if (deep) {
        inside++;
        holes += 1 - shown[p];
      }
    }
  }
  return { error, holes, inside };
}

/**
 * A box as a closed triangle mesh, each face a grid of `cells` × `cells`
 * quads (vertices shared along the edges, outward winding).
 * @param {Box} box @param {number} cells
 */
export function boxMesh(box, cells) {
  /** @type {number[]} */
  const positions = [];
  /** @type {number[]} */
  const indices = [];
  /** @type {Map<string, number>} */
  const ids = new Map();
  /** @param {number[]} p */
  const vertex = (p) => {
    const key = p.map((c) => c.toFixed(6)).join(' ');
    let id = ids.get(key);
    if (id === undefined) {
      id = positions.length / 3;
      ids.set(key, id);
      positions.push(...p);
    }
    return id;
  };
  for (let axis = 0; axis < 3; axis++) {
    const [u, v] = [(axis + 1) % 3, (axis + 2) % 3];
    for (const side of [0, 1]) {
      /** @param {number} i @param {number} j */
      const at = (i, j) => {
        const p = [0, 0, 0];
        p[axis] = side ? box.max[axis] : box.min[axis];
        p[u] = box.min[u] + ((box.max[u] - box.min[u]) * i) / cells;
        p[v] = box.min[v] + ((box.max[v] - box.min[v]) * j) / cells;
        return vertex(p);
      };
      for (let i = 0; i < cells; i++) {
        for (let j = 0; j < cells; j++) {
          const [a, b, c, d] = [at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)];
          // u × v points along +axis: counter-clockwise seen from the max side.
          if (side) indices.push(a, b, c, a, c, d);
          else indices.push(a, c, b, a, d, c);
        }
      }
    }
  }
  return { positions, indices };
}
