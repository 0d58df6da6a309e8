// @ts-check
/**
 * The viewer's chrome inside a shadow root (so a museum site's CSS cannot
 * reach it): canvas sized to device pixels, progress line, cap notice, error
 * overlay with retry, title panel (with the quality chart when the model's
 * curve was measured), the reset / wireframe / relief / fullscreen buttons,
 * the relief view's legend, and the credit line (who made the scan, its licence).
 */

import { describeLevel, describeStudyLevel, renderQualityChart } from './quality-chart.js';
import { NOTES_STYLE } from './annotations.js';
import { TOOLS_STYLE } from './tools-ui.js';
import { SHARE_STYLE } from './share.js';
import { TOUR_STYLE } from './tour.js';
import { SCALE_PERCENTILE, formatDegrees, rampGradient, reliefTicks } from './relief.js';
import { chooseText, markLanguage } from './content-language.js';
import { creditLine } from './rights.js';
import { formatBytes, language, localise, onLanguageChange, t } from './i18n/index.js';
import { languageSwitch } from './i18n/switch.js';

/** Device pixels per CSS pixel, capped: beyond 2 a tablet pays 2.25× the fill for little gain. */
const MAX_PIXEL_RATIO = 2;

export const STYLE = `
:host { display: block; position: relative; min-height: 240px; background: #212329; color: #eceff4;
  font: 14px/1.4 system-ui, -apple-system, "Segoe UI", sans-serif; overflow: hidden; }
.stage { position: absolute; inset: 0; }
canvas { display: block; width: 100%; height: 100%; outline: none; cursor: grab; }
canvas:active { cursor: grabbing; }
/* The focus ring sits inside the canvas's edge, in the 10 px the chrome leaves free (2.4.11). */
canvas:focus-visible { box-shadow: inset 0 0 0 3px #88c0d0; }
.crosshair { display: none; position: absolute; left: 50%; top: 50%; width: 24px; height: 24px; margin: -12px 0 0 -12px;
  pointer-events: none; }
.stage.measuring .crosshair { display: block; }
.crosshair::before, .crosshair::after { content: ""; position: absolute; background: #ebcb8b; box-shadow: 0 0 0 1px #1d2026; }
.crosshair::before { left: 11px; top: 0; width: 2px; height: 24px; }
.crosshair::after { top: 11px; left: 0; height: 2px; width: 24px; }
/* Turn and zoom without a drag (2.5.7): a pad of 28 px buttons (2.5.8 asks 24) over the view's
   start edge, out of the chrome's flow (whose height is spoken for on small screens); the
   tool panes open on the other side. Its arrows point the same way in either direction of text.
   Views under 480 px tall have no room for it beside the panel and the status (turning there
   needs the keys or a drag; the README says so). */
.nav { position: absolute; left: 10px; top: 55%; transform: translateY(-50%); display: grid;
  grid-template-columns: repeat(3, 28px); grid-auto-rows: 28px; gap: 4px; direction: ltr; }
.stage:dir(rtl) .nav { left: auto; right: 10px; }
.nav button { min-height: 0; padding: 0; line-height: 1; }
@media (max-height: 480px) { .nav { display: none; } }
@media (prefers-reduced-motion: reduce) { * { transition: none !important; animation: none !important; } }
.pill { background: rgba(20, 22, 26, 0.72); border-radius: 6px; padding: 6px 10px; }
.chrome { position: absolute; inset: 10px 10px 12px; display: flex; flex-direction: column; gap: 8px;
  pointer-events: none; min-height: 0; }
.chrome > * { pointer-events: auto; }
/* The title panel and the toolbar share the top: side by side where they fit, else the
   toolbar above and the panel under it (wrap-reverse stacks the second line on top). */
.top { display: flex; flex-wrap: wrap-reverse; align-items: flex-end; align-content: flex-end; gap: 8px;
  pointer-events: none; flex: none; }
.top > * { pointer-events: auto; }
.panel { flex: 0 1 26rem; min-width: 0; max-width: 100%; max-height: 40vh; overflow: auto; }
.panel h1 { font-size: 16px; margin: 0; font-weight: 600; overflow-wrap: anywhere; }
.panel p { margin: 4px 0 0; color: #cfd5de; }
.panel:empty, [hidden] { display: none !important; }
.tools { display: flex; flex-wrap: wrap; justify-content: flex-end; gap: 6px; margin-left: auto; max-width: 100%; }
button { font: inherit; color: inherit; background: rgba(20, 22, 26, 0.72); border: 1px solid #4c566a;
  border-radius: 6px; min-height: 36px; padding: 4px 12px; cursor: pointer; }
button:hover { background: rgba(59, 66, 82, 0.9); }
button:focus-visible { outline: 2px solid #88c0d0; outline-offset: 1px; }
select.language { font: inherit; color: inherit; background: rgba(20, 22, 26, 0.72); border: 1px solid #4c566a;
  border-radius: 6px; min-height: 36px; min-width: 36px; padding: 4px 6px; cursor: pointer; }
select.language:focus-visible { outline: 2px solid #88c0d0; outline-offset: 1px; }
select.language option { background: #212329; color: #eceff4; }
button[aria-pressed="true"] { background: #4a6b96; border-color: #81a1c1; }
.panes { display: flex; flex-wrap: wrap; justify-content: flex-end; align-items: flex-start; gap: 8px;
  min-height: 0; flex: 0 1 auto; overflow: auto; pointer-events: none; }
.panes:not(:has(> :not([hidden]))) { display: none; }
.panes > * { pointer-events: auto; width: min(20rem, 100%); max-height: 100%; overflow: auto; }
.spacer { flex: 1 1 0; min-height: 0; pointer-events: none; }
.live { position: absolute; width: 1px; height: 1px; overflow: hidden; clip-path: inset(50%); white-space: nowrap; }
.markers { position: absolute; inset: 0; overflow: hidden; pointer-events: none; }
/* The status pills and the credit line share the bottom: side by side where the credit has
   14rem beside them, else the credit under them. */
.foot { display: flex; flex-wrap: wrap; align-items: flex-end; gap: 6px 8px; pointer-events: none; flex: none; }
.status { display: flex; flex-direction: column; align-items: flex-start; gap: 6px; pointer-events: none; flex: 0 1 auto;
  min-width: 0; max-width: 100%; }
.status > * { max-width: 100%; }
.credit { flex: 1 1 14rem; min-width: 0; max-width: 100%; display: flex; justify-content: flex-end; pointer-events: none; }
/* Attribution: small, but 4.5:1 or better (the link 5.6:1) on its backing even over white. */
.credit-line { display: inline-block; min-width: 0; max-width: 36rem;
  padding: 2px 8px; border-radius: 4px; background: rgba(20, 22, 26, 0.85); color: #d8dee9; font-size: 12px;
  line-height: 1.4; pointer-events: auto; }
/* One line of running text where it fits ("Scan: … · CC BY 4.0"); a long credit wraps, and
   the licence (with its separator) moves whole to the next line. */
.credit-text { overflow-wrap: anywhere; }
.credit-licence, .credit-download { white-space: nowrap; }
.credit a { color: #8fbcbb; text-underline-offset: 2px; }
.credit a:focus-visible { outline: 2px solid #88c0d0; outline-offset: 1px; }
/* Small views: a long credit keeps to two lines (all of it on hover, in its title, and while
   the licence link has focus; a screen reader reads it all); the licence stays whole. */
@media (max-width: 480px), (max-height: 480px) {
  .credit:not(:focus-within) .credit-text { display: -webkit-box; -webkit-box-orient: vertical; -webkit-line-clamp: 2;
    line-clamp: 2; overflow: hidden; }
  .credit:not(:focus-within) .credit-text + * > .credit-separator { display: none; }
}
.notice { background: rgba(94, 72, 20, 0.88); border: 1px solid #ebcb8b; }
.colour { font-size: 12px; color: #cfd5de; }
.colour::before { content: ""; display: inline-block; width: 8px; height: 8px; border-radius: 50%;
  margin-right: 6px; background: #4c566a; }
.colour[data-colour="low"]::before { background: #ebcb8b; }
.colour[data-colour="full"]::before { background: #a3be8c; }
.colour[data-error]::before { background: #bf616a; }
.bar { position: absolute; left: 0; bottom: 0; height: 3px; background: #88c0d0; transition: width 0.3s; }
.error { position: absolute; inset: 0; display: grid; place-items: center; background: rgba(20, 22, 26, 0.6); }
.error div { background: #3b2226; border: 1px solid #bf616a; border-radius: 8px; padding: 16px 20px;
  max-width: min(32rem, 85%); }
.error p { margin: 0 0 12px; }
.quality { margin: 6px 0 0; }
.quality summary { cursor: pointer; font-size: 12px; color: #cfd5de; }
.quality svg { display: block; width: 100%; max-width: 260px; height: auto; margin-top: 4px; }
.quality p { font-size: 12px; }
@media (max-width: 480px), (max-height: 360px) { .quality { display: none; } }
/* Phones: narrower buttons; the panel goes under the toolbar (.top wraps). */
@media (max-width: 480px) {
  button { padding: 4px 8px; }
  .tools { gap: 4px; }
  .panel { flex-basis: 100%; max-height: 30vh; }
}
.legend { width: min(280px, 100%); font-size: 12px; }
.legend-title { color: #cfd5de; }
.legend-ramp { height: 10px; margin: 5px 7px 2px; border-radius: 2px; background: ${rampGradient()}; }
.legend-ticks { position: relative; height: 1.4em; margin: 0 7px; font-variant-numeric: tabular-nums; }
.legend-ticks span { position: absolute; top: 0; transform: translateX(-50%); white-space: nowrap; }
.legend-ticks span:first-child { transform: translateX(-7px); }
.legend-ticks span:last-child { transform: translateX(calc(-100% + 7px)); }
:host([chrome="minimal"]) .panel p { display: none; }
:host([chrome="minimal"]) .quality { display: none; }
:host([chrome="minimal"]) button.optional { display: none; }
:host([chrome="none"]) :is(.chrome, .bar, .markers, .nav) { display: none !important; }
`;

