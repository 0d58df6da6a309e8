// @ts-check
/**
 * The language switch in the viewer's chrome, and the page's first choice
 * of language. A choice made with the switch is kept (localStorage) and
 * written into the address (`?lang=`), so a reload, a shared link and the
 * server's `<html lang dir>` agree with it; the page changes language in
 * place, without a reload.
 */

import { LANGUAGES, STORAGE_KEY, chooseLanguage, supportedLanguage } from './languages.js';
import { language, setLanguage, setOverrides } from './index.js';

let started = false;

/**
 * Picks the page's language once: `?lang=`, the visitor's earlier choice,
 * the page's own `<html lang>` (on this server's pages its answer to the
 * browser's `Accept-Language`; on a museum's site, the language of the page
 * around the element), `navigator.languages`, English.
 */
export function startLanguage() {
  if (started) return;
  started = true;
  setOverrides(servedOverrides());
  setLanguage(
    chooseLanguage({
      query: new URLSearchParams(location.search).get('lang'),
      stored: storedChoice(),
      preferred: [document.documentElement.lang, ...(navigator.languages ?? [navigator.language])],
    }),
  );
}

/**
 * The museum's own words, as this server writes them into its pages
 * (`<script type="application/json" id="vitrine-ui-strings">`); none on
 * another site's page or when the element is missing or unreadable.
 * @returns {unknown}
 */
function servedOverrides() {
  const script = typeof document === 'undefined' ? null : document.getElementById('vitrine-ui-strings');
  if (!script?.textContent) return null;
  try {
    return JSON.parse(script.textContent);
  } catch {
    return null;
  }
}

/** @returns {string | null} */
function storedChoice() {
  try {
    return localStorage.getItem(STORAGE_KEY);
  } catch {
    return null; // storage refused (privacy settings, sandboxed iframe)
  }
}

/**
 * The visitor chose `code`: speak it, keep it, put it in the address.
 * @param {string} code
 */
export function chooseLanguageNow(code) {
  const chosen = supportedLanguage(code);
  if (!chosen) return;
  try {
    localStorage.setItem(STORAGE_KEY, chosen);
  } catch {
    // Not kept: the address still carries it.
  }
  const url = new URL(location.href);
  url.searchParams.set('lang', chosen);
  history.replaceState(history.state, '', url);
  setLanguage(chosen);
}

/**
 * A `<select>` of the languages, each named in itself; its label is filled
 * by `localise()` (ui.js), with the chrome's other texts.
 */
export function languageSwitch() {
  const select = document.createElement('select');
  select.className = 'language';
  select.dataset.i18nLabel = 'language.label';
  select.dataset.i18nTitle = 'language.label';
  for (const l of LANGUAGES) {
    const option = document.createElement('option');
    option.value = l.code;
    option.lang = l.code;
    option.dir = l.dir;
    option.textContent = l.name;
    select.append(option);
  }
  select.value = language();
  select.addEventListener('change', () => chooseLanguageNow(select.value));
  return select;
}
