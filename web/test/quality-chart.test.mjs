// @ts-check
import { test } from 'node:test';
import assert from 'node:assert/strict';
import {
  describeLevel,
  formatCount,
  layoutQualityChart,
  renderQualityChart,
} from '../src/quality-chart.js';

/** @typedef {import('../src/quality-chart.js').QualityPoint} QualityPoint */

/** A curve like a painted torus's: vertices growing ~1.6× a level, errors falling. @type {QualityPoint[]} */
const curve = [
  { level: 0, vertices: 220, hausdorff: 0.031, roy_rmse: 41.2, image_rmse: 38.5 },
  { level: 1, vertices: 340, hausdorff: 0.022, roy_rmse: 33.0, image_rmse: 29.1 },
  { level: 2, vertices: 560, hausdorff: 0.014, roy_rmse: 24.4, image_rmse: 20.7 },
  { level: 3, vertices: 900, hausdorff: 0.008, roy_rmse: 15.9, image_rmse: 12.2 },
  { level: 4, vertices: 1400, hausdorff: 0.003, roy_rmse: 8.1, image_rmse: 6.0 },
  { level: 5, vertices: 1800, hausdorff: 0.0002, roy_rmse: 0.4, image_rmse: 0.9 },
];

test('points are placed left to right by vertex count, on a log scale', () => {
  const layout = layoutQualityChart(curve, 2);
  assert.ok(layout);
  assert.deepEqual(
    layout.series.map((s) => s.key),
    ['image_rmse', 'roy_rmse'],
  );
  for (const s of layout.series) {
    assert.equal(s.points.length, curve.length);
    for (let k = 1; k < s.points.length; k++) assert.ok(s.points[k].x > s.points[k - 1].x, `${s.key} ${k}`);
    assert.equal(s.points[0].x, layout.plot.left);
    assert.equal(s.points.at(-1)?.x, layout.plot.right);
  }
  // Equal ratios of vertices are equal distances: log scale.
  const xs = layoutQualityChart(
    [10, 100, 1000].map((vertices, level) => ({ level, vertices, hausdorff: 0, roy_rmse: null, image_rmse: 1 })),
    0,
  )?.series[0].points.map((p) => p.x);
  assert.ok(xs);
  assert.ok(Math.abs(xs[1] - xs[0] - (xs[2] - xs[1])) < 1e-9);
  // Falling errors go down the chart: y grows downwards in SVG.
  const image = layout.series[0].points;
  for (let k = 1; k < image.length; k++) assert.ok(image[k].y > image[k - 1].y);
  assert.ok(image.every((p) => p.y >= layout.plot.top && p.y <= layout.plot.bottom));
});

test('the marker stands at the level on screen', () => {
  for (const level of [0, 3, 5]) {
    const layout = layoutQualityChart(curve, level);
    assert.equal(layout?.marker?.level, level);
    assert.equal(layout?.marker?.x, layout?.series[0].points[level].x);
    assert.deepEqual(
      layout?.marker?.points.map((p) => p.y),
      layout?.series.map((s) => s.points[level].y),
    );
    const svg = renderQualityChart(curve, level);
    const markers = [...svg.matchAll(/<g class="marker" data-marker="" data-level="(\d+)">/g)];
    assert.deepEqual(
      markers.map((m) => Number(m[1])),
      [level],
    );
  }
  // Nothing on screen yet, or a level without a point: no marker.
  assert.equal(layoutQualityChart(curve, -1)?.marker, null);
  assert.doesNotMatch(renderQualityChart(curve, -1), /data-marker/);
  assert.equal(layoutQualityChart(curve, 9)?.marker, null);
});

test('the SVG draws one polyline per series, its points in increasing x', () => {
  const svg = renderQualityChart(curve, 1);
  assert.match(svg, /^<svg xmlns="http:\/\/www.w3.org\/2000\/svg"[^>]* viewBox="0 0 260 130"/);
  assert.ok(svg.endsWith('</svg>'));
  const lines = [...svg.matchAll(/<polyline class="series" data-series="(\w+)" points="([^"]+)"/g)];
  assert.deepEqual(
    lines.map((m) => m[1]),
    ['image_rmse', 'roy_rmse'],
  );
  for (const [, , points] of lines) {
    const xs = points.split(' ').map((p) => Number(p.split(',')[0]));
    assert.equal(xs.length, curve.length);
    for (let k = 1; k < xs.length; k++) assert.ok(xs[k] > xs[k - 1]);
  }
  assert.match(svg, /image RMSE/);
  assert.match(svg, /colour RMSE \(Roy\)/);
});