export class ViewerUi {
  onReset = () => {};
  onWireframe = () => {};
  onRelief = () => {};
  onSplats = () => {};
  onRetry = () => {};
  onResize = () => {};
  /** An on-screen button turned or zoomed the view by one step. @type {(step: import('./controls.js').Nudge) => void} */
  onNudge = () => {};
  /** The quality curve the chart shows. @type {ReadonlyArray<import('./quality-chart.js').QualityPoint> | null} */
  #curve = null;
  /** Level the chart's marker was drawn at (`null`: redraw). @type {number | null} */
  #chartLevel = null;
  #shownLevel = -1;
  /** The quality study's answers per level, when the model has one. @type {ReadonlyArray<import('./quality-chart.js').StudyLevel> | null} */
  #study = null;

  /**
   * @param {HTMLElement} host
   * @param {ShadowRoot} shadow
   */
  constructor(host, shadow) {
    this.root = host;
    shadow.innerHTML = `<style>${STYLE}${TOOLS_STYLE}${NOTES_STYLE}${SHARE_STYLE}${TOUR_STYLE}</style>
<div class="stage" part="stage">
  <canvas></canvas>
  <div class="markers"></div>
  <div class="crosshair" aria-hidden="true"></div>
  <div class="chrome">
  <div class="top">
  <div class="panel pill" part="panel"></div>
  <div class="tools" role="toolbar" data-i18n-label="tools.label">
    <button data-action="reset" data-i18n="tools.reset" data-i18n-title="tools.reset.title"></button>
    <button data-action="wireframe" data-i18n="tools.wireframe" data-i18n-title="tools.wireframe.title" aria-pressed="false" class="optional"></button>
    <button data-action="relief" data-i18n="tools.relief" data-i18n-title="tools.relief.title" aria-pressed="false" class="optional"></button>
    <button data-action="splats" data-i18n="tools.splats" data-i18n-title="tools.splats.title" aria-pressed="false" class="optional"></button>
    <button data-action="tour" data-i18n="tools.tour" data-i18n-title="tools.tour.title" aria-pressed="false" hidden></button>
    <button data-action="notes" data-i18n="tools.notes" data-i18n-title="tools.notes.title" aria-pressed="false" hidden></button>
    <button data-action="measure" data-i18n="tools.measure" data-i18n-title="tools.measure.title" aria-pressed="false" class="optional"></button>
    <button data-action="light" data-i18n="tools.light" data-i18n-title="tools.light.title" aria-pressed="false" class="optional"></button>
    <button data-action="section" data-i18n="tools.section" data-i18n-title="tools.section.title" aria-pressed="false" class="optional"></button>
    <button data-action="clay" data-i18n="tools.clay" data-i18n-title="tools.clay.title" aria-pressed="false" class="optional"></button>
    <button data-action="snapshot" data-i18n="tools.snapshot" data-i18n-title="tools.snapshot.title" class="optional"></button>
    <button data-action="share" data-i18n="tools.share" data-i18n-title="tools.share.title" aria-pressed="false"></button>
    <button data-action="fullscreen" data-i18n="tools.fullscreen" data-i18n-title="tools.fullscreen.title"></button>
  </div>
  </div>
  <div class="panes"></div>
  <div class="spacer"></div>
  <div class="foot">
  <div class="status">
    <div class="legend pill" role="group" data-i18n-label="legend.label" hidden>
      <div class="legend-title"></div>
      <div class="legend-ramp" aria-hidden="true"></div>
      <div class="legend-ticks"></div>
    </div>
    <div class="notice pill" role="status" hidden></div>
    <div class="colour pill" hidden></div>
    <div class="progress pill" data-i18n="progress.loading"></div>
  </div>
  <div class="credit" part="credit" role="group" data-i18n-label="credit.label" hidden></div>
  </div>
  </div>
  <div class="nav" role="group" data-i18n-label="nav.label">
    <button type="button" data-nudge="in" data-i18n-label="nav.in" data-i18n-title="nav.in">+</button>
    <button type="button" data-nudge="up" data-i18n-label="nav.up" data-i18n-title="nav.up">▲</button>
    <button type="button" data-nudge="out" data-i18n-label="nav.out" data-i18n-title="nav.out">−</button>
    <button type="button" data-nudge="left" data-i18n-label="nav.left" data-i18n-title="nav.left">◀</button>
    <button type="button" data-nudge="down" data-i18n-label="nav.down" data-i18n-title="nav.down">▼</button>
    <button type="button" data-nudge="right" data-i18n-label="nav.right" data-i18n-title="nav.right">▶</button>
  </div>
  <div class="live" aria-live="polite"></div>
  <div class="live loading-live" role="status"></div>
  <div class="live view-description" id="view-description" aria-hidden="true"></div>
  <div class="bar" style="width: 0"></div>
  <div class="error" role="alert" hidden><div><p></p><button data-action="retry" data-i18n="error.retry"></button></div></div>
</div>`;
    const $ = (/** @type {string} */ selector) => /** @type {HTMLElement} */ (shadow.querySelector(selector));
    this.canvas = /** @type {HTMLCanvasElement} */ ($('canvas'));
    this.stage = $('.stage');
    this.panel = $('.panel');
    this.progress = $('.progress');
    this.notice = $('.notice');
    this.colour = $('.colour');
    this.bar = $('.bar');
    this.error = $('.error');
    this.wireButton = $('[data-action="wireframe"]');
    this.reliefButton = $('[data-action="relief"]');
    this.splatsButton = $('[data-action="splats"]');
    this.legend = $('.legend');
    /** The credit line: who made the scan, the licence (manifest `rights`). */
    this.credit = $('.credit');
    /** Tool panes (annotations list, measurement, light, section), under the toolbar. */
    this.panes = $('.panes');
    /** Annotation markers over the canvas. */
    this.markers = $('.markers');
    /** Announcements for screen readers (the annotation selected). */
    this.live = $('.live');
    this.shadow = shadow;
    this.quality = document.createElement('details');
    this.quality.className = 'quality';
    this.quality.open = true;
    this.quality.hidden = true;
    this.quality.innerHTML = '<summary data-i18n="quality.summary"></summary><div class="chart"></div><p></p>';
    $('[data-action="reset"]').onclick = () => this.onReset();
    this.wireButton.onclick = () => this.onWireframe();
    this.reliefButton.onclick = () => this.onRelief();
    this.splatsButton.onclick = () => this.onSplats();
    $('[data-action="fullscreen"]').onclick = () => this.toggleFullscreen();
    $('[data-action="retry"]').onclick = () => this.onRetry();
    for (const b of shadow.querySelectorAll('[data-nudge]')) {
      const button = /** @type {HTMLButtonElement} */ (b);
      button.onclick = () => this.onNudge(/** @type {import('./controls.js').Nudge} */ (button.dataset.nudge));
    }
    /** The language switch, last in the toolbar. */
    this.languages = languageSwitch();
    $('.tools').append(this.languages);
    this.#localise();
    this.#stopListening = onLanguageChange(() => this.#localise());
    this.#watchSize();
  }

