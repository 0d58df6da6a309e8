// @ts-check
/**
 * Guided tours for visitors (`GET /api/models/{slug}/tours`: the tours of
 * the version on screen): a pane with the step's title and text in the
 * page's language, previous / play–pause / next buttons, and keys on the
 * pane (→ next, ← previous, P or Space play and pause, Home the first
 * step). Each step puts its saved view on screen (view-state.js): note,
 * light, section and measurement at once, the camera eased there (at once
 * under `prefers-reduced-motion`). Playing dwells on each step in
 * proportion to its text, then moves on; it stops after the last. A tour
 * link (`?tour=…&step=…`, the element's `tour` and `step`) opens at that step.
 */

import { language, localise, onLanguageChange, t } from './i18n/index.js';
import { parseView } from './view-state.js';

/**
 * @typedef {object} TourStep
 * @property {string} view the share-link fragment
 * @property {Record<string, string>} title
 * @property {Record<string, string>} text Markdown source
 * @property {Record<string, string>} html sanitised by the server
 *
 * @typedef {{ id: number, version: number, title: Record<string, string>, steps: TourStep[] }} Tour
 */

/** How long a camera move between steps takes. */
export const MOVE_MS = 1200;
/** Playing: the shortest stay on a step, and more per character of its text. */
export const DWELL_MS = 3500;
const DWELL_PER_CHAR_MS = 40;
const MAX_DWELL_MS = 15_000;

/**
 * The text of a language map in the page's language, else English, else the first.
 * @param {Record<string, string> | undefined} map
 * @param {string} lang
 */
export function inLanguage(map, lang) {
  if (!map) return '';
  const base = lang.split('-')[0];
  return map[lang] ?? map[base] ?? map.en ?? Object.values(map)[0] ?? '';
}

/**
 * Ease in and out (cubic): 0 → 0, 1 → 1, slow at both ends.
 * @param {number} x 0–1
 */
export function ease(x) {
  return x < 0.5 ? 4 * x * x * x : 1 - (-2 * x + 2) ** 3 / 2;
}

/**
 * The orbit part way from `a` to `b`: target straight, distance on a log
 * scale (zoom feels even), yaw the short way round.
 * @param {import('./camera.js').OrbitState} a
 * @param {import('./camera.js').OrbitState} b
 * @param {number} s 0–1, eased
 * @returns {import('./camera.js').OrbitState}
 */
export function between(a, b, s) {
  let dyaw = (b.yaw - a.yaw) % (2 * Math.PI);
  if (dyaw > Math.PI) dyaw -= 2 * Math.PI;
  if (dyaw < -Math.PI) dyaw += 2 * Math.PI;
  return {
    target: /** @type {import('./camera.js').Vec3} */ ([0, 1, 2].map((k) => a.target[k] + (b.target[k] - a.target[k]) * s)),
    distance: Math.exp(Math.log(a.distance) + (Math.log(b.distance) - Math.log(a.distance)) * s),
    yaw: s >= 1 ? b.yaw : a.yaw + dyaw * s,
    pitch: a.pitch + (b.pitch - a.pitch) * s,
  };
}

/**
 * @param {TourStep} step
 * @param {string} lang
 */
function dwell(step, lang) {
  return Math.min(MAX_DWELL_MS, DWELL_MS + DWELL_PER_CHAR_MS * inLanguage(step.text, lang).length);
}

export class TourPlayer {
  /** @type {Tour[]} */
  tours = [];
  /** @type {Tour | null} */
  tour = null;
  /** Step on screen, from 0 (-1: none yet). */
  index = -1;
  playing = false;
  /** Where the viewer should open (a tour link), until the first level is shown. @type {{ tour: number, step: number } | null} */
  #opening = null;
  /** @type {ReturnType<typeof setTimeout> | null} */
  #timer = null;
  /** @type {number | null} */
  #frame = null;
  /** Resolves when the tours are in (or known to be none). @type {Promise<void>} */
  loaded = Promise.resolve();

