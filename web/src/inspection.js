// @ts-check
/**
 * The researcher's tools beside the camera: measurement (two picks on the
 * level on screen, the straight distance with the level's error, the
 * distance along the surface from the codec's geodesic library, and an
 * offer to refine when a finer level exists), the light (a disc to drag and
 * raking presets), clay, the section plane (axis, offset, side) and a PNG
 * snapshot. The panes' markup is tools-ui.js; the pure parts are pick.js,
 * measure.js, light.js and frame.js.
 */

import { onLanguageChange, t } from './i18n/index.js';
import { STUDIO, discLight, discPosition, rakingLight } from './light.js';
import { diagonal, formatReading, levelHausdorff, measurement } from './measure.js';
import { pixelSize, projectPoint, viewRay } from './pick.js';
import { addTextChunks } from './png-text.js';
import { modelPageUrl, snapshotText } from './rights.js';
import { lightPane, measurePane, sectionPane } from './tools-ui.js';

/** @typedef {[number, number, number]} Vec3 */

/** A press that moves less than this (CSS px) is a click, not a turn. */
const CLICK_PX = 4;
/** Picks snap to the nearest vertex within about this many CSS px. */
const SNAP_PX = 8;

/**
 * @typedef {object} Reading
 * @property {number} value straight distance, model units
 * @property {number | null} error ± model units
 * @property {number} level the level the picks were made on
 * @property {string} text as shown
 * @property {number | null} surface distance along the surface (null: not yet, or failed)
 * @property {Vec3[]} points
 */

export class Inspection {
  measuring = false;
  /** @type {Vec3[]} */
  points = [];
  /** @type {Reading | null} */
  reading = null;
  /** Milliseconds the last pick took in the renderer. @type {number | null} */
  pickMs = null;
  /** @type {HTMLElement[]} */
  #dots = [];
  /** @type {{ x: number, y: number } | null} */
  #press = null;

