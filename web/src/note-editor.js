// @ts-check
/**
 * A curator's translations of a note, in the viewer's notes pane: under a
 * selected note, where the page holds a curator token (the one /admin keeps
 * in sessionStorage), "Translate this note" opens a form of its languages
 * (a BCP 47 tag, a title and a Markdown text each), added and removed one
 * at a time and saved together: the note is sent back whole
 * (`PUT /api/models/{slug}/annotations/{id}`) with `translations`, which
 * replace the stored ones; its own language is left as it is. The server
 * checks tags and lengths too; its refusal shows in the status line.
 */

import { call, savedToken } from './admin/api.js';
import { LANGUAGES } from './i18n/languages.js';
import { language, onLanguageChange, t } from './i18n/index.js';

/** The server's limits (server/src/service/curator/annotations.rs). */
export const MAX_TRANSLATIONS = 20;
const TITLE_MAX = 200;
const TEXT_MAX = 10_000;
/** Longest tag the server takes (RFC 5646 §4.4.1). */
const TAG_MAX = 35;
/** A BCP 47 tag's well-formed shape, as the server checks it (RFC 5646 §2.1). */
const TAG = /^[A-Za-z]{1,8}(-[A-Za-z0-9]{1,8})*$/;
/** The list of suggested tags (the viewer's languages), in the viewer's shadow root. */
const TAG_LIST = 'note-language-tags';

/**
 * @typedef {{ title: string, text: string }} NoteTranslationInput
 * @typedef {{ n: number, tag: string, title: string, text: string }} TranslationEntry a form's row, as typed
 * @typedef {{ n: number, root: HTMLFieldSetElement, tag: HTMLInputElement, title: HTMLInputElement,
 *   text: HTMLTextAreaElement }} TranslationRow
 * @typedef {import('./annotations.js').Annotation} Annotation
 */

/** @param {string} tag */
export function isLanguageTag(tag) {
  return tag.length <= TAG_MAX && TAG.test(tag);
}

/**
 * The rows of the form as the `translations` of a replacement, or the reason
 * they cannot be sent (in the viewer's language). A row left empty is skipped.
 * @param {ReadonlyArray<TranslationEntry>} entries
 * @param {string | null} own the note's own language
 * @returns {Record<string, NoteTranslationInput> | string}
 */
export function translationsOf(entries, own) {
  /** @type {Record<string, NoteTranslationInput>} */
  const out = {};
  const seen = new Set();
  for (const entry of entries) {
    const tag = entry.tag.trim();
    const title = entry.title.trim();
    const text = entry.text.trim() ? entry.text : '';
    if (!tag && !title && !text) continue;
    if (!tag) return t('notes.translations.noTag', { n: entry.n });
    if (!isLanguageTag(tag)) return t('notes.translations.badTag', { tag });
    if (own && tag.toLowerCase() === own.toLowerCase()) return t('notes.translations.own', { tag });
    if (seen.has(tag.toLowerCase())) return t('notes.translations.twice', { tag });
    if (!title) return t('notes.translations.noTitle', { n: entry.n });
    seen.add(tag.toLowerCase());
    out[tag] = { title, text };
  }
  if (seen.size > MAX_TRANSLATIONS) return t('notes.translations.tooMany', { max: MAX_TRANSLATIONS });
  return out;
}

/**
 * The language of a tag named in the viewer's language ("Portuguese (pt)"),
 * or the tag alone where the browser cannot name it.
 * @param {string} tag
 */
function languageName(tag) {
  try {
    const name = new Intl.DisplayNames([language()], { type: 'language' }).of(tag);
    return name && name !== tag ? `${name} (${tag})` : tag;
  } catch {
    return tag;
  }
}

/** The curator token of this page, if any (storage may be closed to an embed). */
function curatorToken() {
  try {
    return savedToken();
  } catch {
    return null;
  }
}

/**
 * @param {string} tag
 * @param {Record<string, string>} [attributes]
 * @param {Array<Node | string>} [children]
 */
function el(tag, attributes = {}, children = []) {
  const node = document.createElement(tag);
  for (const [key, value] of Object.entries(attributes)) node.setAttribute(key, value);
  node.append(...children);
  return node;
}

