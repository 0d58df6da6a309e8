// @ts-check
// The CCC colour lookup's JavaScript twin (src/ccc.js) on hand-made
// complexes, and the PNG decoder the viewer reads cell textures with.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { CellComplex, CccError, bilinear, checkParameters, exitFace, sampleInset } from '../src/ccc.js';
import { PngError, decodePng } from '../src/png.js';
import { cellTexture, encodePng, quadComplex } from './support/ccc-fixtures.mjs';

test('PNG: every row filter, RGB and RGBA, several IDAT chunks', async () => {
  for (const channels of [3, 4]) {
    const width = 37;
    const height = 23;
    const data = new Uint8Array(width * height * channels);
    let seed = 7;
    for (let i = 0; i < data.length; i++) {
      seed = (seed * 1103515245 + 12345) >>> 0;
      // Smooth ramps plus noise, so every filter sees both kinds of rows.
      data[i] = ((i % (width * channels)) * 3 + (seed >>> 28)) & 255;
    }
    const png = encodePng({ width, height, channels, data }, { filters: [0, 1, 2, 3, 4], idatChunk: 97 });
    const decoded = await decodePng(png);
    assert.deepEqual([decoded.width, decoded.height, decoded.channels], [width, height, channels]);
    assert.deepEqual(decoded.data, data);
  }
});

test('PNG: damaged or unsupported files are refused with a reason', async () => {
  const good = encodePng({ width: 2, height: 2, channels: 3, data: new Uint8Array(12).fill(9) });
  await assert.rejects(decodePng(new Uint8Array([1, 2, 3])), PngError);
  const interlaced = good.slice();
  interlaced[28] = 1; // IHDR interlace byte (CRC is not checked; zlib's checksum is)
  await assert.rejects(decodePng(interlaced), /interlaced/);
  const deep = good.slice();
  deep[24] = 16;
  await assert.rejects(decodePng(deep), /bit depth 16/);
  await assert.rejects(decodePng(good.subarray(0, good.length - 20)), PngError);
  const flipped = good.slice();
  flipped[45] ^= 0xff; // inside the compressed data
  await assert.rejects(decodePng(flipped), PngError);
});

test('exit faces: the axis reached first, ties to the lower axis, face coordinates in axis order', () => {
  const c = [0.5, 0.5, 0.5];
  assert.deepEqual(exitFace(c, [0.2, 0, 0]), { face: 0, uv: [0.5, 0.5] });
  assert.deepEqual(exitFace(c, [-0.2, 0.1, 0]), { face: 1, uv: [0.75, 0.5] });
  assert.deepEqual(exitFace(c, [0.1, 0.25, -0.05]), { face: 2, uv: [0.7, 0.4] });
  assert.deepEqual(exitFace(c, [0, -1, 0]), { face: 3, uv: [0.5, 0.5] });
  assert.deepEqual(exitFace(c, [0.25, 0.125, 0.5]), { face: 4, uv: [0.75, 0.625] });
  assert.deepEqual(exitFace(c, [0, 0, -0.3]), { face: 5, uv: [0.5, 0.5] });
  assert.equal(exitFace(c, [0.3, 0.3, 0.1])?.face, 0, 'x and y tie: x wins');
  assert.equal(exitFace(c, [0, -0.3, -0.3])?.face, 3, 'y and z tie: y wins');
  assert.equal(exitFace(c, [0, 0, 0]), null);
  // An off-centre centre: the nearer wall is reached first.
  assert.equal(exitFace([0.9, 0.5, 0.5], [0.1, 0.3, 0])?.face, 0);
  assert.equal(exitFace([0.5, 0.5, 0.95], [0, 0.2, 0.1])?.face, 4);
});

