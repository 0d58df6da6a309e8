// @ts-check
/**
 * The languages the viewer speaks, and how a page picks one: `?lang=`, then
 * the visitor's own earlier choice (the switch keeps it in localStorage),
 * then the browser's languages in order, then English. The server reads
 * `?lang=` and `Accept-Language` the same way for the page's `<html lang dir>`
 * (server/src/service/language.rs lists the same codes).
 */

/**
 * @typedef {'en' | 'pt' | 'es' | 'fr' | 'de' | 'it' | 'ar'} LanguageCode
 * @typedef {{ code: LanguageCode, name: string, dir: 'ltr' | 'rtl' }} Language
 */

/** Each language named in itself, as the switch lists it. @type {ReadonlyArray<Language>} */
export const LANGUAGES = [
  { code: 'en', name: 'English', dir: 'ltr' },
  { code: 'pt', name: 'Português', dir: 'ltr' },
  { code: 'es', name: 'Español', dir: 'ltr' },
  { code: 'fr', name: 'Français', dir: 'ltr' },
  { code: 'de', name: 'Deutsch', dir: 'ltr' },
  { code: 'it', name: 'Italiano', dir: 'ltr' },
  { code: 'ar', name: 'العربية', dir: 'rtl' },
];

/** @type {LanguageCode} */
export const DEFAULT_LANGUAGE = 'en';

/** Where the switch keeps the visitor's choice. */
export const STORAGE_KEY = 'vitrine-lang';

/**
 * The supported language a BCP 47 tag belongs to (`pt-BR` → `pt`), or null.
 * @param {string | null | undefined} tag
 * @returns {LanguageCode | null}
 */
export function supportedLanguage(tag) {
  const primary = tag?.trim().split(/[-_]/)[0].toLowerCase();
  return LANGUAGES.find((l) => l.code === primary)?.code ?? null;
}

/**
 * The first supported language among the candidates, in order of preference.
 * @param {{ query?: string | null, stored?: string | null, preferred?: ReadonlyArray<string> }} candidates
 * @returns {LanguageCode}
 */
export function chooseLanguage({ query = null, stored = null, preferred = [] }) {
  for (const tag of [query, stored, ...preferred]) {
    const code = supportedLanguage(tag);
    if (code) return code;
  }
  return DEFAULT_LANGUAGE;
}

/** @param {LanguageCode} code */
export function direction(code) {
  return LANGUAGES.find((l) => l.code === code)?.dir ?? 'ltr';
}
