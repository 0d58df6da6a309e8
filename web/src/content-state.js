// @ts-check
/**
 * IIIF Content State (API 1.0) for a Scene: the `?iiif-content=` a viewer
 * is opened with, read without a single request (a Content State may name
 * any host; this viewer opens only its own site's models), and the one the
 * share control writes for the current view.
 *
 * Encoding (Content State 1.0 §"Content State Encoding"): UTF-8 JSON,
 * base64url, padding dropped. Also accepted: the plain URI of one of this
 * site's Manifests.
 *
 * Shape written and read: an Annotation whose motivation is `contentState`;
 * its target is the Scene (`/iiif/{slug}/scene`, `partOf` the Manifest) as
 * a SpecificResource whose PointSelector places the camera, and its body the
 * PerspectiveCamera with `lookAt` — the same pair the Manifest paints its
 * home camera with (server/src/service/iiif/presentation.rs). A second
 * target naming one of the model's commenting annotations
 * (`/iiif/{slug}/annotations/{id}`) opens that note. Read also: a target
 * that is the Manifest or the Scene alone (the default view), and a Scene
 * target whose PointSelector has no camera body (the point looked at).
 * Coordinates are the Scene's: +Y up, metres (server/src/service/scene.rs).
 * No DOM (unit-tested in Node).
 */

/** @typedef {[number, number, number]} Vec3 */

/** The Presentation 4 JSON-LD context. */
export const PRESENTATION_CONTEXT = 'http://iiif.io/api/presentation/4/context.json';

/** Longest `iiif-content` read: a view's Content State is well under 2 KiB. */
export const MAX_CONTENT_STATE = 8192;

/**
 * What a Content State asks for, in Scene coordinates.
 * @typedef {object} SceneState
 * @property {string} slug the model
 * @property {Vec3 | null} position camera position
 * @property {Vec3 | null} lookAt point looked at
 * @property {string | null} note id of the commenting annotation to open
 */

/**
 * Why a Content State was not followed: the catalogue key of its message
 * (`contentState.{reason}`) and what to name in it.
 */
export class ContentStateError extends Error {
  /**
   * @param {'encoding' | 'json' | 'shape' | 'foreign' | 'otherModel' | 'unknown'} reason
   * @param {string} [detail]
   */
  constructor(reason, detail = '') {
    super(`${reason}${detail ? `: ${detail}` : ''}`);
    this.reason = reason;
    this.detail = detail;
  }
}

