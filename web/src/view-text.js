// @ts-check
/**
 * Text for the 3D view, for visitors who do not see it (WCAG 1.1.1, 4.1.2,
 * 4.1.3): the canvas's accessible name ("3D view of Torus") and its
 * description — the model's description, the level on screen, where the
 * camera stands ("seen from the left, from above, 2× zoom") and how to
 * operate it — and a polite announcement once per level reached while the
 * model loads (the progress pill changes with every batch of bytes, too
 * often to be read out). In the quality study (a held level) neither says
 * which level is shown: the participants judge it unknowing.
 */

import { chooseText } from './content-language.js';
import { formatNumber, language, onLanguageChange, t } from './i18n/index.js';

/** The eight sides the camera can stand on, from the front (+Z) turning towards +X. */
const SIDES = ['front', 'frontRight', 'right', 'backRight', 'back', 'backLeft', 'left', 'frontLeft'];
/** Above or below the model beyond this pitch (radians, about 20°). */
const ELEVATION = 0.35;
/** The description is written again this long after the camera stops. */
const SETTLE_MS = 150;

/**
 * The side of the model the camera looks from.
 * @param {number} yaw radians about +Y, 0 in front (+Z), growing towards +X
 */
export function viewSide(yaw) {
  const turn = (((yaw / (2 * Math.PI)) % 1) + 1) % 1;
  return SIDES[Math.round(turn * SIDES.length) % SIDES.length];
}

/**
 * Where the camera stands, in words: side, elevation and zoom against the home view.
 * @param {import('./camera.js').OrbitState} state
 * @param {import('./camera.js').OrbitState} home
 */
export function describeCamera(state, home) {
  const parts = [t(`view.from.${viewSide(state.yaw)}`)];
  if (state.pitch > ELEVATION) parts.push(t('view.above'));
  else if (state.pitch < -ELEVATION) parts.push(t('view.below'));
  const zoom = home.distance / Math.max(1e-9, state.distance);
  parts.push(t('view.zoom', { zoom: formatNumber(zoom, { maximumFractionDigits: 1 }) }));
  return new Intl.ListFormat(language(), { type: 'unit', style: 'short' }).format(parts);
}

export class ViewText {
  /** The last level announced (-1: none yet). */
  #announced = -1;
  /** @type {ReturnType<typeof setTimeout> | null} */
  #settle = null;
  /** The quality study holds the level (`hold`): its participants must not be told which one they see. */
  get #blind() {
    return this.viewer.options.hold !== null && this.viewer.options.hold !== undefined;
  }

  /** @param {import('./viewer.js').Viewer} viewer */
  constructor(viewer) {
    this.viewer = viewer;
    const { canvas, shadow } = viewer.ui;
    /** The description the canvas points to (visually hidden, read on focus). */
    this.description = /** @type {HTMLElement} */ (shadow.querySelector('.view-description'));
    /** Loading, announced politely once per level. */
    this.announcer = /** @type {HTMLElement} */ (shadow.querySelector('.loading-live'));
    canvas.setAttribute('role', 'application');
    canvas.setAttribute('aria-describedby', this.description.id);
    onLanguageChange(() => this.update());
    this.update();
  }

  /** The model, the level or the camera changed: the name and description follow (once the camera settles). */
  changed() {
    if (this.#settle) clearTimeout(this.#settle);
    this.#settle = setTimeout(() => this.update(), SETTLE_MS);
  }

  /** Writes the name and description now. */
  update() {
    if (this.#settle) clearTimeout(this.#settle);
    this.#settle = null;
    const { manifest, camera, state, ui } = this.viewer;
    // The model's own words in the visitor's language where the museum wrote them (content-language.js).
    const title = manifest ? chooseText(manifest, 'title').text : '';
    const described = manifest ? chooseText(manifest, 'description').text : '';
    ui.canvas.setAttribute('aria-label', title ? t('view.name', { title }) : t('view.unnamed'));
    const parts = [];
    if (described) parts.push(described);
    if (state.shownLevel >= 0 && !this.#blind) parts.push(t('view.level', { level: state.shownLevel, last: state.lastLevel }));
    if (camera) parts.push(describeCamera(camera.state, camera.home));
    parts.push(t('view.canvas'));
    const text = parts.join(' · ');
    if (this.description.textContent !== text) this.description.textContent = text;
  }

  /**
   * A level reached the screen: said once, politely ("Level 2 of 4 shown";
   * the last: "All detail shown").
   * @param {number} level
   * @param {number} last
   */
  levelShown(level, last) {
    this.changed();
    if (level <= this.#announced || this.#blind) return;
    this.#announced = level;
    this.announcer.textContent = level >= last ? t('view.complete', { last }) : t('view.levelShown', { level, last });
  }

  /** A new model (or a retry): its levels are announced again. */
  restart() {
    this.#announced = -1;
    this.announcer.textContent = '';
    this.update();
  }
}
