// @ts-check
import { test } from 'node:test';
import assert from 'node:assert/strict';
import {
  GLSL_RELIEF,
  RAMP,
  formatDegrees,
  normalDeviation,
  rampGradient,
  reliefColour,
  reliefTicks,
  reliefTop,
  roundTop,
  vertexFaces,
} from '../src/relief.js';

/**
 * An n × n grid of unit squares, each split along its (i, j)–(i+1, j+1)
 * diagonal, counter-clockwise from +z; vertex (i, j) is j·(n+1) + i (the
 * grid of codec/simplify/src/deviation.rs's tests). `height` gives z.
 * @param {number} n
 * @param {(i: number, j: number) => number} height
 */
function grid(n, height) {
  const positions = new Float32Array(3 * (n + 1) * (n + 1));
  for (let j = 0; j <= n; j++) {
    for (let i = 0; i <= n; i++) positions.set([i, j, height(i, j)], 3 * (j * (n + 1) + i));
  }
  const id = (/** @type {number} */ i, /** @type {number} */ j) => j * (n + 1) + i;
  /** @type {number[]} */
  const indices = [];
  for (let j = 0; j < n; j++) {
    for (let i = 0; i < n; i++) indices.push(id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j), id(i + 1, j + 1), id(i, j + 1));
  }
  return { positions, indices: new Uint32Array(indices) };
}

test('θ ≤ 1e-6 on a planar grid, level or tilted', () => {
  for (const height of [() => 0, (/** @type {number} */ i, /** @type {number} */ j) => 0.25 * i - 0.5 * j]) {
    const { positions, indices } = grid(12, height);
    const theta = normalDeviation(positions, indices);
    assert.equal(theta.length, 13 * 13);
    const worst = Math.max(...theta);
    assert.ok(worst <= 1e-6, `largest θ on a plane: ${worst}`);
  }
});

test('a folded grid: the ridge band beside the crest shows θ > 0.2 rad, the crest and the far flanks less', () => {
  // A 90° ridge along x = 6 (z = −|x − 6|), as in deviation.rs's test.
  const { positions, indices } = grid(12, (i) => -Math.abs(i - 6));
  const theta = normalDeviation(positions, indices);
  const at = (/** @type {number} */ i, /** @type {number} */ j) => theta[j * 13 + i];
  for (let j = 3; j <= 9; j++) {
    // One column either side of the crest: every face of the vertex is on one
    // flank, while its two rings reach over the crest onto the other.
    assert.ok(at(5, j) > 0.2, `band left of the crest, row ${j}: ${at(5, j)}`);
    assert.ok(at(7, j) > 0.2, `band right of the crest, row ${j}: ${at(7, j)}`);
    assert.ok(at(6, j) < at(7, j), `crest ${at(6, j)} below the band ${at(7, j)}`);
    // Three columns away the two rings stay on one flank: a plane.
    assert.ok(at(10, j) < 1e-6 && at(2, j) < 1e-6, `flanks, row ${j}: ${at(2, j)}, ${at(10, j)}`);
  }
});

test('a two-face 90° fold with areas √2 and 2√2: θ as derived by hand (and as codec/simplify computes)', () => {
  // A and B on the crease (the y axis), C on the flank x = −z, D on the flank x = z.
  //   T1 = (A, C, B): (C − A) × (B − A) = (1, 0, −1) × (0, 2, 0) = (2, 0, 2): n1 = (1, 0, 1)/√2, area √2
  //   T2 = (A, B, D): (B − A) × (D − A) = (0, 2, 0) × (−2, 0, −2) = (−4, 0, 4): n2 = (−1, 0, 1)/√2, area 2√2
  // n1 ⊥ n2. Two rings reach both faces from every vertex, so every N_region
  // is the direction of √2·n1 + 2√2·n2 ∝ n1 + 2·n2, atan(2) from n1 (towards n2).
  //   C (on T1 only): N_v = n1, θ = atan 2 = 1.1071487 rad (63.43°)
  //   D (on T2 only): N_v = n2, θ = 90° − atan 2 = atan ½ = 0.4636476 rad (26.57°)
  //   A, B (on both): N_v ∝ n1 + n2 (the unweighted mean: 45° from n1), θ = atan 2 − π/4 = 0.3217506 rad (18.43°)
  // Rust's normal_deviation gives 0.3217505543966423, 0.3217505543966423, 1.1071487177940904, 0.4636476090008059.
  const positions = new Float32Array([0, 0, 0, 0, 2, 0, 1, 0, -1, -2, 0, -2]);
  const indices = new Uint32Array([0, 2, 1, 0, 1, 3]);
  const theta = normalDeviation(positions, indices);
  const expected = [Math.atan(2) - Math.PI / 4, Math.atan(2) - Math.PI / 4, Math.atan(2), Math.atan(0.5)];
  for (let v = 0; v < 4; v++) assert.ok(Math.abs(theta[v] - expected[v]) < 1e-6, `vertex ${v}: ${theta[v]} vs ${expected[v]}`);
});

/**
 * θ of codec/simplify's `normal_deviation` (Rust, f64) on the mesh below, a
 * 6 × 6 grid folded along x = 3 with heights nudged by eighths (every
 * coordinate exact in f32, so both sides see the same mesh), printed to 12
 * digits by a scratch program that builds the same IndexedMesh:
 *   z = −|x − 3| + ((7i + 3j) mod 5)/8, triangles as in `grid`.
 * Row j = 0 first.
 */