test('the hand-made quad complex: tiles, mean colour, fallback, clamping inside the tile', () => {
  const fixture = quadComplex();
  const complex = new CellComplex(fixture.parameters, fixture.cells);
  const { parameters: p } = fixture;
  const s = p.cell_size;
  const at = (/** @type {number} */ x, /** @type {number} */ y) => [p.origin[0] + x * s, p.origin[1] + y * s, p.origin[2] + 0.5 * s];
  // Straight above the centre: face +z, the 2×2 tile's four texels.
  const centre = fixture.centre;
  const plusZ = complex.lookup(at(centre[0], centre[1]));
  assert.equal(plusZ.kind, 'tile');
  if (plusZ.kind !== 'tile') return;
  assert.equal(plusZ.face, 4);
  assert.equal(plusZ.tile, fixture.tileOfFace[4]);
  // Quadrants of face +z map to the tile's four texels, exactly at their centres.
  for (const [dx, dy, texel] of /** @type {const} */ ([[-1, -1, 0], [1, -1, 1], [-1, 1, 2], [1, 1, 3]])) {
    // A point whose ray leaves +z at u, v = 0.5 ± 0.25.
    const u = 0.5 + 0.25 * dx;
    const v = 0.5 + 0.25 * dy;
    // Where that ray crosses the quad's plane (z = 0.5).
    const x = centre[0] + (u - centre[0]) * ((0.5 - centre[2]) / (1 - centre[2]));
    const y = centre[1] + (v - centre[1]) * ((0.5 - centre[2]) / (1 - centre[2]));
    const found = complex.lookup(at(x, y));
    assert.equal(found.kind, 'tile');
    if (found.kind !== 'tile') continue;
    assert.ok(Math.abs(found.uv[0] - u) < 1e-12 && Math.abs(found.uv[1] - v) < 1e-12, JSON.stringify(found.uv));
    const colour = complex.colourAt(at(x, y), fixture.atlas);
    assert.deepEqual(colour.map((c) => Math.round(c * 255)), fixture.tileColours[4][texel], `texel ${texel}`);
  }
  // The face coordinate 0 clamps to the first interior texel's centre.
  const edge = complex.lookup(at(0.02, centre[1]));
  assert.equal(edge.kind, 'tile');
  if (edge.kind === 'tile') {
    assert.equal(edge.face, 1, 'near the −x wall the ray leaves through −x');
    const side = p.tile_size + 2 * p.gutter;
    const col = edge.tile % p.atlas.tiles_per_row;
    assert.ok(edge.x >= col * side + p.gutter + 0.5 && edge.x <= col * side + p.gutter + p.tile_size - 0.5);
  }
  // −y has no tile: the cell's mean colour.
  const minusY = complex.lookup(at(centre[0], 0.02));
  assert.deepEqual(minusY, { kind: 'mean', colour: fixture.mean.map((c) => c / 255) });
  // The centre itself: the mean colour.
  assert.equal(complex.lookup([p.origin[0] + centre[0] * s, p.origin[1] + centre[1] * s, p.origin[2] + centre[2] * s]).kind, 'mean');
  // The second cube is empty, and outside the grid is outside: the fallback colour.
  const fallback = p.fallback_colour.map((c) => c / 255);
  assert.deepEqual(complex.lookup(at(1.5, 0.5)), { kind: 'fallback', colour: fallback });
  assert.deepEqual(complex.lookup(at(-0.5, 0.5)), { kind: 'fallback', colour: fallback });
  assert.deepEqual(complex.lookup(at(0.5, 1.5)), { kind: 'fallback', colour: fallback });
});

test('tile numbering counts only the faces below in the mask', () => {
  const fixture = quadComplex({ mask: 0b110101, first: 5 });
  const complex = new CellComplex(fixture.parameters, fixture.cells);
  const p = fixture.parameters;
  const s = p.cell_size;
  const c = fixture.centre;
  const point = (/** @type {number[]} */ d) => c.map((v, a) => p.origin[a] + (v + d[a]) * s);
  // +x: bit 0, first tile; +z: bit 4 with bits 0 and 2 below: first + 2; −z: first + 3.
  const tile = (/** @type {number[]} */ d) => {
    const found = complex.lookup(point(d));
    return found.kind === 'tile' ? [found.face, found.tile] : [found.kind];
  };
  assert.deepEqual(tile([0.3, 0, 0]), [0, 5]);
  assert.deepEqual(tile([0, 0.3, 0]), [2, 6]);
  assert.deepEqual(tile([0, 0, 0.3]), [4, 7]);
  assert.deepEqual(tile([0, 0, -0.001]), [5, 8]);
  assert.deepEqual(tile([-0.3, 0, 0]), ['mean']);
  assert.deepEqual(tile([0, -0.3, 0]), ['mean']);
});

