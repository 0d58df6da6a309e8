// @ts-check
/**
 * The catalogue rule (src/i18n/index.js): every UI string comes from the
 * catalogues, every catalogue has the same keys, every key the code uses
 * exists. See test/support/ui-strings.mjs for what the literal scan sees
 * and what it cannot.
 */
import assert from 'node:assert/strict';
import { readFileSync, readdirSync } from 'node:fs';
import { dirname, join, relative } from 'node:path';
import test from 'node:test';
import { fileURLToPath } from 'node:url';
import { CATALOGUES, formatBytes, formatCount, formatDate, onLanguageChange, setLanguage, setOverrides, t } from '../src/i18n/index.js';
import { LANGUAGES, chooseLanguage } from '../src/i18n/languages.js';
import { literalHtmlStrings, literalUiStrings } from './support/ui-strings.mjs';

const src = join(dirname(fileURLToPath(import.meta.url)), '..', 'src');
const en = CATALOGUES.en;
const keys = new Set(Object.keys(en));

/** @param {string} file relative to src/ */
const catalogue = (file) => LANGUAGES.some((l) => file === join('i18n', `${l.code}.js`));

/** Sources of the page, the element and the workers; the catalogues themselves left out. */
function sources() {
  /** @type {string[]} */
  const files = [];
  const walk = (/** @type {string} */ dir) => {
    for (const entry of readdirSync(dir, { withFileTypes: true })) {
      const path = join(dir, entry.name);
      if (entry.isDirectory()) {
        walk(path);
      } else if (/\.(js|html)$/.test(entry.name) && !catalogue(relative(src, path))) files.push(relative(src, path));
    }
  };
  walk(src);
  return files.sort();
}

/**
 * Text that stays as it is in every language, with the reason.
 * @type {Array<{ file: string, text: string, why: string }>}
 */
const ALLOWED = [
  { file: 'index.html', text: 'Vitrine', why: "the product's name, the tab's title until the page sets one" },
  {
    file: 'index.html',
    text: 'The Vitrine viewer needs JavaScript and WebGL2.',
    why: 'shown only without JavaScript, so no catalogue can reach it',
  },
];

test('no UI string outside the catalogues', () => {
  /** @type {string[]} */
  const found = [];
  for (const file of sources()) {
    const text = readFileSync(join(src, file), 'utf8');
    const findings = file.endsWith('.html') ? literalHtmlStrings(text) : literalUiStrings(text, keys);
    const left = findings.filter((f) => !ALLOWED.some((a) => a.file === file && a.text === f.text));
    for (const f of left) found.push(`${file}:${f.line} (${f.rule}): ${JSON.stringify(f.text)}`);
  }
  assert.deepEqual(found, [], `literal UI strings; put them in src/i18n/*.js and use t():\n${found.join('\n')}`);
});

test('the scan catches a planted literal of every kind, and leaves keys alone', () => {
  const planted = `
    node.textContent = 'Hello visitor';
    node.title = ready ? t('tools.reset') : 'Not ready yet';
    node.setAttribute('aria-label', \`Close \${name}\`);
    alert("Saved the model");
    list.append(el('li', { class: 'x' }, ['Nothing here']));
    el('img', { alt: 'A vase', src });
    box.innerHTML = '<p>Welcome</p><button title="Open the pane">+</button>';
    row.append(\`\${count} levels\`);
  `;
  const texts = literalUiStrings(planted, keys).map((f) => f.text);
  for (const text of ['Hello visitor', 'Not ready yet', 'Close  ', 'Saved the model', 'Nothing here', 'A vase', 'Welcome', 'Open the pane', '  levels']) {
    assert.ok(texts.includes(text), `missed ${JSON.stringify(text)} in ${JSON.stringify(texts)}`);
  }
  const clean = `
    node.textContent = t('measure.first');
    node.title = t('tools.reset.title');
    node.setAttribute('aria-label', t('notes.label', { n, title }));
    el('li', {}, [t('gallery.empty'), m.title, '·']);
    box.innerHTML = '<h2 data-i18n="measure.heading"></h2><button data-axis="x">X</button>';
    const texts = { loading: 'colour.loading' };
    // node.textContent = 'in a comment';
  `;
  assert.deepEqual(literalUiStrings(clean, keys), []);
  assert.deepEqual(
    literalHtmlStrings('<p title="Hover text">Some words</p><script>x = "<b>code</b>"</script>').map((f) => f.text),
    ['Some words', 'Hover text'],
  );
});