const RUST_THETA = [
  0.101055985307, 0.440037649043, 0.724499692134, 0.202848378712, 0.190880716586, 0.061631471587, 0.205728398400,
  0.197174059347, 0.263178106301, 0.725466397392, 0.207363455688, 0.385460703431, 0.142193968868, 0.002751106136,
  0.014935404916, 0.199666882983, 0.528966296571, 0.284700434272, 0.398530754461, 0.236434961179, 0.089720309512,
  0.147255562298, 0.183148578240, 0.411956426828, 0.023553815978, 0.399866183720, 0.208729179511, 0.135619346374,
  0.154792338844, 0.174651880120, 0.358048347128, 0.179126908802, 0.528266977297, 0.210318710497, 0.086794309234,
  0.039190061541, 0.270447129607, 0.323771090645, 0.261131098091, 0.668630522667, 0.286492448178, 0.213863732342,
  0.522698073394, 0.102748473448, 0.333016837858, 0.131227305248, 0.655281064271, 0.409498718643, 0.018230069064,
];

test('JavaScript θ matches Rust normal_deviation on a generated irregular mesh', () => {
  const { positions, indices } = grid(6, (i, j) => -Math.abs(i - 3) + ((7 * i + 3 * j) % 5) / 8);
  const theta = normalDeviation(positions, indices);
  assert.equal(theta.length, RUST_THETA.length);
  let worst = 0;
  for (let v = 0; v < theta.length; v++) worst = Math.max(worst, Math.abs(theta[v] - RUST_THETA[v]));
  // θ leaves as float32 (half an ulp at 0.7 rad is 3e-8).
  assert.ok(worst < 1e-6, `largest difference from Rust: ${worst}`);
  assert.ok(Math.max(...theta) > 0.7, 'the mesh is far from flat');
});

test('a vertex on no face has θ = 0; a degenerate face adds nothing', () => {
  const positions = new Float32Array([0, 0, 0, 1, 0, 0, 0, 1, 0, 5, 5, 5, 2, 0, 0]);
  // Face 1 is degenerate (three collinear corners on the x axis).
  const indices = new Uint32Array([0, 1, 2, 0, 1, 4]);
  const theta = normalDeviation(positions, indices);
  assert.deepEqual([...theta], [0, 0, 0, 0, 0]);
});

test('the vertex → faces rows list each vertex\'s faces in face order', () => {
  const { offsets, faces } = vertexFaces(new Uint32Array([0, 1, 2, 0, 2, 3, 3, 2, 4]), 6);
  assert.deepEqual([...offsets], [0, 2, 3, 6, 8, 9, 9]);
  assert.deepEqual([...faces], [0, 1, 0, 0, 1, 2, 1, 2, 2]);
});

test('the scale tops at the 98th percentile, rounded up to its tick step, at least 1°', () => {
  const degrees = (/** @type {number[]} */ d) => new Float32Array(d.map((x) => (x * Math.PI) / 180));
  // 100 vertices: 98 at 12.3°, 2 at 80°: the 98th percentile is 12.3°, so the top is 15° (steps of 5°).
  assert.equal(reliefTop(degrees([...Array(98).fill(12.3), 80, 80])), 15);
  // 97 + 3: the 98th lands on the 80° ones.
  assert.equal(reliefTop(degrees([...Array(97).fill(12.3), 80, 80, 80])), 80);
  assert.equal(reliefTop(degrees(Array(10).fill(0))), 1);
  assert.equal(reliefTop(new Float32Array(0)), 1);
  assert.equal(reliefTop(degrees([179.9])), 180);
  assert.deepEqual([13.7, 22, 0.8, 4.1, 8.1, 19, 45, 1].map(roundTop), [15, 30, 0.8, 6, 10, 20, 60, 1]);
  assert.deepEqual(reliefTicks(15), [0, 5, 10, 15]);
  assert.deepEqual(reliefTicks(30), [0, 10, 20, 30]);
  assert.deepEqual(reliefTicks(0.8), [0, 0.2, 0.4, 0.6, 0.8]);
  assert.deepEqual(reliefTicks(1), [0, 0.5, 1]);
  assert.deepEqual(reliefTicks(6), [0, 2, 4, 6]);
  assert.deepEqual(reliefTicks(180), [0, 50, 100, 150, 180]);
  assert.deepEqual([0, 0.2, 15, 180].map(formatDegrees), ['0°', '0.2°', '15°', '180°']);
});

test('the ramp: viridis stops at its ends and knots, the same in GLSL and CSS', () => {
  assert.deepEqual(reliefColour(0).map((c) => Math.round(c * 255)), RAMP[0]);
  assert.deepEqual(reliefColour(1).map((c) => Math.round(c * 255)), RAMP[RAMP.length - 1]);
  assert.deepEqual(reliefColour(2), reliefColour(1));
  assert.deepEqual(reliefColour(-1), reliefColour(0));
  assert.deepEqual(reliefColour(3 / 8).map((c) => Math.round(c * 255)), RAMP[3]);
  // Lightness rises along the ramp (a perceptual ramp reads low to high).
  const luma = (/** @type {number[]} */ c) => 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2];
  for (let k = 1; k <= 16; k++) assert.ok(luma(reliefColour(k / 16)) > luma(reliefColour((k - 1) / 16)));
  assert.match(GLSL_RELIEF, /vec3 RELIEF_RAMP\[9\]/);
  assert.match(GLSL_RELIEF, /vec3\(0\.266667, 0\.003922, 0\.329412\)/);
  assert.match(rampGradient(), /^linear-gradient\(to right, rgb\(68 1 84\) 0\.0%, .* rgb\(253 231 37\) 100\.0%\)$/);
});
