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
 * comparisons and tests of the fallback). The
 * worker and the decoder are loaded from beside this script, so the element
 * works on another origin (the service answers CORS).
 */

import { ViewerUi } from './ui.js';
import { Viewer } from './viewer.js';

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

export class VitrineViewerElement extends HTMLElement {
  /** @type {Viewer | null} */
  viewer = null;

  connectedCallback() {
    if (this.viewer) return;
    const shadow = this.shadowRoot ?? this.attachShadow({ mode: 'open' });
    const ui = new ViewerUi(this, shadow);
    const src = this.getAttribute('src');
    if (!src) {
      ui.showError('the element has no src attribute');
      return;
    }
    const query = new URLSearchParams();
    for (const key of ['device', 'token']) {
      const value = this.getAttribute(key);
      if (value) query.set(key, value);
    }
    const level = this.getAttribute('level');
    this.viewer = new Viewer(ui, {
      manifestUrl: manifestUrl(src, document.baseURI),
      query,
      level: level === null || level === '' ? null : Number(level),
      workerUrl: new URL('./worker.js', import.meta.url).href,
      wasmUrl: new URL('./vitrine_wasm.wasm', import.meta.url).href,
      renderWorkerUrl: new URL('./render-worker.js', import.meta.url).href,
      offscreen: this.getAttribute('offscreen') !== 'off',
    });
    void this.viewer.start();
  }

  disconnectedCallback() {
    this.viewer?.stop();
    this.viewer = null;
  }
}

if (!customElements.get('vitrine-viewer')) customElements.define('vitrine-viewer', VitrineViewerElement);
