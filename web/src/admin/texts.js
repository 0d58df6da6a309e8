// @ts-check
/**
 * A version's texts in other languages, in `/admin`: the language its
 * title, description and credit were written in, and their translations
 * (a language tag, and any of title, description and credit line), added
 * and removed one language at a time and saved together
 * (`PUT /api/admin/models/{slug}/versions/{n}/texts` replaces them all).
 * The server checks tags and lengths; its refusal shows in the status line.
 */

import { LANGUAGES } from '../i18n/languages.js';
import { t } from '../i18n/index.js';
import * as api from './api.js';

/** The server's limit on a credit line, in bytes (maxlength counts characters: the server has the last word). */
const CREDIT_MAX = 300;
const TITLE_MAX = 200;
const DESCRIPTION_MAX = 10_000;
/** The id of the list of suggested tags (the viewer's languages), one per page. */
export const TAG_LIST = 'content-language-tags';
/** A language tag's field: Latin letters, left to right on an Arabic page too. */
export const TAG_INPUT = { type: 'text', list: TAG_LIST, autocomplete: 'off', spellcheck: 'false', dir: 'ltr' };
/** Shaped like a BCP 47 tag (the server checks it): only then does it mark the fields' `lang`. */
const PLAUSIBLE_TAG = /^[a-zA-Z]{2,3}(-[a-zA-Z0-9]{1,8})*$/;

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

/** @param {string} text @param {() => unknown} action @param {Record<string, string>} [attributes] */
function button(text, action, attributes = {}) {
  const b = el('button', { type: 'button', ...attributes }, [text]);
  b.addEventListener('click', () => void action());
  return b;
}

/** @param {unknown} e */
function messageOf(e) {
  return e instanceof Error ? e.message : String(e);
}

/**
 * The suggestions offered in every language field: the languages the viewer
 * speaks, each named in itself (any other BCP 47 tag may be typed).
 * Added to the page once.
 */
export function tagSuggestions() {
  const existing = document.getElementById(TAG_LIST);
  if (existing) return existing;
  return el('datalist', { id: TAG_LIST }, LANGUAGES.map((l) => el('option', { value: l.code, label: l.name })));
}

/**
 * @typedef {{ n: number, root: HTMLFieldSetElement, tag: HTMLInputElement, title: HTMLInputElement,
 *   description: HTMLTextAreaElement, credit: HTMLInputElement }} TranslationRow
 */

export class TextsEditor {
  /** @type {TranslationRow[]} */
  rows = [];
  /** Numbers rows for their labels and ids; not reused until the list is written again, so a removed row's id is not taken. */
  #next = 1;

  /** @param {string} slug @param {number} version */
  constructor(slug, version) {
    this.slug = slug;
    this.version = version;
    const v = String(version);
    this.id = `texts-${slug}-${version}`;
    this.status = el('p', { role: 'status' });
    this.original = el('p', { class: 'texts-original' });
    this.language = /** @type {HTMLInputElement} */ (
      el('input', { ...TAG_INPUT, id: `${this.id}-language` })
    );
    this.list = el('div', { class: 'translations' });
    this.addButton = button(t('admin.texts.add'), () => this.add());
    this.saveButton = el('button', { type: 'submit' }, [t('admin.texts.save', { version: v })]);
    const form = /** @type {HTMLFormElement} */ (
      el('form', { class: 'texts-form' }, [
        this.original,
        el('label', { for: this.language.id }, [t('admin.texts.language')]),
        this.language,
        this.list,
        this.addButton,
        this.saveButton,
      ])
    );
    form.addEventListener('submit', (event) => {
      event.preventDefault();
      void this.save();
    });
    this.root = el('section', { class: 'texts', 'aria-labelledby': `${this.id}-h` }, [
      el('h3', { id: `${this.id}-h` }, [t('admin.texts.heading', { version: v })]),
      form,
      this.status,
    ]);
  }

  /** Reads the version's texts from the server and shows them. */
  async load() {
    try {
      this.show(await api.texts(this.slug, this.version));
    } catch (e) {
      this.status.textContent = t('admin.texts.loadFailed', { reason: messageOf(e) });
    }
  }

  /** @param {api.VersionTexts} texts */
  show(texts) {
    this.original.textContent = t('admin.texts.original', { title: texts.title });
    this.language.value = texts.language ?? '';
    this.rows = [];
    this.#next = 1;
    this.list.replaceChildren();
    for (const [tag, translation] of Object.entries(texts.translations ?? {})) this.add(tag, translation, { focus: false });
  }