/**
 * An element whose text is the message `key` (with the row's number), written
 * again when the viewer's language changes.
 * @param {string} tag
 * @param {string} key
 * @param {Record<string, string>} [attributes]
 * @param {number} [n]
 */
function worded(tag, key, attributes = {}, n) {
  const node = el(tag, { ...attributes, 'data-note-text': key, ...(n === undefined ? {} : { 'data-n': String(n) }) });
  node.textContent = t(key, n === undefined ? {} : { n });
  return node;
}

/** @param {unknown} e */
function messageOf(e) {
  return e instanceof Error ? e.message : String(e);
}

export class NoteTranslations {
  /** @type {TranslationRow[]} */
  rows = [];
  /** The note the form is for. @type {Annotation | null} */
  note = null;
  /** Numbers rows for their labels and ids; a removed row's number is not reused while the form is open. */
  #next = 1;

  /**
   * @param {object} options
   * @param {(note: Annotation) => string} options.url the note's address (PUT)
   * @param {(answer: unknown) => Annotation | null} options.saved takes the server's answer to a save (the
   *   note as stored) into the list, and gives it back as the viewer reads it
   */
  constructor({ url, saved }) {
    this.url = url;
    this.saved = saved;
    this.opener = /** @type {HTMLButtonElement} */ (worded('button', 'notes.translations.open', { type: 'button', 'aria-expanded': 'false' }));
    this.opener.hidden = true;
    this.opener.addEventListener('click', () => (this.form.hidden ? this.open() : this.close()));
    this.original = el('p', { class: 'note-original' });
    this.list = el('div', { class: 'note-translation-list' });
    this.addButton = worded('button', 'notes.translations.add', { type: 'button' });
    this.addButton.addEventListener('click', () => this.add());
    this.status = el('p', { role: 'status', class: 'note-status' });
    const close = worded('button', 'notes.translations.close', { type: 'button' });
    close.addEventListener('click', () => this.close());
    this.form = /** @type {HTMLFormElement} */ (
      el('form', { class: 'note-translations', 'aria-labelledby': 'note-translations-h' }, [
        worded('h4', 'notes.translations.heading', { id: 'note-translations-h' }),
        this.original,
        this.list,
        this.addButton,
        worded('button', 'notes.translations.save', { type: 'submit' }),
        close,
        el('datalist', { id: TAG_LIST }, LANGUAGES.map((l) => el('option', { value: l.code, label: l.name }))),
      ])
    );
    this.form.hidden = true;
    this.form.addEventListener('submit', (event) => {
      event.preventDefault();
      void this.save();
    });
    this.root = el('div', { class: 'note-curation' }, [this.opener, this.form, this.status]);
    onLanguageChange(() => this.#relabel());
  }

  /**
   * The note now selected: the opener where the page has a curator token; a
   * form open for another note closes.
   * @param {Annotation} note
   */
  show(note) {
    if (this.note?.id !== note.id) this.close({ focus: false });
    this.note = note;
    this.opener.hidden = curatorToken() === null;
    this.status.textContent = '';
  }

  /** Opens the form on the note's translations and moves the focus into it. */
  open() {
    if (!this.note) return;
    this.#fill();
    this.form.hidden = false;
    this.opener.setAttribute('aria-expanded', 'true');
    /** @type {HTMLElement} */ (this.rows[0]?.tag ?? this.addButton).focus();
  }

  /** The note's translations, one row each. */
  #fill() {
    this.rows = [];
    this.#next = 1;
    this.list.replaceChildren();
    for (const [tag, translation] of Object.entries(this.note?.translations ?? {})) this.add(tag, translation, { focus: false });
    this.#original();
  }

  /** @param {{ focus?: boolean }} [options] */
  close({ focus = true } = {}) {
    const inside = this.form.matches(':focus-within');
    this.form.hidden = true;
    this.opener.setAttribute('aria-expanded', 'false');
    if (focus && inside && !this.opener.hidden) this.opener.focus();
  }