/** @param {string} text @returns {string} */
export function encodeContentState(text) {
  const bytes = new TextEncoder().encode(text);
  let binary = '';
  for (const b of bytes) binary += String.fromCharCode(b);
  return btoa(binary).replace(/\+/g, '-').replace(/\//g, '_').replace(/=+$/, '');
}

/**
 * @param {string} value base64url, padding optional
 * @returns {string} the UTF-8 text
 */
export function decodeContentState(value) {
  if (!/^[A-Za-z0-9_-]+={0,2}$/.test(value)) throw new ContentStateError('encoding');
  const bare = value.replace(/=+$/, '');
  if (bare.length % 4 === 1) throw new ContentStateError('encoding');
  let binary;
  try {
    binary = atob(bare.replace(/-/g, '+').replace(/_/g, '/') + '='.repeat((4 - (bare.length % 4)) % 4));
  } catch {
    throw new ContentStateError('encoding');
  }
  const bytes = Uint8Array.from(binary, (c) => c.charCodeAt(0));
  try {
    return new TextDecoder('utf-8', { fatal: true }).decode(bytes);
  } catch {
    throw new ContentStateError('json');
  }
}

/**
 * The site a Content State must name: the origin and path prefix the
 * viewer's own manifest is served under.
 * @typedef {{ origin: string, prefix: string }} Site
 */

/**
 * @param {string} manifestUrl the viewer's `/api/models/{slug}` (absolute)
 * @returns {Site & { slug: string | null }}
 */
export function siteOf(manifestUrl) {
  const url = new URL(manifestUrl);
  const match = url.pathname.match(/^(.*)\/api\/models\/([a-z0-9-]+)\/?$/);
  return { origin: url.origin, prefix: match ? match[1] : '', slug: match ? match[2] : null };
}

/**
 * The slug of a IIIF URI of this site (`/iiif/{slug}/manifest`, `/scene`,
 * `/annotations/{id}`), and what it names; a URI of another host is refused.
 * @param {unknown} uri
 * @param {Site} site
 * @returns {{ slug: string, what: string, note: string | null }}
 */
function siteResource(uri, site) {
  if (typeof uri !== 'string') throw new ContentStateError('shape');
  let url;
  try {
    url = new URL(uri);
  } catch {
    throw new ContentStateError('shape');
  }
  if (url.origin !== site.origin) throw new ContentStateError('foreign', url.host);
  const path = url.pathname.startsWith(`${site.prefix}/`) ? url.pathname.slice(site.prefix.length) : null;
  const match = path?.match(/^\/iiif\/([a-z0-9-]+)\/(manifest|scene|annotations\/([0-9]+))$/);
  if (!match) throw new ContentStateError('shape');
  return { slug: match[1], what: match[2].startsWith('annotations') ? 'note' : match[2], note: match[3] ?? null };
}

/** @param {any} selector @returns {Vec3 | null} */
function point(selector) {
  const s = Array.isArray(selector) ? selector.find((x) => x?.type === 'PointSelector') : selector;
  if (!s || s.type !== 'PointSelector') return null;
  const p = [s.x, s.y, s.z];
  return p.every((v) => typeof v === 'number' && Number.isFinite(v)) ? /** @type {Vec3} */ (p) : null;
}

/**
 * What a Content State asks this viewer for.
 * @param {string} value the `iiif-content` parameter
 * @param {Site} site
 * @returns {SceneState}
 */
export function readContentState(value, site) {
  const trimmed = value.trim();
  if (trimmed.length > MAX_CONTENT_STATE) throw new ContentStateError('encoding');
  if (/^https?:\/\//i.test(trimmed)) {
    const r = siteResource(trimmed, site);
    if (r.what !== 'manifest' && r.what !== 'scene') throw new ContentStateError('shape');
    return { slug: r.slug, position: null, lookAt: null, note: null };
  }
  let json;
  try {
    json = JSON.parse(decodeContentState(trimmed));
  } catch (error) {
    if (error instanceof ContentStateError) throw error;
    throw new ContentStateError('json');
  }
  if (!json || typeof json !== 'object') throw new ContentStateError('shape');
  const motivation = [json.motivation].flat();
  const targets = json.type === 'Annotation' && motivation.includes('contentState') ? [json.target].flat() : [json];
  /** @type {SceneState | null} */
  let state = null;
  /** @type {string | null} */
  let note = null;
  for (const target of targets) {
    const resource = typeof target === 'string' ? { id: target } : target?.type === 'SpecificResource' ? target.source : target;
    const id = typeof resource === 'string' ? resource : resource?.id;
    const named = siteResource(id, site);
    if (named.what === 'note') {
      if (state && named.slug !== state.slug) throw new ContentStateError('shape');
      note = named.note;
      continue;
    }
    // A Scene's Manifest, where it names one, must be the same model's.
    for (const whole of [resource?.partOf ?? []].flat()) {
      if (whole?.id !== undefined && siteResource(whole.id, site).slug !== named.slug) throw new ContentStateError('shape');
    }
    const at = target?.type === 'SpecificResource' && named.what === 'scene' ? point(target.selector) : null;
    const body = json.body?.type === 'PerspectiveCamera' ? json.body : null;
    state = body
      ? { slug: named.slug, position: at, lookAt: point(body.lookAt), note: null }
      : { slug: named.slug, position: null, lookAt: at, note: null };
  }
  if (!state) throw new ContentStateError('shape');
  return { ...state, note };
}

/**
 * The Content State of a view: the camera at `position` looking at `lookAt`
 * (Scene coordinates) in the model's Scene, and the note open.
 * @param {{ manifest: string, scene: string, note: string | null, position: Vec3, lookAt: Vec3, fieldOfView: number }} view
 * @returns {object}
 */
export function contentStateOf(view) {
  const round = (/** @type {Vec3} */ p) => p.map((x) => Number(x.toPrecision(9)));
  const [x, y, z] = round(view.position);
  const [lx, ly, lz] = round(view.lookAt);
  /** @type {any[]} */
  const target = [
    {
      type: 'SpecificResource',
      source: { id: view.scene, type: 'Scene', partOf: [{ id: view.manifest, type: 'Manifest' }] },
      selector: [{ type: 'PointSelector', x, y, z }],
    },
  ];
  if (view.note !== null) target.push({ id: view.note, type: 'Annotation' });
  return {
    '@context': PRESENTATION_CONTEXT,
    type: 'Annotation',
    motivation: ['contentState'],
    body: { type: 'PerspectiveCamera', fieldOfView: view.fieldOfView, lookAt: { type: 'PointSelector', x: lx, y: ly, z: lz } },
    target: target.length === 1 ? target[0] : target,
  };
}
