// @ts-check
// Share links and IIIF Content State, without a browser: the fragment of a
// view reads back as the same view; a Content State written for a view reads
// back as its camera; bad input is refused with its reason, never fetched.
import assert from 'node:assert/strict';
import test from 'node:test';
import { ContentStateError, contentStateOf, decodeContentState, encodeContentState, readContentState, siteOf } from '../src/content-state.js';
import { formatView, parseView } from '../src/view-state.js';
import { orbitFrom, sceneToWorld, worldToScene } from '../src/share.js';

const site = siteOf('https://museum.example/api/models/bust');

test('a view goes into a fragment and back', () => {
  /** @type {import('../src/view-state.js').ViewState} */
  const view = {
    camera: { target: [0.5, -1.25, 3], distance: 12.5, yaw: 0.7, pitch: -0.2 },
    light: { key: [0.6, 0, 0.8], fill: 0.2 },
    section: { axis: 'y', fraction: 0.42, flip: true },
    note: '17',
    measure: [
      [1, 2, 3],
      [4, 5, 6.5],
    ],
  };
  const fragment = formatView(view);
  assert.match(fragment, /^camera=0\.5,-1\.25,3,12\.5,0\.7,-0\.2&light=/);
  assert.deepEqual(parseView(`#${fragment}`), view);
});

test('fields that do not parse are dropped, the rest kept', () => {
  const view = parseView('camera=1,2,3,0,0,0&light=0,0,0,1&section=w,0.5,0&note=4&measure=1,2,3');
  assert.deepEqual(view, { note: '4' });
  assert.deepEqual(parseView('camera=1,2,3,4,5'), {});
  assert.deepEqual(parseView('section=x,1.5,0'), {});
  assert.deepEqual(parseView(`note=${'9'.repeat(3000)}`), {});
});

test('base64url: UTF-8, no padding, both ways', () => {
  const text = '{"label":"Büste – 胸像"}';
  const encoded = encodeContentState(text);
  assert.match(encoded, /^[A-Za-z0-9_-]+$/);
  assert.equal(decodeContentState(encoded), text);
  assert.equal(decodeContentState(`${encoded}==`.slice(0, encoded.length + ((4 - (encoded.length % 4)) % 4))), text);
});

test('the Content State of a view reads back as its camera and note', () => {
  const state = contentStateOf({
    manifest: 'https://museum.example/iiif/bust/manifest',
    scene: 'https://museum.example/iiif/bust/scene',
    note: 'https://museum.example/iiif/bust/annotations/7',
    position: [0.1, 0.2, 0.3],
    lookAt: [0, 0.05, 0],
    fieldOfView: 40,
  });
  assert.deepEqual(/** @type {any} */ (state).motivation, ['contentState']);
  const read = readContentState(encodeContentState(JSON.stringify(state)), site);
  assert.deepEqual(read, { slug: 'bust', position: [0.1, 0.2, 0.3], lookAt: [0, 0.05, 0], note: '7' });
});

test('a plain manifest URI and a bare Scene target open the default view', () => {
  assert.deepEqual(readContentState('https://museum.example/iiif/bust/manifest', site), { slug: 'bust', position: null, lookAt: null, note: null });
  const scene = { id: 'https://museum.example/iiif/bust/scene', type: 'Scene', partOf: [{ id: 'https://museum.example/iiif/bust/manifest', type: 'Manifest' }] };
  const annotation = { type: 'Annotation', motivation: 'contentState', target: scene };
  assert.equal(readContentState(encodeContentState(JSON.stringify(annotation)), site).slug, 'bust');
});

test('bad Content States are refused with their reason', () => {
  const reason = (/** @type {string} */ value) => {
    try {
      readContentState(value, site);
      return 'accepted';
    } catch (error) {
      assert.ok(error instanceof ContentStateError);
      return error.reason;
    }
  };
  assert.equal(reason('not base64!'), 'encoding');
  assert.equal(reason('A'), 'encoding');
  assert.equal(reason(encodeContentState('{"type": "Annot')), 'json');
  assert.equal(reason(encodeContentState('"just a string"')), 'shape');
  assert.equal(reason('https://elsewhere.example/iiif/bust/manifest'), 'foreign');
  const foreign = { type: 'Annotation', motivation: ['contentState'], target: { id: 'https://elsewhere.example/iiif/x/manifest', type: 'Manifest' } };
  assert.equal(reason(encodeContentState(JSON.stringify(foreign))), 'foreign');
  assert.equal(reason('https://museum.example/api/models/bust'), 'shape');
  const mixed = { id: 'https://museum.example/iiif/bust/scene', type: 'Scene', partOf: [{ id: 'https://museum.example/iiif/vase/manifest' }] };
  assert.equal(reason(encodeContentState(JSON.stringify(mixed))), 'shape');
});

test('an orbit from an eye and a point looked at, and the Scene in model units', () => {
  const orbit = orbitFrom([0, 10, 10], [0, 0, 0]);
  assert.ok(orbit);
  assert.ok(Math.abs(orbit.distance - Math.hypot(10, 10)) < 1e-9);
  assert.ok(Math.abs(orbit.pitch - Math.PI / 4) < 1e-9);
  assert.ok(Math.abs(orbit.yaw) < 1e-9);
  assert.equal(orbitFrom([1, 1, 1], [1, 1, 1]), null);
  assert.deepEqual(sceneToWorld(worldToScene([120, -4, 8], 'mm'), 'mm').map((x) => Math.round(x * 1e9) / 1e9), [120, -4, 8]);
  assert.deepEqual(worldToScene([2, 0, 0], null), [2, 0, 0]);
});