  #original() {
    const own = this.note?.language ?? null;
    this.original.textContent = own ? t('notes.translations.original', { language: languageName(own) }) : t('notes.translations.originalUnknown');
  }

  /**
   * A language's fields, empty (one to add) or filled.
   * @param {string} [tag] @param {{ title?: string, text?: string }} [translation]
   * @param {{ focus?: boolean }} [options]
   */
  add(tag = '', translation = {}, { focus = true } = {}) {
    const n = this.#next++;
    const id = `note-translation-${n}`;
    const row = {
      n,
      root: /** @type {HTMLFieldSetElement} */ (el('fieldset', { class: 'note-translation', 'data-translation': String(n) })),
      tag: /** @type {HTMLInputElement} */ (
        el('input', { type: 'text', id: `${id}-tag`, list: TAG_LIST, autocomplete: 'off', spellcheck: 'false', dir: 'ltr', maxlength: String(TAG_MAX) })
      ),
      title: /** @type {HTMLInputElement} */ (el('input', { type: 'text', id: `${id}-title`, maxlength: String(TITLE_MAX), dir: 'auto' })),
      text: /** @type {HTMLTextAreaElement} */ (el('textarea', { id: `${id}-text`, rows: '4', maxlength: String(TEXT_MAX), dir: 'auto' })),
    };
    // The fields speak the language typed beside them (spelling, fonts, a screen reader's voice).
    const speak = () => {
      const lang = row.tag.value.trim();
      for (const field of [row.title, row.text]) {
        if (isLanguageTag(lang)) field.setAttribute('lang', lang);
        else field.removeAttribute('lang');
      }
    };
    row.tag.addEventListener('input', speak);
    row.tag.value = tag;
    row.title.value = translation.title ?? '';
    row.text.value = translation.text ?? '';
    speak();
    const remove = worded('button', 'notes.translations.remove', { type: 'button' }, n);
    remove.addEventListener('click', () => this.remove(row));
    row.root.append(
      worded('legend', 'notes.translations.translation', {}, n),
      worded('label', 'notes.translations.tag', { for: row.tag.id }, n),
      row.tag,
      worded('label', 'notes.translations.title', { for: row.title.id }, n),
      row.title,
      worded('label', 'notes.translations.text', { for: row.text.id }, n),
      row.text,
      remove,
    );
    this.rows.push(row);
    this.list.append(row.root);
    if (focus) row.tag.focus();
  }

  /**
   * Takes a language out of the form (the change is kept on saving); the
   * focus goes to the next language's remove button, else to "Add a language".
   * @param {TranslationRow} row
   */
  remove(row) {
    const at = this.rows.indexOf(row);
    this.rows.splice(at, 1);
    row.root.remove();
    const next = this.rows[at] ?? this.rows[at - 1];
    /** @type {HTMLElement} */ (next?.root.querySelector('button') ?? this.addButton).focus();
    this.status.textContent = t('notes.translations.removed', { n: row.n });
  }

  async save() {
    const note = this.note;
    if (!note) return;
    const entries = this.rows.map((r) => ({ n: r.n, tag: r.tag.value, title: r.title.value, text: r.text.value }));
    const translations = translationsOf(entries, note.language);
    if (typeof translations === 'string') {
      this.status.textContent = t('notes.translations.failed', { reason: translations });
      return;
    }
    this.status.textContent = t('notes.translations.saving');
    // A replacement carries the whole note; its language, left out, stays as it is.
    const body = { title: note.title, text: note.text, position: note.position, normal: note.normal, view: note.savedView, translations };
    try {
      const answer = await call(this.url(note), {
        method: 'PUT',
        headers: { 'Content-Type': 'application/json' },
        body: JSON.stringify(body),
      });
      // Written again as the server keeps them (tags in its spelling); a focus in a field that
      // goes with them moves to the save button.
      const stored = this.saved(answer);
      if (stored) {
        const inList = this.list.matches(':focus-within');
        this.note = stored;
        this.#fill();
        if (inList) /** @type {HTMLElement} */ (this.form.querySelector('button[type="submit"]')).focus();
      }
      this.status.textContent = t('notes.translations.saved');
    } catch (e) {
      this.status.textContent = t('notes.translations.failed', { reason: messageOf(e) });
    }
  }

  /** The form's words in the viewer's language, its values kept. */
  #relabel() {
    for (const node of this.root.querySelectorAll('[data-note-text]')) {
      const n = /** @type {HTMLElement} */ (node).dataset.n;
      node.textContent = t(/** @type {string} */ (/** @type {HTMLElement} */ (node).dataset.noteText), n === undefined ? {} : { n: Number(n) });
    }
    if (this.note) this.#original();
  }
}