test('the low-resolution atlas is sampled at the same place, scaled', () => {
  const fixture = quadComplex();
  const complex = new CellComplex(fixture.parameters, fixture.cells);
  const p = fixture.parameters;
  // A low-resolution atlas of one colour per 2×2 block: every sample inside
  // a tile's block is that block's colour.
  const f = 2;
  const low = { width: Math.ceil(p.atlas.width / f), height: Math.ceil(p.atlas.height / f), channels: 3, data: new Uint8Array(0) };
  low.data = new Uint8Array(low.width * low.height * 3).fill(77);
  const found = complex.lookup([p.origin[0] + 0.5 * p.cell_size, p.origin[1] + 0.5 * p.cell_size, p.origin[2] + 0.5 * p.cell_size]);
  assert.equal(found.kind, 'tile');
  assert.deepEqual(complex.colourAt([p.origin[0] + 0.5 * p.cell_size, p.origin[1] + 0.5 * p.cell_size, p.origin[2] + 0.5 * p.cell_size], low).map((c) => Math.round(c * 255)), [77, 77, 77]);
});

test('the low-resolution atlas keeps its samples half a low-resolution texel inside the tile', () => {
  const { parameters } = quadComplex();
  const p = { ...parameters, tile_size: 12, gutter: 1 };
  assert.equal(sampleInset(p, 1), 0.5, 'full resolution: CCC.md\'s half texel');
  assert.equal(sampleInset(p, 1 / 4), 2);
  assert.equal(sampleInset({ ...p, tile_size: 2 }, 1 / 8), 1, 'never past the middle of the tile');
  const fixture = quadComplex();
  const complex = new CellComplex(fixture.parameters, fixture.cells);
  const q = fixture.parameters;
  // Near the −x wall, face coordinate u ≈ 0: clamped to the inset.
  const point = [q.origin[0] + 0.02, q.origin[1] + 0.1, q.origin[2] + 0.5];
  const found = complex.lookup(point, 1);
  assert.equal(found.kind, 'tile');
  if (found.kind === 'tile') assert.equal(found.x - (found.tile % q.atlas.tiles_per_row) * 4, q.gutter + 1);
});

test('bilinear sampling: texel centres exact, half-way blends, edges clamped', () => {
  const image = { width: 2, height: 1, channels: 3, data: new Uint8Array([0, 100, 200, 100, 200, 0]) };
  assert.deepEqual(bilinear(image, 0.5, 0.5).map((c) => c * 255), [0, 100, 200]);
  assert.deepEqual(bilinear(image, 1, 0.5).map((c) => Math.round(c * 255)), [50, 150, 100]);
  assert.deepEqual(bilinear(image, -3, 9).map((c) => c * 255), [0, 100, 200]);
  assert.deepEqual(bilinear(image, 5, 0.5).map((c) => c * 255), [100, 200, 0]);
});

test('parameters that cannot describe a complex are refused', () => {
  const { parameters } = quadComplex();
  assert.doesNotThrow(() => checkParameters(parameters));
  assert.throws(() => checkParameters({ ...parameters, version: 2 }), CccError);
  assert.throws(() => checkParameters({ ...parameters, cells: 100 }), /cannot hold/);
  assert.throws(() => checkParameters({ ...parameters, dims: [0, 1, 1] }), /empty grid/);
  assert.throws(
    () => checkParameters(parameters, { width: parameters.cell_texture.width + 1, height: parameters.cell_texture.height }),
    /cell texture is/,
  );
  const small = cellTexture(parameters, []);
  assert.throws(() => new CellComplex(parameters, { ...small, channels: 2 }), /three channels/);
});
