// @ts-check
/**
 * The markup of the tool panes under the toolbar (measurement, light,
 * section) and their styles; inspection.js gives them their behaviour.
 */

import { localise } from './i18n/index.js';

/**
 * @param {string} className
 * @param {string} label the catalogue key of its name
 * @param {string} html its markup, texts as `data-i18n*` keys (i18n/index.js)
 */
function pane(className, label, html) {
  const section = document.createElement('section');
  section.className = `${className} pill`;
  section.dataset.i18nLabel = label;
  section.hidden = true;
  section.innerHTML = html;
  localise(section);
  return section;
}

/** @param {HTMLElement} root @param {string} selector */
function $(root, selector) {
  return /** @type {HTMLElement} */ (root.querySelector(selector));
}

export function measurePane() {
  const p = pane(
    'measure',
    'measure.pane',
    `<h2 data-i18n="measure.heading"></h2><p class="measure-status" role="status"></p><p class="measure-reading" aria-live="polite"></p>
<p class="measure-surface"></p><div class="row"><button type="button" class="refine" hidden></button>
<button type="button" class="clear" data-i18n="measure.clear"></button></div>`,
  );
  return {
    pane: p,
    status: $(p, '.measure-status'),
    reading: $(p, '.measure-reading'),
    surface: $(p, '.measure-surface'),
    refine: /** @type {HTMLButtonElement} */ ($(p, '.refine')),
    clear: /** @type {HTMLButtonElement} */ ($(p, '.clear')),
  };
}

export function lightPane() {
  const p = pane(
    'light',
    'light.pane',
    `<h2 data-i18n="light.heading"></h2><div class="disc" tabindex="0" role="slider" data-i18n-label="light.disc"
  data-i18n-valuetext="light.direction"><span class="handle"></span></div>
<div class="row"><button type="button" data-raking="left" data-i18n="light.left"></button><button type="button" data-raking="right" data-i18n="light.right"></button>
<button type="button" data-raking="top" data-i18n="light.top"></button><button type="button" data-raking="bottom" data-i18n="light.bottom"></button>
<button type="button" class="studio" data-i18n="light.studio"></button></div>`,
  );
  /** @type {Record<string, HTMLButtonElement>} */
  const raking = {};
  for (const b of p.querySelectorAll('[data-raking]')) raking[/** @type {string} */ (/** @type {HTMLElement} */ (b).dataset.raking)] = /** @type {HTMLButtonElement} */ (b);
  return { pane: p, disc: $(p, '.disc'), handle: $(p, '.handle'), studio: /** @type {HTMLButtonElement} */ ($(p, '.studio')), raking };
}

export function sectionPane() {
  const p = pane(
    'section',
    'section.pane',
    `<h2 data-i18n="section.heading"></h2><div class="row" role="group" data-i18n-label="section.axis">
<button type="button" data-axis="x" aria-pressed="true">X</button><button type="button" data-axis="y" aria-pressed="false">Y</button>
<button type="button" data-axis="z" aria-pressed="false">Z</button>
<button type="button" class="flip" aria-pressed="false" data-i18n="section.flip"></button></div>
<label class="offset"><span data-i18n="section.position"></span> <input type="range" min="0" max="1000" value="500"></label>`,
  );
  return {
    pane: p,
    axis: /** @type {HTMLButtonElement[]} */ ([...p.querySelectorAll('[data-axis]')]),
    flip: /** @type {HTMLButtonElement} */ ($(p, '.flip')),
    offset: /** @type {HTMLInputElement} */ ($(p, 'input')),
  };
}

export const TOOLS_STYLE = `
.panes h2 { font-size: 14px; margin: 0 0 4px; }
.panes p { margin: 4px 0; }
.panes .row { display: flex; flex-wrap: wrap; gap: 4px; margin-top: 4px; }
.panes .row button { min-height: 32px; padding: 2px 8px; }
.measure-reading { font-weight: 600; font-variant-numeric: tabular-nums; }
.disc { position: relative; width: 96px; height: 96px; border-radius: 50%; margin: 4px auto;
  background: radial-gradient(circle at 50% 50%, #4c566a, #1d2026); border: 1px solid #81a1c1; touch-action: none; cursor: pointer; }
.disc:focus-visible { outline: 2px solid #88c0d0; }
.handle { position: absolute; left: 28%; top: 20%; width: 14px; height: 14px; margin: -7px 0 0 -7px; border-radius: 50%;
  background: #ebcb8b; pointer-events: none; }
.offset { display: flex; align-items: center; gap: 8px; margin-top: 6px; }
.offset input { flex: 1; min-width: 0; }
.pick-dot { position: absolute; left: 0; top: 0; width: 10px; height: 10px; border-radius: 50%; background: #bf616a;
  border: 2px solid #fff; }
`;