  /** @param {import('./viewer.js').Viewer} viewer */
  constructor(viewer) {
    this.viewer = viewer;
    const ui = viewer.ui;
    this.measure = measurePane();
    this.light = lightPane();
    this.section = sectionPane();
    ui.panes.append(this.measure.pane, this.light.pane, this.section.pane);
    ui.button('measure').onclick = () => this.setMeasuring(!this.measuring);
    ui.button('light').onclick = () => this.#toggle('light', this.light.pane);
    ui.button('section').onclick = () => this.setSection(!this.viewer.look.section);
    ui.button('clay').onclick = () => this.setClay(!this.viewer.look.clay);
    ui.button('snapshot').onclick = () => void this.saveSnapshot();
    this.measure.clear.onclick = () => this.clear();
    this.measure.refine.onclick = () => this.viewer.refine();
    // The panes' fixed texts follow with the chrome (ui.js); the readings are written here.
    onLanguageChange(() => this.#show());
    this.light.studio.onclick = () => this.setLight(STUDIO);
    for (const [from, button] of Object.entries(this.light.raking)) {
      button.onclick = () => this.setLight(rakingLight(/** @type {'left' | 'right' | 'top' | 'bottom'} */ (from)));
    }
    this.#watchDisc();
    this.section.axis.forEach((b) => (b.onclick = () => this.#updateSection({ axis: /** @type {any} */ (b.dataset.axis) })));
    this.section.offset.oninput = () => this.#updateSection({});
    this.section.flip.onclick = () => this.#updateSection({ flip: this.section.flip.getAttribute('aria-pressed') !== 'true' });
    const canvas = ui.canvas;
    canvas.addEventListener('pointerdown', (e) => (this.#press = e.isPrimary && e.button === 0 ? { x: e.clientX, y: e.clientY } : null));
    canvas.addEventListener('pointerup', (e) => {
      const press = this.#press;
      this.#press = null;
      if (!this.measuring || !press || Math.hypot(e.clientX - press.x, e.clientY - press.y) > CLICK_PX) return;
      const box = canvas.getBoundingClientRect();
      void this.pickAt(e.clientX - box.left, e.clientY - box.top);
    });
  }

  /**
   * Enter or Space on the view while measuring: picks the point under the
   * crosshair at the view's centre (turn or pan the model to bring a point
   * there), so a measurement needs no pointer.
   * @returns {boolean} whether a pick was taken
   */
  pickCentre() {
    if (!this.measuring) return false;
    const canvas = this.viewer.ui.canvas;
    void this.pickAt(canvas.clientWidth / 2, canvas.clientHeight / 2);
    return true;
  }

  /** The manifest is in: the readouts use its unit. */
  begin() {
    this.clear();
  }

  /** @param {string} action @param {HTMLElement} pane */
  #toggle(action, pane) {
    const open = pane.hidden === true;
    pane.hidden = !open;
    this.viewer.ui.button(action).setAttribute('aria-pressed', String(open));
  }

  /** @param {boolean} on */
  setMeasuring(on) {
    this.measuring = on;
    this.measure.pane.hidden = !on;
    this.viewer.ui.button('measure').setAttribute('aria-pressed', String(on));
    this.viewer.ui.canvas.style.cursor = on ? 'crosshair' : '';
    this.viewer.ui.stage.classList.toggle('measuring', on);
    if (!on) this.clear();
  }

  clear() {
    this.points = [];
    this.reading = null;
    this.#show();
  }

  /**
   * Picks the surface under a point of the view (CSS px from its top left)
   * and adds it to the measurement.
   * @param {number} x
   * @param {number} y
   * @returns {Promise<Vec3 | null>}
   */
  async pickAt(x, y) {
    const { camera, renderer } = this.viewer;
    if (!camera || !renderer) return null;
    const canvas = this.viewer.ui.canvas;
    const width = canvas.clientWidth;
    const height = canvas.clientHeight;
    const model = this.viewer.look.model;
    const ray = viewRay(camera, model, x, y, width, height);
    // Snap radius: SNAP_PX at the hit's depth (see pickLevel).
    const { hit, vertex, level, ms } = await renderer.pick(ray, SNAP_PX * pixelSize(camera, 1, height));
    this.pickMs = ms;
    if (!hit || level === null) {
      this.measure.status.textContent = t('measure.noSurface');
      return null;
    }
    const point = vertex ?? hit.point;
    if (this.points.length >= 2) this.points = [];
    this.points.push(point);
    if (this.points.length === 2) void this.#read(level);
    else this.reading = null;
    this.#show();
    return point;
  }

  /** @param {number} level the level both picks were made on */
  async #read(level) {
    const manifest = this.viewer.manifest;
    const camera = this.viewer.camera;
    if (!manifest || !camera) return;
    const [a, b] = this.points;
    const bounds = this.viewer.look.bounds ?? camera.box;
    const { value, error } = measurement(a, b, { hausdorff: levelHausdorff(manifest, level), diagonal: diagonal(bounds) });
    /** @type {Reading} */
    const reading = { value, error, level, text: formatReading(value, error, manifest.unit), surface: null, points: [a, b] };
    this.reading = reading;
    this.#show();
    try {
      const { distance } = await this.viewer.surfaceDistance(a, b);
      if (this.reading !== reading) return;
      reading.surface = distance;
    } catch (error) {
      if (this.reading === reading) {
        this.measure.surface.textContent = t('measure.surfaceFailed', { reason: error instanceof Error ? error.message : String(error) });
      }
      return;
    }
    this.#show();
  }

  /** Writes the measurement pane and places the picks' dots. */
  #show() {
    const m = this.measure;
    const reading = this.reading;
    const manifest = this.viewer.manifest;
    m.status.textContent =
      this.points.length === 0 ? t('measure.first') : this.points.length === 1 ? t('measure.second') : '';
    if (reading) reading.text = formatReading(reading.value, reading.error, manifest?.unit);
    m.reading.textContent = reading ? reading.text : '';
    m.surface.textContent =
      reading && reading.surface !== null && Number.isFinite(reading.surface)
        ? t('measure.surface', { reading: formatReading(reading.surface, reading.error, manifest?.unit) })
        : reading?.surface === Infinity
          ? t('measure.separate')
          : '';
    const state = this.viewer.state;
    const finer = reading !== null && reading.level < state.lastLevel;
    m.refine.hidden = !finer;
    m.refine.disabled = (reading !== null && state.targetLevel > reading.level) || state.status === 'capped';
    m.refine.textContent = finer && state.status === 'capped' ? t('measure.capped') : t('measure.refine');
    this.place();
  }

  /** A new level is on screen: the picks stay, the offer to refine follows. */
  levelShown() {
    if (this.reading) this.#show();
  }

  /** Puts the picks' dots where they are on screen. */
  place() {
    const { camera } = this.viewer;
    const canvas = this.viewer.ui.canvas;
    while (this.#dots.length < this.points.length) {
      const dot = document.createElement('div');
      dot.className = 'pick-dot';
      this.viewer.ui.markers.append(dot);
      this.#dots.push(dot);
    }
    this.#dots.forEach((dot, k) => {
      const point = this.points[k];
      dot.hidden = !point || !camera;
      if (!point || !camera) return;
      const p = projectPoint(camera, this.viewer.look.model, point, canvas.clientWidth, canvas.clientHeight);
      dot.style.transform = `translate(${p.x}px, ${p.y}px) translate(-50%, -50%)`;
    });
  }