test('every catalogue has exactly the English keys, slots and plural forms', () => {
  for (const { code } of LANGUAGES) {
    const catalogue = CATALOGUES[code];
    const missing = [...keys].filter((k) => !(k in catalogue));
    const extra = Object.keys(catalogue).filter((k) => !keys.has(k));
    assert.deepEqual({ missing, extra }, { missing: [], extra: [] }, code);
    // The forms whole numbers take (French and Portuguese have a "many" only for millions in compact notation).
    const rules = new Intl.PluralRules(code);
    const categories = new Set(Array.from({ length: 1001 }, (_, n) => rules.select(n)));
    for (const key of keys) {
      const message = catalogue[key];
      const forms = typeof message === 'string' ? [message] : Object.values(message);
      const slots = (/** @type {string} */ s) => [...s.matchAll(/\{(\w+)\}/g)].map((m) => m[1]).filter((n) => n !== 'count');
      const english = en[key];
      const expected = new Set(slots(typeof english === 'string' ? english : english.other));
      for (const form of forms) {
        assert.ok(form.trim(), `${code} ${key}: empty`);
        assert.deepEqual(new Set(slots(form)), expected, `${code} ${key}: slots`);
      }
      if (typeof message !== 'string') {
        for (const c of categories) assert.ok(c in message || c === 'other', `${code} ${key}: no "${c}" form`);
        assert.ok('other' in message, `${code} ${key}: no "other" form`);
      }
    }
  }
});

test('every key the code names exists, and every key is used', () => {
  const namespaces = new Set([...keys].map((k) => k.split('.')[0]));
  /** @type {Set<string>} */
  const used = new Set();
  /** @type {string[]} */
  const prefixes = [];
  for (const file of sources()) {
    const text = readFileSync(join(src, file), 'utf8');
    for (const m of text.matchAll(/['"]([a-z][a-zA-Z]*(?:\.[a-zA-Z]+)+)['"]/g)) {
      if (namespaces.has(m[1].split('.')[0])) used.add(m[1]);
    }
    // A key made at run time (`cap.device.${device}`) covers its family.
    for (const m of text.matchAll(/\bt\(`([a-z][\w.]*\.)\$\{/g)) prefixes.push(m[1]);
  }
  const unknown = [...used].filter((k) => !keys.has(k));
  assert.deepEqual(unknown, [], 'keys used in code but missing from the catalogues');
  const unused = [...keys].filter((k) => !used.has(k) && !prefixes.some((p) => k.startsWith(p)));
  assert.deepEqual(unused, [], 'keys in the catalogues that no code uses');
});

test('t() fills slots, picks plural forms and writes numbers in the language', () => {
  setLanguage('en');
  assert.equal(t('gallery.levels', { count: 1 }), '1 level');
  assert.equal(t('gallery.levels', { count: 12000 }), '12,000 levels');
  assert.equal(t('notes.label', { n: 2, title: 'Front' }), 'Note 2: Front');
  setLanguage('ar');
  assert.equal(t('gallery.levels', { count: 2 }), 'مستويان');
  assert.equal(t('gallery.levels', { count: 3 }), '3 مستويات');
  assert.equal(t('gallery.levels', { count: 11 }), '11 مستوى');
  setLanguage('pt');
  assert.equal(t('gallery.levels', { count: 1 }), '1 nível');
  assert.equal(formatCount(998560), '998.560');
  assert.equal(formatBytes(89588), '87,5 kB');
  setLanguage('de');
  assert.equal(formatDate(Date.UTC(2026, 0, 15, 12)), '15.01.2026');
  setLanguage('en');
  assert.equal(formatBytes(512), '512 bytes');
  assert.equal(formatBytes(1), '1 byte');
});

test('the language is ?lang=, then the kept choice, then the browser, then English', () => {
  assert.equal(chooseLanguage({ query: 'ar', stored: 'fr', preferred: ['de'] }), 'ar');
  assert.equal(chooseLanguage({ query: 'xx', stored: 'fr', preferred: ['de'] }), 'fr');
  assert.equal(chooseLanguage({ query: null, stored: null, preferred: ['ja', 'pt-BR', 'de'] }), 'pt');
  assert.equal(chooseLanguage({ preferred: ['ja'] }), 'en');
});

test("a museum's own words replace a message per language, and only where given", () => {
  setLanguage('en');
  /** @type {string[]} */
  const heard = [];
  const stop = onLanguageChange((code) => heard.push(code));
  setOverrides({ en: { 'page.allModels': '← All stories', 'gallery.levels': 42 }, pt: { 'page.allModels': '← Todas as histórias' }, xx: 'no' });
  assert.equal(t('page.allModels'), '← All stories');
  assert.equal(t('gallery.levels', { count: 2 }), '2 levels', 'a value that is not text is left out');
  assert.deepEqual(heard, ['en'], 'the page is written again');
  setLanguage('pt');
  assert.equal(t('page.allModels'), '← Todas as histórias');
  assert.equal(t('page.embed'), 'Incorporar este modelo', 'the catalogue where nothing is given');
  setLanguage('de');
  assert.equal(t('page.allModels'), '← Alle Modelle');
  setOverrides(null);
  setLanguage('en');
  assert.equal(t('page.allModels'), '← All models');
  stop();
});
