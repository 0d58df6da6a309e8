// @ts-check
// The occlusion depth map's cost (occlusion.js) on a UV sphere of 2 n²
// triangles seen whole, in Node: ms per map, and whether the sphere's back
// is hidden behind its front (it must be) and its front is not.
//   node bench/occlusion-cost.mjs [n (default 1000: 2 M triangles)] [--runs 5]
import { parseArgs } from 'node:util';
import { depthMap, occluded } from '../src/occlusion.js';

const { values, positionals } = parseArgs({ allowPositionals: true, options: { runs: { type: 'string', default: '5' } } });
const n = Number(positionals[0] ?? 1000);
const positions = new Float32Array((n + 1) * (n + 1) * 3);
for (let i = 0; i <= n; i++) {
  for (let j = 0; j <= n; j++) {
    const [theta, phi, k] = [(Math.PI * i) / n, (2 * Math.PI * j) / n, 3 * (i * (n + 1) + j)];
    positions.set([Math.sin(theta) * Math.cos(phi), Math.sin(theta) * Math.sin(phi), Math.cos(theta)], k);
  }
}
const indices = new Uint32Array(6 * n * n);
for (let i = 0, t = 0; i < n; i++) {
  for (let j = 0; j < n; j++, t += 6) {
    const a = i * (n + 1) + j;
    indices.set([a, a + n + 1, a + 1, a + 1, a + n + 1, a + n + 2], t);
  }
}
// An eye at z = 3 looking down −z, 45° vertical field of view, aspect 4:3.
const [f, near, far, aspect, eye] = [1 / Math.tan(Math.PI / 8), 0.1, 10, 4 / 3, 3];
const [a, b] = [(far + near) / (near - far), (2 * far * near) / (near - far)];
// prettier-ignore
const clip = [f / aspect, 0, 0, 0, 0, f, 0, 0, 0, 0, a, -1, 0, 0, -a * eye + b, eye];
const times = [];
for (let run = 0; run < Number(values.runs); run++) {
  const t0 = performance.now();
  const map = depthMap([{ positions, indices, tolerance: 0.01 }], clip, aspect);
  times.push(performance.now() - t0);
  if (!occluded(map, { centre: [0, 0, -0.9], radius: 0.05 }) || occluded(map, { centre: [0, 0, 0.95], radius: 0.04 })) throw new Error('the map is wrong');
}
times.sort((x, y) => x - y);
console.log(`depth map of ${indices.length / 3} triangles (${positions.length / 3} vertices): median ${times[times.length >> 1].toFixed(1)} ms, fastest ${times[0].toFixed(1)} ms of ${times.length}`);
