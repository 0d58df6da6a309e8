// @ts-check
/**
 * A model's own words (its title, description and credit line) in the
 * visitor's language, where the museum wrote them in it. The manifest gives
 * the default texts with their language (`language`, null when not stated)
 * and `translations` by BCP 47 tag, each with any of the three fields; the
 * gallery's list gives titles only. For each field on its own, the visitor's
 * preferences are tried in order (the viewer's language, then the browser's):
 * a text whose tag is the preference (case aside) wins, else one of the same
 * primary language (`pt-BR` for `pt`, and `pt` for `pt-BR`); the default
 * text when none matches. A field a translation leaves out is looked for
 * further down the preferences, then taken from the default.
 */

import { language } from './i18n/index.js';

/**
 * @typedef {'title' | 'description' | 'credit'} ContentField
 * @typedef {Partial<Record<ContentField, string>>} ContentTranslation
 * @typedef {object} ContentSource a manifest or a gallery entry
 * @property {string} [title]
 * @property {string} [description]
 * @property {{ credit?: string | null } | null} [rights]
 * @property {string | null} [language] the tag of the default texts
 * @property {Record<string, ContentTranslation> | null} [translations]
 * @typedef {{ text: string, lang: string | null }} ContentText
 */

/**
 * The visitor's languages, most wanted first: the one the viewer speaks,
 * then the browser's.
 * @returns {string[]}
 */
export function visitorLanguages() {
  const browser = typeof navigator === 'undefined' ? [] : (navigator.languages ?? []);
  return [language(), ...browser];
}

/**
 * The best text of `field` for a reader of `preferences`, and its language.
 * @param {ContentSource | null | undefined} source
 * @param {ContentField} field
 * @param {ReadonlyArray<string>} [preferences]
 * @returns {ContentText}
 */
export function chooseText(source, field, preferences = visitorLanguages()) {
  const fallback = defaultText(source, field);
  /** @type {ContentText[]} */
  const candidates = [];
  if (fallback.lang && fallback.text) candidates.push(fallback);
  for (const [tag, translation] of Object.entries(source?.translations ?? {})) {
    const text = translation?.[field];
    if (typeof text === 'string' && text.trim()) candidates.push({ text, lang: tag });
  }
  for (const preference of preferences) {
    const wanted = normalise(preference);
    if (!wanted) continue;
    const exact = candidates.find((c) => normalise(c.lang) === wanted);
    if (exact) return exact;
    const primary = candidates.find((c) => primaryOf(c.lang) === primaryOf(wanted));
    if (primary) return primary;
  }
  return fallback;
}

/**
 * The title, description and credit chosen together (each on its own terms).
 * @param {ContentSource | null | undefined} source
 * @param {ReadonlyArray<string>} [preferences]
 * @returns {Record<ContentField, ContentText>}
 */
export function chooseTexts(source, preferences = visitorLanguages()) {
  return {
    title: chooseText(source, 'title', preferences),
    description: chooseText(source, 'description', preferences),
    credit: chooseText(source, 'credit', preferences),
  };
}

/**
 * Marks an element with the language of the text it shows: `lang` when the
 * language is known, and `dir="auto"` when it is another language than the
 * page's (an Arabic title on an English page, or the reverse, runs its own
 * way). An unknown language leaves the element to the page's.
 * @param {Element} element
 * @param {string | null} lang
 * @param {string} [page] the page's language
 */
export function markLanguage(element, lang, page = language()) {
  element.removeAttribute('lang');
  element.removeAttribute('dir');
  if (!lang) return;
  element.setAttribute('lang', lang);
  if (primaryOf(lang) !== primaryOf(page)) element.setAttribute('dir', 'auto');
}

/**
 * @param {ContentSource | null | undefined} source
 * @param {ContentField} field
 * @returns {ContentText}
 */
function defaultText(source, field) {
  const value = field === 'credit' ? source?.rights?.credit : source?.[field];
  const lang = typeof source?.language === 'string' && source.language.trim() ? source.language.trim() : null;
  return { text: typeof value === 'string' ? value : '', lang };
}

/** @param {string | null | undefined} tag */
function normalise(tag) {
  return (tag ?? '').trim().replace(/_/g, '-').toLowerCase();
}

/** @param {string | null | undefined} tag */
function primaryOf(tag) {
  return normalise(tag).split('-')[0];
}
