// @ts-check
/**
 * The curators' notes on a model (`GET /api/models/{slug}/annotations`): a
 * marker on the model for each, anchored at its point in model space (so
 * it stays on the surface at every level) and carried through the model's
 * rotation and the camera to the screen; hidden when its normal faces away
 * or the surface hides it (a ray cast on the level on screen, after the
 * camera stops); a list panel; markers and list items are buttons (Tab,
 * Enter); selecting one shows its text, restores its saved view and is
 * announced to screen readers. A server without the route (404) means no
 * notes, and the viewer shows none of this. A note's title and text show in
 * the visitor's language where the curators translated it (the same choice
 * as the model's own texts, content-language.js), marked with their language;
 * note-editor.js lets a curator write the translations.
 */

import { chooseText, markLanguage, visitorLanguages } from './content-language.js';
import { formatCount, localise, onLanguageChange, t } from './i18n/index.js';
import { NoteTranslations } from './note-editor.js';
import { rotate } from './frame.js';
import { diagonal, levelHausdorff } from './measure.js';
import { projectPoint } from './pick.js';

/** @typedef {[number, number, number]} Vec3 */
/**
 * @typedef {object} Annotation
 * @property {string | number} id
 * @property {string} title
 * @property {string} text plain text (the Markdown source)
 * @property {string | null} html sanitised HTML from the server (inserted as HTML only because the server sanitises it)
 * @property {Vec3} position model coordinates
 * @property {Vec3} normal
 * @property {import('./camera.js').OrbitState | null} view
 * @property {unknown} savedView the view as served (sent back as it is when a curator saves the note)
 * @property {string | null} language BCP 47 tag of `title` and `text`, null when not stated
 * @property {Record<string, NoteText>} translations the title and text in other languages, by tag
 */
/**
 * @typedef {object} NoteText
 * @property {string} title
 * @property {string} text the Markdown source
 * @property {string | null} html sanitised by the server, as the note's own
 */
/** A note as shown: its text in one language. @typedef {NoteText & { lang: string | null }} ShownNote */

/** Where each marker is on screen (tests read it). @typedef {{ id: string | number, x: number, y: number, visible: boolean }} Placed */

/** Wait this long after the camera stops before the occlusion test. */
const SETTLE_MS = 120;

/**
 * Keeps the entries the viewer can place, in order; anything else is dropped.
 * @param {unknown} body
 * @returns {Annotation[]}
 */
export function parseAnnotations(body) {
  if (!Array.isArray(body)) return [];
  const vec = (/** @type {any} */ v) => Array.isArray(v) && v.length === 3 && v.every((x) => typeof x === 'number' && Number.isFinite(x));
  /** @type {Annotation[]} */
  const out = [];
  for (const a of body) {
    if (!a || typeof a !== 'object' || !vec(a.position) || !vec(a.normal)) continue;
    const v = a.view;
    const view =
      v && vec(v.target) && [v.distance, v.yaw, v.pitch].every((x) => typeof x === 'number' && Number.isFinite(x)) && v.distance > 0
        ? { target: v.target, distance: v.distance, yaw: v.yaw, pitch: v.pitch }
        : null;
    out.push({
      id: a.id ?? out.length,
      title: typeof a.title === 'string' ? a.title : '',
      text: typeof a.text === 'string' ? a.text : '',
      html: typeof a.html === 'string' ? a.html : null,
      position: a.position,
      normal: a.normal,
      view,
      savedView: a.view ?? null,
      language: typeof a.language === 'string' && a.language.trim() ? a.language.trim() : null,
      translations: parseTranslations(a.translations),
    });
  }
  return out;
}

/**
 * The translations that have a title; the rest is dropped.
 * @param {unknown} value
 * @returns {Record<string, NoteText>}
 */
function parseTranslations(value) {
  /** @type {Record<string, NoteText>} */
  const out = {};
  if (!value || typeof value !== 'object' || Array.isArray(value)) return out;
  for (const [tag, entry] of Object.entries(value)) {
    if (!entry || typeof entry.title !== 'string' || !entry.title.trim()) continue;
    out[tag] = {
      title: entry.title,
      text: typeof entry.text === 'string' ? entry.text : '',
      html: typeof entry.html === 'string' ? entry.html : null,
    };
  }
  return out;
}

