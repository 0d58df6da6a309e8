// @ts-check
/**
 * "Share this view": the toolbar's share button opens a pane with two links
 * to the view on screen — the model page with the view in its fragment
 * (view-state.js) and the same page with a IIIF Content State
 * (content-state.js) that any IIIF-aware viewer can read — copies the first
 * and announces it. On load, a view given to the viewer (`#…` of the page,
 * the element's `view` attribute, a tour step) or a Content State
 * (`?iiif-content=`, the element's `iiif-content`) is applied once the first
 * level is on screen and the notes are in.
 */

import { ContentStateError, contentStateOf, encodeContentState, readContentState, siteOf } from './content-state.js';
import { localise, t } from './i18n/index.js';
import { modelPageUrl } from './rights.js';
import { STUDIO } from './light.js';
import { formatView, isEmptyView } from './view-state.js';

/** @typedef {[number, number, number]} Vec3 */
/** @typedef {import('./view-state.js').ViewState} ViewState */

/** Metres per unit of the manifest's `unit` (server: ingest::curation::metres_per_unit). */
const METRES = /** @type {Record<string, number>} */ ({ mm: 0.001, cm: 0.01, m: 1, in: 0.0254 });

/** @param {string | null | undefined} unit */
export function metresPerUnit(unit) {
  return METRES[unit ?? ''] ?? 1;
}

/**
 * The orbit that puts the eye at `eye` looking at `target` (world frame).
 * @param {Vec3} eye
 * @param {Vec3} target
 * @returns {import('./camera.js').OrbitState | null} null: the two points coincide
 */
export function orbitFrom(eye, target) {
  const back = [0, 1, 2].map((k) => eye[k] - target[k]);
  const distance = Math.hypot(...back);
  if (!(distance > 0)) return null;
  const pitch = Math.asin(Math.max(-1, Math.min(1, back[1] / distance)));
  const yaw = Math.atan2(back[0], back[2]);
  return { target: [...target], distance, yaw, pitch };
}

/**
 * A point of the Scene (+Y up, metres) in the viewer's world frame (upright, model units): the
 * Scene's rotation is the viewer's upright rotation, so only the unit differs.
 * @param {Vec3} p
 * @param {string | null | undefined} unit
 * @returns {Vec3}
 */
export function sceneToWorld(p, unit) {
  const s = metresPerUnit(unit);
  return [p[0] / s, p[1] / s, p[2] / s];
}

/** @param {Vec3} p @param {string | null | undefined} unit @returns {Vec3} */
export function worldToScene(p, unit) {
  const s = metresPerUnit(unit);
  return [p[0] * s, p[1] * s, p[2] * s];
}

export class ShareView {
  /** The view to apply once the model is on screen (null: none, or applied). @type {ViewState | null} */
  #pending = null;
  /** The Content State to apply (null: none). @type {string | null} */
  #contentState = null;
  /** Resolves once a pending view was applied (tests and tours wait on it). @type {Promise<void>} */
  applied = Promise.resolve();
  #resolveApplied = () => {};

  /** @param {import('./viewer.js').Viewer} viewer */
  constructor(viewer) {
    this.viewer = viewer;
    const ui = viewer.ui;
    this.pane = document.createElement('section');
    this.pane.className = 'share pill';
    this.pane.dataset.i18nLabel = 'share.pane';
    this.pane.hidden = true;
    this.pane.innerHTML = `<h2 data-i18n="share.heading"></h2>
<label class="share-link"><span data-i18n="share.link"></span><input type="text" readonly class="view-link"></label>
<div class="row"><button type="button" class="copy-view" data-i18n="share.copyView"></button></div>
<label class="share-link"><span data-i18n="share.contentState"></span><input type="text" readonly class="state-link"></label>
<div class="row"><button type="button" class="copy-state" data-i18n="share.copyState"></button></div>`;
    localise(this.pane);
    ui.panes.append(this.pane);
    this.viewLink = /** @type {HTMLInputElement} */ (this.pane.querySelector('.view-link'));
    this.stateLink = /** @type {HTMLInputElement} */ (this.pane.querySelector('.state-link'));
    this.button = ui.button('share');
    this.button.onclick = () => this.toggle(this.pane.hidden === true);
    /** @type {HTMLButtonElement} */ (this.pane.querySelector('.copy-view')).onclick = () => void this.#copy(this.viewLink.value);
    /** @type {HTMLButtonElement} */ (this.pane.querySelector('.copy-state')).onclick = () => void this.#copy(this.stateLink.value);
  }