  /** @param {import('./light.js').Light} light */
  setLight(light) {
    this.viewer.setLook({ light });
    const [u, v] = discPosition(light);
    this.light.handle.style.left = `${50 + 50 * u}%`;
    this.light.handle.style.top = `${50 - 50 * v}%`;
  }

  /** Dragging on the disc moves the key light (and keyboard arrows on it). */
  #watchDisc() {
    const disc = this.light.disc;
    const move = (/** @type {PointerEvent} */ e) => {
      const r = disc.getBoundingClientRect();
      const u = (2 * (e.clientX - r.left)) / r.width - 1;
      const v = 1 - (2 * (e.clientY - r.top)) / r.height;
      this.setLight(discLight(u, v));
    };
    disc.addEventListener('pointerdown', (e) => {
      try {
        disc.setPointerCapture(e.pointerId);
      } catch {}
      move(e);
    });
    disc.addEventListener('pointermove', (e) => {
      if (e.buttons) move(e);
    });
    disc.addEventListener('keydown', (e) => {
      const step = { ArrowLeft: [-0.1, 0], ArrowRight: [0.1, 0], ArrowUp: [0, 0.1], ArrowDown: [0, -0.1] }[e.key];
      if (!step) return;
      e.preventDefault();
      const [u, v] = discPosition(this.viewer.look.light);
      this.setLight(discLight(u + step[0], v + step[1]));
    });
  }

  /** @param {boolean} on */
  setClay(on) {
    this.viewer.setLook({ clay: on });
    this.viewer.ui.button('clay').setAttribute('aria-pressed', String(on));
  }

  /** @param {boolean} on */
  setSection(on) {
    this.section.pane.hidden = !on;
    this.viewer.ui.button('section').setAttribute('aria-pressed', String(on));
    if (on) this.#updateSection({});
    else this.viewer.setLook({ section: null });
  }

  /**
   * The section in force, as the pane sets it (view-state.js); undefined: none.
   * @returns {{ axis: 'x' | 'y' | 'z', fraction: number, flip: boolean } | undefined}
   */
  currentSection() {
    if (!this.viewer.look.section) return undefined;
    const s = this.section;
    const axis = /** @type {'x' | 'y' | 'z'} */ (s.axis.find((b) => b.getAttribute('aria-pressed') === 'true')?.dataset.axis ?? 'x');
    return { axis, fraction: Number(s.offset.value) / Number(s.offset.max), flip: s.flip.getAttribute('aria-pressed') === 'true' };
  }

  /**
   * Sets the pane and the plane from a shared view (null: no section).
   * @param {{ axis: 'x' | 'y' | 'z', fraction: number, flip: boolean } | null} section
   */
  restoreSection(section) {
    if (!section) {
      if (this.viewer.look.section) this.setSection(false);
      return;
    }
    this.section.offset.value = String(Math.round(section.fraction * Number(this.section.offset.max)));
    this.section.axis.forEach((b) => b.setAttribute('aria-pressed', String(b.dataset.axis === section.axis)));
    this.section.flip.setAttribute('aria-pressed', String(section.flip));
    this.setSection(true);
  }

  /**
   * Measures between two points of a shared view, on the level on screen (null: no measurement).
   * @param {[Vec3, Vec3] | null} points
   */
  restoreMeasurement(points) {
    if (!points) {
      if (this.measuring) this.setMeasuring(false);
      return;
    }
    this.setMeasuring(true);
    this.points = [points[0], points[1]];
    void this.#read(Math.max(0, this.viewer.state.shownLevel));
    this.#show();
  }

  /**
   * The plane from the pane: perpendicular to an upright axis, at a
   * fraction of the model's extent along it; the side beyond is cut away.
   * @param {{ axis?: 'x' | 'y' | 'z', flip?: boolean }} change
   */
  #updateSection(change) {
    const s = this.section;
    if (change.axis) s.axis.forEach((b) => b.setAttribute('aria-pressed', String(b.dataset.axis === change.axis)));
    if (change.flip !== undefined) s.flip.setAttribute('aria-pressed', String(change.flip));
    const axis = s.axis.find((b) => b.getAttribute('aria-pressed') === 'true')?.dataset.axis ?? 'x';
    const flip = s.flip.getAttribute('aria-pressed') === 'true';
    const box = this.viewer.camera?.box;
    if (!box) return;
    const k = axis === 'x' ? 0 : axis === 'y' ? 1 : 2;
    const t = Number(s.offset.value) / Number(s.offset.max);
    const at = box.min[k] + t * (box.max[k] - box.min[k]);
    /** @type {[number, number, number, number]} */
    const plane = [0, 0, 0, flip ? -at : at];
    plane[k] = flip ? -1 : 1;
    this.viewer.setLook({ section: plane });
  }

  /**
   * Saves the view as `{slug}.png` (the browser's PNG encoder, on the canvas
   * that draws it), with the title, the credit and licence, and the model's
   * page in text chunks, so the picture keeps its attribution.
   */
  async saveSnapshot() {
    const renderer = this.viewer.renderer;
    if (!renderer) return null;
    const blob = await this.#labelled(await renderer.snapshot());
    const link = document.createElement('a');
    link.href = URL.createObjectURL(blob);
    link.download = `${this.viewer.manifest?.slug ?? 'vitrine'}.png`;
    this.viewer.ui.shadow.append(link);
    link.click();
    link.remove();
    setTimeout(() => URL.revokeObjectURL(link.href), 10_000);
    return blob;
  }

  /** @param {Blob} blob the encoder's PNG */
  async #labelled(blob) {
    const manifest = this.viewer.manifest;
    if (!manifest) return blob;
    const entries = snapshotText(manifest, modelPageUrl(this.viewer.options.manifestUrl));
    try {
      const bytes = addTextChunks(new Uint8Array(await blob.arrayBuffer()), entries);
      return new Blob([/** @type {Uint8Array<ArrayBuffer>} */ (bytes)], { type: 'image/png' });
    } catch (error) {
      // An encoder's PNG this file cannot read: the picture without its text rather than none.
      console.warn('snapshot: text chunks not written', error);
      return blob;
    }
  }
}
