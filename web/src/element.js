// @ts-check
/**
 * `<vitrine-viewer src="https://museum.example/m/bust">`: the viewer as a
 * custom element, for museum sites that prefer it to an iframe.
 *
 * Attributes: `src` (a model page `/m/{slug}`, an embed page `/embed/{slug}`
 * or a manifest `/api/models/{slug}`, on the Vitrine server), `chrome`
 * (`full` or `minimal`), `device` (`phone`, `tablet`, `desktop`: overrides
 * the server's guess), `level` (stop at this level; for comparisons),
 * `offscreen="off"` (draw on the main thread even where a worker could:
 * comparisons and tests of the fallback), `hold` (show and decode up to this
 * level until `element.viewer.prefetch()` / `display()` say otherwise: the
 * quality study), `background` (`#rrggbb`: the canvas's colour; the study's
 * black), `decoders` (workers that decode a charted stream together, 1–4;
 * default: the device's cores, at most 4), `antialias` (`on` or `off`;
 * default: on a GPU, off on a CPU rasteriser: rasteriser.js), `motion` (what is
 * drawn while the view moves: `auto`, a coarser level where the level on
 * screen is slow to draw; `full`; `coarse`: motion.js). `chrome="none"` draws the model and nothing else. The
 * worker and the decoder are loaded from beside this script, so the element
 * works on another origin (the service answers CORS). `view` opens at a
 * shared view (the fragment of a share link: view-state.js) and
 * `iiif-content` at a IIIF Content State (content-state.js); `tour` and
 * `step` open a guided tour at a step (from 1; tour.js). `refine="view"` refines a
 * charted or nested stream chart by chart where the camera looks, within `vertex-budget`
 * vertices (default by device; README, "View-dependent refinement");
 * `refine="uniform"` batch by batch. Without the attribute a nested stream
 * (format 6, made for scans larger than a device) refines by view and any
 * other stream batch by batch.
 */

import { t } from './i18n/index.js';
import { startLanguage } from './i18n/switch.js';
import { motionMode } from './motion.js';
import { ViewerUi } from './ui.js';
import { Viewer } from './viewer.js';
import { parseView } from './view-state.js';

/**
 * @param {string} src
 * @param {string} base
 * @returns {string} absolute manifest URL
 */
export function manifestUrl(src, base) {
  const url = new URL(src, base);
  const page = url.pathname.match(/^(.*)\/(?:m|embed)\/([a-z0-9-]+)\/?$/);
  if (page) url.pathname = `${page[1]}/api/models/${page[2]}`;
  url.search = '';
  url.hash = '';
  return url.href;
}

/**
 * `#rrggbb` as 0–1 components (as shading.js gives BACKGROUND), or undefined.
 * @param {string | null} value
 * @returns {[number, number, number] | undefined}
 */
export function parseColour(value) {
  const match = value?.match(/^#([0-9a-f]{2})([0-9a-f]{2})([0-9a-f]{2})$/i);
  if (!match) return undefined;
  const [r, g, b] = [1, 2, 3].map((i) => parseInt(match[i], 16) / 255);
  return [r, g, b];
}

export class VitrineViewerElement extends HTMLElement {
  /** @type {Viewer | null} */
  viewer = null;

  connectedCallback() {
    if (this.viewer) return;
    const shadow = this.shadowRoot ?? this.attachShadow({ mode: 'open' });
    const ui = new ViewerUi(this, shadow);
    const src = this.getAttribute('src');
    if (!src) {
      ui.showError(() => t('element.noSrc'));
      return;
    }
    const query = new URLSearchParams();
    for (const key of ['device', 'token']) {
      const value = this.getAttribute(key);
      if (value) query.set(key, value);
    }
    const level = this.getAttribute('level');
    const hold = this.getAttribute('hold');
    this.viewer = new Viewer(ui, {
      manifestUrl: manifestUrl(src, document.baseURI),
      query,
      level: level === null || level === '' ? null : Number(level),
      workerUrl: new URL('./worker.js', import.meta.url).href,
      wasmUrl: new URL('./vitrine_wasm.wasm', import.meta.url).href,
      renderWorkerUrl: new URL('./render-worker.js', import.meta.url).href,
      offscreen: this.getAttribute('offscreen') !== 'off',
      hold: hold === null || hold === '' ? null : Number(hold),
      background: parseColour(this.getAttribute('background')),
      decoders: positiveInteger(this.getAttribute('decoders')),
      antialias: onOff(this.getAttribute('antialias')),
      motion: motionMode(this.getAttribute('motion')),
      view: parseView(this.getAttribute('view')),
      contentState: this.getAttribute('iiif-content'),
      tour: tourLink(this.getAttribute('tour'), this.getAttribute('step')),
      refine: refineMode(this.getAttribute('refine')),
      vertexBudget: positiveInteger(this.getAttribute('vertex-budget')),
    });
    void this.viewer.start();
  }

  disconnectedCallback() {
    this.viewer?.ui.dispose();
    this.viewer?.stopTurntable();
    this.viewer?.stop();
    this.viewer = null;
  }
}

// The page's language, before the first viewer writes its chrome (pages of
// this server and other sites alike).
startLanguage();

if (!customElements.get('vitrine-viewer')) customElements.define('vitrine-viewer', VitrineViewerElement);

/**
 * `refine`: `view` or `uniform`; null (the stream's own default) otherwise.
 * @param {string | null} value
 * @returns {'view' | 'uniform' | null}
 */
function refineMode(value) {
  return value === 'view' || value === 'uniform' ? value : null;
}

/** @param {string | null} value @returns {boolean | null} `on`: true, `off`: false, else null */
function onOff(value) {
  return value === 'on' ? true : value === 'off' ? false : null;
}

/**
 * @param {string | null} tour
 * @param {string | null} step
 * @returns {{ tour: number, step: number } | null}
 */
function tourLink(tour, step) {
  const id = positiveInteger(tour);
  return id === null ? null : { tour: id, step: positiveInteger(step) ?? 1 };
}

/** @param {string | null} value @returns {number | null} */
function positiveInteger(value) {
  const n = Number(value);
  return value !== null && Number.isInteger(n) && n >= 1 ? n : null;
}