/**
 * A note in the language its reader prefers: the visitor's languages in
 * order, an exact tag before one of the same primary language, the note's
 * own words when none matches. Title and text go together.
 * @param {Annotation} a
 * @param {ReadonlyArray<string>} [preferences]
 * @returns {ShownNote}
 */
export function noteInLanguage(a, preferences = visitorLanguages()) {
  const titles = Object.fromEntries(Object.entries(a.translations).map(([tag, { title }]) => [tag, { title }]));
  const { lang } = chooseText({ title: a.title, language: a.language, translations: titles }, 'title', preferences);
  const translation = lang !== null && lang !== a.language ? a.translations[lang] : undefined;
  return translation ? { ...translation, lang } : { title: a.title, text: a.text, html: a.html, lang: a.language };
}

export class Annotations {
  /** @type {Annotation[]} */
  list = [];
  /** @type {Placed[]} */
  placed = [];
  /** @type {Annotation | null} */
  selected = null;
  /** Hidden by the surface at the last test, by id. @type {Set<string | number>} */
  #occluded = new Set();
  /** @type {ReturnType<typeof setTimeout> | null} */
  #settle = null;
  /** @type {HTMLButtonElement[]} */
  #markers = [];

  /** @param {import('./viewer.js').Viewer} viewer */
  constructor(viewer) {
    this.viewer = viewer;
    const ui = viewer.ui;
    this.pane = document.createElement('section');
    this.pane.className = 'notes pill';
    this.pane.dataset.i18nLabel = 'notes.pane';
    this.pane.hidden = true;
    this.pane.innerHTML =
      '<h2 data-i18n="notes.heading"></h2><ol class="note-list"></ol><div class="note-detail" hidden><h3></h3><div class="note-body"></div></div>';
    localise(this.pane);
    ui.panes.append(this.pane);
    this.editor = new NoteTranslations({
      url: (a) => `${this.#url()}/${encodeURIComponent(String(a.id))}`,
      saved: (answer) => this.#replace(answer),
    });
    /** @type {HTMLElement} */ (this.pane.querySelector('.note-detail')).append(this.editor.root);
    // The pane's fixed texts follow with the chrome (ui.js); the notes' labels and texts, in the
    // visitor's language, are written here.
    onLanguageChange(() => {
      this.#label();
      if (this.selected) this.#show(this.selected);
    });
    this.button = ui.button('notes');
    this.button.onclick = () => this.toggle(this.pane.hidden === true);
  }

  /** @param {boolean} open */
  toggle(open) {
    this.pane.hidden = !open;
    this.button.setAttribute('aria-pressed', String(open));
  }

  /** Settles once the notes of the model are in (or known to be none). @type {Promise<void>} */
  loaded = Promise.resolve();

  /** Fetches the model's notes (after the manifest). */
  load() {
    this.loaded = this.#fetch();
    return this.loaded;
  }

