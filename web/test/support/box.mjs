// @ts-check
/**
 * A box of known size as an ASCII PLY, each face a grid of unit squares
 * (shared vertices along the edges, outward winding), for the measurement
 * tests: its corners are vertices, its edges have the lengths given.
 */
import { writeFileSync } from 'node:fs';

/**
 * @param {string} path
 * @param {[number, number, number]} size whole numbers: cells per axis, one unit each
 * @returns {{ vertices: number, faces: number }}
 */
export function writeBox(path, size) {
  /** @type {Map<string, number>} */
  const ids = new Map();
  /** @type {number[][]} */
  const positions = [];
  /** @type {number[][]} */
  const faces = [];
  const vertex = (/** @type {number[]} */ p) => {
    const key = p.join(',');
    let id = ids.get(key);
    if (id === undefined) {
      id = positions.length;
      ids.set(key, id);
      positions.push(p);
    }
    return id;
  };
  for (let axis = 0; axis < 3; axis++) {
    const u = (axis + 1) % 3;
    const v = (axis + 2) % 3;
    for (const side of [0, 1]) {
      for (let i = 0; i < size[u]; i++) {
        for (let j = 0; j < size[v]; j++) {
          const at = (/** @type {number} */ di, /** @type {number} */ dj) => {
            const p = [0, 0, 0];
            p[axis] = side * size[axis];
            p[u] = i + di;
            p[v] = j + dj;
            return vertex(p);
          };
          const [a, b, c, d] = [at(0, 0), at(1, 0), at(1, 1), at(0, 1)];
          // (u, v, axis) is right-handed: counter-clockwise seen from +axis.
          if (side === 1) faces.push([a, b, c], [a, c, d]);
          else faces.push([a, c, b], [a, d, c]);
        }
      }
    }
  }
  const header = [
    'ply',
    'format ascii 1.0',
    `element vertex ${positions.length}`,
    'property float x',
    'property float y',
    'property float z',
    `element face ${faces.length}`,
    'property list uchar int vertex_indices',
    'end_header',
  ];
  const body = [...positions.map((p) => p.join(' ')), ...faces.map((f) => `3 ${f.join(' ')}`)];
  writeFileSync(path, `${[...header, ...body].join('\n')}\n`);
  return { vertices: positions.length, faces: faces.length };
}
