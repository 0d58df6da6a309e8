// @ts-check
/**
 * The viewer's words: `t(key, params)` looks a message up in the catalogue
 * of the page's language (one module per language beside this one, English
 * the reference), fills its `{name}` slots, and picks the plural form of
 * `params.count` by `Intl.PluralRules` (Arabic has six). Numbers, byte sizes
 * and dates go through `Intl` in the same locale. Markup built once carries
 * `data-i18n*` attributes and `localise(root)` fills them, again after each
 * change of language (`onLanguageChange`).
 *
 * A museum may put its own words in place of any message, per language,
 * from the service's configuration (`[ui.strings.pt]` in its TOML file):
 * `setOverrides()` takes them, and `t()` prefers them to the catalogue.
 *
 * The rule, which `test/i18n.test.mjs` enforces: no visible text, title,
 * label or alert in web/src outside these catalogues, every key in every
 * catalogue, and no key in a catalogue that English lacks.
 */

import { DEFAULT_LANGUAGE, direction } from './languages.js';
import ar from './ar.js';
import de from './de.js';
import en from './en.js';
import es from './es.js';
import fr from './fr.js';
import it from './it.js';
import pt from './pt.js';

/**
 * A message: text, or its plural forms (`other` always; `one`, `two`,
 * `few`, `many`, `zero` where the language has them).
 * @typedef {string | ({ other: string } & Partial<Record<Intl.LDMLPluralRule, string>>)} Message
 * @typedef {Record<string, Message>} Catalogue
 * @typedef {import('./languages.js').LanguageCode} LanguageCode
 */

/** @type {Record<LanguageCode, Catalogue>} */
export const CATALOGUES = { en, pt, es, fr, de, it, ar };

/** The museum's own words, by language and key (strings only). @type {Partial<Record<string, Record<string, string>>>} */
let overrides = {};

/**
 * The museum's own words in place of the catalogues' (each language a map
 * of key to text; anything that is not text is left out), then the page
 * written again.
 * @param {unknown} map
 */
export function setOverrides(map) {
  /** @type {Record<string, Record<string, string>>} */
  const kept = {};
  if (map && typeof map === 'object') {
    for (const [code, strings] of Object.entries(map)) {
      if (!strings || typeof strings !== 'object') continue;
      kept[code] = Object.fromEntries(Object.entries(strings).filter(([, text]) => typeof text === 'string'));
    }
  }
  overrides = kept;
  for (const listener of listeners) listener(current);
}

/** The language the page speaks now. @type {LanguageCode} */
let current = DEFAULT_LANGUAGE;
/** @type {Set<(code: LanguageCode) => void>} */
const listeners = new Set();
/** @type {Map<string, { plural: Intl.PluralRules, number: Intl.NumberFormat }>} */
const formats = new Map();

/** Made once per language: a formatter per call would set one up for every progress notice. */
function formatsOf(/** @type {LanguageCode} */ code) {
  let f = formats.get(code);
  if (!f) {
    f = { plural: new Intl.PluralRules(code), number: new Intl.NumberFormat(code, { maximumFractionDigits: 0 }) };
    formats.set(code, f);
  }
  return f;
}

export function language() {
  return current;
}

/**
 * Speaks `code` from now on and tells the listeners (the chrome, the page)
 * to write their text again. The document's `lang` and `dir` follow.
 * @param {LanguageCode} code
 */
export function setLanguage(code) {
  const changed = code !== current;
  current = code;
  if (typeof document !== 'undefined') {
    document.documentElement.lang = code;
    document.documentElement.dir = direction(code);
  }
  if (changed) for (const listener of listeners) listener(code);
}

/**
 * @param {(code: LanguageCode) => void} listener
 * @returns {() => void} stops listening
 */
export function onLanguageChange(listener) {
  listeners.add(listener);
  return () => listeners.delete(listener);
}

/**
 * The message `key` in the current language (English where a catalogue
 * lacks it, the key itself where English does: the test sees to both).
 * Numbers in `params` are written in the language's digits and grouping.
 * @param {string} key
 * @param {Record<string, string | number>} [params]
 */
export function t(key, params = {}) {
  const f = formatsOf(current);
  const message = overrides[current]?.[key] ?? CATALOGUES[current][key] ?? en[key] ?? key;
  const text =
    typeof message === 'string'
      ? message
      : (message[f.plural.select(Number(params.count ?? 0))] ?? message.other);
  return text.replace(/\{(\w+)\}/g, (slot, name) => {
    const value = params[name];
    if (value === undefined) return slot;
    return typeof value === 'number' ? f.number.format(value) : value;
  });
}

/**
 * A whole number with the language's grouping (998,560; 998.560; ٩٩٨٬٥٦٠).
 * @param {number} n
 */
export function formatCount(n) {
  return formatsOf(current).number.format(n);
}

/**
 * @param {number} value
 * @param {Intl.NumberFormatOptions} [options]
 */
export function formatNumber(value, options) {
  return new Intl.NumberFormat(current, options).format(value);
}

/**
 * A size in bytes, kilobytes or megabytes (of 1024), unit words as the
 * language writes them.
 * @param {number} bytes
 */
export function formatBytes(bytes) {
  // Bytes in words ("512 bytes": the plural is the language's), the larger units as symbols.
  if (bytes < 1024) return formatNumber(bytes, { style: 'unit', unit: 'byte', unitDisplay: 'long' });
  const [unit, value, digits] = bytes < 1024 * 1024 ? ['kilobyte', bytes / 1024, 1] : ['megabyte', bytes / (1024 * 1024), 2];
  return formatNumber(value, { style: 'unit', unit, minimumFractionDigits: digits, maximumFractionDigits: digits });
}

/**
 * A date (and time, with `time`) in the language's order and month names.
 * @param {Date | number | string} date
 * @param {{ time?: boolean }} [options]
 */
export function formatDate(date, { time = false } = {}) {
  const options = /** @type {Intl.DateTimeFormatOptions} */ (time ? { dateStyle: 'medium', timeStyle: 'short' } : { dateStyle: 'medium' });
  return new Intl.DateTimeFormat(current, options).format(new Date(date));
}

/**
 * Fills the text of markup built once (the root and what is in it) from its attributes: `data-i18n`
 * (text), `data-i18n-title`, `data-i18n-label` (aria-label),
 * `data-i18n-valuetext` (aria-valuetext), `data-i18n-placeholder`.
 * @param {ParentNode} root
 */
export function localise(root) {
  /** @type {Array<[string, (el: HTMLElement, text: string) => void]>} */
  const slots = [
    ['data-i18n', (el, text) => (el.textContent = text)],
    ['data-i18n-title', (el, text) => (el.title = text)],
    ['data-i18n-label', (el, text) => el.setAttribute('aria-label', text)],
    ['data-i18n-valuetext', (el, text) => el.setAttribute('aria-valuetext', text)],
    ['data-i18n-placeholder', (el, text) => el.setAttribute('placeholder', text)],
  ];
  for (const [attribute, write] of slots) {
    // The root itself too: a pane built on its own carries its name on its outermost element.
    const own = 'matches' in root && /** @type {Element} */ (root).matches(`[${attribute}]`) ? [/** @type {Element} */ (root)] : [];
    for (const el of [...own, ...root.querySelectorAll(`[${attribute}]`)]) write(/** @type {HTMLElement} */ (el), t(/** @type {string} */ (el.getAttribute(attribute))));
  }
}