  /** The model's notes' address. */
  #url() {
    return `${this.viewer.options.manifestUrl.replace(/\/$/, '')}/annotations`;
  }

  async #fetch() {
    /** @type {Annotation[]} */
    let list = [];
    try {
      const response = await fetch(this.#url(), { cache: 'no-store' });
      if (response.ok) list = parseAnnotations(await response.json());
    } catch {
      // No notes: the model is still shown.
    }
    this.#set(list);
  }

  /** @param {Annotation[]} list */
  #set(list) {
    this.list = list;
    this.#occluded.clear();
    this.button.hidden = list.length === 0;
    const items = /** @type {HTMLElement} */ (this.pane.querySelector('.note-list'));
    items.replaceChildren();
    for (const m of this.#markers) m.remove();
    this.#markers = [];
    list.forEach((a, k) => {
      const li = document.createElement('li');
      const item = document.createElement('button');
      item.type = 'button';
      item.className = 'note-item';
      item.onclick = () => this.select(a);
      li.append(item);
      items.append(li);
      const marker = document.createElement('button');
      marker.type = 'button';
      marker.className = 'marker';
      marker.textContent = formatCount(k + 1);
      marker.hidden = true;
      marker.onclick = () => this.select(a);
      this.viewer.ui.markers.append(marker);
      this.#markers.push(marker);
    });
    this.#label();
    this.place();
  }

  /**
   * The list's and the markers' names in the page's language ("Note 2: Front"), each note's
   * title in the visitor's language where it was translated.
   */
  #label() {
    const items = this.pane.querySelectorAll('.note-item');
    this.list.forEach((a, k) => {
      const n = k + 1;
      const shown = noteInLanguage(a);
      items[k].textContent = shown.title || t('notes.untitled', { n });
      markLanguage(items[k], shown.title ? shown.lang : null);
      this.#markers[k].textContent = formatCount(n);
      this.#markers[k].title = shown.title;
      this.#markers[k].setAttribute('aria-label', t('notes.label', { n, title: shown.title }));
    });
  }

  /**
   * Takes a note as the server stored it after a curator's save in place of the one listed.
   * @param {unknown} answer
   * @returns {Annotation | null}
   */
  #replace(answer) {
    const [note] = parseAnnotations([answer]);
    const at = this.list.findIndex((a) => String(a.id) === String(note?.id));
    if (!note || at < 0) return null;
    this.list[at] = note;
    this.#markers[at].onclick = () => this.select(note);
    /** @type {HTMLButtonElement} */ (this.pane.querySelectorAll('.note-item')[at]).onclick = () => this.select(note);
    this.#label();
    if (String(this.selected?.id) === String(note.id)) {
      this.selected = note;
      this.#show(note);
    }
    return note;
  }

  /**
   * Shows a note's text, restores its saved view and announces it.
   * @param {Annotation} a
   * @param {{ camera?: boolean }} [options] `camera: false` keeps the camera where it is (a shared view sets it)
   */
  select(a, { camera: moveCamera = true } = {}) {
    this.selected = a;
    this.toggle(true);
    const shown = this.#show(a);
    this.editor.show(a);
    this.#markers.forEach((m, k) => m.setAttribute('aria-current', this.list[k] === a ? 'true' : 'false'));
    // Announced in the note's language.
    const announcement = document.createElement('span');
    announcement.textContent = `${shown.title}. ${shown.body}`.trim();
    markLanguage(announcement, shown.lang);
    this.viewer.ui.live.replaceChildren(announcement);
    const camera = this.viewer.camera;
    if (moveCamera && a.view && camera) {
      camera.state = structuredClone(a.view);
      this.viewer.renderer?.requestFrame();
      this.viewer.cameraMoved();
    }
  }

  /**
   * Writes a note's title and text in the visitor's language into the detail.
   * @param {Annotation} a
   * @returns {{ title: string, body: string, lang: string | null }}
   */
  #show(a) {
    const shown = noteInLanguage(a);
    const detail = /** @type {HTMLElement} */ (this.pane.querySelector('.note-detail'));
    detail.hidden = false;
    const heading = /** @type {HTMLElement} */ (detail.querySelector('h3'));
    heading.textContent = shown.title;
    markLanguage(heading, shown.lang);
    const body = /** @type {HTMLElement} */ (detail.querySelector('.note-body'));
    // The server sanitises `html` (its Markdown renderer); without it, the text stays text.
    if (shown.html !== null) body.innerHTML = shown.html;
    else body.textContent = shown.text;
    markLanguage(body, shown.lang);
    return { title: shown.title, body: body.textContent ?? '', lang: shown.lang };
  }

  /** A new level is on screen: the surface that may hide a marker changed. */
  levelShown() {
    this.#scheduleOcclusion();
  }

  /** Puts every marker where its point is on screen now (camera moved, resized). */
  place() {
    const camera = this.viewer.camera;
    const canvas = this.viewer.ui.canvas;
    const width = canvas.clientWidth;
    const height = canvas.clientHeight;
    if (!camera || this.list.length === 0 || width === 0 || height === 0) {
      this.placed = [];
      for (const m of this.#markers) m.hidden = true;
      return;
    }
    const model = this.viewer.look.model;
    const { eye } = camera.basis();
    this.placed = this.list.map((a, k) => {
      const p = projectPoint(camera, model, a.position, width, height);
      const world = rotate(model, a.position);
      const n = rotate(model, a.normal);
      const facing = n[0] * (eye[0] - world[0]) + n[1] * (eye[1] - world[1]) + n[2] * (eye[2] - world[2]) > 0;
      const onScreen = p.inFront && p.x >= 0 && p.y >= 0 && p.x <= width && p.y <= height;
      // A point the section plane cuts away goes with it.
      const section = this.viewer.look.section;
      const cut = section !== null && world[0] * section[0] + world[1] * section[1] + world[2] * section[2] > section[3] + 1e-6 * diagonal(camera.box);
      const visible = onScreen && facing && !cut && !this.#occluded.has(a.id) && this.viewer.state.shownLevel >= 0;
      const marker = this.#markers[k];
      marker.hidden = !visible;
      marker.style.transform = `translate(${p.x}px, ${p.y}px) translate(-50%, -50%)`;
      return { id: a.id, x: p.x, y: p.y, visible };
    });
    this.#scheduleOcclusion();
  }

  #scheduleOcclusion() {
    if (this.list.length === 0) return;
    if (this.#settle) clearTimeout(this.#settle);
    this.#settle = setTimeout(() => void this.#testOcclusion(), SETTLE_MS);
  }

  /** Asks the renderer which points the level on screen hides, then places the markers again. */
  async #testOcclusion() {
    this.#settle = null;
    const { camera, renderer, manifest } = this.viewer;
    if (!camera || !renderer || !manifest) return;
    const model = this.viewer.look.model;
    const { eye } = camera.basis();
    // Eye in model coordinates: the rotation's transpose.
    const eyeModel = [0, 1, 2].map((k) => model[3 * k] * eye[0] + model[3 * k + 1] * eye[1] + model[3 * k + 2] * eye[2]);
    const level = this.viewer.state.shownLevel;
    const h = levelHausdorff(manifest, level);
    const diag = diagonal(camera.box);
    // A coarse level's surface lies within its Hausdorff distance of the point, on either side.
    const tolerance = Math.max(0.01 * diag, 2 * (h ?? 0) * diag);
    const hidden = await renderer.occlusion(eyeModel, this.list.map((a) => a.position), tolerance);
    const before = [...this.#occluded].join();
    this.#occluded = new Set(this.list.filter((_, k) => hidden[k]).map((a) => a.id));
    if ([...this.#occluded].join() !== before) {
      this.place();
      if (this.#settle) clearTimeout(this.#settle);
      this.#settle = null;
    }
    this.checked = { level, camera: JSON.stringify(camera.state) };
  }

  /** The level and camera of the last occlusion test (tests wait for it). @type {{ level: number, camera: string } | null} */
  checked = null;
}

export const NOTES_STYLE = `
.notes h2 { font-size: 14px; margin: 0 0 4px; }
.notes h3 { font-size: 14px; margin: 8px 0 2px; }
.note-list { margin: 0; padding-left: 1.4em; }
.note-list button { min-height: 32px; padding: 2px 8px; text-align: left; }
.note-body { color: #cfd5de; overflow-wrap: anywhere; }
.note-body p { margin: 4px 0; }
.marker { position: absolute; left: 0; top: 0; pointer-events: auto; min-height: 0; width: 28px; height: 28px; padding: 0;
  border-radius: 50%; background: #ebcb8b; color: #1d2026; border: 2px solid #1d2026; font-weight: 700; font-size: 13px; }
.marker:hover { background: #f3dca8; }
.note-curation { margin-top: 8px; }
.note-translations h4 { font-size: 13px; margin: 8px 0 2px; }
.note-translations fieldset { border: 1px solid #4c566a; border-radius: 6px; margin: 6px 0; padding: 4px 8px 8px; }
.note-translations label { display: block; margin-top: 4px; }
.note-translations input, .note-translations textarea { display: block; width: 100%; box-sizing: border-box; font: inherit;
  color: #eceff4; background: #1d2026; border: 1px solid #81a1c1; border-radius: 4px; padding: 4px 6px; }
.note-translations input:focus-visible, .note-translations textarea:focus-visible { outline: 2px solid #88c0d0; outline-offset: 1px; }
.note-translations button { margin-block-start: 6px; margin-inline-end: 6px; }
.note-original, .note-status { color: #cfd5de; margin: 4px 0; }
.marker[aria-current="true"] { background: #88c0d0; }
`;