  /** @param {import('./viewer.js').Viewer} viewer */
  constructor(viewer) {
    this.viewer = viewer;
    const ui = viewer.ui;
    this.pane = document.createElement('section');
    this.pane.className = 'tour pill';
    this.pane.dataset.i18nLabel = 'tour.pane';
    this.pane.hidden = true;
    this.pane.tabIndex = -1;
    this.pane.innerHTML = `<h2 data-i18n="tour.pane"></h2>
<label class="tour-choice" hidden><span data-i18n="tour.choose"></span> <select></select></label>
<p class="tour-count" aria-live="polite"></p><h3 class="tour-title"></h3><div class="tour-body"></div>
<div class="row"><button type="button" class="previous" data-i18n="tour.previous"></button>
<button type="button" class="play" data-i18n="tour.play"></button>
<button type="button" class="next" data-i18n="tour.next"></button></div>
<p class="tour-keys" data-i18n="tour.keys"></p>`;
    localise(this.pane);
    ui.panes.append(this.pane);
    const $ = (/** @type {string} */ s) => /** @type {HTMLElement} */ (this.pane.querySelector(s));
    this.choice = /** @type {HTMLSelectElement} */ ($('select'));
    this.count = $('.tour-count');
    this.heading = $('.tour-title');
    this.body = $('.tour-body');
    this.playButton = /** @type {HTMLButtonElement} */ ($('.play'));
    this.previousButton = /** @type {HTMLButtonElement} */ ($('.previous'));
    this.nextButton = /** @type {HTMLButtonElement} */ ($('.next'));
    this.previousButton.onclick = () => this.go(this.index - 1);
    this.nextButton.onclick = () => this.go(this.index + 1);
    this.playButton.onclick = () => (this.playing ? this.pause() : this.play());
    this.choice.onchange = () => this.choose(Number(this.choice.value), 0);
    this.pane.addEventListener('keydown', (e) => this.#key(e));
    this.button = ui.button('tour');
    this.button.onclick = () => this.toggle(this.pane.hidden === true);
    onLanguageChange(() => this.#show());
  }

  /** @param {{ tour: number, step: number } | null} at a tour link's tour and step (from 1) */
  openAt(at) {
    this.#opening = at;
  }

  /** Fetches the tours of the version on screen (after the manifest). */
  load() {
    this.loaded = this.#fetch();
    return this.loaded;
  }

  async #fetch() {
    const url = `${this.viewer.options.manifestUrl.replace(/\/$/, '')}/tours`;
    /** @type {Tour[]} */
    let tours = [];
    try {
      const response = await fetch(url, { cache: 'no-store' });
      if (response.ok) {
        const body = await response.json();
        if (Array.isArray(body)) tours = body.filter((x) => x && Array.isArray(x.steps) && x.steps.length > 0);
      }
    } catch {
      // No tours: the model is still shown.
    }
    this.tours = tours;
    this.button.hidden = tours.length === 0;
    this.choice.replaceChildren(
      ...tours.map((tour) => {
        const option = document.createElement('option');
        option.value = String(tour.id);
        return option;
      }),
    );
    /** @type {HTMLElement} */ (this.pane.querySelector('.tour-choice')).hidden = tours.length < 2;
    this.#labelChoices();
  }

  /** A level is on screen: a tour link opens its step now (the view at once). */
  async levelShown() {
    const at = this.#opening;
    if (!at) return;
    this.#opening = null;
    await Promise.all([this.loaded, this.viewer.whenCamera(), this.viewer.share.applied]);
    const tour = this.tours.find((x) => x.id === at.tour);
    if (!tour) return;
    this.choose(tour.id, Math.max(0, Math.min(tour.steps.length - 1, at.step - 1)), { instant: true });
    this.toggle(true, { focus: false });
  }

  /**
   * @param {boolean} open
   * @param {{ focus?: boolean }} [options]
   */
  toggle(open, { focus = true } = {}) {
    this.pane.hidden = !open;
    this.button.setAttribute('aria-pressed', String(open));
    if (!open) {
      this.pause();
      return;
    }
    if (!this.tour && this.tours.length > 0) this.choose(this.tours[0].id, 0);
    if (focus) this.pane.focus();
  }

  /**
   * @param {number} id
   * @param {number} step from 0
   * @param {{ instant?: boolean }} [options]
   */
  choose(id, step, { instant = false } = {}) {
    this.tour = this.tours.find((x) => x.id === id) ?? null;
    this.choice.value = String(id);
    this.index = -1;
    this.go(step, { instant });
  }

  /**
   * Puts step `k` on screen (from 0); out of range does nothing.
   * @param {number} k
   * @param {{ instant?: boolean, fromPlay?: boolean }} [options]
   */
  go(k, { instant = false, fromPlay = false } = {}) {
    const tour = this.tour;
    if (!tour || k < 0 || k >= tour.steps.length) return;
    if (!fromPlay) this.pause();
    this.index = k;
    const view = parseView(tour.steps[k].view);
    this.viewer.share.apply(view, { camera: false });
    if (view.camera) this.#moveCamera(view.camera, instant);
    this.#show();
    this.viewer.ui.root.dispatchEvent(
      new CustomEvent('vitrine-tour-step', { detail: { tour: tour.id, step: k + 1 }, bubbles: true, composed: true }),
    );
  }

  play() {
    const tour = this.tour;
    if (!tour) return;
    if (this.index >= tour.steps.length - 1) this.go(0);
    this.playing = true;
    this.#show();
    this.#schedule();
  }

  pause() {
    this.playing = false;
    if (this.#timer) clearTimeout(this.#timer);
    this.#timer = null;
    this.#show();
  }

  #schedule() {
    const tour = this.tour;
    if (!this.playing || !tour) return;
    if (this.#timer) clearTimeout(this.#timer);
    this.#timer = setTimeout(() => {
      this.#timer = null;
      if (!this.playing) return;
      if (this.index >= tour.steps.length - 1) {
        this.pause();
        return;
      }
      this.go(this.index + 1, { fromPlay: true });
      this.#schedule();
    }, dwell(tour.steps[this.index], language()) + this.#moveMs());
  }

  /** No eased moves for visitors who asked for less motion. */
  #moveMs() {
    return globalThis.matchMedia?.('(prefers-reduced-motion: reduce)').matches ? 0 : MOVE_MS;
  }