  /**
   * A translation's fields, empty (a language to add) or filled.
   * @param {string} [tag] @param {api.Translation} [translation]
   * @param {{ focus?: boolean }} [options]
   */
  add(tag = '', translation = {}, { focus = true } = {}) {
    const n = this.#next++;
    const id = `${this.id}-${n}`;
    const input = (/** @type {string} */ name, /** @type {number} */ max) =>
      /** @type {HTMLInputElement} */ (el('input', { type: 'text', id: `${id}-${name}`, maxlength: String(max), dir: 'auto' }));
    const row = {
      n,
      root: /** @type {HTMLFieldSetElement} */ (el('fieldset', { class: 'translation', 'data-translation': String(n) })),
      tag: /** @type {HTMLInputElement} */ (el('input', { ...TAG_INPUT, id: `${id}-tag` })),
      title: input('title', TITLE_MAX),
      description: /** @type {HTMLTextAreaElement} */ (
        el('textarea', { id: `${id}-description`, rows: '3', maxlength: String(DESCRIPTION_MAX), dir: 'auto' })
      ),
      credit: input('credit', CREDIT_MAX),
    };
    row.tag.value = tag;
    // The fields speak the language typed beside them (spelling, fonts, a screen reader's voice).
    const speak = () => {
      const lang = row.tag.value.trim();
      for (const field of [row.title, row.description, row.credit]) {
        if (PLAUSIBLE_TAG.test(lang)) field.setAttribute('lang', lang);
        else field.removeAttribute('lang');
      }
    };
    row.tag.addEventListener('input', speak);
    speak();
    row.title.value = translation.title ?? '';
    row.description.value = translation.description ?? '';
    row.credit.value = translation.credit ?? '';
    row.root.append(
      el('legend', {}, [t('admin.texts.translation', { n })]),
      el('label', { for: row.tag.id }, [t('admin.texts.tag', { n })]),
      row.tag,
      el('label', { for: row.title.id }, [t('admin.texts.title', { n })]),
      row.title,
      el('label', { for: row.description.id }, [t('admin.texts.description', { n })]),
      row.description,
      el('label', { for: row.credit.id }, [t('admin.texts.credit', { n })]),
      row.credit,
      el('div', {}, [button(t('admin.texts.remove', { n }), () => this.remove(row))]),
    );
    this.rows.push(row);
    this.list.append(row.root);
    if (focus) row.tag.focus();
  }

  /**
   * Takes a language out of the form (saved with the rest); the focus goes
   * to the next language's remove button, else to "Add a language".
   * @param {TranslationRow} row
   */
  remove(row) {
    const at = this.rows.indexOf(row);
    this.rows.splice(at, 1);
    row.root.remove();
    const next = this.rows[at] ?? this.rows[at - 1];
    /** @type {HTMLElement} */ ((next?.root.querySelector('button') ?? this.addButton)).focus();
    this.status.textContent = t('admin.texts.removed', { n: row.n });
  }

  /** The form as the PUT's body, or the reason it cannot be sent. @returns {api.VersionTextsChange | string} */
  change() {
    /** @type {Record<string, api.Translation>} */
    const translations = {};
    /** @type {Set<string>} */
    const seen = new Set();
    for (const row of this.rows) {
      const tag = row.tag.value.trim();
      /** @type {api.Translation} */
      const fields = {};
      for (const name of /** @type {const} */ (['title', 'description', 'credit'])) {
        const value = row[name].value.trim();
        if (value) fields[name] = value;
      }
      if (!tag && Object.keys(fields).length === 0) continue;
      if (!tag) return t('admin.texts.noTag', { n: row.n });
      if (seen.has(tag.toLowerCase())) return t('admin.texts.twice', { tag });
      seen.add(tag.toLowerCase());
      translations[tag] = fields;
    }
    return { language: this.language.value.trim() || null, translations };
  }

  async save() {
    const change = this.change();
    if (typeof change === 'string') {
      this.status.textContent = t('admin.texts.failed', { reason: change });
      return;
    }
    this.status.textContent = t('admin.texts.saving');
    try {
      const saved = await api.saveTexts(this.slug, this.version, change);
      // Written again as the server keeps them (tags in its spelling); a focus in a field that
      // goes with them moves to the save button.
      const inList = this.list.contains(document.activeElement);
      this.show(saved);
      if (inList) this.saveButton.focus();
      this.status.textContent = t('admin.texts.saved');
    } catch (e) {
      this.status.textContent = t('admin.texts.failed', { reason: messageOf(e) });
    }
  }
}