  #stopListening = () => {};

  /** Writes every text of the chrome in the page's language (again, after a switch). */
  #localise() {
    localise(this.shadow);
    localise(this.quality);
    /** @type {HTMLSelectElement} */ (this.languages).value = language();
    this.#texts = new WeakMap();
    this.#chartLevel = null;
    this.#legendKey = '';
    this.#colourKey = '';
    if (this.#state) this.setProgress(this.#state);
    if (this.#content) this.setDetails(this.#content);
    if (this.#rights) this.setRights(...this.#rights);
    this.showNotice(this.#notice);
    this.showError(this.#error);
  }

  /** Stops following the page's language (the element left the page). */
  dispose() {
    this.#stopListening();
  }

  /** What the chrome last showed, to write it again in another language. @type {import('./viewer.js').ViewerState | null} */
  #state = null;
  /** @type {[Partial<import('./rights.js').Rights> | null | undefined, { href: string, bytes: number } | null] | null} */
  #rights = null;
  /** The model's own words (title, description, credit) in every language given. @type {import('./content-language.js').ContentSource | null} */
  #content = null;
  /** @type {ChromeText} */
  #notice = null;
  /** @type {ChromeText} */
  #error = null;

  /**
   * A toolbar button by its action.
   * @param {string} action
   */
  button(action) {
    return /** @type {HTMLButtonElement} */ (this.shadow.querySelector(`.tools [data-action="${action}"]`));
  }

  /** Keeps the drawing buffer at the canvas's size in device pixels. */
  #watchSize() {
    const apply = (/** @type {number} */ width, /** @type {number} */ height) => {
      const w = Math.max(1, Math.round(width));
      const h = Math.max(1, Math.round(height));
      if (this.canvas.width !== w || this.canvas.height !== h) {
        this.canvas.width = w;
        this.canvas.height = h;
        this.onResize();
      }
    };
    const observer = new ResizeObserver(([entry]) => {
      const ratio = Math.min(devicePixelRatio, MAX_PIXEL_RATIO);
      const width = entry.contentRect.width * ratio;
      const height = entry.contentRect.height * ratio;
      // The device-pixel box is exact at fractional ratios; emulated ratios
      // (DevTools) do not reach it, so it is used only when it agrees.
      const exact = entry.devicePixelContentBoxSize?.[0];
      const agrees = exact && Math.abs(exact.inlineSize - width) <= 1 && Math.abs(exact.blockSize - height) <= 1;
      if (exact && agrees) apply(exact.inlineSize, exact.blockSize);
      else apply(width, height);
    });
    try {
      observer.observe(this.canvas, { box: 'device-pixel-content-box' });
    } catch {
      observer.observe(this.canvas);
    }
  }

  /**
   * The model's title and description, each in the visitor's language where
   * the museum wrote it (content-language.js), marked with its language.
   * @param {import('./content-language.js').ContentSource} content the manifest
   */
  setDetails(content) {
    this.#content = content;
    const title = chooseText(content, 'title');
    const description = chooseText(content, 'description');
    // Written in place: the quality chart after them keeps its focus through a change of language.
    const h = this.panel.querySelector(':scope > h1') ?? document.createElement('h1');
    const p = this.panel.querySelector(':scope > p.description') ?? document.createElement('p');
    if (!(p instanceof HTMLElement)) return;
    p.className = 'description';
    h.textContent = title.text;
    markLanguage(h, title.lang);
    p.textContent = description.text;
    markLanguage(p, description.lang);
    p.hidden = !description.text;
    if (!h.isConnected) this.panel.prepend(h, p);
    if (!this.quality.isConnected) this.panel.append(this.quality);
  }

  /**
   * The credit line: the credit as typed, the licence's name linked to its
   * deed, and the GLB download where the policy offers one; hidden when
   * there is none of them. Curators type the credit and the licence comes
   * from the server, so they go in as text nodes, never markup.
   * @param {Partial<import('./rights.js').Rights> | null | undefined} rights
   * @param {{ href: string, bytes: number } | null} [download] the level this visitor may take
   */
  setRights(rights, download = null) {
    this.#rights = [rights, download];
    // The credit in the visitor's language where the museum gave one (setDetails' manifest); a
    // version without a credit of its own shows none in any language, as the server's page head.
    const credit = this.#content && rights?.credit ? chooseText(this.#content, 'credit') : { text: rights?.credit ?? '', lang: null };
    const line = creditLine(rights ? { ...rights, credit: credit.text } : rights);
    this.credit.replaceChildren();
    this.credit.hidden = line === null && !download;
    if (this.credit.hidden) return;
    const box = document.createElement('span');
    box.className = 'credit-line';
    /** A part after the first, led by a separator in a span of its own: where the credit is
     * clamped to lines of its own (small views), the next part starts a line, and no
     * separator leads it. @param {string} className */
    const part = (className) => {
      const span = document.createElement('span');
      span.className = className;
      if (box.childElementCount > 0) {
        const separator = document.createElement('span');
        separator.className = 'credit-separator';
        separator.textContent = ' · ';
        span.append(separator);
      }
      box.append(span);
      return span;
    };
    if (line?.credit) {
      const text = part('credit-text');
      text.textContent = line.credit;
      text.title = line.credit;
      markLanguage(text, credit.lang);
    }
    if (line?.licence) {
      const licence = part('credit-licence');
      if (line.licence.href) {
        const link = document.createElement('a');
        link.href = line.licence.href;
        link.rel = 'license noopener';
        link.target = '_blank';
        link.textContent = line.licence.name;
        licence.append(link);
      } else {
        licence.append(line.licence.name);
      }
    }
    if (download) {
      const link = document.createElement('a');
      link.href = download.href;
      link.download = '';
      link.textContent = t('credit.download', { size: formatBytes(download.bytes) });
      link.title = t('credit.download.title');
      part('credit-download').append(link);
    }
    this.credit.append(box);
  }

  /**
   * The model's quality curve (manifest `quality`), or `null` to hide the chart.
   * @param {ReadonlyArray<import('./quality-chart.js').QualityPoint> | null} curve
   */
  setQuality(curve) {
    this.#curve = curve && curve.length > 0 ? curve : null;
    this.#chartLevel = null;
    this.#drawQuality(this.#shownLevel);
  }

  /**
   * The quality study's share of "sufficient" per level (null: no study).
   * @param {ReadonlyArray<import('./quality-chart.js').StudyLevel> | null} levels
   */
  setStudy(levels) {
    this.#study = levels && levels.length > 0 ? levels : null;
    this.#chartLevel = null;
    this.#drawQuality(this.#shownLevel);
  }

  /** @param {number} level on screen; the chart is redrawn only when it changes */
  #drawQuality(level) {
    this.#shownLevel = level;
    if (this.#chartLevel === level) return;
    this.#chartLevel = level;
    const svg = this.#curve ? renderQualityChart(this.#curve, level, { study: this.#study }) : '';
    this.quality.hidden = svg === '';
    /** @type {HTMLElement} */ (this.quality.querySelector('.chart')).innerHTML = svg;
    const line = this.#curve ? describeLevel(this.#curve, level) : '';
    const study = line ? describeStudyLevel(this.#study, level) : '';
    /** @type {HTMLElement} */ (this.quality.querySelector('p')).textContent = study ? `${line} · ${study}` : line;
  }

  /**
   * Runs on the main thread for every notice while a model loads, so it
   * stays small: the DOM is touched only where a text or width changed (no
   * style, layout or paint for an unchanged line), and nothing here reads
   * layout.
   * @param {import('./viewer.js').ViewerState} state
   */
  setProgress(state) {
    this.#setColour(state);
    this.#setLegend(state);
    this.#drawQuality(state.shownLevel);
    this.#state = state;
    if (state.shownLevel < 0) {
      this.#write(this.progress, t('progress.received', { size: formatBytes(state.received) }));
      return;
    }
    this.#write(
      this.progress,
      t('progress.level', {
        level: state.shownLevel,
        last: state.lastLevel,
        count: state.vertices,
        size: formatBytes(state.received),
      }),
    );
    const width = `${(100 * state.shownLevel) / Math.max(1, state.lastLevel)}%`;
    if (this.#barWidth !== width) this.bar.style.width = this.#barWidth = width;
  }

  #barWidth = '0';
  /** Text last written per element. @type {WeakMap<HTMLElement, string>} */
  #texts = new WeakMap();

  /** @param {HTMLElement} element @param {string} text */
  #write(element, text) {
    if (this.#texts.get(element) === text) return;
    this.#texts.set(element, text);
    element.textContent = text;
  }

  /**
   * The colour texture's state: loading, low resolution (the full one on its
   * way), full resolution, or why there is none.
   * @param {import('./viewer.js').ViewerState} state
   */
  #setColour(state) {
    const texts = { loading: 'colour.loading', low: 'colour.low', full: 'colour.full' };
    const key = texts[/** @type {keyof typeof texts} */ (state.colour)];
    const text = state.colourError ? t('colour.error', { reason: state.colourError }) : key ? t(key) : null;
    const shown = `${state.colour}\n${state.colourError !== null}\n${text}`;
    if (shown === this.#colourKey) return;
    this.#colourKey = shown;
    this.colour.hidden = text === null;
    this.#write(this.colour, text ?? '');
    this.colour.dataset.colour = state.colour;
    if (state.colourError) this.colour.dataset.error = '';
    else delete this.colour.dataset.error;
  }

  #colourKey = '';

  /**
   * The relief view's legend: the ramp with its ticks in degrees, for the
   * scale of the level on screen; hidden while the view is off.
   * @param {import('./viewer.js').ViewerState} state
   */
  #setLegend(state) {
    const key = state.relief ? String(state.reliefTop) : 'off';
    if (key === this.#legendKey) return;
    this.#legendKey = key;
    this.legend.hidden = !state.relief;
    if (!state.relief) return;
    const top = state.reliefTop;
    const title = /** @type {HTMLElement} */ (this.legend.querySelector('.legend-title'));
    const ramp = /** @type {HTMLElement} */ (this.legend.querySelector('.legend-ramp'));
    const ticks = /** @type {HTMLElement} */ (this.legend.querySelector('.legend-ticks'));
    ramp.hidden = top === null;
    ticks.replaceChildren();
    if (top === null) {
      this.legend.setAttribute('aria-label', t('legend.label'));
      title.textContent = t('legend.computing');
      return;
    }
    const percentile = Math.round(100 * SCALE_PERCENTILE);
    title.textContent = t('legend.title', { percentile });
    this.legend.setAttribute('aria-label', t('legend.description', { top: formatDegrees(top), percentile }));
    for (const value of reliefTicks(top)) {
      const span = document.createElement('span');
      span.textContent = value === top ? `≥ ${formatDegrees(value)}` : formatDegrees(value);
      span.style.left = `${(100 * value) / top}%`;
      ticks.append(span);
    }
  }

  #legendKey = '';

  /**
   * A notice over the view; a function is asked again after a change of language.
   * @param {ChromeText} text
   */
  showNotice(text) {
    this.#notice = text;
    const shown = typeof text === 'function' ? text() : text;
    this.notice.hidden = shown === null;
    this.notice.textContent = shown ?? '';
  }

  /**
   * Why the model cannot be shown (null: it can); a function is asked again after a change of language.
   * @param {ChromeText} reason
   */
  showError(reason) {
    this.#error = reason;
    const shown = typeof reason === 'function' ? reason() : reason;
    this.error.hidden = shown === null;
    /** @type {HTMLElement} */ (this.error.querySelector('p')).textContent = shown ? t('error.prefix', { reason: shown }) : '';
  }

  /** @param {boolean} on */
  setWireframe(on) {
    this.wireButton.setAttribute('aria-pressed', String(on));
  }

  /** @param {boolean} on */
  setRelief(on) {
    this.reliefButton.setAttribute('aria-pressed', String(on));
  }

  /** @param {boolean} on */
  setSplats(on) {
    this.splatsButton.setAttribute('aria-pressed', String(on));
  }

  toggleFullscreen() {
    if (document.fullscreenElement) void document.exitFullscreen();
    else void this.root.requestFullscreen?.().catch(() => {});
  }
}

/** Text of the chrome that may be written again in another language: a string, or a function that writes it. @typedef {string | (() => string) | null} ChromeText */

export { formatBytes, formatCount } from './i18n/index.js';