  /**
   * @param {import('./camera.js').OrbitState} to
   * @param {boolean} instant
   */
  #moveCamera(to, instant) {
    const camera = this.viewer.camera;
    if (!camera) return;
    if (this.#frame !== null) cancelAnimationFrame(this.#frame);
    this.#frame = null;
    const duration = instant ? 0 : this.#moveMs();
    if (duration === 0) {
      this.viewer.share.setCamera(to);
      return;
    }
    const from = structuredClone(camera.state);
    const start = performance.now();
    const frame = (/** @type {number} */ now) => {
      const x = Math.min(1, (now - start) / duration);
      this.viewer.share.setCamera(x >= 1 ? to : between(from, to, ease(x)));
      this.#frame = x >= 1 ? null : requestAnimationFrame(frame);
    };
    this.#frame = requestAnimationFrame(frame);
  }

  /** Whether the camera is still moving to the step (tests wait for it). */
  get moving() {
    return this.#frame !== null;
  }

  /** @param {KeyboardEvent} e */
  #key(e) {
    const onControl = e.target instanceof HTMLButtonElement || e.target instanceof HTMLSelectElement;
    const rtl = getComputedStyle(this.pane).direction === 'rtl';
    const forward = rtl ? 'ArrowLeft' : 'ArrowRight';
    const back = rtl ? 'ArrowRight' : 'ArrowLeft';
    if (e.key === forward || e.key === 'PageDown') this.go(this.index + 1);
    else if (e.key === back || e.key === 'PageUp') this.go(this.index - 1);
    else if (e.key === 'Home') this.go(0);
    else if (e.key === 'End' && this.tour) this.go(this.tour.steps.length - 1);
    else if (e.key === 'p' || e.key === 'P' || (e.key === ' ' && !onControl)) this.playing ? this.pause() : this.play();
    else if (e.key === 'Escape') this.toggle(false);
    else return;
    e.preventDefault();
    e.stopPropagation();
  }

  #labelChoices() {
    const lang = language();
    [...this.choice.options].forEach((option, k) => {
      option.textContent = inLanguage(this.tours[k]?.title, lang) || t('tour.untitled', { n: k + 1 });
    });
  }

  /** Writes the step on screen in the page's language. */
  #show() {
    this.#labelChoices();
    const tour = this.tour;
    const lang = language();
    const step = tour && this.index >= 0 ? tour.steps[this.index] : null;
    this.count.textContent = step && tour ? t('tour.step', { n: this.index + 1, total: tour.steps.length }) : '';
    this.heading.textContent = step ? inLanguage(step.title, lang) : '';
    // The server sanitises `html` (its Markdown renderer).
    if (step) this.body.innerHTML = inLanguage(step.html, lang);
    else this.body.textContent = '';
    this.playButton.textContent = this.playing ? t('tour.pause') : t('tour.play');
    this.playButton.setAttribute('aria-pressed', String(this.playing));
    // aria-disabled rather than disabled: a disabled button would drop the keyboard's focus.
    this.previousButton.setAttribute('aria-disabled', String(!step || this.index === 0));
    this.nextButton.setAttribute('aria-disabled', String(!step || !tour || this.index >= tour.steps.length - 1));
  }
}

export const TOUR_STYLE = `
.tour:focus-visible { outline: 2px solid #88c0d0; }
.tour h3 { font-size: 14px; margin: 4px 0 2px; }
.tour-count { font-size: 12px; color: #cfd5de; }
.tour-body { color: #cfd5de; overflow-wrap: anywhere; }
.tour-body p { margin: 4px 0; }
.tour-keys { font-size: 12px; color: #cfd5de; }
.tour-choice { display: flex; gap: 6px; align-items: center; }
.tour button[aria-disabled="true"] { opacity: 0.5; }
.tour-choice select { font: inherit; color: inherit; background: rgba(20, 22, 26, 0.72); border: 1px solid #4c566a; border-radius: 4px; }
`;