test('empty input draws nothing', () => {
  for (const empty of [[], null, undefined]) {
    assert.equal(layoutQualityChart(empty, 0), null);
    assert.equal(renderQualityChart(empty, 0), '');
    assert.equal(describeLevel(empty, 0), '');
  }
  // Unusable points are dropped, not drawn at NaN.
  const bad = [{ level: 0, vertices: 0, hausdorff: 0, roy_rmse: null, image_rmse: 3 }];
  assert.equal(renderQualityChart(bad, 0), '');
});

test('without colour only the image RMSE is drawn; one level still makes a chart', () => {
  const clay = curve.map((p) => ({ ...p, roy_rmse: null }));
  const layout = layoutQualityChart(clay, 0);
  assert.deepEqual(
    layout?.series.map((s) => s.key),
    ['image_rmse'],
  );
  assert.doesNotMatch(renderQualityChart(clay, 0), /Roy/);
  const single = layoutQualityChart([curve[5]], 5);
  assert.equal(single?.series[0].points.length, 1);
  assert.ok(Number.isFinite(single?.series[0].points[0].x));
  assert.equal(single?.marker?.level, 5);
  assert.doesNotMatch(renderQualityChart([curve[5]], 5), /NaN|Infinity/);
});

test('axes: the ends and powers of ten of the vertex counts; whole decades of error', () => {
  assert.equal(formatCount(1000), '1k');
  assert.equal(formatCount(1_500_000), '1.5M');
  assert.equal(formatCount(400), '400');
  const layout = layoutQualityChart(curve, 0);
  assert.deepEqual(
    layout?.xTicks.map((t) => t.label),
    ['220', '1k', '1.8k'],
  );
  assert.deepEqual(
    layout?.yTicks.map((t) => t.label),
    ['0.1', '1', '10', '100'],
  );
  // Errors on a log scale too: equal ratios, equal heights; an exact level sits on the floor.
  const ys = layoutQualityChart(
    [0, 1, 10, 100].map((image_rmse, level) => ({ level, vertices: 10 + level, hausdorff: 0, roy_rmse: null, image_rmse })),
    0,
  )?.series[0].points.map((p) => p.y);
  assert.ok(ys && layout);
  assert.ok(Math.abs(ys[1] - ys[2] - (ys[2] - ys[3])) < 1e-9);
  assert.equal(ys[0], layout.plot.bottom);
  assert.equal(ys[3], layout.plot.top);
  assert.equal(describeLevel(curve, 3), 'Level 3: image RMSE 12.2 · colour RMSE 15.9 · Hausdorff 0.80% of the diagonal');
});

test('a quality study adds a bar per level with answers: the share of "sufficient"', async () => {
  const { describeStudyLevel } = await import('../src/quality-chart.js');
  const study = [
    { level: 1, answers: 4, sufficient: 0 },
    { level: 3, answers: 4, sufficient: 2 },
    { level: 5, answers: 4, sufficient: 4 },
    { level: 9, answers: 4, sufficient: 4 },
  ];
  const layout = layoutQualityChart(curve, 3, { study });
  assert.ok(layout);
  assert.deepEqual(layout.study.map((b) => [b.level, b.share]), [[1, 0], [3, 0.5], [5, 1]], 'levels off the curve are left out');
  const full = layout.study[2];
  assert.equal(full.y, layout.plot.top, '100 % reaches the top of the plot');
  assert.equal(layout.study[0].y, layout.plot.bottom);
  const svg = renderQualityChart(curve, 3, { study });
  assert.equal((svg.match(/data-study-level=/g) ?? []).length, 3);
  assert.match(svg, /data-study-level="3" data-share="0.5"/);
  assert.match(svg, /sufficient %/);
  assert.equal(renderQualityChart(curve, 3).includes('data-study-level'), false, 'no study, no bars');
  assert.equal(describeStudyLevel(study, 3), 'sufficient for 2 of 4 (50%) in the quality study');
  assert.equal(describeStudyLevel(study, 2), '');
  assert.equal(describeStudyLevel(null, 3), '');
});