  /**
   * Opens the pane with fresh links and copies the view's link.
   * @param {boolean} open
   */
  toggle(open) {
    this.pane.hidden = !open;
    this.button.setAttribute('aria-pressed', String(open));
    if (!open) return;
    this.refresh();
    void this.#copy(this.viewLink.value);
  }

  /** Writes the two links for the view on screen. */
  refresh() {
    this.viewLink.value = this.viewUrl() ?? '';
    this.stateLink.value = this.contentStateUrl() ?? '';
  }

  /** @param {string} text */
  async #copy(text) {
    if (!text) return;
    try {
      await navigator.clipboard.writeText(text);
      this.viewer.ui.live.textContent = t('share.copied');
    } catch {
      // No clipboard (an insecure page, a refused permission): the link stays selected to copy by hand.
      this.viewLink.select();
      this.viewer.ui.live.textContent = t('share.copyByHand');
    }
  }

  /** The view on screen. @returns {ViewState} */
  current() {
    const { camera, look, annotations, inspection } = this.viewer;
    /** @type {ViewState} */
    const view = {};
    if (camera) view.camera = structuredClone(camera.state);
    if (look.light.key.some((x, k) => x !== STUDIO.key[k]) || look.light.fill !== STUDIO.fill) view.light = structuredClone(look.light);
    const section = inspection.currentSection();
    if (section) view.section = section;
    if (annotations.selected && !annotations.pane.hidden) view.note = String(annotations.selected.id);
    if (inspection.measuring && inspection.points.length === 2) view.measure = [inspection.points[0], inspection.points[1]];
    return view;
  }

  /** The model page with this view in its fragment (and `?level=` where one is held). */
  viewUrl() {
    const page = this.#page();
    if (!page) return null;
    page.hash = formatView(this.current());
    return page.href;
  }

  /**
   * The model page with a Content State of this view: camera and note in
   * the Content State (what any IIIF viewer can read), what IIIF has no
   * words for (light, section, measurement) in the fragment as in a view link.
   */
  contentStateUrl() {
    const page = this.#page();
    const state = this.contentState();
    if (!page || !state) return null;
    page.searchParams.set('iiif-content', encodeContentState(JSON.stringify(state)));
    const { camera: _camera, note: _note, ...rest } = this.current();
    page.hash = formatView(rest);
    return page.href;
  }

  /** The model page, with the viewer's language and held level. */
  #page() {
    const href = modelPageUrl(this.viewer.options.manifestUrl);
    if (!href) return null;
    const page = new URL(href);
    page.searchParams.set('lang', document.documentElement.lang || 'en');
    if (this.viewer.options.level !== null) page.searchParams.set('level', String(this.viewer.options.level));
    return page;
  }

  /** The Content State (JSON) of the camera and note on screen; null before the model is. */
  contentState() {
    const { camera, manifest, annotations } = this.viewer;
    if (!camera || !manifest) return null;
    const iiif = this.viewer.options.manifestUrl.replace(/\/api\/models\/([a-z0-9-]+)\/?$/, '/iiif/$1');
    const { eye } = camera.basis();
    const selected = annotations.selected && !annotations.pane.hidden ? annotations.selected : null;
    return contentStateOf({
      manifest: `${iiif}/manifest`,
      scene: `${iiif}/scene`,
      note: selected ? `${iiif}/annotations/${selected.id}` : null,
      position: worldToScene(eye, manifest.unit),
      lookAt: worldToScene(camera.state.target, manifest.unit),
      fieldOfView: (camera.fovY * 180) / Math.PI,
    });
  }

  /**
   * A view and a Content State to apply when the model is on screen.
   * @param {ViewState} view
   * @param {string | null} contentState
   */
  expect(view, contentState) {
    this.#pending = isEmptyView(view) ? null : view;
    this.#contentState = contentState;
    if (this.#pending || contentState !== null) this.applied = new Promise((resolve) => (this.#resolveApplied = resolve));
  }

  /** A level is on screen: the first time, the pending view is applied (after the notes are in). */
  async levelShown() {
    const view = this.#pending;
    const contentState = this.#contentState;
    if (!view && contentState === null) return;
    this.#pending = null;
    this.#contentState = null;
    await Promise.all([this.viewer.annotations.loaded, this.viewer.whenCamera()]);
    if (contentState !== null) this.#applyContentState(contentState);
    // Beside a Content State, the fragment adds to it: its camera and note stay.
    if (view) this.apply(view, { camera: contentState === null, note: contentState === null });
    this.#resolveApplied();
  }

  /**
   * Puts a view on screen now: note, camera, light, section, measurement.
   * @param {ViewState} view
   * @param {{ camera?: boolean, note?: boolean }} [options] `camera: false` leaves the camera to the
   *   caller (a tour eases it); `note: false` leaves the notes as they are
   */
  apply(view, { camera: moveCamera = true, note: setNote = true } = {}) {
    const { annotations, inspection } = this.viewer;
    const note = view.note === undefined ? null : annotations.list.find((a) => String(a.id) === view.note);
    if (note) annotations.select(note, { camera: false });
    else if (setNote) annotations.toggle(false);
    if (moveCamera && view.camera) this.setCamera(view.camera);
    inspection.setLight(view.light ?? STUDIO);
    inspection.restoreSection(view.section ?? null);
    inspection.restoreMeasurement(view.measure ?? null);
  }

  /** @param {import('./camera.js').OrbitState} state */
  setCamera(state) {
    const camera = this.viewer.camera;
    if (!camera) return;
    camera.state = structuredClone(state);
    this.viewer.renderer?.requestFrame();
    this.viewer.cameraMoved();
  }

  /** @param {string} value */
  #applyContentState(value) {
    const { manifest, camera, annotations } = this.viewer;
    if (!manifest || !camera) return;
    const site = siteOf(this.viewer.options.manifestUrl);
    try {
      const state = readContentState(value, site);
      if (site.slug !== null && state.slug !== site.slug) throw new ContentStateError('otherModel', state.slug);
      if (state.note !== null) {
        const note = annotations.list.find((a) => String(a.id) === state.note);
        if (note) annotations.select(note, { camera: false });
      }
      const lookAt = state.lookAt ? sceneToWorld(state.lookAt, manifest.unit) : camera.state.target;
      if (state.position) {
        const orbit = orbitFrom(sceneToWorld(state.position, manifest.unit), lookAt);
        if (orbit) this.setCamera(orbit);
      } else if (state.lookAt) {
        this.setCamera({ ...camera.state, target: lookAt });
      }
    } catch (error) {
      this.viewer.ui.showNotice(() => contentStateMessage(error));
    }
  }
}

/**
 * The visitor's words for why a Content State was not followed.
 * @param {unknown} error
 */
export function contentStateMessage(error) {
  if (error instanceof ContentStateError) return t(`contentState.${error.reason}`, { name: error.detail });
  return t('contentState.shape', { name: '' });
}

export const SHARE_STYLE = `
.share-link { display: flex; flex-direction: column; gap: 2px; margin-top: 6px; }
.share-link input { font: inherit; color: inherit; background: rgba(20, 22, 26, 0.72); border: 1px solid #4c566a;
  border-radius: 4px; padding: 4px 6px; min-width: 0; }
.share-link input:focus-visible { outline: 2px solid #88c0d0; }
`;
